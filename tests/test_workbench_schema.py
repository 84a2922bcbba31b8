"""Workbench parts that run without FreeCAD: the document schema, the panel's checks, tool suggestions,
the part-frame toolpath display, the environment activation, and job_from_dict."""

from __future__ import annotations

import dataclasses
import json
import math
import re
import sys
import tomllib
import typing
from types import SimpleNamespace

import numpy as np
import pytest

from spur_cad.cad.specs import StockSpec
from spur_cad.cam.finishing import plan_finishing
from spur_cad.cam.ir import MoveKind, Operation, ToolpathBuilder
from spur_cad.cam.machine import Machine, RoughingParams
from spur_cad.cam.recommend import check_roughing_reach, check_tools, recommend_tools
from spur_cad.cam.roughing import roughing_levels
from spur_cad.cam.strategies import FinishingParams
from spur_cad.cam.tools import Tool
from spur_cad.errors import JobFileError, SpurCadError
from spur_cad.job import (
    MODIFICATION_SECTIONS,
    GearSection,
    Job,
    JobSection,
    SimulationSection,
    job_from_dict,
    load_job,
    parse_job,
)
from spur_cad.post.settings import PostSettings
from tests.gears import GEAR_CASES
from tests.textbook import Textbook
from tests.tiers import sweep
from tests.workbench_helper import REFERENCE_JOB, ROOT, small_job_text


@pytest.fixture
def wb(monkeypatch):
    """The workbench package (plain-Python modules only), importable from workbench/."""
    monkeypatch.syspath_prepend(str(ROOT / "workbench"))
    from spur_cad_workbench import colours, display, environment, schema, simulation, validation

    return SimpleNamespace(schema=schema, validation=validation, display=display, environment=environment,
                           simulation=simulation, colours=colours)


# --- job_from_dict -------------------------------------------------------------------------------

# The reference job file's values, written out by hand (keys the file omits have the documented defaults).
REFERENCE_VALUES = {
    "job": JobSection(name="reference gear z23 m4", profile_tolerance_mm=0.001),
    "gear": GearSection(teeth=23, module_mm=4.0, face_width_mm=20.0, pressure_angle_deg=20.0,
                        profile_shift_coefficient=0.0, addendum_coefficient=1.0, dedendum_coefficient=1.25,
                        rack_tip_radius_mm=0.8, thickness_allowance_percent=5.0, thickness_allowance_mm=0.0),
    "stock": StockSpec(radial_allowance_mm=0.5, front_margin_mm=1.0, back_margin_mm=2.0, stub_diameter_mm=80.0,
                       stub_length_mm=40.0),
    "tools.roughing": Tool(diameter_mm=3.5, kind="flat", flutes=3, flute_length_mm=12.0, stick_out_mm=15.0,
                           tool_number=1, cutting_speed_m_min=80.0, feed_per_tooth_mm=0.015),
    "tools.finishing": Tool(diameter_mm=2.0, kind="bull_nose", corner_radius_mm=0.5, flutes=2, flute_length_mm=12.0,
                            stick_out_mm=15.0, tool_number=2, cutting_speed_m_min=120.0, feed_per_tooth_mm=0.02),
    "roughing": RoughingParams(flank_allowance_mm=0.3, finish_stock_mm=0.02, step_over_fraction=0.5,
                               max_level_depth_fraction=0.5, clamp_rotary=False),
    "finishing": FinishingParams(strategy="generating", target_scallop_mm=0.005, step_over_mm=0.0),
    "machine": Machine(name="vertical machining centre with rotary table (reference process)",
                       max_spindle_rpm=7000.0, max_feed_mm_min=5000.0, max_rotary_speed_deg_min=3600.0,
                       clearance_mm=1.0, block_time_s=0.004),
    "post": PostSettings(dialect="linuxcnc", folded=True, line_numbers=False),
    "simulation": SimulationSection(enabled=True, resolution_mm=0.005),
}


@pytest.mark.parametrize("load", ["parse_job", "job_from_dict"])
def test_the_reference_job_holds_the_values_written_in_the_file(load):
    text = REFERENCE_JOB.read_text()
    job = parse_job(text, "doc") if load == "parse_job" else job_from_dict(tomllib.loads(text), "doc")
    assert job.source == "doc"
    for name, expected in REFERENCE_VALUES.items():
        assert job.section(name) == expected, name
    # and every key in the file, as tomllib reads it, with the type the job file declares (int -> float)
    data = tomllib.loads(text)
    tables = {**{k: v for k, v in data.items() if k != "tools"}, **{f"tools.{k}": v for k, v in data["tools"].items()}}
    for name, table in tables.items():
        for key, value in table.items():
            held = getattr(job.section(name), key)
            assert held == value and type(held) is type(getattr(REFERENCE_VALUES[name], key)), (name, key)
    assert job.gear.thickness_allowance_fraction == pytest.approx(0.05)


