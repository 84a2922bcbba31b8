"""An install by FreeCAD's Addon Manager, done as the Addon Manager does it, then the workbench in FreeCAD.

What the Addon Manager does (read in FreeCAD/AddonManager at 23e7ee0cfc4baeeadc71f69b72e379ebd95d8450,
2026-07-22, version 2026.7.22; Debian testing's FreeCAD 1.1.3 ships 2026.2.19, which does the same steps):
- Addon.py: package.xml's <depend type="python"> become `python_requires` (optional="true": `python_optional`);
  MissingDependencies.package_is_installed drops those FreeCAD's Python imports already (find_spec(name), else
  importlib.metadata.distribution(name)); the rest, sorted.
- addonmanager_installer_gui.py: a required package not on the allow-list (ALLOWED_PYTHON_PACKAGES.txt, see
  tests/data/addon_manager/README.md) is dropped after an error dialog, or, for a custom repository (2026.7.22
  on), kept after a confirmation; optional ones are offered unticked.
- addonmanager_dependency_installer.py (DependencyInstaller): one pip call per package, `python -m pip
  --disable-pip-version-check install --target <user data>/AdditionalPythonPackages/py3XY <name>
  --break-system-packages --constraint <FreeCAD/Addons>/Data/Python/3.X/constraints.txt`
  (addonmanager_utilities.create_pip_call, get_pip_target_directory; each call killed after 120 s).
- FreeCAD appends `<user data>/AdditionalPythonPackages/py3XY` (1.x; 0.20: `AdditionalPythonPackages`, where
  0.20's own Addon Manager installs) to sys.path before it runs the addons' Init.py (src/App/FreeCADInit.py).
- The addon itself: a clone of the whole repository in `<user data>/Mod/spur_cad`.

Here: in a FreeCAD whose Addon Manager has DependencyInstaller (1.x), its own classes read package.xml and run
the pip calls (`driven`); in 0.20 the test makes the calls above itself (`reproduced`). Both with the committed
constraints (the preference `pip_constraints_path` pointed at tests/data/addon_manager/Addons/Data/Python, as a
local folder is read), except in FreeCAD 1.0.0, whose Addon Manager knows no constraints and runs pip without
them (as it does for its users), the allow-list step left out: the Addon Manager 2026.7.22 keeps a custom repository's
packages (the route docs/install.md describes), and which packages the shipped lists would drop is checked in
tests/test_workbench_package.py. The optional jinja2 is not ticked. The addon is a copy of the checkout's
tracked files. Then freecadcmd, with nothing else set up, makes a gear, its stock and a job with the workbench.
Downloads about 380 MB from PyPI on Debian 12 (its FreeCAD's Python has numpy, scipy, matplotlib, pillow);
about a minute and a half here.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

from spur_cad.freecad_install import user_data_dir
from tests.freecad_helper import describe, run_freecad_code
from tests.workbench_helper import (
    ROOT,
    SMALL_GEAR_PROPERTIES,
    SMALL_JOB_PROPERTIES,
    SMALL_STOCK_PROPERTIES,
)

pytestmark = [pytest.mark.slow, pytest.mark.freecad]

CONSTRAINTS_BASE = ROOT / "tests" / "data" / "addon_manager" / "Addons" / "Data" / "Python"
INSTALL_TIMEOUT_S = 1200.0

PROBE_BODY = """
import importlib.metadata, importlib.util, sys, FreeCAD

def installed(name):  # MissingDependencies.package_is_installed
    if importlib.util.find_spec(name) is not None:
        return True
    try:
        importlib.metadata.distribution(name)
        return True
    except importlib.metadata.PackageNotFoundError:
        return False

RESULT.update(version=[int(part) for part in FreeCAD.Version()[:2]], python=list(sys.version_info[:2]),
              installed={name: installed(name) for name in NAMES},
              driven=importlib.util.find_spec("addonmanager_dependency_installer") is not None)
"""

# The Addon Manager's own steps, in FreeCAD 1.x: package.xml -> Addon -> MissingDependencies -> DependencyInstaller.
DRIVE_BODY = """
import FreeCAD
import addonmanager_freecad_interface as fci
import addonmanager_utilities as utils
from Addon import Addon, MissingDependencies
from addonmanager_dependency_installer import DependencyInstaller

# the Addon Manager's preferences: the Python that runs pip, and where the constraints are (a local folder)
# (1.x: PathToPythonExecutable, read by freecad.utils.get_python_exe; the Addon Manager's own fallback for
# older FreeCADs reads ExternalPythonExecutable)
for _name in ("PathToPythonExecutable", "ExternalPythonExecutable"):
    FreeCAD.ParamGet("User parameter:BaseApp/Preferences/PythonConsole").SetString(_name, PIP_PYTHON)
try:
    fci.Preferences().set("pip_constraints_path", CONSTRAINTS_BASE)
    constrained = True
except RuntimeError:  # FreeCAD 1.0.0's Addon Manager knows no constraints ("Unrecognized preference"): no -c
    constrained = False
