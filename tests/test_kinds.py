"""Gear kinds and machine set-ups as types (issue 45): the flags are read only where the kinds and set-ups are
defined, and the kinds' and set-ups' declared capabilities agree with independent facts."""

from __future__ import annotations

import ast
import dataclasses
import math
from pathlib import Path

import pytest

from spur_cad.cam.machine import Machine
from spur_cad.cam.setups import LYING_FLAT, ROTARY_TABLE, SETUPS, MachineSetup, setup_for_axes
from spur_cad.geometry.internal import InternalGearSpec
from spur_cad.geometry.kinds import EXTERNAL_HELICAL, EXTERNAL_SPUR, INTERNAL_SPUR, KINDS, GearKind
from spur_cad.geometry.spec import GearSpec

RING = dict(teeth=60, module_mm=2.0, addendum_coefficient=0.9, rack_tip_radius_mm=0.4, shaper_cutter_teeth=20,
            rim_outer_diameter_mm=140.0, face_width_mm=10.0)  # tests/test_internal_gear.py's ring
ROOT = Path(__file__).resolve().parents[1]
KIND_MODULES = frozenset({"spur_cad/geometry/kinds.py", "spur_cad/geometry/spec.py", "spur_cad/geometry/internal.py"})
SETUP_MODULES = frozenset({"spur_cad/cam/setups.py", "spur_cad/cam/machine.py"})
# The flags, under their old names (GearSpec.is_helical) and as the kind's and set-up's own booleans: reading one
# outside the defining modules is a branch on the kind or set-up that should be a question to the object.
KIND_FLAGS = frozenset({"is_helical", "is_internal", "helical", "prismatic", "teeth_inward"})
SETUP_FLAGS = frozenset({"rotary_axis", "cuts_helical", "cuts_teeth_inward"})
# A finishing strategy declares `helical` too (what it can cut): read where its capabilities are defined.
STRATEGY_CAPABILITY_MODULES = frozenset({"spur_cad/cam/strategies/__init__.py", "spur_cad/cam/strategies/base.py"})
ORDERING = (ast.Eq, ast.NotEq, ast.Lt, ast.LtE, ast.Gt, ast.GtE)


def _mentions(node: ast.AST, names: set[str]) -> bool:
    """Whether an expression reads a name or attribute in `names`, or indexes by such a string ("MachineAxes")."""
    for sub in ast.walk(node):
        if isinstance(sub, ast.Name) and sub.id in names or isinstance(sub, ast.Attribute) and sub.attr in names:
            return True
        if isinstance(sub, ast.Constant) and isinstance(sub.value, str) and sub.value in names:
            return True
    return False


def _is_zero(node: ast.AST) -> bool:
    return isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) and node.value == 0