# (old text, new text, the message after "doc:<line>: " / "doc: ", the key whose line it names)
MESSAGES = [
    ("flutes = 3", "flutes = 3.5", "[tools.roughing] flutes must be a whole number, got 3.5", "flutes"),
    ("teeth = 23", "teeth = 3", "[gear] teeth must be in 5..1000, got 3", "teeth"),
    ("max_spindle_rpm = 7000.0", "max_spindle_rmp = 7000.0", "unknown key 'max_spindle_rmp' in [machine]",
     "max_spindle_rmp"),
    ('strategy = "generating"', 'strategy = "spiral"', "[finishing] strategy 'spiral' is unknown", "strategy"),
    ("feed_per_tooth_mm = 0.015", "feed_per_tooth_mm = inf",
     "[tools.roughing] feed_per_tooth_mm must be a finite number, got inf", "feed_per_tooth_mm"),
    ("finish_stock_mm = 0.02 ", "finish_stock_mm = 0.5 ",
     "[roughing] finish_stock_mm = 0.5 must be below flank_allowance_mm = 0.3", "finish_stock_mm"),
    ("rack_tip_radius_mm = 0.8", "rack_tip_radius_mm = 2.5",
     "invalid gear: rack_tip_radius_mm = 2.5 mm is outside the accepted range [0, 2.4] mm", "rack_tip_radius_mm"),
    ("stub_diameter_mm = 80.0", "stub_diameter_mm = 200.0",
     "invalid [stock]: stub diameter 200 mm is larger than the blank", "stub_diameter_mm"),
]


@pytest.mark.parametrize("old, new, message, key", MESSAGES)
def test_messages_name_the_key_and_its_line(old, new, message, key):
    text = REFERENCE_JOB.read_text()
    assert old in text
    bad = text.replace(old, new)
    line = next(n for n, content in enumerate(bad.splitlines(), start=1) if content.startswith(new.strip()))
    assert bad.splitlines()[line - 1].startswith(key)
    with pytest.raises(JobFileError) as from_file:
        parse_job(bad, "doc")
    with pytest.raises(JobFileError) as from_dict:
        job_from_dict(tomllib.loads(bad), "doc")
    assert str(from_file.value).startswith(f"doc:{line}: {message}"), str(from_file.value)
    assert str(from_dict.value).startswith(f"doc: {message}"), str(from_dict.value)


# --- schema --------------------------------------------------------------------------------------

# Every input property name of schema version 1: saved documents use them, so they never change.
V1_PROPERTIES = {
    "gear": "Teeth Module PressureAngle ProfileShift FaceWidth AddendumCoefficient DedendumCoefficient RackTipRadius "
            "ThicknessAllowancePercent ThicknessAllowance BoreDiameter KeywayWidth KeywayDepth",
    "stock": "RadialAllowance FrontMargin BackMargin StubDiameter StubLength",
    "job": "JobName ProfileTolerance UseRoughingTool RoughingToolKind RoughingToolDiameter RoughingCornerRadius "
           "RoughingFlutes RoughingFluteLength RoughingStickOut RoughingToolNumber RoughingCuttingSpeed "
           "RoughingFeedPerTooth UseFinishingTool FinishingToolKind FinishingToolDiameter FinishingCornerRadius "
           "FinishingFlutes FinishingFluteLength FinishingStickOut FinishingToolNumber FinishingCuttingSpeed "
           "FinishingFeedPerTooth FlankAllowance FinishStock StepOverFraction MaxLevelDepthFraction ClampRotary "
           "FinishingStrategy TargetScallop FinishingStepOver MachineName MaxSpindleRpm MaxFeed RapidFeed "
           "MaxRotarySpeed Clearance BlockTime RotaryContinuous AMin AMax XMin XMax YMin YMax ZMin ZMax "
           "RotaryClampCode RotaryUnclampCode SimulationEnabled SimulationResolution PostDialect LineNumbers "
           "LineNumberStep MaxLineNumber LineNumberOverflow Folded RotarySign RotaryMode ProgramNumber Coolant",
}


def _section_classes() -> dict[str, type]:
    """Job-file sections and their dataclasses, read from spur_cad.job.Job's fields (so new sections count)."""
    hints = typing.get_type_hints(Job)
    sections = {("gear" if f.name == "gear_section" else f.name): hints[f.name] for f in dataclasses.fields(Job)
                if f.name not in ("source", "gear", "tools", "text", "strategies", "dialects", "report_template_text",
                                  "rotary_calibration", "modifications", "modification_values",
                                  "roughing_strategy_left_out", "pair")}
    sections["tools.roughing"] = sections["tools.finishing"] = sections["tools.bottom"] = Tool
    sections.update(MODIFICATION_SECTIONS)  # read with [gear]: the Job holds them as FlankModifications
    # an optional section (`lathe: LatheSection | None`) is its dataclass
    return {name: next((a for a in typing.get_args(cls) if a is not type(None)), cls) for name, cls in sections.items()}


