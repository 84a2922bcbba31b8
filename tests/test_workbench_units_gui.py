"""Errors and units as a new user meets them in FreeCAD's GUI under Xvfb (issue 28, points 3 and 6).

Errors: a bad gear input (a negative module, too few teeth, a profile shift that makes the tooth pointed, NaN)
is kept as typed, and the gear's Status and the report view say what is wrong in one sentence that names the
field by its title and unit, with no traceback and no job-file key; the tree icon carries an error badge.
Units: under the "Imperial decimal" schema every field, note and message of the job's task panel shows
inches (no "mm"), a value typed in inches reaches the job in the same mm, untouched values stay exact, and
the gear's precise outputs are in inches; under the standard schema they have 4 decimals in mm. A screenshot
of the imperial panel goes to test-artifacts/.
"""

from __future__ import annotations

import re

import pytest

from tests.freecad_helper import describe
from tests.workbench_helper import (
    ARTIFACTS,
    GUI_PRELUDE,
    SMALL_GEAR_PROPERTIES,
    SMALL_STOCK_PROPERTIES,
    run_workbench_code,
)

IMPERIAL_SHOT = ARTIFACTS / "workbench_panel_imperial.png"
MM = re.compile(r"(?<![A-Za-z])mm(?![A-Za-z])")
KEY_NAME = re.compile(r"\b[a-z]+(?:_[a-z0-9]+)+\b")  # a job-file key such as module_mm

BODY = GUI_PRELUDE + r"""

def badge_red(obj):
    # share of strongly red pixels in the lower left quarter of the object's tree icon
    image = obj.ViewObject.Icon.pixmap(64, 64).toImage()
    red = 0
    for x in range(0, 32, 2):
        for y in range(32, 64, 2):
            colour = image.pixelColor(x, y)
            red += colour.red() > 180 and colour.green() < 60 and colour.blue() < 60
    return red / 256.0

def message_boxes():
    return [w.text() for w in QtGui.QApplication.topLevelWidgets()
            if isinstance(w, QtGui.QMessageBox) and w.isVisible()]

FreeCADGui.activateWorkbench("SpurCadWorkbench")
from spur_cad_workbench import commands
FreeCAD.Units.setSchema(0)
doc = FreeCAD.newDocument("Units")
gear = commands.make_gear(doc, **PROPS["gear"])
stock = commands.make_stock(gear, **PROPS["stock"])
job = commands.make_job(gear, stock)
doc.recompute()
settle()
RESULT["valid_badge"] = badge_red(gear)
RESULT["precise_standard"] = {p: [getattr(gear, p + "Precise"), getattr(gear, p).Value]
                              for p in ("SpanMeasurement", "DimensionOverPins", "ToothThickness", "TipRadius")}

bad = {}
for prop, value in (("Module", -3.0), ("Teeth", 2), ("ProfileShift", 2.0), ("ProfileShift", float("nan"))):
    good = getattr(gear, prop)
    report.clear()
    setattr(gear, prop, value)
    kept = getattr(gear, prop)
    kept = kept.Value if hasattr(kept, "Value") else kept
    doc.recompute()
    settle()
    bad[f"{prop}={value}"] = dict(kept=repr(kept), status=gear.Status, report=report.toPlainText(),
                                  state=list(gear.State), badge=badge_red(gear), stock=stock.Status, job=job.Status,
                                  boxes=message_boxes())
    setattr(gear, prop, good)
    doc.recompute()
    settle()
RESULT["bad"] = bad
RESULT["fixed"] = [gear.Status, stock.Status, job.Status, badge_red(gear)]

# the imperial schema: the gear's precise outputs and the job's panel
names = FreeCAD.Units.listSchemas()
# listed by description in 0.20 and 1.0 ("Imperial decimal (in, lb)"), by name in 1.1 ("ImperialDecimal")
imperial = [i for i, name in enumerate(names) if name.startswith(("Imperial decimal", "ImperialDecimal"))]
FreeCAD.Units.setSchema(imperial[0])
gear.touch()
doc.recompute()
RESULT["precise_imperial"] = {p: [getattr(gear, p + "Precise"), getattr(gear, p).Value]
                              for p in ("SpanMeasurement", "DimensionOverPins")}
before = {p: getattr(job, p) for p in ("TargetScallop", "FinishingToolDiameter", "RapidFeed", "LatheRoughingFeed")}
before = {p: (v.getValueAs("mm/min").Value if p == "RapidFeed" else getattr(v, "Value", v)) for p, v in before.items()}
RESULT["before"] = before
FreeCADGui.ActiveDocument.setEdit(job.Name)
settle()
panel = job.ViewObject.Proxy.panel
for section in panel.sections.values():
    section.set_open(True)
settle()

def panel_texts():
    texts = {}
    for prop, widget in panel.widgets.items():
        if isinstance(widget, QtGui.QAbstractSpinBox):
            texts[f"field:{prop}"] = widget.text()
        texts[f"label:{prop}"] = panel.labels[prop].text()
        if panel.notes[prop].isVisible():
            texts[f"note:{prop}"] = panel.notes[prop].text()
    for group, label in panel.messages.items():
        if label.isVisible():
            texts[f"message:{group}"] = label.text()
    for name in ("summary", "summary_figures", "summary_advice", "summary_limits"):
        texts[name] = getattr(panel, name).text()
    return texts

RESULT["imperial_texts"] = panel_texts()
panel.form.grab().save(IMPERIAL_SHOT)
panel.set_value("FinishingToolDiameter", 9.0)          # too wide: the message and the summary, in inches
RESULT["imperial_error"] = panel_texts()
panel.set_value("FinishingToolDiameter", before["FinishingToolDiameter"])
panel.set_value("MaxFeed", 1.0)                        # unusually low feed: refused, in in/min
RESULT["imperial_feed_error"] = panel_texts()
panel.set_value("MaxFeed", 5000.0)
lathe_was = panel.widgets["WriteLatheProgram"].isChecked()
panel.set_value("WriteLatheProgram", True)
lathe_feed_was = panel.widgets["LatheFinishingFeed"].value()
panel.widgets["LatheFinishingFeed"].setValue(80.0)       # in/rev: far beyond the key's range, refused in in/rev
panel.revalidate()
RESULT["imperial_lathe_error"] = panel_texts()
panel.widgets["LatheFinishingFeed"].setValue(lathe_feed_was)
panel.set_value("WriteLatheProgram", lathe_was)

def type_into(prop, text):
    box = panel.widgets[prop]
    box.lineEdit().selectAll()
    box.lineEdit().insert(text)
    box.interpretText() if hasattr(box, "interpretText") else None
    settle()

type_into("Clearance", "0.2 in")
type_into("MaxFeed", "200 in/min")
panel.widgets["LatheFinishingFeed"].setValue(0.004)    # in/rev
settle()
RESULT["typed_texts"] = [panel.widgets[p].text() for p in ("Clearance", "MaxFeed", "LatheFinishingFeed")]
RESULT["messages_before_ok"] = panel.current_messages()
RESULT["accepted"] = panel.accept()
settle()
from spur_cad_workbench import schema
from spur_cad_workbench.properties import document_values
data = schema.job_data(document_values(job))
RESULT["job_file"] = dict(clearance=data["machine"]["clearance_mm"],
                          max_feed=data["machine"]["max_feed_mm_min"],
                          scallop=data["finishing"]["target_scallop_mm"],
                          diameter=data["tools"]["finishing"]["diameter_mm"],
                          rapid=data["machine"]["rapid_feed_mm_min"])
RESULT["lathe_feed_property"] = job.LatheFinishingFeed
FreeCAD.Units.setSchema(0)
RESULT["hooked"] = hooked
"""


