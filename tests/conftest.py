"""pytest plumbing for the external tools: FreeCAD (`freecad` marker), LinuxCNC `rs274`
(`linuxcnc` marker), headless Chromium and poppler's pdfinfo / pdftotext (`browser` marker), and the CadQuery
front-end (`cadquery` marker: the engine needs OCP only; the build123d 0.13 flavour, which cannot hold CadQuery 2.8,
runs with `-m "not cadquery"`).

A marked test whose tool is missing is skipped locally, but fails when the environment
variable CI is "true": CI installs the tools (.ci/run), so a missing tool there is a bug.
"""

from __future__ import annotations

import os
import shutil
import sysconfig
from pathlib import Path

import pytest

from spur_cad.dependencies import is_installed
from tests.rs274_helper import rs274_path

FREECADCMD_NAMES = ("freecadcmd", "FreeCADCmd", "freecadcmd-python3")
FREECADCMD_CANDIDATES = ("/usr/lib/freecad/bin/freecadcmd-python3", "/usr/lib/freecad/bin/FreeCADCmd",
                         "/usr/lib/freecad-python3/bin/FreeCADCmd")
FREECAD_GUI_NAMES = ("freecad", "FreeCAD", "freecad-python3")

__all__ = ["browser_paths", "freecad_gui_paths", "freecadcmd_path", "rs274_path"]


def _find(names: tuple[str, ...], candidates: tuple[str, ...] = (), env_var: str | None = None) -> str | None:
    """First executable from $env_var, then `names` on PATH, then the fixed `candidates`."""
    override = os.environ.get(env_var) if env_var else None
    if override:
        return override if os.access(override, os.X_OK) else None
    for name in names:
        found = shutil.which(name)
        if found:
            return found
    return next((path for path in candidates if os.access(path, os.X_OK)), None)


def freecadcmd_path() -> str | None:
    """Path of FreeCAD's console executable ($FREECADCMD, freecadcmd, FreeCADCmd), or None."""
    return _find(FREECADCMD_NAMES, FREECADCMD_CANDIDATES, "FREECADCMD")


def freecad_gui_paths() -> tuple[str, str] | None:
    """(xvfb-run, freecad) for running the GUI headless, or None if either is missing."""
    xvfb_run = shutil.which("xvfb-run")
    freecad = _find(FREECAD_GUI_NAMES, ("/usr/lib/freecad/bin/freecad-python3",), "FREECAD_GUI")
    return (xvfb_run, freecad) if xvfb_run and freecad else None


def browser_paths() -> tuple[str, str, str] | None:
    """(chromium, pdfinfo, pdftotext): Debian's Chromium to render and print report.html, poppler to read the
    PDF it prints; None if any is missing."""
    chromium = _find(("chromium", "chromium-browser"), (), "CHROMIUM")
    pdfinfo, pdftotext = shutil.which("pdfinfo"), shutil.which("pdftotext")
    return (chromium, pdfinfo, pdftotext) if chromium and pdfinfo and pdftotext else None


def running_in_ci() -> bool:
    """True when the environment variable CI says so (GitHub/GitLab set CI=true)."""
    return os.environ.get("CI", "").strip().lower() in ("true", "1", "yes")


def require_tool(path, tool: str, what: str):
    """Return `path`; if it is missing, fail under CI and skip otherwise."""
    if path:
        return path
    message = f"CI requires {tool}: {what} not found"
    if running_in_ci():
        pytest.fail(message, pytrace=False)
    pytest.skip(f"{tool} not available: {what} not found")


def pytest_runtest_setup(item: pytest.Item) -> None:
    """Skip (locally) or fail (CI=true) marked tests whose external tool is missing."""
    if item.get_closest_marker("freecad"):
        require_tool(freecadcmd_path(), "FreeCAD", "freecadcmd")
    if item.get_closest_marker("linuxcnc"):
        require_tool(rs274_path(), "LinuxCNC", "rs274")
    if item.get_closest_marker("browser"):
        require_tool(browser_paths(), "Chromium and poppler", "chromium, pdfinfo or pdftotext")
    if item.get_closest_marker("cadquery"):
        require_tool(is_installed("cadquery") or None, "CadQuery", "the cadquery package (spur_cad[cadquery])")


@pytest.fixture(scope="session")
def freecadcmd() -> str:
    """Path of `freecadcmd` (skip locally / fail in CI when missing)."""
    return require_tool(freecadcmd_path(), "FreeCAD", "freecadcmd")


@pytest.fixture(scope="session")
def freecad_gui() -> tuple[str, str]:
    """(xvfb-run, freecad) for GUI tests (skip locally / fail in CI when missing)."""
    return require_tool(freecad_gui_paths(), "FreeCAD GUI", "xvfb-run or freecad")


@pytest.fixture(scope="session")
def browser() -> tuple[str, str, str]:
    """(chromium, pdfinfo, pdftotext) (skip locally / fail in CI when missing)."""
    return require_tool(browser_paths(), "Chromium and poppler", "chromium, pdfinfo or pdftotext")


@pytest.fixture(scope="session")
def rs274() -> str:
    """Path of LinuxCNC's `rs274` (skip locally / fail in CI when missing)."""
    return require_tool(rs274_path(), "LinuxCNC", "rs274")


@pytest.fixture(scope="session")
def venv_site_packages() -> str:
    """site-packages (purelib) of the running interpreter, to put on FreeCAD's sys.path."""
    return sysconfig.get_paths()["purelib"]


@pytest.fixture(scope="session")
def small_job(tmp_path_factory):
    """The hostile corpus's base job made valid (face width 3 mm, no simulation): a run takes seconds."""
    base = Path(__file__).resolve().parent / "data" / "hostile" / "clearance_negative.toml"
    text = "\n".join(base.read_text().splitlines()[1:]).replace("clearance_mm = -1.0", "clearance_mm = 1.0")
    path = tmp_path_factory.mktemp("small_job") / "job.toml"
    path.write_text(text + "\n")
    return path