def test_every_job_file_key_has_exactly_one_property_with_its_old_name(wb):
    fields = [f for fs in wb.schema.FIELDS.values() for f in fs if f.key]
    pairs = [(f.section, f.key) for f in fields]
    expected = {(name, field.name) for name, cls in _section_classes().items() for field in dataclasses.fields(cls)}
    assert sorted(pairs) == sorted(expected)
    props = [f.prop for fs in (*wb.schema.FIELDS.values(), *wb.schema.OUTPUTS.values()) for f in fs]
    assert len(props) == len(set(props))
    for role, names in V1_PROPERTIES.items():  # new keys may add properties; none of these may go or move
        assert set(names.split()) <= {f.prop for f in wb.schema.FIELDS[role]}, role


def test_properties_carry_the_keys_meaning_group_and_unit(wb):
    """Tooltip = the key's meaning (with its unit where the property type has none), group = the key's group."""
    from spur_cad.keys import keys_of

    for f in (f for fs in wb.schema.FIELDS.values() for f in fs if f.key):
        k = next(k for k in keys_of(_section_classes()[f.section]) if k.name == f.key)
        group = k.group.format(Role=f.section[6:].capitalize())
        side = f.section.removeprefix("gear.modifications.") if f.section.startswith("gear.modifications.") else ""
        assert f.doc.startswith(k.meaning) and f.group == (f"{group}: {side} flank" if side else group), f
        assert f.unit == k.unit


# The documented mapping (schema.py's docstring), checked on properties of every row. Every mm input is a
# PropertyDistance (schema 4): a PropertyLength would store a typed -3 as 0 without a word.
EXPECTED_TYPES = {
    "Module": "App::PropertyDistance", "FaceWidth": "App::PropertyDistance",
    "RoughingFeedPerTooth": "App::PropertyDistance",
    "XMin": "App::PropertyDistance", "ZMax": "App::PropertyDistance",
    "PressureAngle": "App::PropertyAngle", "AMin": "App::PropertyFloat", "AMax": "App::PropertyFloat",
    "MaxFeed": "App::PropertySpeed", "RapidFeed": "App::PropertySpeed",
    "RoughingCuttingSpeed": "App::PropertyFloat", "MaxSpindleRpm": "App::PropertyFloat",
    "MaxRotarySpeed": "App::PropertyFloat", "BlockTime": "App::PropertyFloat",
    "ThicknessAllowancePercent": "App::PropertyFloat", "ProfileShift": "App::PropertyFloat",
    "Teeth": "App::PropertyInteger", "RotarySign": "App::PropertyInteger", "ClampRotary": "App::PropertyBool",
    "PostDialect": "App::PropertyEnumeration", "FinishingStrategy": "App::PropertyEnumeration",
    "RoughingToolKind": "App::PropertyEnumeration", "RotaryMode": "App::PropertyEnumeration",
    "JobName": "App::PropertyString", "RotaryClampCode": "App::PropertyString",
}


def test_property_types_follow_the_documented_unit_mapping(wb):
    for prop, expected in EXPECTED_TYPES.items():
        assert wb.schema.field_by_prop(prop).property_type == expected, prop
    numeric = {"length", "distance", "angle", "speed", "float"}
    for f in (f for fs in wb.schema.FIELDS.values() for f in fs):
        if not f.key:
            assert f.kind == "bool"
            continue
        annotation = typing.get_type_hints(_section_classes()[f.section])[f.key]
        allowed = {int: {"int"}, bool: {"bool"}, str: {"string", "choice"}, float: numeric}[annotation]
        assert f.kind in allowed, f
        assert f.kind != "length", f  # clamps to >= 0: outputs only
        if f.kind == "distance":
            assert f.unit in ("mm", "um")
        if f.kind == "angle":
            assert f.unit == "deg"


def test_plain_values_convert_freecads_quantities(wb):
    class Quantity:  # what FreeCAD returns for unit-carrying properties: Value in mm, deg or mm/s
        def __init__(self, value):
            self.Value = value

        def getValueAs(self, unit):
            return self.Value * {"mm/min": 60.0, "um": 1000.0}[unit]

    speed, length = wb.schema.field_by_prop("MaxFeed"), wb.schema.field_by_prop("Module")
    assert wb.schema.plain_value(speed, Quantity(5000.0 / 60.0)) == 5000.0
    for feed in (5000.0, 777.7, 1000.1, 12345.6):  # as a document saves the speed: 16 digits in mm/s
        assert wb.schema.plain_value(speed, Quantity(float(f"{feed / 60.0:.16g}"))) == feed
    assert wb.schema.plain_value(length, Quantity(4.0)) == 4.0
    assert wb.schema.plain_value(speed, 4000.0) == 4000.0  # a PropertyFloat of a schema-1 document
    relief = wb.schema.field_by_prop("TipRelief")  # um keys: set and read in um, not the Quantity's mm
    for amount_um in (15.0, 14.6, 2.7, 0.3):
        assert wb.schema.plain_value(relief, Quantity(amount_um / 1000.0)) == amount_um
    assert wb.schema.plain_value(relief, 15.0) == 15.0  # a PropertyFloat of a schema-4 document (SpindleRunout)


