"""Installing without a source checkout (issue 16): a wheel built from the repository carries the FreeCAD
addon (package.xml, workbench/, resources/icons/, LICENSE as spur_cad/freecad_addon/), installs into a
fresh venv, `spur-cad install-freecad` from that venv links its own copy, and FreeCAD builds the
reference job through the workbench from it.

The wheel is built offline from a copy of the working tree (tracked and untracked files, not the ignored
ones: what a commit of it would hold) with this environment's setuptools (--no-build-isolation), and
installed with --no-deps into a fresh venv. Its dependencies come from this environment through a .pth
file written after the install: a plain path entry, so this environment's own .pth files (the editable
spur_cad's finder among them) are not run and its spur_cad stays out of reach. Everything runs from a
temporary folder, never from the checkout.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from dataclasses import dataclass
from pathlib import Path

import pytest

from tests.freecad_helper import describe, run_freecad_code
from tests.workbench_helper import REFERENCE_JOB, ROOT

ADDON_PARTS = ("package.xml", "LICENSE", "workbench", "resources/icons", "resources/examples")  # the addon folder
STEP_TIMEOUT_S = 180


@dataclass(frozen=True)
class WheelInstall:
    wheel: Path
    build_output: str  # what building the wheel printed (standard output and error)
    source: Path  # the copy of the working tree the wheel was built from
    venv: Path
    site_packages: Path  # the fresh venv's
    outside: Path  # an empty folder outside the checkout to run commands from


def _run(cmd: list, cwd: Path, env: dict | None = None) -> subprocess.CompletedProcess:
    proc = subprocess.run([str(part) for part in cmd], cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=STEP_TIMEOUT_S, stdin=subprocess.DEVNULL)
    assert proc.returncode == 0, f"{cmd} exited {proc.returncode}:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    return proc


def _environment(**extra: str) -> dict[str, str]:
    """This process's environment without what would point Python, pip or FreeCAD elsewhere."""
    env = {name: value for name, value in os.environ.items()
           if not name.startswith(("PIP_", "PYTHON", "FREECAD_USER_", "XDG_")) and name != "VIRTUAL_ENV"}
    env["PIP_DISABLE_PIP_VERSION_CHECK"] = "1"
    return {**env, **extra}


def _git_files(*paths: str, untracked: bool = False) -> list[str]:
    """Files git knows in the checkout (under `paths`), as a commit would hold them; with `untracked`, also
    the untracked files that are not ignored. Deleted files are left out."""
    cmd = ["git", "-C", ROOT, "ls-files", "-z", "--cached"] + (["--others", "--exclude-standard"] if untracked else [])
    names = _run([*cmd, "--", *paths], cwd=ROOT).stdout.split("\0")
    return sorted(name for name in set(names) if name and os.path.lexists(ROOT / name))


def _copy_working_tree(dest: Path) -> Path:
    for name in _git_files(untracked=True):
        target = dest / name
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / name, target, follow_symlinks=False)  # spur_cad/freecad_addon/* stay links
    return dest