def flag_reads(source: str) -> list[tuple[int, str, str]]:
    """(line, family, what) of every flag read in a module's source: attribute reads of is_helical / is_internal,
    a helix angle compared with 0 or taken as a truth value (family "kind"); a comparison of `axes` or of the
    workbench's MachineAxes (family "setup")."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Attribute) and node.attr in KIND_FLAGS and isinstance(node.ctx, ast.Load):
            found.append((node.lineno, "kind", node.attr))
        elif isinstance(node, ast.Attribute) and node.attr in SETUP_FLAGS and isinstance(node.ctx, ast.Load):
            found.append((node.lineno, "setup", node.attr))
        elif isinstance(node, ast.Compare) and all(isinstance(op, ORDERING) for op in node.ops):
            operands = [node.left, *node.comparators]
            if any(_mentions(o, {"helix_angle_deg"}) for o in operands) and any(_is_zero(o) for o in operands):
                found.append((node.lineno, "kind", "helix_angle_deg compared with 0"))
            if any(_mentions(o, {"axes", "MachineAxes"}) for o in operands):
                found.append((node.lineno, "setup", "axes compared"))
        elif isinstance(node, (ast.If, ast.IfExp, ast.While)) and _mentions_directly(node.test, "helix_angle_deg"):
            found.append((node.lineno, "kind", "helix_angle_deg as a truth value"))
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "bool"
              and node.args and _mentions_directly(node.args[0], "helix_angle_deg")):
            found.append((node.lineno, "kind", "bool(helix_angle_deg)"))
    return found


def _mentions_directly(node: ast.AST, name: str) -> bool:
    """The expression is (a negation of) the name or attribute itself."""
    while isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not):
        node = node.operand
    return isinstance(node, ast.Name) and node.id == name or isinstance(node, ast.Attribute) and node.attr == name


def _package_sources():
    for folder in ("spur_cad", "workbench"):
        for path in sorted((ROOT / folder).rglob("*.py")):
            yield path.relative_to(ROOT).as_posix(), path.read_text(encoding="utf-8")


def test_flags_are_read_only_where_kinds_and_setups_are_defined():
    """Acceptance of issue 45: code asks spec.kind and machine.setup; the flags stay in at most three modules each."""
    assert len(KIND_MODULES) <= 3 and len(SETUP_MODULES) <= 3
    stray = [f"{name}:{line}: {what}" for name, source in _package_sources()
             for line, family, what in flag_reads(source)
             if name not in (KIND_MODULES if family == "kind" else SETUP_MODULES)
             and not (what == "helical" and name in STRATEGY_CAPABILITY_MODULES)]
    assert not stray, "flags read outside the kind and set-up modules:\n" + "\n".join(stray)


@pytest.mark.parametrize("snippet, expected", [
    ("if spec.is_helical:\n    pass\n", [(1, "kind", "is_helical")]),
    ("x = a if job.gear.is_internal else b\n", [(1, "kind", "is_internal")]),
    ("if spec.helix_angle_deg != 0.0:\n    pass\n", [(1, "kind", "helix_angle_deg compared with 0")]),
    ("if 0 < spec.helix_angle_deg:\n    pass\n", [(1, "kind", "helix_angle_deg compared with 0")]),
    ("if not spec.helix_angle_deg:\n    pass\n", [(1, "kind", "helix_angle_deg as a truth value")]),
    ("flat = job.machine.axes == 3\n", [(1, "setup", "axes compared")]),
    ("flat = int(values['job']['MachineAxes']) != 4\n", [(1, "setup", "axes compared")]),
    ("ok = letter in self.axes\n", []),  # a string of axis letters (verify/reader.py), not the set-up
    ("if spec.kind.helical:\n    pass\n", [(1, "kind", "helical")]),
    ("k = spec.kind\nsign = -1 if k.teeth_inward else 1\n", [(2, "kind", "teeth_inward")]),
    ("flat = not job.machine.setup.rotary_axis\n", [(1, "setup", "rotary_axis")]),
    ("turn = spec.section_turn_rad(1.0)\nok = machine.setup.cuts(spec.kind)\n", []),
])
def test_flag_reads_finds_each_form(snippet, expected):
    """The checker itself: each form of a flag read is found, the kind's and set-up's questions are not."""
    assert flag_reads(snippet) == expected


# --- the kinds' capabilities against independent facts ------------------------------------------------------
def test_each_spec_names_its_kind():
    assert GearSpec(teeth=20, module_mm=2.0).kind is EXTERNAL_SPUR
    assert GearSpec(teeth=20, module_mm=2.0, helix_angle_deg=15.0).kind is EXTERNAL_HELICAL
    ring = InternalGearSpec(**RING)
    assert ring.kind is INTERNAL_SPUR
    assert KINDS == {k.name: k for k in (EXTERNAL_SPUR, EXTERNAL_HELICAL, INTERNAL_SPUR)}


@pytest.mark.parametrize("hand, sign", [("right", 1), ("left", -1)])
def test_helical_section_turns_by_x_tan_beta_over_r(hand, sign):
    """A helix on the reference cylinder r = z m_n / (2 cos beta) advances r d(theta) = dX tan(beta) (unrolled, the
    helix is a line at beta to the axis); a right hand turns positive A with +X (docs/architecture.md, Frames).
    The lead written out as ISO 21771 gives it: p_z = pi z m_n / sin(beta)."""
    z, m_n, beta_deg = 23, 1.5, 17.0
    spec = GearSpec(teeth=z, module_mm=m_n, helix_angle_deg=beta_deg, hand=hand, face_width_mm=20.0)
    beta = math.radians(beta_deg)
    r = z * m_n / (2.0 * math.cos(beta))
    for x in (0.0, 3.0, 12.5, -4.0):
        assert spec.kind.section_turn_rad(spec, x) == pytest.approx(sign * x * math.tan(beta) / r, rel=1e-12, abs=0)
        assert spec.section_turn_rad(x) == spec.kind.section_turn_rad(spec, x)
    lead = math.pi * z * m_n / math.sin(beta)
    assert spec.kind.lead_mm(spec) == pytest.approx(lead, rel=1e-12)
    assert abs(spec.section_turn_rad(lead)) == pytest.approx(2.0 * math.pi, rel=1e-12)  # one lead: one turn


def test_prismatic_kinds_keep_their_section():
    spur = GearSpec(teeth=17, module_mm=3.0, face_width_mm=30.0)
    ring = InternalGearSpec(**RING)
    for spec in (spur, ring):
        assert spec.kind.prismatic and spec.kind.solid == "extrude" and spec.kind.measured_in == "transverse"
        assert all(spec.section_turn_rad(x) == 0.0 for x in (0.0, 7.0, spec.face_width_mm))
        assert spec.lead_mm == math.inf and spec.kind.cut_straight
    assert EXTERNAL_HELICAL.solid == "sweep" and EXTERNAL_HELICAL.measured_in == "normal"
    assert not EXTERNAL_HELICAL.cut_straight


def test_roll_sign_follows_the_teeth():
    """A ring's involute runs with negative roll parameters (geometry/internal.py: u = -t, root to tip |u|
    decreasing); an external gear's with positive ones."""
    ring = InternalGearSpec(**RING)
    spur = GearSpec(teeth=17, module_mm=3.0)
    for spec in (ring, spur):
        involute = next(s for s in spec.tooth_space_profile().segments if s.label == "involute")
        assert math.copysign(1.0, involute.end) == spec.kind.roll_sign
        assert math.copysign(1.0, involute.start) == spec.kind.roll_sign or involute.start == 0.0