MODIFIED_JOB = """[gear]
teeth = 23
module_mm = 4
face_width_mm = 20
rack_tip_radius_mm = 1.52

[gear.modifications]
tip_relief_um = 15
tip_relief_start_diameter_mm = 96
lead_crowning_um = 8

[gear.modifications.right]
tip_relief_um = 20
tip_relief_shape = "parabolic"
"""


def test_flank_modifications_round_trip_through_the_gears_properties(wb):
    """The common table, the right flank's override (the left one takes the common values) and the amounts in um;
    a job file's partial side table reads back as the same modifications."""
    job = parse_job(MODIFIED_JOB, "mods.toml")
    values = wb.schema.values_from_job(job)
    gear = values["gear"]
    assert (gear["TipRelief"], gear["RightTipRelief"], gear["RightTipReliefStartDiameter"]) == (15.0, 20.0, 96.0)
    assert (gear["RightFlankOwnValues"], gear["LeftFlankOwnValues"], gear["RightTipReliefShape"]) == \
        (True, False, "parabolic")
    assert wb.schema.field_by_prop("RightLeadCrowning").group == "Flank modifications: right flank"
    data = json.loads(json.dumps(wb.schema.job_data(values)))
    assert set(data["gear"]["modifications"]) >= {"right"} and "left" not in data["gear"]["modifications"]
    again = job_from_dict(data, "mods.toml")
    assert again.modifications == job.modifications
    assert again.modifications.right.tip_relief_mm == 0.02 and again.modifications.left.tip_relief_mm == 0.015
    assert again.modifications.right.lead_crowning_mm == 0.008 and again.modifications.right.tip_relief_parabolic
    gear["LeftFlankOwnValues"], gear["LeftLeadCrowning"] = True, 3.0  # the left flank's own values now
    changed = job_from_dict(wb.schema.job_data(values), "mods.toml").modifications
    assert changed.left.lead_crowning_mm == 0.003 and changed.right == job.modifications.right


def test_a_gear_without_modification_amounts_writes_no_modification_table(wb):
    """Start diameters or shapes alone set nothing: the job (and its PlannedValues fingerprint) stays as before."""
    values = wb.schema.default_values()
    values["gear"].update(TipReliefStartDiameter=96.0, RightFlankOwnValues=True, RightTipReliefShape="parabolic")
    assert "modifications" not in wb.schema.job_data(values)["gear"]
    values["gear"]["RightEndRelief"] = 5.0  # an amount on a side switched on writes the tables
    assert set(wb.schema.job_data(values)["gear"]["modifications"]) > {"right", "end_relief_um"}


def test_a_modification_error_is_filed_under_its_property(wb):
    """Too long a relief: the command line's message, blamed on the field of the table that gives the key."""
    values = wb.schema.values_from_job(parse_job(MODIFIED_JOB, "mods.toml"))
    values["gear"]["RightTipReliefStartDiameter"] = 80.0  # below the form diameter
    result = wb.validation.validate(values, "mods")
    assert not result.ok
    assert result.problems[0].prop == "RightTipReliefStartDiameter", result.problems


def test_defaults_are_in_the_choices(wb):
    values = wb.schema.default_values()
    for role, fields in wb.schema.FIELDS.items():
        for f in fields:
            if f.kind == "choice":
                assert values[role][f.prop] in f.choices, f


@pytest.mark.parametrize("text", [REFERENCE_JOB.read_text(), small_job_text(),
                                  "[gear]\nteeth = 30\nmodule_mm = 2\nface_width_mm = 10\n"])
def test_job_round_trips_through_properties(wb, text):
    job = parse_job(text, "a.toml")
    values = wb.schema.values_from_job(job)
    assert set(values) == {"gear", "stock", "job"}
    again = job_from_dict(json.loads(json.dumps(wb.schema.job_data(values))), "a.toml")
    assert again == job


def test_a_roughing_top_job_opens_as_the_same_pair_of_roughing_and_bottom_tools(wb):
    """The panel has no [tools.roughing_top]: a job file's larger tool becomes its roughing tool and the job's
    roughing tool its bottom tool, which plans the same two programs (tests/test_two_stage.py)."""
    text = small_job_text() + ("\n[tools.roughing_top]\nkind = \"flat\"\ndiameter_mm = 9.5\nflutes = 4\n"
                               "tool_number = 7\n")
    job = parse_job(text, "top.toml")
    assert not any(f.section == "tools.roughing_top" for fields in wb.schema.FIELDS.values() for f in fields)
    again = job_from_dict(json.loads(json.dumps(wb.schema.job_data(wb.schema.values_from_job(job)))), "top.toml")
    assert again.tools.roughing == job.tools.roughing_top and again.tools.bottom == job.tools.roughing
    assert again.tools.roughing_top is None


