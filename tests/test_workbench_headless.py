"""The workbench in FreeCAD's console (freecadcmd), installed as users install it: objects made through the
commands' Python entry points recompute, follow property changes, export exactly what the CLI writes,
save and reopen without pickles, and report bad input as messages."""

from __future__ import annotations

import json
import tomllib
import zipfile
from pathlib import Path

import pytest

from spur_cad.cam.strategies import strategy_names
from spur_cad.cli import main
from spur_cad.job import load_job, parse_job
from spur_cad.pipeline import plan_cam
from tests.freecad_helper import describe
from tests.textbook import Textbook, span_iso
from tests.workbench_helper import (
    REFERENCE_JOB,
    SMALL_GEAR_PROPERTIES,
    SMALL_JOB_PROPERTIES,
    SMALL_STOCK_PROPERTIES,
    output_differences,
    run_workbench_code,
    small_job_text,
)

pytestmark = pytest.mark.freecad

STATES = """
def states(doc):
    return {o.Name: [list(o.State), getattr(o, "Status", "")] for o in doc.Objects}
"""


def _all_up_to_date(states: dict) -> bool:
    return all(state == ["Up-to-date"] and status == "ok" for state, status in states.values())


SMALL_BODY = STATES + """
import math, FreeCAD, Part
from spur_cad_workbench import commands
doc = FreeCAD.newDocument("Wb")
gear = commands.make_gear(doc, **PROPS["gear"])
stock = commands.make_stock(gear, **PROPS["stock"])
job = commands.make_job(gear, stock, **PROPS["job"])
doc.recompute()
RESULT["first"] = states(doc)
RESULT["first_tip_radius"] = gear.TipRadius.Value
gear.Teeth = 13                                   # a property change recomputes gear, stock and job
doc.recompute()
RESULT["second"] = states(doc)
b, z = gear.FaceWidth.Value, gear.Teeth
bb = gear.Shape.BoundBox
RESULT["bbox"] = [bb.XMin, bb.XMax, bb.YMin, bb.YMax, bb.ZMin, bb.ZMax]
RESULT["radii"] = dict(tip=gear.TipRadius.Value, root=gear.RootRadius.Value, base=gear.BaseRadius.Value,
                       span=gear.SpanMeasurement.Value, k=gear.SpanTeeth, undercut=gear.Undercut,
                       blank=stock.BlankRadius.Value)
r = gear.TipRadius.Value - 0.3 * gear.Module.Value
inside = lambda y, zz: gear.Shape.isInside(FreeCAD.Vector(b / 2, y, zz), 1e-6, True)
RESULT["space0_at_plus_z"] = inside(0.0, r)
RESULT["tooth_at_half_pitch"] = inside(r * math.sin(math.pi / z), r * math.cos(math.pi / z))
RESULT["volume"] = gear.Shape.Volume
RESULT["stock_bbox"] = [stock.Shape.BoundBox.XMin, stock.Shape.BoundBox.XMax, stock.Shape.BoundBox.ZMax]
RESULT["job"] = dict(roughing=job.RoughingMoves, finishing=job.FinishingMoves,
                     max_flat=job.FinishingMaxFlatWidth.Value, types=[job.RoughingToolpath.TypeId,
                     job.FinishingToolpath.TypeId], shown=job.FinishingToolpath.DisplayedMoves,
                     total=job.FinishingToolpath.Moves)
# Toolpath points in the part frame must lie outside the gear, and finishing ones hug its surface.
for name, obj in (("roughing", job.RoughingToolpath), ("finishing", job.FinishingToolpath)):
    along_x = name == "roughing" or job.FinishingStrategy == "generating"
    moves = [c for c in obj.Path.Commands if c.Name in ("G0", "G1")]
    if along_x:  # passes run along X across the face at constant (Y, Z): check the passes mid-face
        key = lambda c: (round(c.Parameters["Y"], 9), round(c.Parameters["Z"], 9))
        cuts = [c for p, c in zip(moves, moves[1:]) if c.Name == "G1" and key(c) == key(p)
                and abs(c.Parameters["X"] - p.Parameters["X"]) > 1e-6]
    else:
        cuts = [c for c in moves if c.Name == "G1"]
    pts = [FreeCAD.Vector(c.Parameters["X"], c.Parameters["Y"], c.Parameters["Z"])
           for c in cuts[::max(1, len(cuts) // 80)]]
    if along_x:
        pts = [FreeCAD.Vector(b / 2, p.y, p.z) for p in pts]
    pts = [p for p in pts if 0.0 < p.x < b]
    distances = [gear.Shape.distToShape(Part.Vertex(p))[0] for p in pts]
    RESULT[name + "_inside"] = [d for p, d in zip(pts, distances) if gear.Shape.isInside(p, 1e-4, False) and d > 1e-4]
    RESULT[name + "_distances"] = distances
RESULT["files"] = commands.export_job(job, OUT)
# the same job file imported into a second document exports the same files too
imported = commands.import_job_file(FreeCAD.newDocument("Imported"), JOB_FILE)
RESULT["imported_labels"] = [o.Label for o in imported]
commands.export_job(imported[2], OUT_IMPORTED)
"""