@pytest.fixture(scope="module")
def wheel_install(tmp_path_factory) -> WheelInstall:
    """The wheel built from this working tree, installed alone into a fresh venv."""
    work = tmp_path_factory.mktemp("wheel")
    outside = work / "outside"
    outside.mkdir()
    source = _copy_working_tree(work / "source")
    dist = work / "dist"
    env = _environment()
    built = _run([sys.executable, "-m", "pip", "wheel", "-v", "--no-deps", "--no-build-isolation", "--no-index", "-w",
                  dist, source], cwd=outside, env=env)
    (wheel,) = dist.glob("spur_cad-*.whl")
    venv = work / "venv"
    _run([sys.executable, "-m", "venv", "--without-pip", venv], cwd=outside, env=env)
    python = venv / "bin" / "python"
    _run([sys.executable, "-m", "pip", "--python", python, "install", "--no-deps", "--no-index", wheel],
         cwd=outside, env=env)
    site = Path(_run([python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                     cwd=outside, env=env).stdout.strip())
    (site / "spur_cad_test_dependencies.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    return WheelInstall(wheel, built.stdout + built.stderr, source, venv, site, outside)


PROBE = """
import importlib.util, json, sys
import numpy, spur_cad
from spur_cad.freecad_install import addon_root
root = addon_root()
resources_py = root / "workbench" / "spur_cad_workbench" / "resources.py"
spec = importlib.util.spec_from_file_location("probe_resources", resources_py)
resources = importlib.util.module_from_spec(spec)
spec.loader.exec_module(resources)
print(json.dumps({"spur_cad": spur_cad.__file__, "version": spur_cad.__version__, "addon": str(root),
                  "icon": resources.icon_path("spur_cad"), "numpy": numpy.__file__}))
"""


def test_the_wheel_builds_without_a_warning(wheel_install):
    """setuptools warned of the addon's folders missing from `packages` (they may be left out of a wheel) and of
    `project.license` as a table; the build (verbose: every setuptools message shown) now warns of nothing."""
    warnings = [line for line in wheel_install.build_output.splitlines()
                if re.search(r"warn|deprecat|would be ignored", line, re.IGNORECASE)]
    assert warnings == [], "\n".join(warnings)
    assert "spur_cad-" in wheel_install.build_output  # the output was really captured


@pytest.mark.slow
def test_the_installed_wheel_runs_the_example_it_carries(wheel_install):
    """`spur-cad run` from the wheel's venv on the reference job the wheel carries writes the whole set."""
    site = wheel_install.site_packages
    job = site / "spur_cad" / "freecad_addon" / "resources" / "examples" / "reference_gear.toml"
    assert job.is_file() and not job.is_symlink()
    out = wheel_install.outside / "reference_out"
    _run([wheel_install.venv / "bin" / "spur-cad", "run", job, "--out", out], cwd=wheel_install.outside,
         env=_environment())
    assert {"gear.step", "roughing.ngc", "finishing.ngc", "report.html", "summary.json"} <= {
        path.name for path in out.iterdir()}
    summary = json.loads((out / "summary.json").read_text())
    assert summary["gear"]["tip_radius_mm"] == 50.0 and summary["simulation"]["enabled"]


def test_the_wheel_carries_the_addon_and_installs_apart_from_the_checkout(wheel_install):
    """Every file git tracks in the addon's parts is in the wheel, byte for byte as in the working tree the
    wheel was built from (its copy: the checkout may change meanwhile); the installed spur_cad and its
    addon are real files in the venv (no link back into the checkout); the addon's resources.py finds the
    icons beside it; install-freecad from the venv links that copy and records the venv."""
    expected = _git_files(*ADDON_PARTS)
    assert "workbench/InitGui.py" in expected and "resources/icons/spur_cad.svg" in expected
    with zipfile.ZipFile(wheel_install.wheel) as wheel:
        shipped = {name: wheel.read(name) for name in wheel.namelist() if name.startswith("spur_cad/freecad_addon/")}
    missing = [name for name in expected if f"spur_cad/freecad_addon/{name}" not in shipped]
    assert missing == [], f"not in the wheel (pyproject.toml [tool.setuptools.package-data]): {missing}"
    for name in expected:
        assert shipped[f"spur_cad/freecad_addon/{name}"] == (wheel_install.source / name).read_bytes(), name

    site = wheel_install.site_packages
    probe = json.loads(_run([wheel_install.venv / "bin" / "python", "-c", PROBE], cwd=wheel_install.outside,
                            env=_environment()).stdout)
    assert Path(probe["spur_cad"]) == site / "spur_cad" / "__init__.py"
    assert Path(probe["addon"]) == site / "spur_cad" / "freecad_addon"
    assert Path(probe["icon"]) == site / "spur_cad" / "freecad_addon" / "resources" / "icons" / "spur_cad.svg"
    assert Path(probe["icon"]).is_file()
    assert Path(probe["numpy"]).is_relative_to(sysconfig.get_paths()["purelib"])  # dependencies: the .pth route
    installed = [path for path in Path(probe["addon"]).rglob("*") if "__pycache__" not in path.parts]
    assert not [path for path in installed if path.is_symlink() or path.resolve().is_relative_to(ROOT)]
    assert {path.relative_to(probe["addon"]).as_posix() for path in installed if path.is_file()} >= set(expected)

    home = wheel_install.outside.parent / "home_install"
    home.mkdir()
    done = _run([wheel_install.venv / "bin" / "spur-cad", "install-freecad"], cwd=wheel_install.outside,
                env=_environment(HOME=str(home)))
    data = home / ".local" / "share" / "FreeCAD"
    link = data / "Mod" / "spur_cad"
    assert link.is_symlink() and link.resolve() == Path(probe["addon"]) and str(link) in done.stdout
    record = json.loads((data / "spur_cad_environment.json").read_text())
    assert record["site_packages"] == [str(site)] and record["spur_cad_version"] == probe["version"]
    assert Path(record["python"]).parent == wheel_install.venv / "bin"


FREECAD_BODY = """
import FreeCAD
import spur_cad
from spur_cad_workbench import commands, resources
RESULT["files"] = {"spur_cad": spur_cad.__file__, "commands": commands.__file__, "icon": resources.icon_path("gear")}
doc = FreeCAD.newDocument("FromWheel")
gear, stock, job = commands.import_job_file(doc, JOB)
objects = {"gear": gear, "stock": stock, "job": job}
RESULT["states"] = {kind: [list(obj.State), obj.Status] for kind, obj in objects.items()}
shape = gear.Shape
RESULT["gear"] = dict(solids=len(shape.Solids), valid=shape.isValid(), volume=shape.Volume, teeth=gear.Teeth,
                      tip=gear.TipRadius.Value, width=gear.FaceWidth.Value)
RESULT["moves"] = {tp.Operation: tp.Moves for tp in (job.RoughingToolpath, job.FinishingToolpath)}
"""


@pytest.mark.freecad
@pytest.mark.slow
def test_freecad_builds_the_reference_job_from_the_wheel_install(wheel_install, freecadcmd, tmp_path):
    """install-freecad from the wheel's venv, then FreeCAD (a fresh HOME, nothing else on its path) imports
    spur_cad and the workbench from the venv's copy and builds the reference job: gear, stock and job
    recompute with Status "ok", the gear is one valid solid, both toolpaths have moves."""
    work = tmp_path / "fc"
    home = work / "home"  # the HOME run_freecad_code gives FreeCAD
    home.mkdir(parents=True)
    _run([wheel_install.venv / "bin" / "spur-cad", "install-freecad"], cwd=wheel_install.outside,
         env=_environment(HOME=str(home)))
    body = f"JOB = {str(REFERENCE_JOB)!r}\n" + FREECAD_BODY
    result, proc = run_freecad_code(body, work, freecadcmd=freecadcmd, timeout_s=STEP_TIMEOUT_S)
    assert result is not None and result.get("ok"), describe(proc, result)
    site = wheel_install.site_packages
    for name, file in result["files"].items():
        assert Path(file).resolve().is_relative_to(site) and not Path(file).resolve().is_relative_to(ROOT), name
    assert "spur_cad:" not in proc.stdout + proc.stderr  # no warning from the workbench's Init.py
    assert result["states"] == {kind: [["Up-to-date"], "ok"] for kind in ("gear", "stock", "job")}, result["states"]
    gear = result["gear"]
    assert gear["solids"] == 1 and gear["valid"] and gear["teeth"] > 0
    assert 0 < gear["volume"] < 3.1416 * gear["tip"] ** 2 * gear["width"]
    assert result["moves"]["roughing"] > 0 and result["moves"]["finishing"] > 0