def test_tool_switch_off_drops_the_tool_section(wb):
    values = wb.schema.values_from_job(load_job(REFERENCE_JOB))
    values["job"]["UseRoughingTool"] = False
    job = job_from_dict(wb.schema.job_data(values), "x")
    assert job.tools.roughing is None and job.tools.finishing is not None


# --- validation (the task panel's checks) -------------------------------------------------------------


def _small_values(wb, **job_changes):
    values = wb.schema.values_from_job(parse_job(small_job_text(), "small.toml"))
    values["job"].update(job_changes)
    return values


def test_valid_job_has_no_messages_and_the_recommendations(wb):
    result = wb.validation.validate(_small_values(wb))
    assert result.ok and result.messages == {}
    job, rec = result.job, result.recommendations
    g = job.gear
    book = Textbook(g.teeth, g.module_mm, g.pressure_angle_deg, g.profile_shift_coefficient, g.addendum_coefficient,
                    g.dedendum_coefficient, g.rack_tip_radius_mm, g.thickness_allowance_fraction,
                    g.thickness_allowance_mm)
    # Independent of the code under test: root arc 2 v r_f with v = d_1 / r, flute length = blank - root.
    assert rec.finishing_max_flat_width_mm == pytest.approx(2 * book.corner_offset / book.r * book.rf, abs=1e-9)
    assert rec.required_flute_length_mm == pytest.approx(book.ra + job.stock.radial_allowance_mm - book.rf)
    # finishing by generation (the job's strategy) never plunges: roughing may leave one pass's slot, 0.5 x D
    assert job.finishing.strategy == "generating"
    assert rec.plunge_allowance_mm == pytest.approx(0.5 * job.tools.finishing.diameter_mm)
    notes = wb.validation.recommendation_notes(rec)  # without FreeCAD's unit schema: mm to 0.1 um
    for prop, limit in (("RoughingToolDiameter", rec.roughing_max_diameter_mm),
                        ("FinishingToolDiameter", rec.finishing_max_flat_width_mm)):
        shown = re.search(r"at most (\d+\.\d{1,4}) mm", notes[prop])
        assert shown is not None and abs(float(shown.group(1)) - limit) <= 0.00005, notes[prop]


def _cli_message(text: str) -> str:
    """The message `spur-cad run` shows for a job (checked the CLI's way: parse, then plan)."""
    from spur_cad.pipeline import plan_cam

    try:
        plan_cam(parse_job(text, "small.toml"))
    except SpurCadError as exc:
        return str(exc)
    raise AssertionError("the job is valid")


@pytest.mark.parametrize("changes, group, old, new", [
    ({"FinishingToolDiameter": 9.0}, "Finishing tool", "diameter_mm = 1.5", "diameter_mm = 9.0"),
    ({"RoughingToolDiameter": -1.0}, "Roughing tool", "diameter_mm = 2.0", "diameter_mm = -1.0"),
    # 4 mm: above the roughing limit (3.19 mm since generating lets roughing leave 0.5 D above the root; 3 mm fits)
    ({"RoughingToolDiameter": 4.0}, "Roughing tool", "diameter_mm = 2.0", "diameter_mm = 4.0"),
    ({"TargetScallop": 0.5}, "Finishing strategy", "target_scallop_mm = 0.05", "target_scallop_mm = 0.5"),
])
def test_invalid_values_give_the_command_lines_message_in_their_group(wb, changes, group, old, new):
    result = wb.validation.validate(_small_values(wb, **changes), "small.toml")
    assert not result.ok
    cli = _cli_message(small_job_text().replace(old, new))
    cli = cli.split(": ", 1)[1] if cli.startswith("small.toml:") else cli
    assert result.messages == {group: cli}


def test_gear_errors_are_filed_under_gear(wb):
    values = _small_values(wb)
    values["gear"]["Teeth"] = 3
    result = wb.validation.validate(values, "doc")
    assert list(result.messages) == ["Gear"]
    assert result.messages["Gear"] == "[gear] teeth must be in 5..1000, got 3"


