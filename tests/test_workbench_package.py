"""The Addon Manager metadata (package.xml): schema fields present, consistent with pyproject and the code,
and read by FreeCAD's own metadata parser."""

from __future__ import annotations

import ast
import re
import tomllib
import xml.etree.ElementTree as ET

import pytest

import spur_cad
from tests.freecad_helper import describe, run_freecad_code
from tests.workbench_helper import ROOT

NS = {"p": "https://wiki.freecad.org/Package_Metadata"}


@pytest.fixture(scope="module")
def package():
    return ET.parse(ROOT / "package.xml").getroot()


@pytest.fixture(scope="module")
def pyproject():
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]


def _text(root, path: str) -> str:
    element = root.find(path, NS)
    assert element is not None, f"package.xml has no {path}"
    return (element.text or "").strip()


def test_required_fields_are_present(package):
    assert package.tag == "{https://wiki.freecad.org/Package_Metadata}package" and package.get("format") == "1"
    assert _text(package, "p:name") == "spur_cad"
    assert len(_text(package, "p:description")) > 20
    assert re.fullmatch(r"\d{4}-\d{2}-\d{2}", _text(package, "p:date"))
    maintainer = package.find("p:maintainer", NS)
    assert maintainer is not None and maintainer.get("email") and maintainer.text.strip()
    assert package.find("p:url", NS).get("type") == "repository"


def test_version_and_licence_match_pyproject(package, pyproject):
    assert _text(package, "p:version") == pyproject["version"] == spur_cad.__version__
    licence = package.find("p:license", NS)
    assert licence.text.strip() == pyproject["license"]["text"]
    assert (ROOT / licence.get("file")).is_file()
    assert "Apache License" in (ROOT / licence.get("file")).read_text()[:200]


def test_icon_exists(package):
    icon = ROOT / _text(package, "p:icon")
    assert icon.suffix == ".svg" and icon.is_file()
    ET.parse(icon)


def test_workbench_entry_names_the_class_and_a_loadable_subdirectory(package):
    workbench = package.find("p:content/p:workbench", NS)
    assert workbench is not None
    classname = _text(workbench, "p:classname")
    folder = ROOT / _text(workbench, "p:subdirectory")
    assert (folder / "Init.py").is_file() and (folder / "InitGui.py").is_file()
    tree = ast.parse((folder / "InitGui.py").read_text())
    classes = {node.name for node in tree.body if isinstance(node, ast.ClassDef)}
    assert classname in classes
    calls = [node for node in ast.walk(tree) if isinstance(node, ast.Call)
             and getattr(node.func, "attr", "") == "addWorkbench"]
    assert len(calls) == 1 and calls[0].args[0].func.id == classname
    assert re.fullmatch(r"\d+\.\d+\.\d+", _text(workbench, "p:freecadmin"))


def test_python_dependencies_cover_pyprojects(package, pyproject):
    depends = {d.text.strip() for d in package.findall("p:depend", NS) if d.get("type") == "python"}
    required = {re.split(r"[<>=!~ \[]", spec, maxsplit=1)[0].lower() for spec in pyproject["dependencies"]}
    assert required <= depends


@pytest.mark.freecad
def test_freecad_reads_the_metadata(freecadcmd, tmp_path):
    """FreeCAD 0.20's own parser (the one InitApplications and the Addon Manager use) accepts the file."""
    body = f"""
import FreeCAD
meta = FreeCAD.Metadata({str(ROOT / "package.xml")!r})
workbench = meta.Content["workbench"][0]
RESULT.update(name=meta.Name, version=meta.Version, classname=workbench.Classname,
              subdirectory=workbench.Subdirectory, supported=meta.supportsCurrentFreeCAD(),
              depends=[d["package"] for d in meta.Depend], licence=meta.License[0]["name"])
"""
    result, proc = run_freecad_code(body, tmp_path, freecadcmd=freecadcmd)
    assert result is not None and result.get("ok"), describe(proc, result)
    assert result["name"] == "spur_cad" and result["version"] == "0.1.0"
    assert result["classname"] == "SpurCadWorkbench" and result["subdirectory"] == "./workbench"
    assert result["supported"] is True and result["licence"] == "Apache-2.0"
    assert {"numpy", "scipy", "matplotlib", "cadquery", "build123d"} <= set(result["depends"])