@pytest.fixture(scope="module")
def units_result(freecad_gui, tmp_path_factory):
    ARTIFACTS.mkdir(exist_ok=True)
    IMPERIAL_SHOT.unlink(missing_ok=True)
    props = {"gear": SMALL_GEAR_PROPERTIES, "stock": SMALL_STOCK_PROPERTIES}
    body = f"PROPS = {props!r}\nIMPERIAL_SHOT = {str(IMPERIAL_SHOT)!r}\n" + BODY
    work = tmp_path_factory.mktemp("units")
    # the bad gear inputs typed on purpose: one line each
    expected_log = (r"^Err: Gear: Module must be in \[0\.05 mm, 100 mm\], got -3 mm\.$",
                    r"^Err: Gear: Teeth must be in 5\.\.1000, got 2\.$",
                    r"^Err: Gear: Profile shift coefficient x: the tooth is pointed: [^\n]*$",
                    r"^Err: Gear: Profile shift coefficient x must be a finite number, got nan\.$")
    result, proc = run_workbench_code(body, work, gui=freecad_gui, timeout_s=420, log_allowed=expected_log)
    assert result is not None and result.get("ok"), describe(proc, result)
    assert result["hooked"] == [], result["hooked"]
    return result


def _one_sentence(text: str) -> bool:
    return text.endswith(".") and "\n" not in text.strip() and ". " not in text.rstrip(".")