@pytest.mark.parametrize("strategy", ["generating", "perimeter"])
@pytest.mark.parametrize("name", sweep(sorted(GEAR_CASES), fast=["pa25_sharp_rack_z17", "undercut_z8"]))
def test_suggested_tools_pass_the_tool_limits(wb, name, strategy):
    z, m, pa, x, rho, frac, mm = GEAR_CASES[name]
    values = wb.schema.default_values()
    values["gear"].update(Teeth=z, Module=m, PressureAngle=pa, ProfileShift=x, RackTipRadius=rho,
                          ThicknessAllowancePercent=frac * 100, ThicknessAllowance=mm, FaceWidth=10.0)
    values["job"]["FinishingStrategy"] = strategy
    suggested = wb.validation.suggest_tools(values)
    if strategy == "generating" and rho == 0.0:
        # a sharp rack cannot be played by a tool with a corner: nothing to suggest, and the check says why
        assert suggested == {}
        values["job"].update(UseFinishingTool=True, FinishingToolKind="bull_nose", FinishingToolDiameter=2.0,
                             FinishingCornerRadius=0.2)
        message = wb.validation.validate(values).messages["Finishing tool"]
        assert "larger than the rack tip radius rho = 0 mm" in message
        return
    values["job"].update(suggested)
    job = job_from_dict(wb.schema.job_data(values), name)
    assert job.tools.finishing is not None and job.tools.finishing.kind == "bull_nose"
    blank = job.stock.blank_radius_mm(job.gear)
    rec = recommend_tools(job.gear, blank, job.machine.clearance_mm, job.tools.finishing)
    # the tool that reaches the bottom of the spaces: the bottom tool of two-stage roughing, else the roughing tool
    deepest = job.tools.bottom if job.tools.bottom is not None else job.tools.roughing
    check_tools(job.gear, rec, deepest, job.tools.finishing)
    if job.tools.bottom is not None:  # the upper levels' tool: a larger flat end mill
        assert job.tools.roughing.kind == "flat" and job.tools.roughing.diameter_mm > deepest.diameter_mm
    assert job.finishing.strategy == strategy  # the suggested tool must fit the strategy, flanks included
    plan_finishing(job.gear, job.tools.finishing, job.machine, dataclasses.replace(job.finishing, step_over_mm=10.0),
                   blank)
    if deepest is not None:
        levels = roughing_levels(job.gear, deepest, job.roughing, blank)
        check_roughing_reach(deepest, levels.lowest_height_mm - job.gear.root_radius_mm, rec)


# --- toolpath display in the part frame ---------------------------------------------------------------


def _machine_pose(p_y: float, p_z: float, a_deg: float) -> tuple[float, float]:
    """Where a point fixed to the part at (p_y, p_z) is when A is commanded (docs/architecture.md)."""
    a = math.radians(a_deg)
    return p_y * math.cos(a) - p_z * math.sin(a), p_y * math.sin(a) + p_z * math.cos(a)


def test_display_turns_each_pose_back_by_a(wb):
    rng = np.random.default_rng(7)
    part = rng.uniform(-30, 30, size=(50, 2))
    angles = rng.uniform(-720, 720, size=50)
    for (py, pz), a in zip(part, angles):
        builder = ToolpathBuilder(Operation.FINISHING, 1, 1000.0)
        y, z = _machine_pose(py, pz, a)
        builder.move(MoveKind.LINEAR, 1.0, y, z, a, 100.0)
        shown = wb.display.display_path(builder.build())
        assert np.allclose(shown.points[-1], [1.0, py, pz], atol=1e-9)


def test_index_move_is_drawn_as_an_arc_around_the_axis(wb):
    """Turning A by 90 deg with the tool held at radius 40 draws a quarter circle of radius 40 in the part."""
    builder = ToolpathBuilder(Operation.ROUGHING, 1, 1000.0)
    builder.move(MoveKind.RAPID, 0.0, 0.0, 40.0, 0.0)
    builder.move(MoveKind.RAPID, 0.0, 0.0, 40.0, 90.0)
    shown = wb.display.display_path(builder.build())
    radii = np.hypot(shown.points[:, 1], shown.points[:, 2])
    assert np.allclose(radii, 40.0)
    assert len(shown.points) >= 1 + 90 / wb.display.MAX_A_STEP_DEG
    end_angle = math.degrees(math.atan2(shown.points[-1, 1], shown.points[-1, 2]))
    assert end_angle == pytest.approx(90.0)  # the part point now under the tool was 90 deg toward +Y


def test_a_3_axis_program_is_drawn_lying_flat_with_its_arcs_as_arcs(wb):
    """Gear axis = machine Z (Z0 the top face, drawn at the part's x = b), machine X, Y = the part's y, z: a
    clockwise half circle of radius 30 about the axis at Z -4 stays on the circle at x = b - 4, from machine +Y
    over +X to -Y (the part's +z, +y, -z)."""
    face_width = 20.0
    builder = ToolpathBuilder(Operation.FINISHING, 1, 1000.0)
    builder.move(MoveKind.RAPID, 0.0, 30.0, 5.0, 0.0)
    builder.move(MoveKind.LINEAR, 0.0, 30.0, -4.0, 0.0, 100.0)
    builder.arc(True, 0.0, -30.0, -4.0, 0.0, 0.0, 500.0)
    shown = wb.display.display_flat_path(builder.build(), face_width)
    on_arc = shown.points[3:]
    assert np.allclose(np.hypot(on_arc[:, 1], on_arc[:, 2]), 30.0) and np.allclose(on_arc[:, 0], face_width - 4.0)
    assert len(on_arc) >= 180 / wb.display.MAX_ARC_STEP_DEG
    assert np.allclose(shown.points[0], [face_width + 5.0, 0.0, 30.0])  # the rapid's start: above the top face
    assert on_arc[:, 1].min() > -1e-9 and on_arc[:, 1].max() == pytest.approx(30.0)  # clockwise: through +X
    assert np.allclose(on_arc[-1], [face_width - 4.0, 0.0, -30.0])
    assert list(shown.rapid[:2]) == [True, True] and not shown.rapid[2:].any()


