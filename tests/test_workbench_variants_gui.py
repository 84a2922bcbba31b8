"""The task panel with the flank modifications, the 3-axis variant, the 2-D export and an internal gear, in
FreeCAD's GUI under Xvfb in a 240 px dock (as tests/test_workbench_panel_gui.py): the modification chart drawn
in its own section within the dock's width, axes = 3 from the panel to a recomputed 3-axis job (a flat end mill
needed, said at the field), the 3-axis and export groups labelled with units, an internal gear (its ring
recomputed, no span) refused by the job with the command line's message. Screenshots go to test-artifacts/."""

from __future__ import annotations

import numpy as np
import pytest

from tests.freecad_helper import describe
from tests.workbench_helper import ARTIFACTS, GUI_PRELUDE, run_workbench_code

MODIFICATIONS_SHOT = ARTIFACTS / "workbench_panel_modifications.png"
THREE_AXIS_SHOT = ARTIFACTS / "workbench_panel_three_axis.png"
DOCK_WIDTH_PX = 240
GEAR = dict(Teeth=23, Module=4.0, FaceWidth=20.0, RackTipRadius=0.8, TipRelief=15.0, TipReliefStartDiameter=96.0,
            LeadCrowning=8.0, RightFlankOwnValues=True, RightTipRelief=20.0, RightTipReliefStartDiameter=96.0,
            RightTipReliefShape="parabolic", RightLeadCrowning=8.0)