@pytest.mark.freecad
def test_bad_gear_inputs_are_kept_and_refused_in_one_sentence_with_the_field_s_title(units_result):
    r = units_result
    assert r["valid_badge"] == 0.0
    expected = {"Module=-3.0": ("-3.0", "Module", " mm"), "Teeth=2": ("2", "Teeth", ""),
                "ProfileShift=2.0": ("2.0", "Profile shift coefficient x", "pointed"),
                "ProfileShift=nan": ("nan", "Profile shift coefficient x", "finite")}
    for case, (kept, name, words) in expected.items():
        found = r["bad"][case]
        assert found["kept"] == kept, (case, found)  # not clamped to 0
        status = found["status"]
        assert status.startswith(f"error: {name} ") or status.startswith(f"error: {name}:"), (case, status)
        message = status.removeprefix("error: ")
        assert words in message and _one_sentence(message), (case, message)
        assert not KEY_NAME.search(message) and "[gear]" not in message, (case, message)
        lines = [line for line in found["report"].splitlines() if line.strip()]
        assert len(lines) == 1 and lines[0].endswith(f"Gear: {message}"), (case, found["report"])
        assert "Traceback" not in found["report"] and found["boxes"] == []
        assert found["badge"] > 0.3, case  # the tree icon's red error badge
        assert found["stock"] == found["job"] == "stale: Gear has an error"
    module = r["bad"]["Module=-3.0"]["status"]
    assert module == "error: Module must be in [0.05 mm, 100 mm], got -3 mm."
    assert r["fixed"] == ["ok", "ok", "ok", 0.0]


@pytest.mark.freecad
def test_inspection_values_have_4_decimals_in_mm_and_follow_an_imperial_schema(units_result):
    r = units_result
    for prop, (text, value) in r["precise_standard"].items():
        found = re.fullmatch(r"(\d+\.\d{4}) mm", text)
        assert found and abs(float(found.group(1)) - value) <= 0.00005, (prop, text, value)
    for prop, (text, value) in r["precise_imperial"].items():
        found = re.fullmatch(r"(\d+\.\d+) in", text)
        assert found and abs(float(found.group(1)) * 25.4 - value) <= 0.0002, (prop, text, value)


@pytest.mark.freecad
def test_the_panel_shows_inches_under_an_imperial_schema_and_keeps_the_values(units_result):
    r = units_result
    for name in ("imperial_texts", "imperial_error", "imperial_feed_error", "imperial_lathe_error"):
        shown = {key: text for key, text in r[name].items() if MM.search(text)}
        assert shown == {}, (name, shown)
    texts = r["imperial_texts"]
    for prop in ("FinishingToolDiameter", "TargetScallop", "Clearance"):
        assert texts[f"field:{prop}"].endswith(" in"), texts[f"field:{prop}"]
    assert texts["field:MaxFeed"].endswith(" in/min") and texts["field:LatheFinishingFeed"].endswith(" in/rev")
    # micrometres show: the scallop (a few um) is not rounded to 0.00 in (FreeCAD's 2 decimals)
    scallop_in = float(texts["field:TargetScallop"].split()[0])
    assert scallop_in > 0 and scallop_in == pytest.approx(r["before"]["TargetScallop"] / 25.4, abs=0.5e-5)
    assert " in" in texts["summary_limits"] and "at most" in texts["summary_limits"]
    error = r["imperial_error"]
    assert error["message:Finishing tool"].startswith("Finishing tool: diameter at most ")
    assert " in " in error["message:Finishing tool"] or error["message:Finishing tool"].endswith(" in")
    assert "in/min" in r["imperial_feed_error"]["message:Machine"]
    lathe = r["imperial_lathe_error"]["message:Lathe tools"]  # at the field's own group
    assert "in/rev" in lathe and lathe.endswith("got 80 in/rev"), lathe  # as typed, in its unit
    assert r["typed_texts"][0] == "0.2 in" and r["typed_texts"][1] == "200 in/min"
    assert r["accepted"] is True, r["messages_before_ok"]
    job_file, before = r["job_file"], r["before"]
    assert job_file["clearance"] == pytest.approx(5.08, abs=1e-12)
    assert job_file["max_feed"] == pytest.approx(5080.0, abs=1e-9)
    assert r["lathe_feed_property"] == pytest.approx(0.1016, abs=1e-12)
    # untouched fields: exactly what the job held
    assert job_file["scallop"] == before["TargetScallop"] and job_file["diameter"] == before["FinishingToolDiameter"]
    assert job_file["rapid"] == before["RapidFeed"]


@pytest.mark.freecad
def test_the_imperial_panel_screenshot_shows_text(units_result):
    import matplotlib.image
    import numpy as np

    image = matplotlib.image.imread(IMPERIAL_SHOT)[..., :3]
    assert image.shape[0] > 200 and np.mean(np.all(image < 0.3, axis=-1)) > 0.005