def test_commands_recompute_follow_changes_and_export_like_the_cli(freecadcmd, tmp_path):
    props = {"gear": SMALL_GEAR_PROPERTIES, "stock": SMALL_STOCK_PROPERTIES, "job": SMALL_JOB_PROPERTIES}
    out, out_imported = tmp_path / "workbench_out", tmp_path / "imported_out"
    job_file = tmp_path / "small13.toml"
    job_file.write_text(small_job_text(teeth=13))
    body = (f"PROPS = {props!r}\nOUT = {str(out)!r}\nOUT_IMPORTED = {str(out_imported)!r}\n"
            f"JOB_FILE = {str(job_file)!r}\n" + SMALL_BODY)
    result, proc = run_workbench_code(body, tmp_path / "fc", freecadcmd=freecadcmd)
    assert result is not None and result.get("ok"), describe(proc, result)
    assert "Traceback" not in proc.stdout + proc.stderr, describe(proc, result)
    assert _all_up_to_date(result["first"]) and _all_up_to_date(result["second"]), result
    assert set(result["first"]) == {"Gear", "Stock", "Job", "RoughingToolpath", "FinishingToolpath"}

    # computed properties against the textbook (z changed from 12 to 13)
    book = Textbook(z=13, m=3.0, alpha_deg=20.0, rho=0.9, allowance_fraction=0.02)
    assert result["first_tip_radius"] == pytest.approx(3.0 * (6 + 1))
    radii = result["radii"]
    assert radii["tip"] == pytest.approx(book.ra) and radii["root"] == pytest.approx(book.rf)
    assert radii["base"] == pytest.approx(book.rb)
    assert radii["span"] == pytest.approx(span_iso(book, radii["k"]), abs=1e-9)
    assert radii["blank"] == pytest.approx(book.ra + 0.5)

    # placed per docs/architecture.md: axis X, front face X = 0, tooth space 0 symmetric about +Z
    x0, x1, y0, y1, z0, z1 = result["bbox"]
    assert (x0, x1) == pytest.approx((0.0, 6.0), abs=1e-6)
    assert max(abs(y0), y1, abs(z0), z1) == pytest.approx(book.ra, abs=1e-3)
    assert result["space0_at_plus_z"] is False and result["tooth_at_half_pitch"] is True
    assert result["stock_bbox"] == pytest.approx([-1.0, 7.0, book.ra + 0.5], abs=1e-6)

    # toolpaths drawn in the part frame: outside the gear; the finishing tip centre touches it
    assert result["roughing_inside"] == [] and result["finishing_inside"] == []
    finishing = sorted(result["finishing_distances"])  # mostly cutting: within the tool's reach of the flank
    assert finishing[0] < 1e-3 and finishing[int(0.9 * len(finishing))] <= 1.5, finishing
    assert min(result["roughing_distances"]) > 0.0
    assert result["job"]["types"] == ["Path::FeaturePython", "Path::FeaturePython"]

    # exported files: the same content as `spur-cad run` on the same job file
    cli = tmp_path / "cli_out"
    assert main(["run", str(job_file), "--out", str(cli), "--quiet"]) == 0
    assert output_differences(cli, out, (str(job_file), "Wb")) == []
    assert output_differences(cli, out_imported, (str(job_file), "Imported")) == []
    assert result["imported_labels"] == ["Gear", "Stock", "small quick gear"]
    summary = json.loads((cli / "summary.json").read_text())
    assert result["job"]["roughing"] == summary["roughing"]["moves"]
    assert result["job"]["finishing"] == summary["finishing"]["moves"] == result["job"]["total"]
    assert result["job"]["max_flat"] == pytest.approx(summary["tools"]["finishing_max_flat_width_mm"])
    cli_set = {p.name for p in cli.iterdir() if not p.name.startswith(".spur_cad")}  # the set, not its manifest
    assert {Path(f).name for f in result["files"]} == cli_set


REFERENCE_BODY = STATES + """
import FreeCAD
from spur_cad_workbench import commands
doc = FreeCAD.newDocument("Ref")
gear, stock, job = commands.import_job_file(doc, JOB)
RESULT["states"] = states(doc)
RESULT["gear"] = dict(teeth=gear.Teeth, module=gear.Module.Value, rho=gear.RackTipRadius.Value,
                      allowance=gear.ThicknessAllowancePercent, b=gear.FaceWidth.Value)
RESULT["stock"] = dict(stub=stock.StubDiameter.Value, back=stock.BackMargin.Value)
RESULT["job"] = dict(label=job.Label, rough_d=job.RoughingToolDiameter.Value, kind=job.FinishingToolKind,
                     corner=job.FinishingCornerRadius.Value, scallop=job.TargetScallop.Value,
                     clearance=job.Clearance.Value, block=job.BlockTime,
                     max_feed=float(job.MaxFeed.getValueAs("mm/min")))
RESULT["toolpaths"] = {tp.Operation: dict(moves=tp.Moves, shown=tp.DisplayedMoves, size=tp.Path.Size)
                       for tp in (job.RoughingToolpath, job.FinishingToolpath)}
"""


