"""What a new user sees in the 3D view, and a saved simulation reopened (issue 28, defects 4 and 5).

One FreeCAD GUI session (Xvfb) creates a gear, stock and job with the toolbar commands, simulates and
imports a job file, reading the camera after each step: the view is isometric (the gear, whose axis
is X, seen obliquely) and the objects' bounding boxes lie inside the view, filling it; while a
simulation is visible the toolpaths are hidden. The same session saves a document with a simulation
(made by the Python entry points), which a new GUI session and a new freecadcmd open without any
error text in the report view, on stdout or on stderr. Screenshots go to test-artifacts/.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.freecad_helper import describe
from tests.workbench_helper import (
    ARTIFACTS,
    GUI_PRELUDE,
    SMALL_GEAR_PROPERTIES,
    SMALL_JOB_PROPERTIES,
    SMALL_STOCK_PROPERTIES,
    run_workbench_code,
    small_job_text,
)

GEAR_SHOT = ARTIFACTS / "workbench_new_gear_view.png"
SIMULATION_SHOT = ARTIFACTS / "workbench_simulation_on_top.png"
REOPENED_SHOT = ARTIFACTS / "workbench_reopened_simulation.png"
ERROR_WORDS = ("error", "traceback", "exception", "failed")

COMMON = GUI_PRELUDE + r"""

def camera(doc, objects):
    # the view direction and where the objects' bounding box corners land on the screen (pixels)
    view = FreeCADGui.getDocument(doc.Name).ActiveView
    settle_view(view)
    box = FreeCAD.BoundBox()
    for obj in objects:
        box.add(obj.Shape.BoundBox)
    corners = [FreeCAD.Vector(x, y, z) for x in (box.XMin, box.XMax) for y in (box.YMin, box.YMax)
               for z in (box.ZMin, box.ZMax)]
    screen = [list(view.getPointOnScreen(corner)) for corner in corners]
    return {"direction": list(view.getViewDirection()), "screen": screen, "size": list(view.getSize())}
"""

BUILD = COMMON + r"""
def answer_file_dialog(path):
    def fill(left=50):
        dialog = QtGui.QApplication.activeModalWidget()
        if not isinstance(dialog, QtGui.QFileDialog):
            if left:
                QtCore.QTimer.singleShot(100, lambda: fill(left - 1))
            return
        dialog.findChild(QtGui.QLineEdit, "fileNameEdit").setText(path)
        dialog.accept()
    QtCore.QTimer.singleShot(100, fill)

def select(obj):
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(obj)

def visibility(job):
    return [job.RoughingToolpath.ViewObject.Visibility, job.FinishingToolpath.ViewObject.Visibility]

FreeCADGui.activateWorkbench("SpurCadWorkbench")
settle()
FreeCADGui.runCommand("SpurCad_Gear")      # no document open: the command makes one
settle()
doc = FreeCAD.ActiveDocument
gear = doc.getObject("Gear")
RESULT["gear"] = camera(doc, [gear])
FreeCADGui.Selection.clearSelection()
FreeCADGui.ActiveDocument.ActiveView.saveImage(GEAR_SHOT, 1000, 800, "White")
for name, value in PROPS["gear"].items():
    setattr(gear, name, value)
doc.recompute()

select(gear)
FreeCADGui.runCommand("SpurCad_Stock")
settle()
stock = doc.getObject("Stock")
RESULT["stock"] = camera(doc, [gear, stock])

select(stock)
FreeCADGui.runCommand("SpurCad_Job")
settle()
job = doc.getObject("Job")
job.ViewObject.Proxy.panel.reject()
settle()
RESULT["job"] = camera(doc, [gear, stock])
job.UseBottomTool = False  # the small job's one roughing tool (a new job may rough in two stages)
for name, value in PROPS["job"].items():
    setattr(job, name, value)
doc.recompute()
RESULT["toolpaths_before"] = visibility(job)

select(job)
FreeCADGui.runCommand("SpurCad_Simulate")
settle()
simulation = [o for o in doc.Objects if getattr(getattr(o, "Proxy", None), "KIND", "") == "simulation"][0]
RESULT["simulated"] = [visibility(job), simulation.ViewObject.Visibility, simulation.ViewObject.DisplayMode]
FreeCADGui.Selection.clearSelection()
FreeCADGui.ActiveDocument.ActiveView.saveImage(SIMULATION_SHOT, 1000, 800, "White")
simulation.ViewObject.Visibility = False   # Space on the simulation: the toolpaths come back
RESULT["simulation_hidden"] = visibility(job)
simulation.ViewObject.Visibility = True
RESULT["simulation_shown"] = visibility(job)