BODY = GUI_PRELUDE + r"""

FreeCADGui.activateWorkbench("SpurCadWorkbench")
settle()

from spur_cad_workbench import commands
doc = FreeCAD.newDocument("Variants")
gear = commands.make_gear(doc, **GEAR)
stock = commands.make_stock(gear)
job = commands.make_job(gear, stock)
doc.recompute()
RESULT["statuses"] = [gear.Status, job.Status]

def open_panel():
    global dock
    FreeCADGui.ActiveDocument.setEdit(job.Name)
    settle()
    dock = set_task_dock_width(DOCK_WIDTH)   # once the panel is open: 1.1's overlay dock shows with its task
    panel = job.ViewObject.Proxy.panel
    scroll = panel.form.parentWidget()
    while not isinstance(scroll, QtGui.QScrollArea):
        scroll = scroll.parentWidget()
    return panel, scroll

def outside(panel, scroll, widgets):
    # visible widgets reaching past the task view, and labels whose words or lines do not fit
    viewport, problems = scroll.viewport(), []
    for widget in widgets:
        if not widget.isVisible():
            continue
        left = widget.mapTo(viewport, QtCore.QPoint(0, 0)).x()
        if left < 0 or left + widget.width() > viewport.width():
            problems.append([widget.objectName(), left, widget.width(), viewport.width()])
        if isinstance(widget, QtGui.QLabel) and widget.text():
            longest = max(widget.fontMetrics().horizontalAdvance(word) for word in widget.text().split())
            if longest > widget.width() or widget.heightForWidth(widget.width()) > widget.height():
                problems.append([widget.objectName(), "text", widget.text(), widget.width(), widget.height()])
        if isinstance(widget, QtGui.QAbstractSpinBox) and \
                widget.fontMetrics().boundingRect(widget.text()).width() + 18 > widget.width():
            problems.append([widget.objectName(), "text", widget.text(), widget.width()])
    return problems

panel, scroll = open_panel()
RESULT["title"] = panel.form.toolTip()
section = panel.modifications_section
RESULT["folded"] = [section.header.text(), section.summary.text(), section.summary.isVisible()]
section.set_open(True)
settle()
scroll.ensureWidgetVisible(panel.modifications_chart, 0, 0)
settle()
pixmap = panel.modifications_chart.pixmap()
RESULT["chart"] = [panel.modifications_chart.isVisible(), pixmap.width(), pixmap.height(),
                   panel.modifications_chart.width(), panel.modifications_note.text()]
RESULT["chart_outside"] = outside(panel, scroll, [panel.modifications_chart, panel.modifications_note])
RESULT["scroll_modifications"] = scroll.horizontalScrollBar().maximum()
scroll.viewport().grab().save(MODIFICATIONS_SHOT)
RESULT["dock_width"] = dock.width()

# the 3-axis variant from the panel (an unmodified gear: 3 axes refuse modifications): a bull-nose finishing tool is
# refused at its field, a flat one plans
section.set_open(False)
FreeCADGui.Control.closeDialog()
settle()
for prop in ("TipRelief", "LeadCrowning", "RightFlankOwnValues"):
    setattr(gear, prop, False if prop == "RightFlankOwnValues" else FreeCAD.Units.Quantity("0 um"))
doc.recompute()
panel, scroll = open_panel()
panel.set_value("MachineAxes", 3)
RESULT["axes3_problem"] = [panel.highlighted, panel.summary.text()]
RESULT["three_axis_enabled"] = [panel.widgets[p].isEnabled() for p in ("HoldingTabs", "TabWidth", "OnionSkin")]
panel.set_value("FinishingToolKind", "flat")
panel.set_value("FinishingCornerRadius", 0.0)
panel.set_value("FinishingToolDiameter", 2.0)
panel.set_value("RoughingToolKind", "flat")
panel.set_value("ExportDxf", True)
panel.set_value("ExportOffset", 0.15)
RESULT["axes3_valid"] = [panel.result.ok, panel.summary.text(), panel.plan()]
RESULT["axes3_figures"] = panel.summary_figures.text()
RESULT["axes3_limits"] = [panel.summary_limits.text(), panel.notes["RoughingToolDiameter"].isVisible()]
for group in ("Machine", "3-axis", "2-D export"):
    panel.sections[group].set_open(True)
settle()

from spur_cad_workbench import schema
shown = [f.prop for f in schema.JOB_FIELDS if f.group in ("Machine", "3-axis", "2-D export")]
RESULT["labels"] = {p: panel.labels[p].text() for p in ("MachineAxes", "HoldingTabs", "TabWidth", "ExportDxf",
                                                           "ExportOffset")}
RESULT["texts"] = {p: panel.widgets[p].text() if hasattr(panel.widgets[p], "text") else
                   panel.widgets[p].currentText() for p in ("TabWidth", "TabHeight", "OnionSkin", "ExportOffset")}
RESULT["axes_widget"] = [panel.widgets["MachineAxes"].metaObject().className(),
                         panel.widgets["MachineAxes"].currentText()]
RESULT["open_outside"] = outside(panel, scroll, [w for p in shown for w in (panel.widgets[p], panel.labels[p])])
RESULT["scroll_open"] = scroll.horizontalScrollBar().maximum()
scroll.ensureWidgetVisible(panel.widgets["ExportOffset"], 0, 0)
settle()
scroll.viewport().grab().save(THREE_AXIS_SHOT)
RESULT["accepted"] = panel.accept()
settle()
RESULT["three_axis_job"] = [job.Status, job.MachineAxes, job.FinishingMoves > 0, job.FinishingToolpath.Label,
                            list(job.Warnings)]
points = [c.Parameters for c in job.FinishingToolpath.Path.Commands if c.Name == "G1"]
RESULT["drawn_flat"] = [min(p["X"] for p in points), max(p["X"] for p in points),
                        min((p["Y"] ** 2 + p["Z"] ** 2) ** 0.5 for p in points), gear.RootRadius.Value]
panel, scroll = open_panel()
RESULT["title_3"] = panel.form.toolTip()
FreeCADGui.Control.closeDialog()
settle()

# an internal gear: the gear is fine, the rotary-table job refuses it with the command line's sentence (3 axes cut it)
job.MachineAxes = 4
gear.Teeth = 60
gear.Module = 2.0
gear.RackTipRadius = 0.4            # as resources/examples/ring_gear.toml: the cutter's tip rounds apart
gear.AddendumCoefficient = 0.9
gear.Internal = True
gear.ShaperCutterTeeth = 20
gear.RimOuterDiameter = 150.0
doc.recompute()
RESULT["internal"] = [gear.Status, job.Status]
RESULT["ring"] = [gear.SpanMeasurementPrecise, gear.SpanMeasurement.Value, gear.DimensionOverPins.Value,
                  gear.TipRadius.Value < gear.RootRadius.Value, gear.Shape.isValid(), gear.Shape.BoundBox.YMax]
panel, scroll = open_panel()
RESULT["internal_panel"] = [panel.messages["Gear"].text(), panel.messages["Gear"].isVisible(), panel.result.ok]
FreeCADGui.Control.closeDialog()
settle()
RESULT["hooked"] = hooked
"""


