"""`spur-cad install-freecad [--uninstall]`: the link in FreeCAD's user Mod folder, the recorded
environment, errors, the user data folder of each FreeCAD version (1.1's versioned ones,
FREECAD_USER_DATA), Addon Manager copies, and a real FreeCAD that then loads the workbench with
spur_cad and OCP; the workbench's Init.py without a record (an Addon Manager install) taking spur_cad from
the addon's own folder. The wheel route is tests/test_wheel_install.py, the Addon Manager's
tests/test_addon_manager.py."""

from __future__ import annotations

import json
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest

from spur_cad.cli import main
from spur_cad.freecad_install import user_data_dir, user_data_dirs
from tests.freecad_helper import describe, run_freecad_code
from tests.workbench_helper import ROOT


@pytest.fixture
def home(tmp_path, monkeypatch):
    home = tmp_path / "home"
    home.mkdir()
    monkeypatch.setenv("HOME", str(home))
    for name in ("XDG_DATA_HOME", "FREECAD_USER_DATA", "FREECAD_USER_HOME"):
        monkeypatch.delenv(name, raising=False)
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
    assert record["python_version"] == f"{sys.version_info[0]}.{sys.version_info[1]}"  # the Python that installed
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
    for name in ("HOME", "XDG_DATA_HOME", "FREECAD_USER_DATA", "FREECAD_USER_HOME"):
        monkeypatch.delenv(name, raising=False)
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


# FreeCAD 1.1 and later keep their user data in versioned subfolders (v1-1, ...) of the folder 0.20 and 1.0
# use; the rule is FreeCAD's ApplicationDirectories.cpp (docs/install.md). These tests need no FreeCAD:
# spur_cad.freecad_install.user_data_dir is the rule, install must reach every folder it can give.

VERSIONS = [(0, 20), (0, 21), (1, 0), (1, 1), (1, 2), (1, 3)]


def _folders(env: dict) -> dict:
    return {version: user_data_dir(env, version) for version in VERSIONS}


def test_user_data_folder_per_freecad_version(tmp_path):
    """0.20-1.0: the unversioned folder; 1.1+: the newest v<major>-<minor> not newer than itself, the
    unversioned folder when there is none, its own versioned folder when nothing exists yet."""
    env = {"HOME": str(tmp_path)}
    root = _data(tmp_path)
    fresh = _folders(env)  # nothing there: 1.1 and later would create their own versioned folder
    assert fresh[(0, 20)] == fresh[(0, 21)] == fresh[(1, 0)] == root
    assert fresh[(1, 1)] == root / "v1-1" and fresh[(1, 3)] == root / "v1-3"
    root.mkdir(parents=True)  # settings of 0.20 or 1.0, not migrated: 1.1 keeps using them
    assert set(_folders(env).values()) == {root}
    (root / "v1-2").mkdir()
    for junk in ("v1-1-old", "v0-21", "v1-100", "V1-1", "v1-1x"):
        (root / junk).mkdir()
    (root / "v1-1").write_text("a file, not a folder")
    folders = _folders(env)
    assert folders[(1, 1)] == root  # v1-2 is newer than 1.1; the junk and the file do not count
    assert folders[(1, 2)] == folders[(1, 3)] == root / "v1-2"
    assert folders[(1, 0)] == root
    assert user_data_dirs(env) == [root, root / "v1-2"]


def test_freecad_user_data_variables_replace_every_folder(tmp_path):
    """FREECAD_USER_DATA (else FREECAD_USER_HOME) naming an existing folder is used as it is by every version;
    naming a missing folder it is ignored, as FreeCAD ignores it."""
    custom, other = tmp_path / "custom", tmp_path / "other"
    custom.mkdir()
    other.mkdir()
    env = {"HOME": str(tmp_path), "FREECAD_USER_DATA": str(custom), "FREECAD_USER_HOME": str(other)}
    assert set(_folders(env).values()) == {custom} and user_data_dirs(env) == [custom]
    env["FREECAD_USER_DATA"] = str(tmp_path / "missing")
    assert set(_folders(env).values()) == {other}
    del env["FREECAD_USER_HOME"]
    assert _folders(env)[(1, 0)] == _data(tmp_path)