def test_large_programs_show_whole_stations_first_and_last(wb):
    builder = ToolpathBuilder(Operation.FINISHING, 2, 1000.0)
    for station in range(40):
        for i in range(1000):
            builder.move(MoveKind.LINEAR, station * 0.1, float(i), 30.0, 0.0, 100.0, station=station)
    path = builder.build()
    moves = wb.display.shown_moves(path, limit=5000)
    stations = np.unique(path.station[moves])
    assert len(moves) <= 5000 and len(stations) == 5
    assert stations[0] == 0 and stations[-1] == 39
    assert all(np.count_nonzero(path.station[moves] == s) == 1000 for s in stations)


def test_polylines_split_rapids_from_feeds(wb):
    builder = ToolpathBuilder(Operation.ROUGHING, 1, 1000.0)
    builder.move(MoveKind.RAPID, 0.0, 0.0, 50.0, 0.0)
    builder.move(MoveKind.LINEAR, 0.0, 0.0, 45.0, 0.0, 100.0)
    builder.move(MoveKind.LINEAR, 10.0, 0.0, 45.0, 0.0, 100.0)
    builder.move(MoveKind.RAPID, 10.0, 0.0, 50.0, 0.0)
    runs = wb.display.polylines(wb.display.display_path(builder.build()))
    assert [rapid for rapid, _ in runs] == [False, True]
    assert np.allclose(runs[0][1], [[0, 0, 50], [0, 0, 45], [10, 0, 45]])
    text = wb.display.gcode_text(wb.display.display_path(builder.build()))
    assert text.splitlines()[2] == "G1 X0.0000 Y0.0000 Z45.0000"


# --- simulation colours -----------------------------------------------------------------------------


def test_deviation_colours(wb):
    colours = wb.colours.deviation_colours(np.array([-1.0, -0.05, 0.0, 0.05, 1.0]), 0.1)
    assert np.allclose(colours[0], [0, 0, 1]) and np.allclose(colours[-1], [1, 0, 0])
    assert np.allclose(colours[2], [0, 1, 0])
    assert np.allclose(colours[1], [0, 0.5, 0.5]) and np.allclose(colours[3], [0.5, 0.5, 0])


def test_simulation_guard_names_the_missing_simulator(wb, monkeypatch):
    monkeypatch.setitem(sys.modules, "spur_cad.sim", None)  # as if spur_cad had no simulator
    with pytest.raises(wb.simulation.SimulationUnavailable, match="^simulation not available"):
        wb.simulation.simulator()


# --- environment activation (the workbench's Init.py) ----------------------------------------------------


def test_activate_puts_recorded_folders_first_and_reads_pth(wb, tmp_path, monkeypatch):
    monkeypatch.setattr(sys, "path", list(sys.path))
    site_dir, extra = tmp_path / "site", tmp_path / "extra"
    site_dir.mkdir()
    extra.mkdir()
    (site_dir / "extra.pth").write_text(str(extra) + "\n")
    record = {"site_packages": [str(site_dir)], "python_version": f"{sys.version_info[0]}.{sys.version_info[1]}"}
    (tmp_path / wb.environment.RECORD_NAME).write_text(json.dumps(record))
    assert wb.environment.activate(tmp_path) == []
    assert sys.path[:2] == [str(site_dir), str(extra)]


def test_activate_reports_problems(wb, tmp_path, monkeypatch):
    monkeypatch.setattr(sys, "path", list(sys.path))
    record = {"site_packages": [str(tmp_path / "gone")], "python_version": "2.7"}
    (tmp_path / wb.environment.RECORD_NAME).write_text(json.dumps(record))
    problems = wb.environment.activate(tmp_path)
    assert any("Python 2.7" in p for p in problems)
    assert any("gone does not exist" in p for p in problems)
    assert wb.environment.activate(tmp_path / "nothing_installed") == []