answer_file_dialog(JOB_FILE)
FreeCADGui.runCommand("SpurCad_ImportJob")  # a new document named after the job file
settle()
imported = FreeCAD.ActiveDocument
RESULT["imported"] = [imported.Name, camera(imported, [imported.getObject("Gear"), imported.getObject("Stock")])]

# the document issue 28 reopens: made by the entry points, simulated, saved
from spur_cad_workbench import commands
saved = FreeCAD.newDocument("Saved")
saved_gear = commands.make_gear(saved, **PROPS["gear"])
saved_stock = commands.make_stock(saved_gear, **PROPS["stock"])
saved_job = commands.make_job(saved_gear, saved_stock, **PROPS["job"])
saved.recompute()
commands.simulate(saved_job)
saved.saveAs(SAVED)
settle()
RESULT["report"] = report.toPlainText()
RESULT["hooked"] = hooked
"""

REOPEN = COMMON + r"""
doc = FreeCAD.openDocument(SAVED)
settle()
simulation = doc.getObject("Simulation")
job = doc.getObject("Job")
RESULT["objects"] = {o.Name: [list(o.State), o.Status] for o in doc.Objects}
RESULT["simulation"] = [simulation.ViewObject.Visibility, simulation.ViewObject.DisplayMode,
                        len(simulation.Points.Points), len(simulation.Color),
                        [job.RoughingToolpath.ViewObject.Visibility, job.FinishingToolpath.ViewObject.Visibility]]
view = FreeCADGui.ActiveDocument.ActiveView
view.viewIsometric()
view.fitAll()
settle_view(view)
view.saveImage(REOPENED_SHOT, 1000, 800, "White")
doc.recompute()                             # the job plans again: the same values, the simulation stays current
settle()
RESULT["after_recompute"] = [simulation.Status, simulation.ViewObject.DisplayMode]
RESULT["report"] = report.toPlainText()
RESULT["hooked"] = hooked
"""

REOPEN_CONSOLE = r"""
import FreeCAD
doc = FreeCAD.openDocument(SAVED)
RESULT["objects"] = {o.Name: [list(o.State), o.Status] for o in doc.Objects}
RESULT["points"] = len(doc.getObject("Simulation").Points.Points)
"""


def _props() -> dict:
    return {"gear": SMALL_GEAR_PROPERTIES, "stock": SMALL_STOCK_PROPERTIES, "job": SMALL_JOB_PROPERTIES}


def _error_lines(*texts: str) -> list[str]:
    """Lines of FreeCAD's output that report an error of any kind."""
    return [line for text in texts for line in text.splitlines() if any(w in line.lower() for w in ERROR_WORDS)]


@pytest.fixture(scope="module")
def built(freecad_gui, tmp_path_factory):
    """The first session: commands, camera readings, screenshots and the saved document's path."""
    ARTIFACTS.mkdir(exist_ok=True)
    for shot in (GEAR_SHOT, SIMULATION_SHOT, REOPENED_SHOT):
        shot.unlink(missing_ok=True)
    work = tmp_path_factory.mktemp("views")
    job_file = work / "small.toml"
    job_file.write_text(small_job_text())
    saved = work / "saved_simulation.FCStd"
    body = (f"PROPS = {_props()!r}\nJOB_FILE = {str(job_file)!r}\nSAVED = {str(saved)!r}\n"
            f"GEAR_SHOT = {str(GEAR_SHOT)!r}\nSIMULATION_SHOT = {str(SIMULATION_SHOT)!r}\n" + BUILD)
    result, proc = run_workbench_code(body, work / "build", gui=freecad_gui, timeout_s=420)
    assert result is not None and result.get("ok"), describe(proc, result)
    assert result["hooked"] == [], result["hooked"]
    assert _error_lines(result["report"]) == [], result["report"]
    assert saved.exists()
    return result, saved