def test_reference_job_file_maps_onto_the_document(freecadcmd, tmp_path):
    """The reference job file: every value lands on its property; its finishing by generation (7,705 moves)
    is drawn whole (the export path is checked with the small job above)."""
    body = f"JOB = {str(REFERENCE_JOB)!r}\n" + REFERENCE_BODY
    result, proc = run_workbench_code(body, tmp_path / "fc", freecadcmd=freecadcmd, timeout_s=300)
    assert result is not None and result.get("ok"), describe(proc, result)
    assert _all_up_to_date(result["states"]), result["states"]
    data = tomllib.loads(REFERENCE_JOB.read_text())
    gear, tools = data["gear"], data["tools"]
    assert result["gear"] == {"teeth": gear["teeth"], "module": gear["module_mm"], "rho": gear["rack_tip_radius_mm"],
                              "allowance": gear["thickness_allowance_percent"], "b": gear["face_width_mm"]}
    assert result["stock"] == {"stub": data["stock"]["stub_diameter_mm"], "back": data["stock"]["back_margin_mm"]}
    assert result["job"] == {"label": data["job"]["name"], "rough_d": tools["roughing"]["diameter_mm"],
                             "kind": tools["finishing"]["kind"], "corner": tools["finishing"]["corner_radius_mm"],
                             "scallop": data["finishing"]["target_scallop_mm"],
                             "clearance": data["machine"]["clearance_mm"], "block": data["machine"]["block_time_s"],
                             "max_feed": data["machine"]["max_feed_mm_min"]}
    plan = plan_cam(load_job(REFERENCE_JOB))  # the same file through the library
    roughing, finishing = result["toolpaths"]["roughing"], result["toolpaths"]["finishing"]
    assert roughing["moves"] == len(plan.roughing.toolpath) and roughing["shown"] == roughing["moves"]
    assert finishing["moves"] == len(plan.finishing.toolpath) > 7_000
    assert finishing["shown"] == finishing["moves"] and finishing["size"] >= finishing["shown"]


SAVE_BODY = STATES + """
import FreeCAD
RESULT["version"] = [int(part) for part in FreeCAD.Version()[:2]]
from spur_cad_workbench import commands, properties, schema
doc = FreeCAD.newDocument("Saved")
gear = commands.make_gear(doc, **PROPS["gear"])
stock = commands.make_stock(gear, **PROPS["stock"])
job = commands.make_job(gear, stock, **PROPS["job"])
doc.recompute()
RESULT["new_types"] = {p: job.getTypeIdOfProperty(p) for p in ("MaxFeed", "AMin", "FinishingStrategy")}
RESULT["new_max_feed"] = [job.MaxFeed.Value, job.MaxFeed.UserString]
gear.removeProperty("KeywayDepth")      # as if saved by an older schema without this property
gear.SchemaVersion = 0
gear.setGroupOfProperty("TipRadius", "Computed")  # the groups of schemas 1 and 2
gear.setGroupOfProperty("Status", "Base")
gear.removeProperty("Module")           # schema 3: an input in mm that is never negative was a PropertyLength
gear.addProperty("App::PropertyLength", "Module", "Gear", "module m")
gear.Module = PROPS["gear"]["Module"]
gear.setExpression("Module", "FaceWidth / 2")  # a binding (as a spreadsheet's): kept when Module is re-created
gear.removeProperty("SpanMeasurementPrecise")  # schema 4 added the precise outputs
# as saved by schema 1: MaxFeed a plain float, AMin an angle (which clamped -99999 to -360), and a shorter list
job.removeProperty("MaxFeed")
job.addProperty("App::PropertyFloat", "MaxFeed", "Machine", "linear feed limit (mm/min)")
job.MaxFeed = 4321.5
job.removeProperty("AMin")
job.addProperty("App::PropertyAngle", "AMin", "Machine", "A travel limit, low (deg)")
job.AMin = -99999.0
job.FinishingStrategy = ["perimeter"]
job.removeProperty("BottomRoughingMoves")  # schema 4's bottom-tool results: not in an older document
job.removeProperty("SpindleRunout")  # schema 4: a um key was a PropertyFloat holding um
job.addProperty("App::PropertyFloat", "SpindleRunout", "Machine accuracy", "spindle runout (um)")
job.SpindleRunout = 3.5
job.SchemaVersion = 1
RESULT["saved_values"] = properties.read_values(job, schema.JOB_FIELDS)
doc.saveAs(FILE)
FreeCAD.closeDocument("Saved")
doc = FreeCAD.openDocument(FILE)
RESULT["restored"] = states(doc)
gear = doc.getObject("Gear")
RESULT["migrated"] = dict(version=gear.SchemaVersion, has=("KeywayDepth" in gear.PropertiesList),
                          value=gear.KeywayDepth.Value)
RESULT["migrated_module"] = [gear.getTypeIdOfProperty("Module"), gear.Module.Value,
                             "SpanMeasurementPrecise" in gear.PropertiesList]
RESULT["migrated_expressions"] = [list(item) for item in gear.ExpressionEngine]
RESULT["migrated_groups"] = [gear.getGroupOfProperty("TipRadius"), gear.getGroupOfProperty("Status")]
job = doc.getObject("Job")
RESULT["schema_version"] = schema.SCHEMA_VERSION
RESULT["job_version"] = job.SchemaVersion
RESULT["migrated_types"] = {p: job.getTypeIdOfProperty(p) for p in ("MaxFeed", "AMin", "FinishingStrategy")}
RESULT["bottom_results"] = ["BottomRoughingMoves" in job.PropertiesList, job.BottomRoughingMoves]
RESULT["migrated_runout"] = [job.getTypeIdOfProperty("SpindleRunout"), job.SpindleRunout.UserString]
RESULT["strategies"] = job.getEnumerationsOfProperty("FinishingStrategy")
RESULT["restored_values"] = properties.read_values(job, schema.JOB_FIELDS)
for obj in doc.Objects:
    obj.touch()
doc.recompute()
RESULT["recomputed"] = states(doc)
RESULT["moves"] = [job.RoughingMoves, job.FinishingMoves, job.FinishingToolpath.Moves]
RESULT["precise"] = [gear.SpanMeasurementPrecise, gear.SpanMeasurement.Value]
RESULT["links"] = [job.Gear.Name, job.Stock.Name, doc.getObject("Stock").Gear.Name]
doc.save()
FreeCAD.closeDocument(doc.Name)
doc = FreeCAD.openDocument(FILE)                 # reopened again: nothing left to migrate
RESULT["second_restore"] = states(doc)
RESULT["reopened_values"] = properties.read_values(doc.getObject("Job"), schema.JOB_FIELDS)
"""

