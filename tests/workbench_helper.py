"""Shared pieces of the workbench tests: a small quick job, running code in FreeCAD with the workbench
installed the way users install it, and comparing the workbench's exported files with the CLI's."""

from __future__ import annotations

import json
import re
from pathlib import Path

from tests.freecad_helper import run_freecad_code

ROOT = Path(__file__).resolve().parents[1]
ARTIFACTS = ROOT / "test-artifacts"
REFERENCE_JOB = ROOT / "resources" / "examples" / "reference_gear.toml"

# A job that plans in about a second: 12 teeth, 6 mm face width, finishing stations 1.5 mm apart.
SMALL_JOB = """
[job]
name = "small quick gear"
profile_tolerance_mm = 0.002

[gear]
teeth = {teeth}
module_mm = 3.0
rack_tip_radius_mm = 0.9
thickness_allowance_percent = 2.0
face_width_mm = 6.0
bore_diameter_mm = 10.0

[stock]
radial_allowance_mm = 0.5

[tools.roughing]
kind = "flat"
diameter_mm = 2.0
flutes = 3

[tools.finishing]
kind = "bull_nose"
diameter_mm = {finishing_diameter}
corner_radius_mm = 0.5

[roughing]
strategy = "levels"               # given (the default is flank): the tests written for this job read levels

[finishing]
target_scallop_mm = 0.05
step_over_mm = 1.5
"""

# The same job as property values of the workbench's objects (written out by hand, not via the schema).
SMALL_GEAR_PROPERTIES = dict(Teeth=12, Module=3.0, RackTipRadius=0.9, ThicknessAllowancePercent=2.0, FaceWidth=6.0,
                             BoreDiameter=10.0)
SMALL_STOCK_PROPERTIES = dict(RadialAllowance=0.5)
SMALL_JOB_PROPERTIES = dict(JobName="small quick gear", ProfileTolerance=0.002, UseBottomTool=False,
                            FlankAllowance=0.1, UseRoughingTool=True,  # 0.1: the job file's default
                            RoughingStrategy="levels",  # as SMALL_JOB gives it (the default, a new job's, is flank)
                            RoughingToolKind="flat", RoughingToolDiameter=2.0, RoughingFlutes=3,
                            UseFinishingTool=True, FinishingToolKind="bull_nose", FinishingToolDiameter=1.5,
                            FinishingCornerRadius=0.5, TargetScallop=0.05, FinishingStepOver=1.5)


# FreeCAD's log entry of a verification that fails (an error, as the report view shows it): one line per tooth space
# that is off, then the verdict. For tests that make one fail on purpose (run_freecad_code's log_allowed).
VERIFY_FAIL_LOG = r"^Err: Verify program: space 0: [^\n]*(\nspace \d+: [^\n]*)*\nFAIL: [^\n]*$"

# Waits for the 3D view's camera to come to rest, for GUI code (needs time, QtGui and settle()).
SETTLE_VIEW = r"""
import time

def settle_view(view, limit_s=15.0):
    # process events until the 3D view's camera has come to rest: FreeCAD 1.0 and 1.1 animate a change of view
    # (viewIsometric, fitAll) over a quarter of a second or more, longer on a busy machine, and a camera read before
    # the end sees a view on its way. At rest: unchanged over three reads 50 ms apart; at most limit_s.
    deadline = time.monotonic() + limit_s
    readings = [view.getCamera()]
    while time.monotonic() < deadline:
        settle()
        time.sleep(0.05)
        readings.append(view.getCamera())
        if len(readings) >= 4 and len(set(readings[-4:])) == 1:
            return
    raise RuntimeError(f"the 3D view's camera still moved after {limit_s} s")
"""

GUI_PRELUDE = r"""
import os, sys, time, traceback
import FreeCAD, FreeCADGui
from PySide import QtCore, QtGui

hooked = []
sys.excepthook = lambda kind, value, tb: hooked.append("".join(traceback.format_exception(kind, value, tb)))
main_window = FreeCADGui.getMainWindow()
report = main_window.findChild(QtGui.QTextEdit, "Report view")

def settle(times=8):
    for _ in range(times):
        QtGui.QApplication.processEvents()

def dock_showing(class_name):
    # the dock widget whose content is FreeCAD's widget of C++ class `class_name`, found by what it shows, not by its
    # title. Only the docks are looked at: wrapping every widget of the main window (findChildren(QWidget)) also wraps
    # the panel's FreeCAD-made fields, and such stale wrappers came back for the fields of a panel opened later.
    for dock in main_window.findChildren(QtGui.QDockWidget):
        if dock.widget() is not None and dock.widget().metaObject().className() == class_name:
            return dock
    return None

def task_dock():
    # the task view's dock: 0.20 a tab ("combiTab") of the "Combo View" dock, 1.0 a dock "Tasks" beside "Model", 1.1 a
    # dock "Tasks" in the right-hand overlay (observed in each)
    dock = dock_showing("Gui::TaskView::TaskView")
    if dock is None:
        dock = model_dock()
        assert dock.widget().findChild(QtGui.QTabWidget, "combiTab") is not None, "no task view found"
    return dock

def model_dock():
    # the model tree's dock (Gui::DockWnd::ComboView): "Combo View" in 0.20 (its first tab), "Model" in 1.0 and 1.1
    return dock_showing("Gui::DockWnd::ComboView")

def set_task_dock_width(width):
    # a dock in the main window's dock areas is resized by the main window (0.20, 1.0); 1.1's overlay
    # (Gui::OverlayTabWidget, outside the dock areas, 388 px wide by default) by fixing the overlay's own width (FreeCAD
    # puts its width back when the panel changes; Qt keeps a widget's geometry within its fixed width)
    dock = task_dock()
    overlay = dock.parentWidget()
    while overlay is not None and overlay.metaObject().className() != "Gui::OverlayTabWidget":
        overlay = overlay.parentWidget()
    if overlay is not None:
        overlay.setFixedWidth(width)
    else:
        main_window.resizeDocks([dock], [width], QtCore.Qt.Horizontal)
    settle()
    return dock
""" + SETTLE_VIEW
"""The start of a test body run in FreeCAD's GUI: uncaught exceptions collected in `hooked` (a test asserts it
stays empty), the main window and its report view, `settle()` (let Qt process pending events), and the docks
found by what they hold (`task_dock()`, `model_dock()`, `set_task_dock_width(px)`), whose titles and places differ
between FreeCAD 0.20, 1.0 and 1.1."""


