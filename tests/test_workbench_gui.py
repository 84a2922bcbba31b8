"""The workbench in FreeCAD's GUI (xvfb): it activates, every command runs from its toolbar command and is
echoed as a macro line, the job's task panel accepts and rejects values with the command line's messages,
and a screenshot of the 3D view (gear, stock, toolpaths) goes to test-artifacts/. Any Python exception
in the report view (or reaching sys.excepthook) fails the test."""

from __future__ import annotations

import re

import numpy as np
import pytest

from spur_cad.cam.restart import parse_restart
from spur_cad.errors import SpurCadError
from spur_cad.job import parse_job
from spur_cad.pipeline import plan_cam, restart_program
from tests.freecad_helper import describe
from tests.workbench_helper import (
    ARTIFACTS,
    SETTLE_VIEW,
    SMALL_GEAR_PROPERTIES,
    SMALL_JOB_PROPERTIES,
    SMALL_STOCK_PROPERTIES,
    VERIFY_FAIL_LOG,
    run_workbench_code,
    small_job_text,
)

SCREENSHOT = ARTIFACTS / "workbench_3d_view.png"

GUI_BODY = r"""
import json, os, sys, traceback
import FreeCAD, FreeCADGui
from PySide import QtCore, QtGui

hooked = []
sys.excepthook = lambda kind, value, tb: hooked.append("".join(traceback.format_exception(kind, value, tb)))
main_window = FreeCADGui.getMainWindow()
report = main_window.findChild(QtGui.QTextEdit, "Report view")
console = main_window.findChild(QtGui.QPlainTextEdit, "Python console")
FreeCAD.ParamGet("User parameter:BaseApp/Preferences/Macro").SetBool("ScriptToPyConsole", True)

def settle():
    for _ in range(5):
        QtGui.QApplication.processEvents()
""" + SETTLE_VIEW + r"""

def answer_file_dialog(path):
    # type the path into the next file dialog and press OK, as a user would (give up after 5 s)
    def fill(left=50):
        dialog = QtGui.QApplication.activeModalWidget()
        if not isinstance(dialog, QtGui.QFileDialog):
            if left:
                QtCore.QTimer.singleShot(100, lambda: fill(left - 1))
            return
        dialog.findChild(QtGui.QLineEdit, "fileNameEdit").setText(path)
        dialog.accept()
    QtCore.QTimer.singleShot(100, fill)

def answer_restart_dialog(space, then_path):
    # pick the tooth space in the next Restart program dialog, then type the path into the file dialog after it
    def fill(left=50):
        dialog = QtGui.QApplication.activeModalWidget()
        if dialog is None or dialog.objectName() != "SpurCadRestartDialog":
            if left:
                QtCore.QTimer.singleShot(100, lambda: fill(left - 1))
            return
        combo = dialog.findChild(QtGui.QComboBox, "space")
        combo.setCurrentIndex(combo.findData(space))
        answer_file_dialog(then_path)
        dialog.accept()
    QtCore.QTimer.singleShot(100, fill)

def select(obj):
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(obj)

FreeCADGui.activateWorkbench("SpurCadWorkbench")
settle()
workbench = FreeCADGui.activeWorkbench()
RESULT["workbench"] = workbench.name()
RESULT["toolbar"] = workbench.getToolbarItems().get("spur_cad", [])
menus = [m for m in main_window.menuBar().findChildren(QtGui.QMenu) if m.title() == "spur_cad"]
RESULT["menu"] = [a.text() for a in menus[0].actions()] if menus else []

doc = FreeCAD.newDocument("Gui")
FreeCADGui.runCommand("SpurCad_Gear")
gear = doc.getObject("Gear")
for name, value in PROPS["gear"].items():
    setattr(gear, name, value)
doc.recompute()
select(gear)
FreeCADGui.runCommand("SpurCad_Stock")
stock = doc.getObject("Stock")
for name, value in PROPS["stock"].items():
    setattr(stock, name, value)
select(stock)
FreeCADGui.runCommand("SpurCad_Job")
settle()
job = doc.getObject("Job")
panel = job.ViewObject.Proxy.panel
RESULT["panel_open"] = bool(FreeCADGui.Control.activeDialog())
RESULT["suggested_messages"] = panel.current_messages()
for name, value in PROPS["job"].items():
    panel.set_value(name, value)
RESULT["valid_messages"] = panel.current_messages()
RESULT["notes"] = {name: label.text() for name, label in panel.notes.items() if label.text()}
suggested_diameter = job.FinishingToolDiameter.Value
panel.set_value("FinishingToolDiameter", 9.0)
RESULT["too_wide"] = panel.current_messages()
RESULT["accept_too_wide"] = panel.accept()
RESULT["unchanged"] = job.FinishingToolDiameter.Value == suggested_diameter
RESULT["still_open"] = bool(FreeCADGui.Control.activeDialog())
panel.set_value("FinishingToolDiameter", 1.5)
panel.set_value("RoughingToolDiameter", -1.0)
RESULT["negative"] = panel.current_messages()
panel.set_value("RoughingToolDiameter", 2.0)
RESULT["fixed"] = panel.current_messages()
RESULT["accept_valid"] = panel.accept()
settle()
RESULT["closed"] = not FreeCADGui.Control.activeDialog()
RESULT["applied"] = [job.FinishingToolDiameter.Value, job.RoughingToolDiameter.Value, job.FinishingStepOver.Value]
RESULT["states"] = {o.Name: [list(o.State), o.Status] for o in doc.Objects}

FreeCADGui.ActiveDocument.setEdit(job.Name)  # double-click: edit the job again, then cancel
settle()
panel = job.ViewObject.Proxy.panel
panel.set_value("FinishingCornerRadius", 0.3)
RESULT["reject"] = panel.reject()
settle()
RESULT["after_reject"] = [job.FinishingCornerRadius.Value, bool(FreeCADGui.Control.activeDialog())]

FreeCADGui.Selection.clearSelection()  # no selection highlight in the picture
view = FreeCADGui.ActiveDocument.ActiveView
view.viewIsometric()
view.fitAll()
settle_view(view)
view.saveImage(SCREENSHOT, 1280, 960, "White")

select(job)
FreeCADGui.runCommand("SpurCad_Simulate")
settle()
simulations = [o for o in doc.Objects if getattr(getattr(o, "Proxy", None), "KIND", "") == "simulation"]
boxes = [w for w in QtGui.QApplication.topLevelWidgets() if w.objectName() == "SpurCadMessage" and w.isVisible()]
RESULT["simulation"] = [len(simulations), [b.text() for b in boxes]]

os.makedirs(OUT)
answer_file_dialog(OUT)
select(job)
FreeCADGui.runCommand("SpurCad_Export")
settle()
RESULT["exported"] = sorted(os.listdir(OUT))

# Verify program: the exported programs (roughing first) read back, cut and judged; shown on the gear
import spur_cad_workbench.commands as wb_commands
programs = sorted((os.path.join(OUT, n) for n in os.listdir(OUT) if n.startswith(("roughing.", "finishing."))),
                  key=lambda path: "finishing" in path)
verification = wb_commands.verify_programs(job, programs)
settle()
boxes = [w for w in QtGui.QApplication.topLevelWidgets() if w.objectName() == "SpurCadMessage" and w.isVisible()]
RESULT["verification"] = [verification.Label, verification.Status, verification.MaxGougeMicrons,
                          len(verification.Points.Points),
                          [b.text() for b in boxes if b.windowTitle() == "Verify program"]]
for box in boxes:
    box.close()
answer_file_dialog([p for p in programs if "roughing" in p][0])   # the command: roughing alone leaves finish stock
select(job)
FreeCADGui.runCommand("SpurCad_Verify")
settle()
boxes = [w for w in QtGui.QApplication.topLevelWidgets() if w.objectName() == "SpurCadMessage" and w.isVisible()]
RESULT["verify_command"] = [b.text() for b in boxes if b.windowTitle() == "Verify program"]
for box in boxes:
    box.close()

# Restart program: roughing from tooth space 3, written where the user says
RESTART = os.path.join(OUT + "_restart", "roughing_space3.ngc")
os.makedirs(OUT + "_restart")
answer_restart_dialog(3, RESTART)
select(job)
FreeCADGui.runCommand("SpurCad_Restart")
settle()
RESULT["restart"] = open(RESTART).read() if os.path.exists(RESTART) else None

answer_file_dialog(JOB_FILE)
FreeCADGui.runCommand("SpurCad_ImportJob")     # into a new document named after the job file
settle()
imported_doc = FreeCAD.ActiveDocument
RESULT["imported"] = [imported_doc.Name, [o.Label for o in imported_doc.Objects
                                          if getattr(getattr(o, "Proxy", None), "KIND", "") == "job"]]

imported_job = imported_doc.getObject("Job")   # a bad value: Export shows the message, writes nothing
imported_job.FinishingToolDiameter = 9.0
os.makedirs(OUT + "_bad")
answer_file_dialog(OUT + "_bad")
select(imported_job)
for box in QtGui.QApplication.topLevelWidgets():   # the earlier commands' boxes (results, PASS) closed
    if box.objectName() == "SpurCadMessage":
        box.close()
FreeCADGui.runCommand("SpurCad_Export")
settle()
boxes = [w for w in QtGui.QApplication.topLevelWidgets() if w.objectName() == "SpurCadMessage" and w.isVisible()]
RESULT["export_error"] = [[b.windowTitle(), b.text()] for b in boxes]
RESULT["exported_bad"] = os.listdir(OUT + "_bad")

settle()
RESULT["report"] = report.toPlainText()
RESULT["console"] = console.toPlainText() if console is not None else ""
RESULT["hooked"] = hooked
"""