PRIMITIVE_PROPERTIES = {"App::PropertyAngle", "App::PropertyBool", "App::PropertyDistance", "App::PropertyEnumeration",
                        "App::PropertySpeed",
                        "App::PropertyExpressionEngine", "App::PropertyFloat", "App::PropertyInteger",
                        "App::PropertyLength", "App::PropertyLink", "App::PropertyMap", "App::PropertyPlacement",
                        "App::PropertyString", "App::PropertyStringList", "App::PropertyUUID",
                        "Part::PropertyPartShape", "Path::PropertyPath", "App::PropertyPythonObject"}
# FreeCAD 1.0 and 1.1 give every Part feature (Part::FeaturePython too) a ShapeMaterial property (observed), saved
# with the document; FreeCAD's own, not the workbench's.
PART_FEATURE_PROPERTIES_1X = {"Materials::PropertyMaterial"}


def test_documents_save_and_reopen_without_pickles(freecadcmd, tmp_path):
    props = {"gear": SMALL_GEAR_PROPERTIES, "stock": SMALL_STOCK_PROPERTIES, "job": SMALL_JOB_PROPERTIES}
    saved = tmp_path / "gear.FCStd"
    body = f"PROPS = {props!r}\nFILE = {str(saved)!r}\n" + SAVE_BODY
    result, proc = run_workbench_code(body, tmp_path / "fc", freecadcmd=freecadcmd)
    assert result is not None and result.get("ok"), describe(proc, result)
    assert "Traceback" not in proc.stdout + proc.stderr, describe(proc, result)
    restored = result["restored"]  # the migrated gear is touched (a property was added), nothing is invalid
    assert all("Invalid" not in state and status == "ok" for state, status in restored.values()), restored
    assert _all_up_to_date(result["recomputed"]), result
    assert result["schema_version"] == 5
    assert result["migrated"] == {"version": 5, "has": True, "value": 0.0}
    # schema 3's PropertyLength inputs re-created as PropertyDistance with their value; precise outputs added
    assert result["migrated_module"] == ["App::PropertyDistance", SMALL_GEAR_PROPERTIES["Module"], True]
    assert result["migrated_expressions"] == [["Module", "FaceWidth / 2"]]
    precise, span = result["precise"]
    assert precise == f"{span:.4f} mm"
    # unit-carrying types: a feed is a speed shown in FreeCAD's units (mm/s) and read back in mm/min
    types = {"MaxFeed": "App::PropertySpeed", "AMin": "App::PropertyFloat",
             "FinishingStrategy": "App::PropertyEnumeration"}
    assert result["new_types"] == types
    assert result["new_max_feed"][0] == pytest.approx(5000.0 / 60.0) and "mm/s" in result["new_max_feed"][1]
    # schema-1 types re-created with the values they held, the drop-down list brought up to date
    assert result["job_version"] == 5 and result["migrated_types"] == types
    assert result["migrated_runout"] == ["App::PropertyDistance", "3.50 \u00b5m"]  # schema 5: the um in a Quantity
    assert result["bottom_results"] == [True, 0]  # schema 4's results of the bottom tool, added on reopening
    assert result["migrated_groups"] == ["Values: computed", "Values: status"]
    assert result["strategies"] == list(strategy_names())  # the registry's list, brought up to date
    before = result["saved_values"]
    assert before["MaxFeed"] == 4321.5 and before["AMin"] == -360.0  # the angle had clamped
    assert before["SpindleRunout"] == 3.5 and result["restored_values"]["SpindleRunout"] == 3.5
    assert result["restored_values"] == before and result["reopened_values"] == before
    assert _all_up_to_date(result["second_restore"]), result["second_restore"]
    assert result["moves"][0] > 0 and result["moves"][1] == result["moves"][2] > 0
    assert result["links"] == ["Gear", "Stock", "Gear"]
    with zipfile.ZipFile(saved) as archive:
        document = archive.read("Document.xml").decode()
    import xml.etree.ElementTree as ET

    root = ET.fromstring(document)
    types = {p.get("type") for p in root.iter("Property")}
    expected = PRIMITIVE_PROPERTIES | (PART_FEATURE_PROPERTIES_1X if result["version"] >= [1, 0] else set())
    assert types <= expected, types - expected
    proxies = [(p.get("module"), p.get("class"), p.get("value")) for p in root.iter("Python")]
    assert len(proxies) == 5
    import base64

    for module, _, value in proxies:
        assert module == "spur_cad_workbench.features"
        assert base64.b64decode(value) == b"null"  # JSON null: no pickled state