def _assert_isometric_and_fitted(reading: dict, fill: float = 0.35) -> None:
    """The view looks along no principal axis, and the objects lie inside it and span a good part of it."""
    direction = np.array(reading["direction"])
    assert np.all(np.abs(direction) > 0.3), direction  # every component well away from zero
    width, height = reading["size"]
    screen = np.array(reading["screen"])
    assert np.all(screen[:, 0] >= 0) and np.all(screen[:, 0] <= width), (screen, width)
    assert np.all(screen[:, 1] >= 0) and np.all(screen[:, 1] <= height), (screen, height)
    span = screen.max(axis=0) - screen.min(axis=0)
    assert max(span[0] / width, span[1] / height) > fill, (span, width, height)


@pytest.mark.freecad
def test_a_new_gear_is_seen_isometric_and_fitted_and_stock_and_job_keep_it_fitted(built):
    result, _ = built
    _assert_isometric_and_fitted(result["gear"])
    iso = np.array(result["gear"]["direction"])
    assert np.allclose(iso, np.array([-1.0, 1.0, -1.0]) / np.sqrt(3.0), atol=1e-3)  # FreeCAD's isometric view
    for step in ("stock", "job"):  # fitted again, in the same orientation
        _assert_isometric_and_fitted(result[step])
        assert np.allclose(result[step]["direction"], iso, atol=1e-6)
    # the screenshot: the gear drawn in its colour, the background white
    import matplotlib.image

    image = matplotlib.image.imread(GEAR_SHOT)[..., :3]
    white = np.all(image > 0.98, axis=-1).mean()
    assert 0.2 < white < 0.95, white


@pytest.mark.freecad
def test_an_imported_job_is_seen_isometric_and_fitted(built):
    result, _ = built
    name, reading = result["imported"]
    assert name == "small"
    _assert_isometric_and_fitted(reading)


@pytest.mark.freecad
def test_the_simulation_is_shown_and_the_toolpaths_hidden_while_it_is(built):
    result, _ = built
    assert result["toolpaths_before"] == [True, True]
    toolpaths, shown, mode = result["simulated"]
    assert toolpaths == [False, False] and shown is True and mode == "Color"
    assert result["simulation_hidden"] == [True, True]
    assert result["simulation_shown"] == [False, False]
    # the screenshot: the deviation colours (green on the design) on the gear, right of the colour bar
    import matplotlib.image

    image = matplotlib.image.imread(SIMULATION_SHOT)[..., :3]
    part = image[:, image.shape[1] // 4:]
    assert np.all(np.abs(part - np.array([0.0, 1.0, 0.0])) < 0.2, axis=-1).sum() > 2000
    for colour in ((0.85, 0.45, 0.1), (0.1, 0.55, 0.2)):  # and no roughing (orange) or finishing (green) path
        assert np.all(np.abs(part - np.array(colour)) < 0.08, axis=-1).sum() < 50, colour


@pytest.mark.freecad
def test_a_saved_simulation_reopens_in_a_new_gui_session_without_any_error(built, freecad_gui, tmp_path):
    _, saved = built
    body = f"SAVED = {str(saved)!r}\nREOPENED_SHOT = {str(REOPENED_SHOT)!r}\n" + REOPEN
    result, proc = run_workbench_code(body, tmp_path / "reopen", gui=freecad_gui, timeout_s=300)
    assert result is not None and result.get("ok"), describe(proc, result)
    assert result["hooked"] == []
    assert _error_lines(result["report"], proc.stdout, proc.stderr) == [], describe(proc, result)
    objects = result["objects"]
    assert sorted(objects) == ["FinishingToolpath", "Gear", "Job", "RoughingToolpath", "Simulation", "Stock"]
    assert all(state == [] or state == ["Up-to-date"] for state, _ in objects.values()), objects
    assert all(status == "ok" for _, status in objects.values()), objects
    visible, mode, points, colours, toolpaths = result["simulation"]
    assert visible is True and mode == "Color" and points == colours > 0
    assert toolpaths == [False, False]
    assert result["after_recompute"] == ["ok", "Color"]


@pytest.mark.freecad
def test_a_saved_simulation_reopens_in_freecadcmd_without_any_error(built, freecadcmd, tmp_path):
    _, saved = built
    result, proc = run_workbench_code(f"SAVED = {str(saved)!r}\n" + REOPEN_CONSOLE, tmp_path / "console",
                                      freecadcmd=freecadcmd)
    assert result is not None and result.get("ok"), describe(proc, result)
    assert _error_lines(proc.stdout, proc.stderr) == [], describe(proc, result)
    assert all(status == "ok" for _, status in result["objects"].values()) and result["points"] > 0
