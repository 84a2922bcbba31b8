"""The Addon Manager metadata (package.xml): consistent with pyproject and the code, read by FreeCAD's own
metadata parser, and valid under the rules FreeCAD and the Addon Manager apply to it.

Where the rules come from (read in their sources; none of their code is copied here):
- FreeCAD/AddonManager at commit 23e7ee0cfc4baeeadc71f69b72e379ebd95d8450 (2026-07-22), the Addon Manager
  FreeCAD 1.x ships: addonmanager_metadata.py (MetadataReader: the namespace is taken from the root
  <package>, version strings must start with a digit, url types and dependency types by name);
  Addon.py (version_is_ok: FreeCAD.Version() as [major, minor, patch, revision] must lie within
  freecadmin..freecadmax of each metadata level; extract_metadata_dependencies: <depend type="python">
  become pip requirements, <pythonmin> the minimum Python; a repository url without a branch means
  "master"); addonmanager_installer_gui.py (_check_python_version refuses an older Python;
  _handle_disallowed_python: python dependencies are compared lower-cased with the allow-list
  ALLOWED_PYTHON_PACKAGES.txt); AddonCatalogCacheCreator.py and addonmanager_icon_utilities.py (the
  top-level <icon>, relative to package.xml, must exist, an .svg must start with an <svg> root after
  the XML prolog and parse as XML, at most 10 MiB).
- FreeCAD/FreeCAD src/App/Metadata.cpp at commit 005d610381f1c2c24ff55eab81602c6086c9e3fe: only format
  "1" is read; a name must not contain / \\ ? % * : | " < >; a dependency type other than automatic,
  internal, addon or python is an error; supportsCurrentFreeCAD compares freecadmin/freecadmax with
  "major.minor.point.revision" (revision "0" when empty) as (major, minor, patch, suffix) tuples, the
  suffix being the text after the patch number (".<revision>"), so "1.1.0" as freecadmax excludes 1.1.0
  itself. src/App/FreeCADInit.py / src/Gui/FreeCADGuiInit.py (processMetadataFile): a workbench whose
  range excludes the running FreeCAD is skipped; its folder is <subdirectory> (else <name>) and needs
  InitGui.py; <classname> is looked up with Gui.getWorkbench for the icon.
"""

from __future__ import annotations

import ast
import re
import tomllib
import xml.etree.ElementTree as ET

import pytest

import spur_cad
from tests.freecad_helper import describe, run_freecad_code
from tests.workbench_helper import ROOT

NAMESPACE = "https://wiki.freecad.org/Package_Metadata"
NS = {"p": NAMESPACE}
URL_TYPES = {"bugtracker", "discussion", "documentation", "readme", "repository", "website"}
DEPENDENCY_TYPES = {"automatic", "internal", "addon", "python"}
NAME_FORBIDDEN = set('/\\?%*:|"<>')
MAX_ICON_BYTES = 10 * 1024 * 1024

# FreeCAD releases as FreeCAD.Version() gives them (major, minor, patch, revision); the workbench is meant
# for 0.20 to 1.1 (issue 16), whatever the build's revision string.
SUPPORTED = [("0", "20", "0", ""), ("0", "20", "2", ""), ("0", "20", "2", "29177 (Git)"), ("0", "21", "2", "33771"),
             ("1", "0", "0", "38495 (Git)"), ("1", "0", "2", "39319 (Git)"), ("1", "1", "0", ""),
             ("1", "1", "0", "43466 (Git)"), ("1", "1", "5", "45000 (Git)")]
UNSUPPORTED = [("0", "19", "4", "24291 (Git)"), ("1", "2", "0", "46000 (Git)"), ("2", "0", "0", "")]


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


def _workbench(package):
    workbenches = package.findall("p:content/p:workbench", NS)
    assert len(workbenches) == 1, "package.xml must declare exactly one workbench"
    return workbenches[0]


# --- FreeCAD's and the Addon Manager's version comparisons, rewritten from their descriptions above ---

def core_version(text: str) -> tuple[int, int, int, str]:
    """A version string as Metadata.cpp's Meta::Version reads it: three integers and the rest as suffix."""
    match = re.match(r"\s*(\d+)(?:.(\d+)(?:.(\d+)\s*(\S*))?)?", text)  # "." : any one separator character
    assert match, f"not a version: {text!r}"
    major, minor, patch, suffix = match.groups()
    return int(major), int(minor or 0), int(patch or 0), suffix or ""