ERROR_BODY = STATES + """
import FreeCAD
from spur_cad_workbench import commands
doc = FreeCAD.newDocument("Bad")
gear = commands.make_gear(doc, **PROPS["gear"])
stock = commands.make_stock(gear, **PROPS["stock"])
job = commands.make_job(gear, stock, **PROPS["job"])
doc.recompute()
job.FinishingToolDiameter = 9.0
doc.recompute()
RESULT["job_status"] = job.Status
gear.Teeth = 3
doc.recompute()
RESULT["after"] = states(doc)
from spur_cad.errors import SpurCadError
try:
    commands.export_job(job, OUT)
except SpurCadError as exc:
    RESULT["export_error"] = str(exc)
try:
    commands.make_gear(doc, Teth=20)
except SpurCadError as exc:
    RESULT["unknown_property"] = str(exc)
"""


def _cli_error(text: str, tmp_path: Path, capsys) -> str:
    job_file = tmp_path / "bad.toml"
    job_file.write_text(text)
    assert main(["run", str(job_file), "--out", str(tmp_path / "bad_out"), "--quiet"]) == 2
    line = capsys.readouterr().err.strip()
    assert line.startswith("spur-cad: error: ")
    return line[len("spur-cad: error: "):]


def test_bad_input_is_a_message_on_the_object_not_a_traceback(freecadcmd, tmp_path, capsys):
    props = {"gear": SMALL_GEAR_PROPERTIES, "stock": SMALL_STOCK_PROPERTIES, "job": SMALL_JOB_PROPERTIES}
    body = f"PROPS = {props!r}\nOUT = {str(tmp_path / 'never')!r}\n" + ERROR_BODY
    # the two input errors, each one line in the report (FreeCAD's log), and nothing else
    expected_log = (r"^Err: Job: Finishing tool: diameter at most [^\n]*$",
                    r"^Err: Gear: Teeth must be in 5\.\.1000, got 3\.$")
    result, proc = run_workbench_code(body, tmp_path / "fc", freecadcmd=freecadcmd, log_allowed=expected_log)
    assert result is not None and result.get("ok"), describe(proc, result)
    output = proc.stdout + proc.stderr
    assert "Traceback" not in output, describe(proc, result)
    # The command line points at the key's line ("bad.toml:24: ..."); the document has no file lines.
    # The objects say it in one sentence with the field's title (the command line names the key).
    assert result["job_status"].startswith("error: Finishing tool: diameter at most ")
    assert "_mm" not in result["job_status"] and result["job_status"].endswith(".")
    gear_message = _cli_error(small_job_text(teeth=3), tmp_path, capsys).split(": ", 1)[1]  # drop "bad.toml:8"
    after = result["after"]
    assert after["Gear"][1] == "error: Teeth must be in 5..1000, got 3."
    assert after["Stock"][1] == "stale: Gear has an error"  # reported once, on the gear
    assert "Gear: Teeth must be in 5..1000, got 3." in output  # one line in the report (here: the console)
    assert output.count("must be in 5..1000") == 1
    assert result["export_error"].endswith(gear_message)
    assert not (tmp_path / "never").exists()
    assert result["unknown_property"].startswith("unknown gear properties: Teth")