class _Strategy:
    def __init__(self, helical: bool) -> None:
        self.helical = helical


def test_helical_kind_needs_a_helical_strategy():
    assert EXTERNAL_HELICAL.accepts_strategy(_Strategy(True))
    assert not EXTERNAL_HELICAL.accepts_strategy(_Strategy(False))
    assert all(kind.accepts_strategy(_Strategy(False)) for kind in (EXTERNAL_SPUR, INTERNAL_SPUR))


@pytest.mark.parametrize("changes", [{"solid": "loft"}, {"measured_in": "axial"}, {"solid": "sweep"},
                                     {"measured_in": "normal"}])
def test_a_kind_with_inconsistent_capabilities_is_refused(changes):
    fields = dict(name="x", prismatic=True, teeth_inward=False, solid="extrude", measured_in="transverse") | changes
    with pytest.raises(ValueError, match="gear kind 'x'"):
        GearKind(**fields)


# --- the set-ups ------------------------------------------------------------------------------------------------
def test_machine_axes_choose_the_setup():
    assert Machine().setup is ROTARY_TABLE and Machine(axes=3).setup is LYING_FLAT
    assert setup_for_axes(4) is ROTARY_TABLE and SETUPS == {4: ROTARY_TABLE, 3: LYING_FLAT}
    assert ROTARY_TABLE.rotary_axis and not LYING_FLAT.rotary_axis
    assert LYING_FLAT.reads_section("three_axis") and not ROTARY_TABLE.reads_section("three_axis")