def core_supports(freecad: tuple[str, str, str, str], low: str, high: str) -> bool:
    """Metadata::supportsCurrentFreeCAD for a running FreeCAD (major, minor, point, revision)."""
    running = core_version(".".join([*freecad[:3], freecad[3].split()[0] if freecad[3] else "0"]))
    unset = (0, 0, 0, "")
    return not ((low and core_version(low) != unset and core_version(low) > running)
                or (high and core_version(high) != unset and core_version(high) < running))


def manager_version(text: str) -> list:
    """addonmanager_metadata.Version(from_string=...): from the first digit, up to three dot-separated
    numbers, the last one allowed a text suffix."""
    digits = re.search(r"\d", text)
    if digits is None:
        raise ValueError(f"no digit in version {text!r}")
    parts = text[digits.start():].split(".", 2)
    version = [0, 0, 0, ""]
    for index, part in enumerate(parts):
        number = re.match(r"\d*", part).group()
        if not number:
            raise ValueError(f"invalid version {text!r}")
        version[index] = int(number)
        if number != part:
            version[3] = part[len(number):]
    return version


def manager_supports(freecad: tuple[str, str, str, str], low: str, high: str) -> bool:
    """Addon.version_is_ok: [major, minor, patch, revision] within [freecadmin, freecadmax] (list order)."""
    running = [int(freecad[0]), int(freecad[1]), int(freecad[2]), freecad[3]]
    return (manager_version(low) if low else running) <= running <= (manager_version(high) if high else running)


# --- the package.xml itself ---

def test_required_fields_are_present(package):
    """Format 1 in the Package_Metadata namespace (the only format FreeCAD reads); name, description, date,
    maintainer with e-mail; urls of known types, a repository url with its branch (the Addon Manager assumes
    "master"), and none a placeholder (spur_cad has no public address: it names none rather than a made-up one;
    the Addon Manager takes the repository a user adds as a custom one, docs/install.md)."""
    assert package.tag == "{" + NAMESPACE + "}package" and package.get("format") == "1"
    name = _text(package, "p:name")
    assert name == "spur_cad" and not NAME_FORBIDDEN & set(name)
    assert len(_text(package, "p:description")) > 20
    assert re.fullmatch(r"\d{4}-\d{2}-\d{2}", _text(package, "p:date"))
    maintainer = package.find("p:maintainer", NS)
    assert maintainer is not None and maintainer.get("email") and maintainer.text.strip()
    urls = package.findall("p:url", NS)
    assert {url.get("type") for url in urls} <= URL_TYPES
    repositories = [url for url in urls if url.get("type") == "repository"]
    assert len(repositories) <= 1 and all(url.get("branch") and url.text.strip() for url in repositories)
    for url in urls:
        host = re.sub(r"^[a-z]+://", "", (url.text or "").strip()).split("/")[0]
        assert host and not re.search(r"(^|\.)(example\.(com|org|net)|example|invalid|test|localhost)$", host), url.text


def test_every_element_is_in_the_package_namespace(package):
    """FreeCAD's parser matches tag names within the document's namespace: an element from another (or
    none) would be ignored, silently."""
    outside = [element.tag for element in package.iter() if not element.tag.startswith("{" + NAMESPACE + "}")]
    assert outside == []


def test_version_and_licence_match_pyproject(package, pyproject):
    assert _text(package, "p:version") == pyproject["version"] == spur_cad.__version__
    assert manager_version(_text(package, "p:version"))[:3] == [int(p) for p in pyproject["version"].split(".")]
    licence = package.find("p:license", NS)
    assert licence.text.strip() == pyproject["license"]  # pyproject's SPDX string (PEP 639)
    assert pyproject["license-files"] == [licence.get("file")]
    assert re.fullmatch(r"[A-Za-z0-9.+-]+", licence.text.strip())  # an SPDX identifier, as the Addon Manager wants
    assert (ROOT / licence.get("file")).is_file()
    assert "Apache License" in (ROOT / licence.get("file")).read_text()[:200]


