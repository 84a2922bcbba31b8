"""`spur-cad install-freecad [--uninstall]`: the link in FreeCAD's user Mod folder, the recorded
environment, errors, and a real FreeCAD that then loads the workbench with spur_cad and cadquery."""

from __future__ import annotations

import json
import sysconfig
from pathlib import Path

import pytest

from spur_cad.cli import main
from tests.freecad_helper import describe, run_freecad_code
from tests.workbench_helper import ROOT


@pytest.fixture
def home(tmp_path, monkeypatch):
    home = tmp_path / "home"
    home.mkdir()
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.delenv("XDG_DATA_HOME", raising=False)
    return home


def _data(home: Path) -> Path:
    return home / ".local" / "share" / "FreeCAD"


def test_install_links_the_addon_and_records_the_environment(home, capsys):
    assert main(["install-freecad"]) == 0
    link = _data(home) / "Mod" / "spur_cad"
    assert link.is_symlink() and link.resolve() == ROOT
    assert (link / "package.xml").is_file() and (link / "workbench" / "InitGui.py").is_file()
    record = json.loads((_data(home) / "spur_cad_environment.json").read_text())
    assert sysconfig.get_paths()["purelib"] in record["site_packages"]
    assert record["python_version"] == "3.11"
    out = capsys.readouterr().out
    assert str(link) in out and "--uninstall" in out


def test_install_twice_replaces_its_own_link(home):
    assert main(["install-freecad"]) == 0
    assert main(["install-freecad"]) == 0
    assert (_data(home) / "Mod" / "spur_cad").resolve() == ROOT


def test_install_honours_xdg_data_home(home, tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "xdg"))
    assert main(["install-freecad"]) == 0
    assert (tmp_path / "xdg" / "FreeCAD" / "Mod" / "spur_cad").is_symlink()
    assert not (_data(home) / "Mod").exists()


def test_install_refuses_to_replace_a_real_folder(home, capsys):
    folder = _data(home) / "Mod" / "spur_cad"
    folder.mkdir(parents=True)
    (folder / "package.xml").write_text("<package/>")
    assert main(["install-freecad"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("spur-cad: error: ") and "is not a link made by `spur-cad install-freecad`" in err
    assert len(err.strip().splitlines()) == 1
    assert (folder / "package.xml").read_text() == "<package/>"
    assert not (_data(home) / "spur_cad_environment.json").exists()


def test_install_without_home_is_a_clear_error(monkeypatch, capsys):
    monkeypatch.delenv("HOME", raising=False)
    monkeypatch.delenv("XDG_DATA_HOME", raising=False)
    assert main(["install-freecad"]) == 2
    assert capsys.readouterr().err == "spur-cad: error: HOME is not set: cannot find FreeCAD's user folder\n"


def test_uninstall_removes_link_and_record(home, capsys):
    assert main(["install-freecad"]) == 0
    assert main(["install-freecad", "--uninstall"]) == 0
    assert not (_data(home) / "Mod" / "spur_cad").exists()
    assert not (_data(home) / "Mod" / "spur_cad").is_symlink()
    assert not (_data(home) / "spur_cad_environment.json").exists()
    assert ROOT.is_dir() and (ROOT / "package.xml").is_file()  # the checkout itself is untouched
    capsys.readouterr()
    assert main(["install-freecad", "--uninstall"]) == 0
    assert "nothing to uninstall" in capsys.readouterr().out


def test_uninstall_leaves_a_real_folder(home, capsys):
    folder = _data(home) / "Mod" / "spur_cad"
    folder.mkdir(parents=True)
    assert main(["install-freecad", "--uninstall"]) == 2
    assert "is not a link made by" in capsys.readouterr().err and folder.is_dir()


IMPORT_BODY = """
import sys, FreeCAD
RESULT["user_data"] = FreeCAD.getUserAppDataDir()
try:
    import numpy, cadquery, spur_cad, spur_cad_workbench.features
    RESULT.update(imported=True, numpy=numpy.__file__, cadquery=cadquery.__file__,
                  spur_cad=spur_cad.__file__, workbench=spur_cad_workbench.features.__file__)
except ImportError as exc:
    RESULT.update(imported=False, error=str(exc))
"""


@pytest.mark.freecad
def test_freecad_loads_the_installed_workbench_and_forgets_it_after_uninstall(freecadcmd, tmp_path, monkeypatch):
    """FreeCAD (HOME = the run's home, no other path set up) imports spur_cad, cadquery and the workbench."""
    home = tmp_path / "home"  # the HOME run_freecad_code gives FreeCAD
    home.mkdir()
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.delenv("XDG_DATA_HOME", raising=False)
    assert main(["install-freecad"]) == 0
    result, proc = run_freecad_code(IMPORT_BODY, tmp_path, freecadcmd=freecadcmd)
    assert result is not None and result.get("ok"), describe(proc, result)
    assert Path(result["user_data"]) == _data(home)  # our rule for the user folder is FreeCAD's
    assert result["imported"], describe(proc, result)
    venv = Path(sysconfig.get_paths()["purelib"])
    assert Path(result["numpy"]).is_relative_to(venv) and Path(result["cadquery"]).is_relative_to(venv)
    assert Path(result["spur_cad"]).resolve() == (ROOT / "spur_cad" / "__init__.py")
    assert "spur_cad:" not in proc.stdout + proc.stderr  # no warning from Init.py
    assert main(["install-freecad", "--uninstall"]) == 0
    result, proc = run_freecad_code(IMPORT_BODY, tmp_path, freecadcmd=freecadcmd)
    assert result is not None and result.get("ok"), describe(proc, result)
    assert result["imported"] is False