@pytest.mark.parametrize("setup, kind, cuts", [
    (ROTARY_TABLE, EXTERNAL_SPUR, True), (ROTARY_TABLE, EXTERNAL_HELICAL, True), (ROTARY_TABLE, INTERNAL_SPUR, False),
    (LYING_FLAT, EXTERNAL_SPUR, True), (LYING_FLAT, EXTERNAL_HELICAL, False), (LYING_FLAT, INTERNAL_SPUR, True),
])
def test_which_setup_cuts_which_kind(setup, kind, cuts):
    """The rotary table's tool cannot reach inside a ring along the axis; lying flat, the end mill's side cuts
    straight teeth only (docs/cam.md)."""
    assert setup.cuts(kind) is cuts


def test_lying_flat_cuts_with_flat_end_mills_only():
    assert LYING_FLAT.accepts_tool_kind("flat") and not LYING_FLAT.accepts_tool_kind("ball")
    assert all(ROTARY_TABLE.accepts_tool_kind(kind) for kind in ("flat", "bull_nose", "ball"))


def test_a_setup_with_inconsistent_capabilities_is_refused():
    with pytest.raises(ValueError, match="rotary axis"):
        MachineSetup("x", axes=3, rotary_axis=True, reaches=frozenset({"helical teeth"}),
                     follows_modifications=True, tool_kinds=(), finishing_needs_roughing=False, sections=(),
                     z_origin="the rotary axis")


# --- the set-ups' rows of the report's set-up sheet -----------------------------------------------------------
def _sheet(setup, gear, **changes):
    """The set-up sheet's rows as the report shows them, {label: (value, unit)}, for set-up facts of a z23 blank."""
    from spur_cad.report.sheet import sheet_row
    from spur_cad.result import SetupFacts

    facts = SetupFacts(**(dict(machine_name="mill", blank_diameter_mm=101.5, blank_x_min_mm=-2.0, blank_x_max_mm=22.0,
                               stub_diameter_mm=0.0, stub_length_mm=0.0, work_offset="G54", rotary_sign=1,
                               coolant=True, clearance_mm=5.0, z_min_mm=None, z_max_mm=None, finish_stock_mm=0.2,
                               flank_allowance_mm=0.3, roughing_step_down_mm=None, roughing_step_over_mm=None,
                               machine_setup=setup) | changes))
    rows = [sheet_row(row) for row in setup.setup_sheet_rows(facts, gear)]
    assert len({row.label for row in rows}) == len(rows)
    return {row.label: (row.value, row.unit) for row in rows}


@pytest.mark.parametrize("setup", [ROTARY_TABLE, LYING_FLAT])
def test_each_setup_sheet_names_the_machine_blank_work_offset_and_tooth_space_0(setup):
    """Every set-up's sheet: the machine, the blank's diameter (3 decimals, mm), the work offset with Z = 0 where the
    set-up's programs have it (`z_origin`), and where tooth space 0 points: +Z about the rotary axis (the machine
    frame of docs/architecture.md), +Y lying flat (cam/three_axis.py's frame)."""
    sheet = _sheet(setup, GearSpec(teeth=23, module_mm=4.0, face_width_mm=20.0).facts())
    assert sheet["machine"] == ("mill", "")
    assert sheet["blank diameter"] == ("101.500", "mm")
    offset = sheet["work offset"][0]
    assert offset.startswith("G54: ") and f"Z = 0 on {setup.z_origin}" in offset
    space_0 = [value for label, (value, _) in sheet.items() if "tooth space 0" in f"{label} {value}"]
    assert len(space_0) == 1 and ("points to +Z" if setup.rotary_axis else "points to +Y") in space_0[0]