SIM_BODY = """
import FreeCAD
from spur_cad_workbench import commands, simulation
doc = FreeCAD.newDocument("Sim")
gear = commands.make_gear(doc, **PROPS["gear"])
stock = commands.make_stock(gear, **PROPS["stock"])
job = commands.make_job(gear, stock, **PROPS["job"])
doc.recompute()
try:
    simulation.simulator()
except simulation.SimulationUnavailable as exc:
    RESULT["unavailable"] = str(exc)
else:
    sim = commands.simulate(job, resolution_mm=0.02)
    pts = sim.Points.Points
    RESULT.update(count=len(pts), colours=len(sim.Color), gouge=sim.MaxGougeMicrons / 1000.0,
                  leftover=sim.MaxLeftoverMicrons / 1000.0, scale=sim.ColourScale.Value,
                  largest=max(abs(d) for d in sim.Deviations), job=sim.Job.Name, status=sim.Status,
                  legend=sim.Legend, xs=[min(p.x for p in pts), max(p.x for p in pts)],
                  radii=[min((p.y**2 + p.z**2) ** 0.5 for p in pts), max((p.y**2 + p.z**2) ** 0.5 for p in pts)],
                  green=sum(1 for c in sim.Color if c[1] > 0.99), red=sum(1 for c in sim.Color if c[0] > 0.99),
                  blue=sum(1 for c in sim.Color if c[2] > 0.99))
"""


def test_simulate_shows_the_design_points_coloured_by_deviation(freecadcmd, tmp_path):
    props = {"gear": SMALL_GEAR_PROPERTIES, "stock": SMALL_STOCK_PROPERTIES, "job": SMALL_JOB_PROPERTIES}
    body = f"PROPS = {props!r}\n" + SIM_BODY
    result, proc = run_workbench_code(body, tmp_path / "fc", freecadcmd=freecadcmd)
    assert result is not None and result.get("ok"), describe(proc, result)
    if "unavailable" in result:
        assert result["unavailable"].startswith("simulation not available")
        return
    spec = parse_job(small_job_text(), "s").gear
    assert result["count"] == result["colours"] > 0
    assert result["xs"][0] >= -1e-9 and result["xs"][1] <= spec.face_width_mm + 1e-9
    assert result["radii"][0] >= spec.root_radius_mm - 0.01 and result["radii"][1] <= spec.tip_radius_mm + 0.01
    assert 0.0 <= result["gouge"] <= 0.02  # within the resolution: the toolpaths do not gouge
    assert result["green"] > 0 and "blue: gouge" in result["legend"]
    assert result["job"] == "Job" and result["status"] == "ok"
    # the scale is the largest deviation shown (at least the resolution): the worst point is fully coloured
    assert result["scale"] == pytest.approx(max(result["largest"], 0.02))
    if result["largest"] > 0.02:
        assert result["red"] > 0 or result["blue"] > 0


HELICAL_BODY = STATES + """
import math, FreeCAD
from spur_cad_workbench import commands
doc = FreeCAD.newDocument("Helical")
gear, stock, job = commands.import_job_file(doc, JOB_FILE)
doc.recompute()
RESULT["states"] = states(doc)
RESULT["props"] = [gear.HelixAngle.Value if hasattr(gear.HelixAngle, "Value") else gear.HelixAngle, str(gear.Hand)]
RESULT["volume"] = gear.Shape.Volume
RESULT["valid"] = gear.Shape.isValid()
b, r = gear.FaceWidth.Value, gear.ReferenceRadius.Value if hasattr(gear, "ReferenceRadius") else None
# a point on the tooth centre line at the reference radius, at the front, and further back with the angle from
# +Z toward +Y changed by +-b tan(beta) / r: a turn by +T in the positive A sense lowers that angle by T
z = gear.Teeth
rr = gear.BaseRadius.Value / math.cos(math.radians(20.6469))
def inside(x, turn):
    a = math.pi / z + turn
    return gear.Shape.isInside(FreeCAD.Vector(x, rr * math.sin(a), rr * math.cos(a)), 1e-6, True)
turn = b * math.tan(math.radians(15.0)) / rr
RESULT["inside"] = [inside(0.01, 0.0), inside(b / 2, turn / 2), inside(b / 2, -turn / 2), inside(b - 0.01, -turn)]

RESULT["files"] = commands.export_job(job, OUT)
"""