def test_activate_lets_preloaded_packages_find_the_environments_modules(wb, tmp_path, monkeypatch):
    """Like Debian's mpl_toolkits (a regular package imported by a .pth file before FreeCAD starts)."""
    monkeypatch.setattr(sys, "path", list(sys.path))
    system, env = tmp_path / "system", tmp_path / "env"
    (system / "wb_test_toolkit").mkdir(parents=True)
    (system / "wb_test_toolkit" / "__init__.py").write_text("")
    (env / "wb_test_toolkit").mkdir(parents=True)
    (env / "wb_test_toolkit" / "plot3d.py").write_text("NAME = 'from env'\n")
    monkeypatch.syspath_prepend(str(system))
    import wb_test_toolkit  # noqa: F401

    monkeypatch.setitem(sys.modules, "wb_test_toolkit", sys.modules["wb_test_toolkit"])
    (tmp_path / wb.environment.RECORD_NAME).write_text(json.dumps({"site_packages": [str(env)]}))
    wb.environment.activate(tmp_path)
    from wb_test_toolkit import plot3d

    assert plot3d.NAME == "from env"
    monkeypatch.delitem(sys.modules, "wb_test_toolkit.plot3d")


@pytest.mark.slow  # each hand plans a helical job (15 s); the helical toolpath display test stays in the fast tier
@pytest.mark.parametrize("hand", ["right", "left"])
def test_suggested_tools_for_a_helical_gear_plan_both_operations(wb, hand):
    """Helical: the finishing corner is the rack tip radius and the roughing tool passes the reach rule with the
    width it sweeps along the lead; the whole plan builds."""
    from spur_cad.pipeline import plan_cam

    values = wb.schema.default_values()
    values["gear"].update(Teeth=23, Module=4.0, RackTipRadius=0.8, FaceWidth=20.0, HelixAngle=15.0, Hand=hand)
    values["job"]["FinishingStrategy"] = "generating"
    suggested = wb.validation.suggest_tools(values)
    values["job"].update(suggested)
    job = job_from_dict(wb.schema.job_data(values), "helical")
    assert job.gear.is_helical and job.tools.finishing.corner_radius_mm == 0.8
    assert job.tools.roughing is not None
    plan = plan_cam(job)
    assert plan.roughing.toolpath.inverse_time.any() and not plan.finishing.toolpath.inverse_time.any()


def test_new_jobs_number_the_tools_t1_t2_and_a_shared_number_is_an_error_at_the_field(wb):
    values = wb.schema.default_values()
    assert (values["job"]["RoughingToolNumber"], values["job"]["FinishingToolNumber"]) == (1, 2)
    values["job"].update(wb.validation.suggest_tools(values))
    assert wb.validation.validate(values).ok
    values["job"]["FinishingToolNumber"] = 1
    result = wb.validation.validate(values)
    assert not result.ok
    assert list(result.messages) == ["Finishing tool"]
    assert "tool_number = 1 is also the roughing tool's number" in result.messages["Finishing tool"]


def _cut_points_inside_gear_mm(wb, path, spec, turn_back: bool = True) -> float:
    """Deepest a drawn cutting segment's tool-tip centre goes into the gear outline, sampled along each straight
    segment within the face width, each point turned back by the textbook helix at its X (0: never inside)."""
    import shapely
    from shapely.geometry import Polygon

    from spur_cad.geometry import gear_outline
    from spur_cad.sim import subset

    gear = Polygon(gear_outline(spec, 1e-4))
    drawn = wb.display.display_path(subset(path, path.space == 0))
    points = drawn.points if turn_back else np.column_stack([path.x, path.y, path.z])[path.space == 0]
    rapid = drawn.rapid if turn_back else path.kind[path.space == 0] == MoveKind.RAPID
    tan_over_r = math.tan(math.radians(spec.helix_angle_deg)) / spec.reference_radius_mm
    sign = 1.0 if spec.hand == "right" else -1.0
    deepest = 0.0
    for i in np.nonzero(~rapid[1:])[0] + 1:
        for t in np.linspace(0.0, 1.0, 41):
            x, y, z = points[i - 1] + t * (points[i] - points[i - 1])
            if not 0.0 <= x <= spec.face_width_mm:
                continue
            turn = -sign * x * tan_over_r
            q = shapely.Point(y * math.cos(turn) - z * math.sin(turn), y * math.sin(turn) + z * math.cos(turn))
            if gear.contains(q):
                deepest = max(deepest, gear.exterior.distance(q))
    return deepest


@pytest.mark.slow  # plans the helical example (7 s)
def test_helical_toolpaths_are_drawn_in_the_tooth_spaces_of_the_helical_gear(wb):
    """Acceptance (workbench): the drawn roughing and finishing paths line up with the helical solid: every
    tool-tip centre of a cutting segment, turned back by the helix at its X, lies outside the gear (in a space
    or above the tip). The machine poses drawn without turning back by A land inside the teeth."""
    from spur_cad.pipeline import plan_cam

    job = load_job(ROOT / "resources" / "examples" / "helical_gear.toml")
    plan = plan_cam(job)
    for path in (plan.roughing.toolpath, plan.finishing.toolpath):
        assert _cut_points_inside_gear_mm(wb, path, job.gear) <= 1e-6
    assert _cut_points_inside_gear_mm(wb, plan.finishing.toolpath, job.gear, turn_back=False) > 1.0