addon = Addon("spur_cad", "https://git.invalid/spur_cad", Addon.Status.NOT_INSTALLED, "main")
addon.load_metadata_file(PACKAGE_XML)
try:
    deps = MissingDependencies()
    deps.import_from_addon(addon, [addon])
except TypeError:  # FreeCAD 1.0.0's Addon Manager: the addon and all addons go to the constructor
    deps = MissingDependencies(addon, [addon])
installer = DependencyInstaller([], list(deps.python_requires), [], None)
failures = []
installer.failure.connect(lambda short, detail: failures.append([short, detail]))
installer.no_pip.connect(lambda call: failures.append(["no pip", call]))
finished = []
installer.finished.connect(lambda *args: finished.append(True))
installer.run()
# 2026.x says whether every required package went in; FreeCAD 1.0.0's installer only emits `failure` for one
# that did not (and `finished` at the end either way)
succeeded = getattr(installer, "finished_successfully", bool(finished) and not failures)
RESULT.update(requires=list(deps.python_requires), optional=list(deps.python_optional), failures=failures,
              succeeded=succeeded, target=utils.get_pip_target_directory(),
              constrained=constrained,
              calls=[utils.create_pip_call(["install", "--target", "TARGET", name]) if constrained
                     else ["python", "-m", "pip", "install", "--disable-pip-version-check", "--target", "TARGET", name]
                     for name in deps.python_requires])
"""

BUILD_BODY = """
import importlib.util, sys, FreeCAD
import numba, numpy, OCP, spur_cad
from spur_cad_workbench import commands
doc = FreeCAD.newDocument("AddonManager")
gear = commands.make_gear(doc, **PROPS["gear"])
stock = commands.make_stock(gear, **PROPS["stock"])
job = commands.make_job(gear, stock, **PROPS["job"])
doc.recompute()
RESULT.update(states={o.Name: [list(o.State), getattr(o, "Status", "")] for o in doc.Objects},
              valid=gear.Shape.isValid(), volume=gear.Shape.Volume, tip=gear.TipRadius.Value,
              moves=[job.RoughingMoves, job.FinishingMoves], jit=numba.njit(lambda x: x + 1)(41),
              files={m.__name__: m.__file__ for m in (spur_cad, OCP, numba, numpy)},
              jinja2=importlib.util.find_spec("jinja2") is not None, user_data=FreeCAD.getUserAppDataDir())
"""

def python_dependencies() -> tuple[list[str], list[str]]:
    """package.xml's (required, optional) python dependencies."""
    import xml.etree.ElementTree as ET

    ns = {"p": "https://wiki.freecad.org/Package_Metadata"}
    depends = [d for d in ET.parse(ROOT / "package.xml").getroot().findall(".//p:depend", ns)
               if d.get("type") == "python"]
    optional = [d.text.strip() for d in depends if d.get("optional", "false").lower() == "true"]
    return [d.text.strip() for d in depends if d.text.strip() not in optional], optional


def copy_addon(destination: Path) -> None:
    """The repository as the Addon Manager's clone has it: every tracked file of the checkout (its working
    copy), links kept as links."""
    listed = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-z"], capture_output=True, check=True).stdout
    for name in listed.decode().split("\0"):
        source = ROOT / name
        if not name or not (source.exists() or source.is_symlink()):
            continue
        target = destination / name
        target.parent.mkdir(parents=True, exist_ok=True)
        if source.is_symlink():
            target.symlink_to(os.readlink(source))
        else:
            shutil.copy2(source, target)


def reproduce_pip_calls(names: list[str], target: Path, python: tuple[int, int]) -> list[str]:
    """DependencyInstaller._install_required's calls (create_pip_call's arguments), made here; returns each
    call's command line. Runs in order, stops at the first failure, as it does."""
    constraints = CONSTRAINTS_BASE / f"{python[0]}.{python[1]}" / "constraints.txt"
    target.mkdir(parents=True, exist_ok=True)
    calls = []
    for name in names:
        call = [sys.executable, "-m", "pip", "--disable-pip-version-check", "install", "--target", str(target), name,
                "--break-system-packages", "--constraint", str(constraints)]
        proc = subprocess.run(call, capture_output=True, text=True, timeout=INSTALL_TIMEOUT_S)
        assert proc.returncode == 0, f"{' '.join(call)}\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
        calls.append(" ".join(call))
    return calls