def small_job_text(teeth: int = 12, finishing_diameter: float = 1.5) -> str:
    return SMALL_JOB.format(teeth=teeth, finishing_diameter=finishing_diameter)


def install_workbench(home: Path) -> None:
    """Install the workbench for a user whose HOME is `home`, as `spur-cad install-freecad` does."""
    from spur_cad.freecad_install import install

    install({"HOME": str(home)})


def run_workbench_code(body: str, work: Path, **kwargs):
    """run_freecad_code with the workbench installed in the run's HOME (work/home) and no other path set up."""
    install_workbench(work / "home")
    return run_freecad_code(body, work, **kwargs)


def step_volumes(path: Path) -> list[float]:
    """Volumes (mm^3) of the solids in a STEP file, by OCP's NURBS-accurate integration."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_Reader
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer

    from spur_cad.cad.solid import solid_volume_mm3

    reader = STEPControl_Reader()
    assert reader.ReadFile(str(path)) == IFSelect_RetDone, path
    reader.TransferRoots()
    explorer = TopExp_Explorer(reader.OneShape(), TopAbs_SOLID)
    volumes = []
    while explorer.More():
        volumes.append(solid_volume_mm3(explorer.Current()))
        explorer.Next()
    return sorted(volumes)


_DATE = re.compile(r"\d{4}-\d{2}-\d{2}")
GCODE_SUFFIXES = {".ngc", ".nc", ".mpf", ".min", ".tap", ".gcode", ".spf", ".ssb"}


def _without_date_comments(text: str) -> list[str]:
    return [line for line in text.splitlines() if not (_DATE.search(line) and ("(" in line or ";" in line))]


def _summary_differences(cli: Path, wb: Path) -> list[str]:
    """summary.json: equal apart from timings, the job's source and the STEP sizes."""
    a, b = json.loads(cli.read_text()), json.loads(wb.read_text())
    for data in (a, b):
        data.pop("timings_s", None)
        data.get("job", {}).pop("file", None)
        data.get("simulation", {}).pop("seconds", None)
        # STEP sizes: OCCT names each product "Open CASCADE STEP translator 7.9 <n>" with a
        # per-process export counter, so the size depends on how many exports ran before.
        data.get("cad", {}).pop("step_bytes", None)
    if a != b:
        return [f"summary.json differs in {sorted(k for k in set(a) | set(b) if a.get(k) != b.get(k))}"]
    return []


def output_differences(cli_dir: Path, workbench_dir: Path, sources: tuple[str, ...] = ()) -> list[str]:
    """How the workbench's files differ from the CLI's for the same job (empty: the same content).

    STEP: solid volumes within 1e-9 relative; summary.json: equal apart from timings, the job's
    source and the STEP sizes; G-code: equal apart from comment lines with a date; the HTML report: equal apart from
    the job's source (`sources`: the CLI's and the workbench's) and times in seconds; other files: bytes.
    """
    problems = []
    cli_names = sorted(p.name for p in cli_dir.iterdir())
    wb_names = sorted(p.name for p in workbench_dir.iterdir())
    if cli_names != wb_names:
        problems.append(f"file names differ: CLI {cli_names}, workbench {wb_names}")
    for name in sorted(set(cli_names) & set(wb_names)):
        cli, wb = cli_dir / name, workbench_dir / name
        if name.endswith(".step"):
            a, b = step_volumes(cli), step_volumes(wb)
            if len(a) != len(b) or any(abs(x - y) > 1e-9 * abs(x) for x, y in zip(a, b)):
                problems.append(f"{name}: volumes {a} vs {b}")
        elif name == "summary.json":
            problems += _summary_differences(cli, wb)
        elif Path(name).suffix in GCODE_SUFFIXES:
            if _without_date_comments(cli.read_text()) != _without_date_comments(wb.read_text()):
                problems.append(f"{name}: G-code differs")
        elif name.endswith(".html"):
            if _comparable_html(cli.read_text(), sources) != _comparable_html(wb.read_text(), sources):
                problems.append(f"{name}: differs")
        elif cli.read_bytes() != wb.read_bytes():
            problems.append(f"{name}: bytes differ")
    return problems


def _comparable_html(text: str, sources: tuple[str, ...]) -> str:
    """An HTML report without what legitimately differs between two runs: the job's source and times."""
    for source in sources:
        text = text.replace(source, "<source>")
    return re.sub(r"(\[s\]</th>\s*<td[^>]*>)[^<]*", r"\1<time>", text)