def test_install_reaches_every_freecad_version(home, capsys):
    """With the unversioned folder and v1-1, v1-2 present, every version from 0.20 on finds the link and
    the record in the folder it takes; uninstall clears them all."""
    for folder in ("v1-1", "v1-2"):
        (_data(home) / folder).mkdir(parents=True)
    assert main(["install-freecad"]) == 0
    out = capsys.readouterr().out
    env = {"HOME": str(home)}
    for version, folder in _folders(env).items():
        assert (folder / "Mod" / "spur_cad").resolve() == ROOT, version
        assert json.loads((folder / "spur_cad_environment.json").read_text())["site_packages"], version
    assert "for FreeCAD 1.1" in out and "for FreeCAD 1.2" in out and "for FreeCAD 0.20 and 1.0" in out
    assert main(["install-freecad", "--uninstall"]) == 0
    for folder in user_data_dirs(env):
        assert not (folder / "Mod" / "spur_cad").is_symlink() and not (folder / "spur_cad_environment.json").exists()


def test_install_on_a_new_account_is_found_by_freecad_1_1(home):
    """Nothing of FreeCAD's yet: the unversioned folder made by the install is what 1.1 then takes
    (it creates v1-1 only when there is no FreeCAD folder at all)."""
    assert main(["install-freecad"]) == 0
    assert user_data_dir({"HOME": str(home)}, (1, 1)) == _data(home)
    assert (_data(home) / "Mod" / "spur_cad").resolve() == ROOT


def test_install_with_freecad_user_data_writes_only_there(home, tmp_path, monkeypatch):
    custom = tmp_path / "portable"
    custom.mkdir()
    monkeypatch.setenv("FREECAD_USER_DATA", str(custom))
    assert main(["install-freecad"]) == 0
    assert (custom / "Mod" / "spur_cad").resolve() == ROOT and (custom / "spur_cad_environment.json").is_file()
    assert not _data(home).exists()


def _addon_manager_copy(folder: Path) -> Path:
    copy = folder / "Mod" / "spur_cad"
    (copy / "workbench").mkdir(parents=True)
    (copy / "package.xml").write_bytes((ROOT / "package.xml").read_bytes())
    (copy / "workbench" / "InitGui.py").write_text("# the Addon Manager's copy\n")
    return copy


def test_install_keeps_an_addon_manager_copy_and_records_the_environment(home, capsys):
    """The Addon Manager installs the workbench as a folder but cannot provide spur_cad: install-freecad keeps
    that folder and writes the record beside it, so the copy's workbench imports this environment's spur_cad."""
    copy = _addon_manager_copy(_data(home) / "v1-1")
    assert main(["install-freecad"]) == 0
    assert not copy.is_symlink() and (copy / "workbench" / "InitGui.py").read_text() == "# the Addon Manager's copy\n"
    record = json.loads((_data(home) / "v1-1" / "spur_cad_environment.json").read_text())
    assert record["addon"] == str(copy) and sysconfig.get_paths()["purelib"] in record["site_packages"]
    assert (_data(home) / "Mod" / "spur_cad").resolve() == ROOT  # the unversioned folder gets the link
    assert "kept the copy of the workbench in " + str(copy) in capsys.readouterr().out
    assert main(["install-freecad", "--uninstall"]) == 0
    assert (copy / "package.xml").is_file() and not (_data(home) / "v1-1" / "spur_cad_environment.json").exists()
    assert "left " + str(copy) in capsys.readouterr().out


def test_a_foreign_folder_in_any_version_stops_the_install_before_any_change(home, capsys):
    foreign = _data(home) / "v1-1" / "Mod" / "spur_cad"
    foreign.mkdir(parents=True)
    (foreign / "package.xml").write_text("<package><name>other</name></package>")
    assert main(["install-freecad"]) == 2
    assert str(foreign) in capsys.readouterr().err
    assert not (_data(home) / "Mod").exists() and not (_data(home) / "spur_cad_environment.json").exists()