def test_a_helical_gear_in_the_document_is_the_swept_solid_and_exports_like_the_cli(freecadcmd, tmp_path):
    """The helical example imported: helix angle and hand on the gear object, the solid turned by the helix
    (right hand: the section at the back face is turned by +b tan(beta) / r in the positive A sense, so a point
    of the tooth seen at angle a from +Z toward +Y at the front is at a - b tan(beta) / r at the back), and the
    export identical to `spur-cad run` of the same file."""
    example = Path(__file__).resolve().parents[1] / "resources" / "examples" / "helical_gear.toml"
    out = tmp_path / "wb_out"
    body = f"JOB_FILE = {str(example)!r}\nOUT = {str(out)!r}\n" + HELICAL_BODY
    result, proc = run_workbench_code(body, tmp_path / "fc", freecadcmd=freecadcmd, timeout_s=300)
    assert result is not None and result.get("ok"), describe(proc, result)
    assert _all_up_to_date(result["states"]), result["states"]
    assert result["props"] == [15.0, "right"]
    assert result["valid"] and result["inside"] == [True, False, True, True]
    cli = tmp_path / "cli_out"
    assert main(["run", str(example), "--out", str(cli), "--quiet"]) == 0
    summary = json.loads((cli / "summary.json").read_text())
    # FreeCAD integrates the swept faces more coarsely than spur_cad (1.2e-5 here); the turn is checked above
    assert result["volume"] == pytest.approx(summary["cad"]["gear_volume_mm3"], rel=1e-4)
    assert output_differences(cli, out, (str(example), "Helical")) == []


DEFAULT_JOB_BODY = """
import FreeCAD
from spur_cad_workbench import commands, schema
from spur_cad_workbench.properties import document_values
doc = FreeCAD.newDocument("Default")
gear = commands.make_gear(doc)                     # what the toolbar's three buttons make, no value given
stock = commands.make_stock(gear)
job = commands.make_job(gear, stock)
doc.recompute()
RESULT["states"] = {o.Name: [list(o.State), getattr(o, "Status", "")] for o in doc.Objects}
RESULT["minutes"] = {title: getattr(job, title + "TimeWithAcceleration")
                     for title in ("Roughing", "BottomRoughing", "Finishing")}
RESULT["data"] = schema.job_data(document_values(job))
"""


def test_the_default_job_starts_from_advised_tools_and_a_time_a_shop_accepts(freecadcmd, tmp_path):
    """Issues 28 point 1 and 29: gear, stock and job made with no values recompute without error, rough by flanks
    (one tool: two-stage roughing by levels saves no tenth of that), and the job's cycle time, every program
    counted, is within one shift (8 h; 18 h 36 min before issue 28, 4 h 48 min in two stages by levels before
    issue 29); each program's time is the engine's own estimate for the job the document holds."""
    from spur_cad.job import job_from_dict

    result, proc = run_workbench_code(DEFAULT_JOB_BODY, tmp_path / "fc", freecadcmd=freecadcmd)
    assert result is not None and result.get("ok"), describe(proc, result)
    assert _all_up_to_date(result["states"]), result["states"]
    job = job_from_dict(result["data"], "default")
    assert job.roughing.strategy == "flank" and job.tools.bottom is None
    plan = plan_cam(job)
    minutes = result["minutes"]
    for title, planned in (("Roughing", plan.roughing), ("BottomRoughing", plan.roughing_bottom),
                           ("Finishing", plan.finishing)):
        expected = planned.estimate.time_with_acceleration_s / 60.0 if planned is not None else 0.0
        assert minutes[title] == pytest.approx(expected, rel=1e-9)
    assert 60.0 < sum(minutes.values()) < 8 * 60.0


MODIFIED_SAVE_BODY = """
import FreeCAD
from spur_cad_workbench import commands
doc = FreeCAD.newDocument("Modified")
gear = commands.make_gear(doc, **PROPS, **MODS)
plain = commands.make_gear(doc, **PROPS)
doc.recompute()
doc.saveAs(FILE)
"""

MODIFIED_OPEN_BODY = """
import FreeCAD
from spur_cad_workbench import properties, schema
doc = FreeCAD.openDocument(FILE)
gear, plain = doc.getObject("Gear"), doc.getObject("Gear001")
values = properties.read_values(gear, schema.GEAR_FIELDS)
RESULT["values"] = {prop: values[prop] for prop in MODS}
RESULT["shown"] = [gear.getTypeIdOfProperty("TipRelief"), gear.TipRelief.UserString,
                   gear.getGroupOfProperty("TipRelief"), gear.getGroupOfProperty("RightTipRelief")]
mods = properties.job_of(gear).modifications
RESULT["mm"] = [mods.left.tip_relief_mm, mods.right.tip_relief_mm, mods.right.tip_relief_parabolic]
RESULT["status"] = [gear.Status, plain.Status]
RESULT["volumes"] = [gear.Shape.Volume, plain.Shape.Volume, gear.Shape.isValid()]
"""