def test_icon_is_a_valid_svg_where_the_addon_manager_looks(package):
    """The top-level <icon> (the one the Addon Manager's catalogue takes, relative to package.xml): an SVG
    whose first element is <svg>, parseable, at most 10 MiB."""
    relative = _text(package, "p:icon")
    assert not relative.startswith("/") and "\\" not in relative  # relative to package.xml, "/" separators
    icon = ROOT / relative
    data = icon.read_bytes()
    assert icon.suffix == ".svg" and 0 < len(data) <= MAX_ICON_BYTES
    prolog = re.compile(rb"\A(?:\xef\xbb\xbf)?(?:\s+|<\?xml[^>]*\?>|<!--.*?-->|<!DOCTYPE[^>]*>)*", re.DOTALL)
    assert re.match(rb"<svg[\s>]", data[prolog.match(data).end():], re.IGNORECASE), "the first element is not <svg>"
    assert ET.fromstring(data).tag.endswith("svg")


def test_workbench_entry_names_the_class_and_a_loadable_subdirectory(package):
    workbench = _workbench(package)
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


def test_freecad_range_is_0_20_to_1_1_for_freecad_and_the_addon_manager(package):
    """The declared range, compared as FreeCAD (loading the workbench) and the Addon Manager (installing
    it) compare it: every 0.20-1.1 release is in, whatever its revision string; 0.19 and 1.2 are out."""
    workbench = _workbench(package)
    low, high = _text(workbench, "p:freecadmin"), _text(workbench, "p:freecadmax")
    for level in (package, workbench):  # no other level may narrow it
        for tag in ("freecadmin", "freecadmax"):
            found = [e.text.strip() for e in level.findall(f"p:{tag}", NS)]
            assert found in ([], [low if tag == "freecadmin" else high])
    for freecad in SUPPORTED:
        assert core_supports(freecad, low, high) and manager_supports(freecad, low, high), freecad
    for freecad in UNSUPPORTED:
        assert not core_supports(freecad, low, high) and not manager_supports(freecad, low, high), freecad


def test_the_version_rules_as_modelled_exclude_a_bare_patch_maximum():
    """The comparison models above reproduce the trap that makes freecadmax 1.1.99: FreeCAD 1.1.0 runs as
    1.1.0.<revision> and lies above a freecadmax of "1.1.0" (FreeCAD 0.20 shows the same below)."""
    assert not core_supports(("1", "1", "0", "43466 (Git)"), "0.20.0", "1.1.0")
    assert not core_supports(("1", "1", "0", ""), "0.20.0", "1.1.0")
    assert not manager_supports(("1", "1", "0", "43466 (Git)"), "0.20.0", "1.1.0")
    assert core_supports(("0", "20", "0", ""), "0.20.0", "")  # freecadmin itself is in
    with pytest.raises(ValueError):
        manager_version("latest")


ADDON_MANAGER_DATA = ROOT / "tests" / "data" / "addon_manager"  # the lists, with their sources (README.md there)
# The one OCP distribution package.xml asks for (the workbench needs OCP, no front-end): CadQuery 2.8's own.
OCP_DISTRIBUTION = "cadquery-ocp"
# spur_cad's requirements package.xml may leave out or make optional, each with why: on no allow-list.
NOT_ALLOWED = {"jinja2": "optional: report.html's engine; a report export without it says what to install",
               "tqdm": "left out: only the command line's progress bars, which work without it"}


def allow_list(path) -> set[str]:
    """A list of allowed packages as the Addon Manager reads one: a name per line, lines starting with "#" left
    out, compared lower-cased (AddonInstaller._load_local_allowed_packages_list, _handle_disallowed_python)."""
    return {line.strip().lower() for line in path.read_text().splitlines() if line.strip() and line[0] != "#"}


def _python_depends(package) -> tuple[list[str], list[str]]:
    """(required, optional) python dependencies, in the file's order."""
    depends = [d for d in package.findall(".//p:depend", NS) if d.get("type") == "python"]
    required = [d.text.strip() for d in depends if d.get("optional", "false").lower() != "true"]
    optional = [d.text.strip() for d in depends if d.get("optional", "false").lower() == "true"]
    return required, optional


def test_dependencies_are_well_typed_and_match_pyproject(package, pyproject):
    """Every <depend> has a type FreeCAD knows (another is a parse error there). The python ones are what the
    Addon Manager hands to pip, one name each: pyproject's requirements under their pip names, lower-case as
    it compares them with its allow-list, those on no allow-list optional or left out for the reason NOT_ALLOWED
    gives, and the OCP that pyproject leaves to an extra (OCP_DISTRIBUTION, of pyproject's extra `cadquery`)."""
    depends = package.findall(".//p:depend", NS)
    assert all(d.get("type", "automatic") in DEPENDENCY_TYPES for d in depends)
    assert all(d.get("optional", "false") in ("true", "True", "false", "False") for d in depends)
    required, optional = _python_depends(package)
    python = required + optional
    assert len(python) == len(set(python))
    assert all(re.fullmatch(r"[a-z0-9]([a-z0-9._-]*[a-z0-9])?", name) for name in python)
    wanted = {re.split(r"[<>=!~ \[;]", spec, maxsplit=1)[0].lower() for spec in pyproject["dependencies"]}
    assert set(required) == (wanted - set(NOT_ALLOWED)) | {OCP_DISTRIBUTION}
    assert set(optional) <= set(NOT_ALLOWED) and set(optional) <= wanted
    assert set(NOT_ALLOWED) <= wanted  # the reasons above are about spur_cad's own requirements