def _expected(text: str) -> str:
    """The message the command line gives for a job (validation, then planning), without file:line."""
    try:
        plan_cam(parse_job(text, "panel.toml"))
    except SpurCadError as exc:
        return re.sub(r"^panel\.toml(:\d+)?: ", "", str(exc))
    raise AssertionError("the job is valid")


@pytest.mark.freecad
def test_workbench_commands_panel_and_screenshot_in_the_gui(freecad_gui, tmp_path):
    ARTIFACTS.mkdir(exist_ok=True)
    SCREENSHOT.unlink(missing_ok=True)
    job_file = tmp_path / "small.toml"
    job_file.write_text(small_job_text())
    props = {"gear": SMALL_GEAR_PROPERTIES, "stock": SMALL_STOCK_PROPERTIES, "job": SMALL_JOB_PROPERTIES}
    body = (f"PROPS = {props!r}\nOUT = {str(tmp_path / 'exported')!r}\nJOB_FILE = {str(job_file)!r}\n"
            f"SCREENSHOT = {str(SCREENSHOT)!r}\n" + GUI_BODY)
    # roughing alone verified (FAIL, an error) and an export with a bad value, both on purpose
    expected_log = (VERIFY_FAIL_LOG, r"^Err: Export: Finishing tool: diameter at most [^\n]*$")
    result, proc = run_workbench_code(body, tmp_path / "fc", gui=freecad_gui, timeout_s=300, log_allowed=expected_log)
    assert result is not None and result.get("ok"), describe(proc, result)

    # no Python exception anywhere, nor an error line in the report view
    assert result["hooked"] == []
    for word in ("Traceback", "Exception", "Error"):
        assert word not in result["report"], result["report"]

    names = ["SpurCad_Gear", "SpurCad_Stock", "SpurCad_Job", "SpurCad_ImportJob", "SpurCad_Simulate", "SpurCad_Verify",
             "SpurCad_Restart", "SpurCad_Export"]
    assert result["workbench"] == "SpurCadWorkbench"
    assert result["toolbar"] == names
    assert len(result["menu"]) == len(names)

    # the task panel: suggested tools are valid; the command line's messages beside the right group
    assert result["panel_open"] and result["suggested_messages"] == {} and result["valid_messages"] == {}
    assert "at most" in result["notes"]["RoughingToolDiameter"]
    assert "at most" in result["notes"]["FinishingCornerRadius"]
    assert result["too_wide"] == {"Finishing tool": _expected(small_job_text(finishing_diameter=9.0))}
    assert result["accept_too_wide"] is False and result["unchanged"] and result["still_open"]
    negative = small_job_text().replace("diameter_mm = 2.0", "diameter_mm = -1.0")
    assert result["negative"] == {"Roughing tool": _expected(negative)}
    assert result["fixed"] == {} and result["accept_valid"] is True and result["closed"]
    assert result["applied"] == [1.5, 2.0, 1.5]
    assert all(state == ["Up-to-date"] and status == "ok" for state, status in result["states"].values())
    assert result["reject"] is True and result["after_reject"] == [0.5, False]

    # simulate, export, import
    count, boxes = result["simulation"]
    assert count == 1 or boxes == ["simulation not available: this spur_cad has no simulator (spur_cad.sim)"]
    assert {"gear.step", "stock.step", "job.step", "summary.json"} <= set(result["exported"])
    label, status, gouge, points, texts = result["verification"]
    assert label == "Job verification"
    assert status == "ok" and gouge <= 5.0 and points > 0 and texts and texts[0].splitlines()[-1].startswith("PASS: ")
    # roughing alone leaves its finish stock and flank allowance on the flanks: FAIL
    assert result["verify_command"] and result["verify_command"][0].splitlines()[-1].startswith("FAIL: ")
    assert any(name.startswith("roughing.") for name in result["exported"])
    assert result["imported"] == ["small", ["small quick gear"]]
    # the message box: one sentence naming the field as the panel does (the command line names the key)
    [[title, text]] = result["export_error"]
    assert title == "Export" and text.startswith("Finishing tool: diameter at most ") and text.endswith(".")
    assert "_mm" not in text and "[tools." not in text and "Traceback" not in text, text  # r_t, d_1: symbols
    assert result["exported_bad"] == []
    assert f"Export: {text}" in result["report"]  # the same line in the report view

    # the restart program the command wrote is the one `spur-cad run --restart roughing:space=3` writes
    job = parse_job(small_job_text(), "small.toml")
    assert result["restart"] == restart_program(job, plan_cam(job), parse_restart("roughing:space=3"))[1].decode()

    # every command went through FreeCADGui.doCommandGui: echoed as macro lines
    for call in ("make_gear(", "make_stock(", "make_job(", "simulate(", "export_job(", "import_job_file(",
                 "verify_programs(", "write_restart_program("):
        assert f"spur_cad_workbench.commands.{call}" in result["console"], result["console"][-2000:]

    # the screenshot shows the gear and both toolpaths in their colours
    import matplotlib.image

    image = matplotlib.image.imread(SCREENSHOT)[..., :3]
    assert image.shape[:2] == (960, 1280)
    for colour in ((0.85, 0.45, 0.1), (0.1, 0.55, 0.2)):  # roughing orange, finishing green
        close = np.all(np.abs(image - np.array(colour)) < 0.08, axis=-1)
        assert close.sum() > 500, (colour, int(close.sum()))
    white = np.all(image > 0.98, axis=-1).mean()
    assert 0.2 < white < 0.95