def test_flank_modifications_are_gear_properties_in_um_saved_and_reopened_in_a_new_process(freecadcmd, tmp_path):
    """The common table and the right flank's own values as PropertyDistance shown in um, in their groups; saved,
    reopened by another FreeCAD process with their values, the job's modifications and a solid with less material
    than the unmodified gear's."""
    mods = dict(TipRelief=20.0, TipReliefStartDiameter=40.0, RightFlankOwnValues=True, RightTipRelief=30.0,
                RightTipReliefStartDiameter=40.0, RightTipReliefShape="parabolic")
    saved = tmp_path / "modified.FCStd"
    head = f"PROPS = {SMALL_GEAR_PROPERTIES!r}\nMODS = {mods!r}\nFILE = {str(saved)!r}\n"
    result, proc = run_workbench_code(head + MODIFIED_SAVE_BODY, tmp_path / "save", freecadcmd=freecadcmd)
    assert result is not None and result.get("ok"), describe(proc, result)
    result, proc = run_workbench_code(head + MODIFIED_OPEN_BODY, tmp_path / "open", freecadcmd=freecadcmd)
    assert result is not None and result.get("ok"), describe(proc, result)
    assert result["values"] == mods
    assert result["shown"] == ["App::PropertyDistance", "20.00 \u00b5m", "Flank modifications",
                               "Flank modifications: right flank"]
    assert result["mm"] == [0.02, 0.03, True]
    assert result["status"] == ["ok", "ok"]
    modified, plain, valid = result["volumes"]
    assert valid and modified < plain - 1e-3, result["volumes"]


SIDES_SAVE_BODY = """
import FreeCAD
from spur_cad_workbench import commands, properties, schema
doc = FreeCAD.newDocument("Sides")
gear = commands.make_gear(doc, **PROPS, **COMMON)
gear.LeftFlankOwnValues = True                    # the user switches a side on and changes one amount
properties.write_values(gear, {"LeftTipRelief": 25.0})
gear.RightFlankOwnValues = True                   # and the other side's crowning off
properties.write_values(gear, {"RightLeadCrowning": 0.0})
doc.recompute()
RESULT["status"] = gear.Status
doc.saveAs(FILE)
"""

SIDES_OPEN_BODY = """
import FreeCAD
from spur_cad_workbench import properties, schema
doc = FreeCAD.openDocument(FILE)
gear = doc.getObject("Gear")
values = properties.read_values(gear, schema.GEAR_FIELDS)
RESULT["sides"] = {prop: values[prop] for prop in ("LeftTipRelief", "LeftTipReliefStartDiameter", "LeftLeadCrowning",
                                                   "RightTipRelief", "RightLeadCrowning")}
RESULT["tables"] = schema.job_data(properties.document_values(gear))["gear"]["modifications"]
mods = properties.job_of(gear).modifications
RESULT["mm"] = {side: [getattr(mods, side).tip_relief_mm, getattr(mods, side).tip_relief_start_roll_mm,
                       getattr(mods, side).lead_crowning_mm] for side in ("left", "right")}
"""


def test_a_flank_side_switched_on_writes_only_what_differs_from_the_common_values(freecadcmd, tmp_path):
    """A side switched on starts from the common values: changing one amount gives its table that one key and the
    side keeps the common relief start and crowning; saved and reopened in a new process (reading the switch must
    not copy the common values over the side's own)."""
    common = dict(TipRelief=15.0, TipReliefStartDiameter=40.0, LeadCrowning=8.0)
    saved = tmp_path / "sides.FCStd"
    head = f"PROPS = {SMALL_GEAR_PROPERTIES!r}\nCOMMON = {common!r}\nFILE = {str(saved)!r}\n"
    result, proc = run_workbench_code(head + SIDES_SAVE_BODY, tmp_path / "save", freecadcmd=freecadcmd)
    assert result is not None and result.get("ok"), describe(proc, result)
    assert result["status"] == "ok"
    result, proc = run_workbench_code(head + SIDES_OPEN_BODY, tmp_path / "open", freecadcmd=freecadcmd)
    assert result is not None and result.get("ok"), describe(proc, result)
    assert result["sides"] == dict(LeftTipRelief=25.0, LeftTipReliefStartDiameter=40.0, LeftLeadCrowning=8.0,
                                   RightTipRelief=15.0, RightLeadCrowning=0.0)
    tables = result["tables"]
    assert tables["left"] == {"tip_relief_um": 25.0} and tables["right"] == {"lead_crowning_um": 0.0}
    assert (tables["tip_relief_um"], tables["tip_relief_start_diameter_mm"], tables["lead_crowning_um"]) == \
        (15.0, 40.0, 8.0)
    (left_tip, left_start, left_crowning), (right_tip, right_start, right_crowning) = \
        result["mm"]["left"], result["mm"]["right"]
    assert (left_tip, left_crowning) == (0.025, 0.008) and (right_tip, right_crowning) == (0.015, 0.0)
    assert left_start == right_start > 0.0  # the left's relief starts at the common diameter