@pytest.fixture(scope="module")
def addon_manager_install(freecadcmd, tmp_path_factory):
    """A FreeCAD user (HOME = <work>/home) after the Addon Manager installed spur_cad and its dependencies."""
    required, optional = python_dependencies()
    probe_work = tmp_path_factory.mktemp("probe")
    body = f"NAMES = {required + optional!r}\n" + PROBE_BODY
    probe, proc = run_freecad_code(body, probe_work, freecadcmd=freecadcmd)
    assert probe is not None and probe.get("ok"), describe(proc, probe)
    python = tuple(probe["python"])
    if tuple(sys.version_info[:2]) != python:
        pytest.skip(f"pip needs a Python {python[0]}.{python[1]} like FreeCAD's; the tests run in "
                    f"{sys.version_info[0]}.{sys.version_info[1]}")
    work = tmp_path_factory.mktemp("addon_manager")
    user_data = user_data_dir({"HOME": str(work / "home")}, tuple(probe["version"]))
    copy_addon(user_data / "Mod" / "spur_cad")
    wanted = sorted(name for name in required if not probe["installed"][name])
    started = time.monotonic()
    if probe["driven"]:
        body = (f"PIP_PYTHON = {sys.executable!r}\nCONSTRAINTS_BASE = {str(CONSTRAINTS_BASE)!r}\n"
                f"PACKAGE_XML = {str(user_data / 'Mod' / 'spur_cad' / 'package.xml')!r}\n" + DRIVE_BODY)
        install, proc = run_freecad_code(body, work, freecadcmd=freecadcmd, timeout_s=INSTALL_TIMEOUT_S)
        assert install is not None and install.get("ok"), describe(proc, install)
        assert install["failures"] == [] and install["succeeded"], install["failures"]
        # every missing package is asked for; FreeCAD 1.0.0's Addon Manager looks packages up by their import name,
        # so it also asks again for one FreeCAD already has under another (pillow, imported as PIL): harmless
        again = set(install["requires"]) - set(wanted)
        assert set(wanted) <= set(install["requires"]) and all(probe["installed"][n] for n in again), install
        assert set(install["optional"]) >= {n for n in optional if not probe["installed"][n]}, install
        target = Path(install["target"])
    else:
        target = user_data / "AdditionalPythonPackages"  # FreeCAD 0.20's, and its Addon Manager's
        if probe["version"] >= [1, 0]:
            target = target / f"py{python[0]}{python[1]}"
        install = {"calls": reproduce_pip_calls(wanted, target, python), "requires": wanted}
    install["seconds"] = time.monotonic() - started
    yield dict(work=work, user_data=user_data, target=target, probe=probe, install=install)
    shutil.rmtree(target, ignore_errors=True)  # about 1.3 GB


def test_the_addon_manager_install_makes_a_gear_in_freecad(freecadcmd, addon_manager_install):
    """After the install FreeCAD, with nothing else set up, imports spur_cad from the addon's folder and its
    dependencies from the Addon Manager's folder (numba compiling), and the workbench makes a valid gear, its
    stock and a job; jinja2 (optional, not ticked) is absent unless FreeCAD's Python has it."""
    found = addon_manager_install
    props = dict(gear=SMALL_GEAR_PROPERTIES, stock=SMALL_STOCK_PROPERTIES, job=SMALL_JOB_PROPERTIES)
    result, proc = run_freecad_code(f"PROPS = {props!r}\n" + BUILD_BODY, found["work"], freecadcmd=freecadcmd,
                                    timeout_s=300)
    assert result is not None and result.get("ok"), describe(proc, result) + f"\ninstall: {found['install']}"
    assert Path(result["user_data"]).resolve() == found["user_data"].resolve()
    files = {name: Path(path).resolve() for name, path in result["files"].items()}
    assert files["spur_cad"] == (found["user_data"] / "Mod" / "spur_cad" / "spur_cad" / "__init__.py").resolve()
    assert files["OCP"].is_relative_to(found["target"].resolve())
    assert files["numba"].is_relative_to(found["target"].resolve())
    assert all(state == ["Up-to-date"] and status == "ok" for state, status in result["states"].values()), result
    assert result["valid"] and result["volume"] > 0 and result["tip"] > 0 and min(result["moves"]) > 0
    assert result["jit"] == 42
    assert result["jinja2"] == found["probe"]["installed"]["jinja2"]
    print(f"install ({'driven' if found['probe']['driven'] else 'reproduced'}): {found['install']['seconds']:.0f} s,"
          f" {found['install']['requires']}")


def test_without_cadquery_ocp_in_the_install_the_gear_cannot_be_made(freecadcmd, addon_manager_install, tmp_path):
    """Guard: the same install without cadquery-ocp's files (what a package.xml without it, or an Addon Manager
    dropping it for its allow-list, leaves; planted for a second user whose folder links to the first install's
    other files) fails in the test above's body, on the missing OCP."""
    found = addon_manager_install
    user_data = user_data_dir({"HOME": str(tmp_path / "home")}, tuple(found["probe"]["version"]))
    copy_addon(user_data / "Mod" / "spur_cad")
    folder = user_data / found["target"].relative_to(found["user_data"])
    folder.mkdir(parents=True)
    left_out = [entry.name for entry in found["target"].iterdir()
                if entry.name.lower().startswith(("ocp", "cadquery_ocp"))]
    assert "OCP" in left_out
    for entry in found["target"].iterdir():
        if entry.name not in left_out:
            (folder / entry.name).symlink_to(entry)
    props = dict(gear=SMALL_GEAR_PROPERTIES, stock=SMALL_STOCK_PROPERTIES, job=SMALL_JOB_PROPERTIES)
    result, proc = run_freecad_code(f"PROPS = {props!r}\n" + BUILD_BODY, tmp_path, freecadcmd=freecadcmd)
    assert result is not None and result.get("ok") is False, describe(proc, result)
    assert "No module named 'OCP'" in result["error"]