@pytest.mark.parametrize("python", ["3.11", "3.12", "3.13", "3.14"])
def test_required_dependencies_are_allowed_and_pinned(package, python):
    """Each required python dependency is on FreeCAD/Addons' list of reviewed packages for that Python and pinned
    by its constraints file (the Addon Manager installs it with those constraints); the optional ones are on no
    list. FreeCAD's Python 3.11 (official 1.0 and 1.1 builds) to 3.14 (Debian testing's 1.1)."""
    folder = ADDON_MANAGER_DATA / "Addons" / "Data" / "Python" / python
    allowed = allow_list(folder / "Allowed-Packages")
    pinned = {re.split(r"[=<>!~ ;]", line, maxsplit=1)[0].lower().replace("_", "-")
              for line in (folder / "constraints.txt").read_text().splitlines() if line.strip()}
    required, optional = _python_depends(package)
    assert [name for name in required if name not in allowed] == []
    assert [name for name in required if name not in pinned] == []
    assert [name for name in optional if name in allowed] == []


def test_what_the_addon_manager_downloads_today_lacks_only_the_ocp(package):
    """The allow-list the Addon Manager itself reads (FreeCAD/FreeCAD-addons' ALLOWED_PYTHON_PACKAGES.txt,
    downloaded, else its own copy) has every required dependency but cadquery-ocp: the one package a catalogue
    install would drop (docs/install.md says what unblocks it). Its `ocp` is another project ("Open
    Collaboration Platform" on PyPI), not OpenCascade's."""
    required, _ = _python_depends(package)
    for path in (ADDON_MANAGER_DATA / "FreeCAD-addons" / "ALLOWED_PYTHON_PACKAGES.txt",
                 ADDON_MANAGER_DATA / "AddonManager" / "ALLOWED_PYTHON_PACKAGES.txt"):
        assert [name for name in required if name not in allow_list(path)] == [OCP_DISTRIBUTION], path


def test_python_minimum_matches_pyproject(package, pyproject):
    """<pythonmin> (the Addon Manager refuses the install on an older Python) is pyproject's lower bound."""
    lower = re.search(r">=\s*(\d+)\.(\d+)", pyproject["requires-python"])
    assert manager_version(_text(package, "p:pythonmin")) == [int(lower[1]), int(lower[2]), 0, ""]


@pytest.mark.freecad
def test_freecad_reads_the_metadata(freecadcmd, tmp_path):
    """FreeCAD 0.20's own parser (the one InitApplications and the Addon Manager use) accepts the file,
    supports the running version, and its range check agrees with the model above at the range's edges
    (temporary copies with freecadmin/freecadmax moved around the running 0.20.x)."""
    source = (ROOT / "package.xml").read_text()
    variants = {}
    for low, high in (("0.20.0", "0.20.1"), ("0.20.0", "0.20.2"), ("0.20.0", "0.20.3"), ("0.20.2", "1.1.99"),
                      ("0.20.3", "1.1.99"), ("0.21.0", "")):
        text = source.replace("<freecadmin>0.20.0</freecadmin>", f"<freecadmin>{low}</freecadmin>")
        text = re.sub(r"<freecadmax>[^<]*</freecadmax>", f"<freecadmax>{high}</freecadmax>" if high else "", text)
        path = tmp_path / f"package_{low}_{high}.xml"
        path.write_text(text)
        variants[str(path)] = (low, high)
    body = f"""
import FreeCAD
meta = FreeCAD.Metadata({str(ROOT / "package.xml")!r})
workbench = meta.Content["workbench"][0]
RESULT.update(name=meta.Name, version=meta.Version, classname=workbench.Classname,
              subdirectory=workbench.Subdirectory, supported=workbench.supportsCurrentFreeCAD(),
              low=workbench.FreeCADMin, high=workbench.FreeCADMax,
              depends=[d["package"] for d in meta.Depend], licence=meta.License[0]["name"],
              running=list(FreeCAD.Version()[:4]))
RESULT["variants"] = {{p: FreeCAD.Metadata(p).Content["workbench"][0].supportsCurrentFreeCAD()
                      for p in {sorted(variants)!r}}}
"""
    result, proc = run_freecad_code(body, tmp_path, freecadcmd=freecadcmd)
    assert result is not None and result.get("ok"), describe(proc, result)
    assert result["name"] == "spur_cad" and result["version"] == "0.1.0"
    assert result["classname"] == "SpurCadWorkbench" and result["subdirectory"] == "./workbench"
    assert result["supported"] is True and result["licence"] == "Apache-2.0"
    assert (result["low"], result["high"]) == ("0.20.0", "1.1.99")
    assert {"numpy", "scipy", "matplotlib", "cadquery-ocp", "numba", "jinja2"} <= set(result["depends"])
    running = tuple(result["running"])
    predicted = {path: core_supports(running, low, high) for path, (low, high) in variants.items()}
    assert result["variants"] == predicted, running
    assert not all(predicted.values()) and any(predicted.values())  # the edges were really on both sides