IMPORT_BODY = """
import sys, FreeCAD
RESULT["user_data"] = FreeCAD.getUserAppDataDir()
try:
    import numpy, OCP, spur_cad, spur_cad_workbench.features
    RESULT.update(imported=True, numpy=numpy.__file__, ocp=OCP.__file__,
                  spur_cad=spur_cad.__file__, workbench=spur_cad_workbench.features.__file__)
except ImportError as exc:
    RESULT.update(imported=False, error=str(exc))
"""


@pytest.mark.freecad
def test_freecad_loads_the_installed_workbench_and_forgets_it_after_uninstall(freecadcmd, tmp_path, monkeypatch):
    """FreeCAD (HOME = the run's home, no other path set up) imports spur_cad, OCP and the workbench."""
    home = tmp_path / "home"  # the HOME run_freecad_code gives FreeCAD
    home.mkdir()
    monkeypatch.setenv("HOME", str(home))
    for name in ("XDG_DATA_HOME", "FREECAD_USER_DATA", "FREECAD_USER_HOME"):
        monkeypatch.delenv(name, raising=False)
    assert main(["install-freecad"]) == 0
    result, proc = run_freecad_code(IMPORT_BODY, tmp_path, freecadcmd=freecadcmd)
    assert result is not None and result.get("ok"), describe(proc, result)
    assert Path(result["user_data"]) == _data(home)  # our rule for the user folder is FreeCAD's
    assert result["imported"], describe(proc, result)
    venv = Path(sysconfig.get_paths()["purelib"])
    assert Path(result["numpy"]).is_relative_to(venv) and Path(result["ocp"]).is_relative_to(venv)
    assert Path(result["spur_cad"]).resolve() == (ROOT / "spur_cad" / "__init__.py")
    assert "spur_cad:" not in proc.stdout + proc.stderr  # no warning from Init.py
    assert main(["install-freecad", "--uninstall"]) == 0
    result, proc = run_freecad_code(IMPORT_BODY, tmp_path, freecadcmd=freecadcmd)
    assert result is not None and result.get("ok"), describe(proc, result)
    assert result["imported"] is False


def _tree(folder: Path) -> set[str]:
    return {str(path.relative_to(folder)) for path in folder.rglob("*")}


def test_uninstall_leaves_no_empty_folder_it_made_and_keeps_those_it_found(home, capsys):
    """Installing on a machine where FreeCAD never ran creates its user data folder and `Mod`: uninstalling
    removes them again. Folders that were there before, `~/.local/share` above FreeCAD's, or that hold
    anything else after all, stay."""
    (home / ".local" / "share").mkdir(parents=True)
    before = _tree(home)
    assert main(["install-freecad"]) == 0 and main(["install-freecad"]) == 0  # a second install keeps the record
    assert main(["install-freecad", "--uninstall"]) == 0
    assert _tree(home) == before
    # FreeCAD's folder existed already (FreeCAD ran once): it stays, the Mod folder made by the install goes.
    _data(home).mkdir()
    (_data(home) / "user.cfg").write_text("<FCParameters/>")
    before = _tree(home)
    assert main(["install-freecad"]) == 0
    (_data(home) / "Mod" / "another_workbench").mkdir()  # the user installs another workbench meanwhile
    assert main(["install-freecad", "--uninstall"]) == 0
    assert _tree(home) == before | {".local/share/FreeCAD/Mod", ".local/share/FreeCAD/Mod/another_workbench"}


def test_a_record_naming_other_folders_removes_none_of_them(home, tmp_path):
    """The record is a file on disk: folders it names outside the install's own are never touched."""
    assert main(["install-freecad"]) == 0
    record = _data(home) / "spur_cad_environment.json"
    victims = [tmp_path / "empty_victim", home / ".local" / "share", home / ".local"]
    victims[0].mkdir()
    data = json.loads(record.read_text())
    data["created_folders"] = [str(v) for v in victims] + [123, None]
    record.write_text(json.dumps(data))
    assert main(["install-freecad", "--uninstall"]) == 0
    assert all(v.is_dir() for v in victims)