@pytest.fixture(scope="module")
def variants(freecad_gui, tmp_path_factory):
    ARTIFACTS.mkdir(exist_ok=True)
    for shot in (MODIFICATIONS_SHOT, THREE_AXIS_SHOT):
        shot.unlink(missing_ok=True)
    body = (f"GEAR = {GEAR!r}\nDOCK_WIDTH = {DOCK_WIDTH_PX}\nMODIFICATIONS_SHOT = {str(MODIFICATIONS_SHOT)!r}\n"
            f"THREE_AXIS_SHOT = {str(THREE_AXIS_SHOT)!r}\n" + BODY)
    # the internal gear's job refused on purpose: one line
    expected_log = (r"^Err: Job: Internal = true: the rotary table cannot cut an internal gear [^\n]*$",)
    result, proc = run_workbench_code(body, tmp_path_factory.mktemp("variants"), gui=freecad_gui, timeout_s=600,
                                      log_allowed=expected_log)
    assert result is not None and result.get("ok"), describe(proc, result)
    assert result["hooked"] == [], result["hooked"]
    return result


def _image(path):
    import matplotlib.image

    return matplotlib.image.imread(path)[..., :3]


@pytest.mark.freecad
def test_the_modification_chart_is_drawn_within_the_dock(variants):
    r = variants
    assert r["statuses"] == ["ok", "ok"]
    header, summary, shown = r["folded"]
    assert header == "Flank modifications" and shown
    assert summary == ("tip relief 15 \u00b5m, lead crowning 8 \u00b5m; right flank: tip relief 20 \u00b5m, lead "
                       "crowning 8 \u00b5m")
    visible, width, height, label_width, note = r["chart"]
    assert visible and 0 < width <= label_width and height > width  # stacked: profile above lead
    assert note.startswith("The gear's: tip relief 15") and "Edit them on the gear's properties" in note
    assert r["chart_outside"] == [] and r["scroll_modifications"] == 0
    image = _image(MODIFICATIONS_SHOT)
    assert image.shape[1] <= r["dock_width"] <= DOCK_WIDTH_PX + 4
    blue = np.all(np.abs(image - np.array([31, 119, 180]) / 255.0) < 0.08, axis=-1)  # the right flank's curve
    assert blue.sum() > 15


@pytest.mark.freecad
def test_three_axes_from_the_panel_to_a_recomputed_job_with_labelled_fields(variants):
    r = variants
    assert r["title"].startswith("4-axis job: ") and r["title_3"].startswith("3-axis job: ")
    highlighted, problem = r["axes3_problem"]
    assert highlighted == "FinishingToolKind" and "flat end mill" in problem
    assert r["three_axis_enabled"] == [True, True, True]
    ok, summary, planned = r["axes3_valid"]
    assert ok and planned, summary
    assert "Finishing" in r["axes3_figures"]
    assert r["axes3_limits"] == [r["axes3_limits"][0], False] and "flat end mills" in r["axes3_limits"][0]
    assert r["axes_widget"] == ["QComboBox", "3"]
    assert r["labels"]["MachineAxes"] == "Axes (4: rotary table, 3: flat)"
    assert r["labels"]["ExportDxf"] == "Write gear.dxf" and r["labels"]["HoldingTabs"] == "Holding tabs"
    assert all(text.endswith("mm") for text in r["texts"].values()), r["texts"]
    assert r["open_outside"] == [] and r["scroll_open"] == 0
    assert r["accepted"]
    status, axes, moves, label, warnings = r["three_axis_job"]
    assert status == "ok" and axes == 3 and moves, r["three_axis_job"]
    x_low, x_high, radius_low, root_radius = r["drawn_flat"]
    # lying flat: along the gear axis from below the bottom face (break-through) to below the top face x = b
    assert x_low < 0.0 < x_high < 20.0 and radius_low == pytest.approx(root_radius + 1.0, abs=0.01)
    assert _image(THREE_AXIS_SHOT).shape[1] <= r["dock_width"]


@pytest.mark.freecad
def test_an_internal_gear_is_refused_by_the_job_with_the_command_lines_reason(variants):
    gear_status, job_status = variants["internal"]
    assert gear_status == "ok"
    # the ring: no span ("none", not a number), a dimension between pins, tips inside the roots, the rim outside
    span_text, span, between, tips_inside, valid, outer = variants["ring"]
    assert span_text == "none" and span == 0.0 and 0.0 < between < 120.0 and tips_inside and valid
    assert outer == pytest.approx(75.0, abs=0.01)  # the rim (FreeCAD's bound box is not exact)
    assert job_status.startswith("error: ") and "internal" in job_status.lower(), job_status
    message, visible, ok = variants["internal_panel"]
    assert visible and not ok and "internal" in message.lower(), message