FAULTS = [  # (what is planted in a copy of package.xml, old text, new text, the check that must catch it)
    ("freecadmax 1.1.0", "1.1.99", "1.1.0", "range"),
    ("freecadmax 1.0.99", "1.1.99", "1.0.99", "range"),
    ("freecadmin 0.21.0", "<freecadmin>0.20.0", "<freecadmin>0.21.0", "range"),
    ("no freecadmax", "<freecadmax>1.1.99</freecadmax>", "", "range"),
    ("pythonmin 3.10", "<pythonmin>3.11.0", "<pythonmin>3.10.0", "python"),
    ("unknown dependency type", 'type="python">numba', 'type="pip">numba', "depends"),
    ("missing dependency", '<depend type="python">numba</depend>', "", "depends"),
    ("import name for a pip name", ">cadquery-ocp<", ">OCP<", "depends"),
    ("jinja2 required", '<depend type="python" optional="true">jinja2', '<depend type="python">jinja2', "depends"),
    ("tqdm required", "</package>", '<depend type="python">tqdm</depend></package>', "depends"),
    ("cadquery for OCP", ">cadquery-ocp<", ">cadquery<", "depends"),
    ("OCP without VTK (on no list)", ">cadquery-ocp<", ">cadquery-ocp-novtk<", "allowed"),
    ("jinja2 required (on no list)", '<depend type="python" optional="true">jinja2', '<depend type="python">jinja2',
     "allowed"),
    ("url without branch", "<icon>", '<url type="repository">https://git.host.org/spur_cad</url><icon>', "fields"),
    ("placeholder url", "<icon>", '<url type="repository" branch="main">https://example.invalid/spur_cad</url><icon>',
     "fields"),
    ("no maintainer e-mail", ' email="maintainers@spur-cad.invalid"', "", "fields"),
    ("format 2", 'format="1"', 'format="2"', "fields"),
    ("name with a slash", "<name>spur_cad</name>", "<name>spur/cad</name>", "fields"),
    ("element outside the namespace", "<icon>", '<icon xmlns="urn:other">', "namespace"),
]
CHECKS = {
    "range": lambda package, pyproject: test_freecad_range_is_0_20_to_1_1_for_freecad_and_the_addon_manager(package),
    "python": test_python_minimum_matches_pyproject,
    "allowed": lambda package, pyproject: test_required_dependencies_are_allowed_and_pinned(package, "3.11"),
    "depends": test_dependencies_are_well_typed_and_match_pyproject,
    "fields": lambda package, pyproject: test_required_fields_are_present(package),
    "namespace": lambda package, pyproject: test_every_element_is_in_the_package_namespace(package),
}


@pytest.mark.parametrize("fault, old, new, check", FAULTS, ids=[fault[0] for fault in FAULTS])
def test_each_rule_catches_its_planted_fault(fault, old, new, check, pyproject):
    """Guard for the checks above: the check for a rule fails on a copy of package.xml that breaks it."""
    source = (ROOT / "package.xml").read_text()
    assert old in source, f"the fault {fault!r} no longer applies to package.xml"
    broken = ET.fromstring(source.replace(old, new, 1).encode())
    with pytest.raises(AssertionError):
        CHECKS[check](broken, pyproject)