def test_the_rotary_table_sheet_gives_a_zero_by_the_pitch_angle_the_stub_and_the_blank_along_x():
    """A's zero: space k under the tool at A = -k 360/z (z = 23: 15.6522 deg to 4 decimals); the stub row only with a
    stub; the post's A sign said when it is reversed; the clearance for turning A."""
    gear = GearSpec(teeth=23, module_mm=4.0, face_width_mm=20.0).facts()
    sheet = _sheet(ROTARY_TABLE, gear)
    assert "A = -k x 15.6522°" in sheet["A zero"][0] and "opposite sign" not in sheet["A zero"][0]
    assert sheet["blank along X (front face of the gear at X = 0)"] == ("-2.000 to 22.000", "mm")
    assert sheet["clearance above the blank for moves that turn A"] == ("5.000", "mm")
    assert not [label for label in sheet if "stub" in label]
    stub = _sheet(ROTARY_TABLE, gear, stub_diameter_mm=30.0, stub_length_mm=25.0, rotary_sign=-1)
    assert stub["holding stub toward the chuck (+X)"] == ("D 30.000 x 25.000", "mm")
    assert "(the post writes A with the opposite sign)" in stub["A zero"][0]


def test_the_lying_flat_sheet_gives_the_blank_thickness_and_no_rotary_axis():
    """Lying flat: the blank is faced to the face width; nothing turns A; a ring (root outside its tip) is clamped on
    its rim and centred on the rim, an external gear on its bore."""
    external = _sheet(LYING_FLAT, GearSpec(teeth=23, module_mm=4.0, face_width_mm=20.0).facts())
    assert external["blank thickness (faced to the face width)"] == ("20.000", "mm")
    assert not [label for label, (value, _) in external.items() if "A " in f"{label} " or "rotary" in value]
    assert "on its bore" in external["gear axis"][0] and "the bore's centre" in external["work offset"][0]
    ring = _sheet(LYING_FLAT, InternalGearSpec(**RING).facts())
    assert ring["blank thickness (faced to the face width)"] == ("10.000", "mm")
    assert "on its rim" in ring["gear axis"][0] and "the rim's centre" in ring["work offset"][0]
    assert "blank diameter (the rim's outside, not cut)" in ring


def test_each_setup_names_the_tool_limits_that_apply_to_it():
    """The limits the report lists are fields of ToolRecommendations; lying flat the side of a flat end mill cuts,
    so no generating tool, corner radius or flat width is a limit there (the rotary table lists them)."""
    from spur_cad.cam.recommend import ToolRecommendations

    fields = {f.name for f in dataclasses.fields(ToolRecommendations)}
    generating = {"finishing_generating_max_diameter_mm", "finishing_max_corner_radius_mm",
                  "finishing_max_flat_width_mm"}
    for setup in (ROTARY_TABLE, LYING_FLAT):
        names = [name for name, _ in setup.tool_limit_labels]
        assert names and set(names) <= fields and len(set(names)) == len(names)
        assert bool(generating & set(names)) is setup.rotary_axis


def test_each_setup_words_roughing_by_levels_with_the_places_the_report_fills():
    """The set-up's phrases for roughing by levels name the levels and only the places the report fills
    (html.program_notes: levels, lowest_above_root_mm, lowest_z_mm, tips); on the rotary table the levels are
    counted per space down to a height above the root circle, lying flat down to a Z (from the top face)."""
    import string

    filled = {"levels", "lowest_above_root_mm", "lowest_z_mm", "tips"}
    for setup in (ROTARY_TABLE, LYING_FLAT):
        for phrase in (setup.levels_roughing, setup.levels_roughing_note):
            places = {name for _, name, _, _ in string.Formatter().parse(phrase) if name is not None}
            assert "levels" in places and places <= filled, (setup.name, phrase)
    assert "{lowest_above_root_mm} mm above the root circle{tips}" in ROTARY_TABLE.levels_roughing_note
    assert "down to Z {lowest_z_mm} mm" in LYING_FLAT.levels_roughing_note