# --- the workbench's Init.py (spur_cad_workbench.environment.activate) in a Python that has no spur_cad ---

_ACTIVATE = """
import importlib.util, json, sys
sys.path[:0] = ARGS["first"]
sys.path.insert(0, ARGS["workbench"])  # as FreeCAD puts the addon's <subdirectory> on sys.path
from spur_cad_workbench import environment
before = list(sys.path)
logged = []
problems = environment.activate(ARGS["user"], **({"addon_folder": __import__("pathlib").Path(ARGS["addon"])}
                                                 if ARGS["addon"] else {}), log=logged.append)
spec = importlib.util.find_spec("spur_cad")
print(json.dumps(dict(problems=problems, added=[p for p in sys.path if p not in before], last=sys.path[-1],
                      first=sys.path[0], origin=spec.origin if spec else None, logged=logged)))
"""


def _activate(user: Path, addon: Path | None = None, first: tuple[Path, ...] = ()) -> dict:
    """Run activate() in a fresh `python -I -S` (no site-packages: spur_cad is not importable there unless `first`
    holds one) with the checkout's workbench folder on sys.path, as FreeCAD has it."""
    args = dict(user=str(user), addon=str(addon) if addon else "", first=[str(f) for f in first],
                workbench=str(ROOT / "workbench"))
    proc = subprocess.run([sys.executable, "-I", "-S", "-c", f"ARGS = {args!r}\n" + _ACTIVATE],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


def _fake_spur_cad(folder: Path) -> Path:
    (folder / "spur_cad").mkdir(parents=True)
    (folder / "spur_cad" / "__init__.py").write_text("")
    return folder


def test_without_a_record_the_addon_folder_provides_spur_cad(tmp_path):
    """No spur_cad_environment.json (the Addon Manager installed the workbench): the folder above the workbench,
    which holds the spur_cad package in a clone of the repository, is appended to sys.path, and said in the log."""
    user = tmp_path / "user"
    user.mkdir()
    found = _activate(user)  # the default: the addon folder of this workbench, here the checkout
    assert found["problems"] == [] and found["added"] == [str(ROOT)] and found["last"] == str(ROOT)
    assert Path(found["origin"]) == ROOT / "spur_cad" / "__init__.py"
    assert len(found["logged"]) == 1 and str(ROOT) in found["logged"][0]
    addon = _fake_spur_cad(tmp_path / "Mod" / "spur_cad")
    found = _activate(user, addon)
    assert found["added"] == [str(addon)] and Path(found["origin"]) == addon / "spur_cad" / "__init__.py"


def test_without_a_record_an_importable_spur_cad_is_kept(tmp_path):
    """A spur_cad already importable (installed into FreeCAD's Python, or earlier on sys.path) stays the one
    imported: the addon's folder is not added. A folder without the package is not added either."""
    user = tmp_path / "user"
    user.mkdir()
    other = _fake_spur_cad(tmp_path / "elsewhere")
    found = _activate(user, _fake_spur_cad(tmp_path / "addon"), first=(other,))
    assert found["added"] == [] and Path(found["origin"]) == other / "spur_cad" / "__init__.py"
    assert found["logged"] == []
    (tmp_path / "empty").mkdir()
    found = _activate(user, tmp_path / "empty")
    assert found["added"] == [] and found["origin"] is None and found["problems"] == []


def test_a_record_wins_over_the_addon_folder(tmp_path):
    """With the record `install-freecad` writes, its site-packages go first and the addon folder is not added,
    even where the workbench is an Addon Manager copy holding spur_cad."""
    user, env = tmp_path / "user", _fake_spur_cad(tmp_path / "env")
    user.mkdir()
    record = {"site_packages": [str(env)], "python_version": f"{sys.version_info[0]}.{sys.version_info[1]}"}
    (user / "spur_cad_environment.json").write_text(json.dumps(record))
    found = _activate(user, _fake_spur_cad(tmp_path / "addon"))
    assert found["problems"] == [] and found["added"] == [str(env)] and found["first"] == str(env)
    assert Path(found["origin"]) == env / "spur_cad" / "__init__.py"
