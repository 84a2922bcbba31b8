"""Finishing by generation (docs/method.md), accepted by checks that repeat none of its mathematics:
the independent 2-D silhouette checker (tests/silhouette.py) against the designed gear, the IR's
own arrays, LinuxCNC's interpreter on the posted program, planted faults that must be caught,
and the pass counts docs/method.md reports from an independent check of the reference gear."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
import shapely
from shapely.geometry import Polygon

from spur_cad.cam.finishing import plan_finishing
from spur_cad.cam.ir import Feature, MoveKind
from spur_cad.cam.machine import Machine
from spur_cad.cam.strategies import FinishingParams, get_strategy, strategy_names
from spur_cad.cam.strategies.generating import MOVES_PER_PASS, GeneratingParams, generating_tool_limits
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.geometry import GearSpec, gear_outline
from spur_cad.post import PostSettings, ProgramInfo, post_program
from tests import silhouette
from tests.gcode_reader import inlined_lines
from tests.gears import spec_of
from tests.rs274_helper import canon_args, run_rs274
from tests.tiers import sweep

HALF_MICRON = 0.5e-3
TOOL_LENGTH = 30.0
MACHINE = Machine()


def _gear(name: str) -> GearSpec:
    extra = {
        # docs/method.md's other checked gears: a shifted 12-tooth gear and a 25 deg gear with negative shift.
        "shifted_z12_x04": (12, 3.0, 20.0, 0.4, 0.5, 0.03),
        "pa25_z31_negative_shift": (31, 2.0, 25.0, -0.2, 0.5, 0.02),
    }
    if name in extra:
        z, m, pa, x, rho, frac = extra[name]
        return GearSpec(teeth=z, module_mm=m, pressure_angle_deg=pa, profile_shift_coefficient=x,
                        rack_tip_radius_mm=rho, thickness_allowance_fraction=frac, face_width_mm=10.0)
    return spec_of(name)


# (gear, tool diameter, corner radius): the reference gear's D2 r0.5 (docs/method.md) and r_t = rho,
# the others with r_t = rho and r_t = 0.6 rho, diameters inside the gear's limits.
CASES = [
    ("reference_z23_m4", 2.0, 0.5),
    ("reference_z23_m4", 2.6, 0.8),
    ("undercut_z8", 1.45, 0.6),
    ("undercut_z8", 1.0, 0.36),
    ("many_teeth_z120", 0.77, 0.25),
    ("many_teeth_z120", 0.59, 0.15),
    ("shifted_z12_x04", 2.1, 0.5),
    ("shifted_z12_x04", 1.75, 0.3),
    ("pa25_z31_negative_shift", 1.13, 0.5),
    ("pa25_z31_negative_shift", 0.76, 0.3),
]


def _tool(diameter: float, corner: float) -> Tool:
    return Tool(diameter_mm=diameter, kind="bull_nose", corner_radius_mm=corner, flutes=2)


def _plan(spec: GearSpec, tool: Tool, scallop: float = 0.005, **keys):
    section = FinishingParams(strategy="generating", target_scallop_mm=scallop, **keys)
    return plan_finishing(spec, tool, MACHINE, section, spec.tip_radius_mm + 0.5)


def _safe_z(spec: GearSpec) -> float:
    return spec.tip_radius_mm + 0.5 + MACHINE.clearance_mm


_OUTLINES: dict[str, Polygon] = {}


def _design(name: str, spec: GearSpec) -> Polygon:
    if name not in _OUTLINES:
        _OUTLINES[name] = Polygon(gear_outline(spec, 1e-5))
    return _OUTLINES[name]


def _check(name, spec, tool, path, spaces, rows=None, labels=("root", "fillet", "involute", "tip")):
    """(deepest reach into the design, largest leftover, its label) of the design points of `spaces`
    (with the given segment labels) against the motion rows of `spaces` and their neighbours (a space's
    passes also finish the tip land of a neighbouring tooth)."""
    near = {(k + d) % spec.teeth for k in spaces for d in (-1, 0, 1)}
    mask = path.motion_mask & np.isin(path.space, sorted(near))
    if rows is not None:
        mask &= rows
    sils = silhouette.silhouettes_in_part_frame(path, tool.diameter_mm, tool.effective_corner_radius_mm, TOOL_LENGTH,
                                                mask=mask)
    penetration = silhouette.max_penetration_mm(_design(name, spec), sils)
    points, labels = silhouette.design_boundary(spec, spaces, labels)
    leftover = silhouette.leftover_mm(points, sils)
    worst = int(np.argmax(leftover))
    return penetration, float(leftover[worst]), str(labels[worst]), leftover, labels


# --------------------------------------------------------------------------- the acceptance check


@pytest.mark.parametrize("name, diameter, corner", sweep(CASES, fast=["reference_z23_m4", "undercut_z8"]))
def test_generating_never_gouges_and_leaves_at_most_the_target(name, diameter, corner):
    spec, tool = _gear(name), _tool(diameter, corner)
    scallop = 0.005
    path, _ = _plan(spec, tool, scallop)
    spaces = [0, 1, spec.teeth - 1]
    penetration, leftover, label, *_ = _check(name, spec, tool, path, spaces)
    assert penetration <= HALF_MICRON, penetration
    assert leftover <= scallop + HALF_MICRON, (leftover, label)


@pytest.mark.parametrize("end", ["rack", "raised"])
def test_reference_gear_at_one_micron(end):
    name = "reference_z23_m4"
    spec, tool = _gear(name), _tool(2.0, 0.5)
    path, _ = _plan(spec, tool, 0.001, flank_tool_end=end)
    penetration, leftover, label, *_ = _check(name, spec, tool, path, [0])
    assert penetration <= HALF_MICRON
    assert leftover <= 0.001 + HALF_MICRON, (leftover, label)


def test_raised_end_fits_a_tool_the_rack_end_cannot_take():
    """docs/method.md: a raised end lets a larger tool finish the reference gear's flanks."""
    name = "reference_z23_m4"
    spec = _gear(name)
    limits = generating_tool_limits(spec, 0.5, 0.005, spec.tip_radius_mm + 0.5)
    assert 3.8 <= limits.flank_mode_max_diameter_mm <= 4.0  # docs/method.md: 3.9 mm
    assert 4.8 <= limits.flank_mode_max_diameter_raised_mm <= 5.1  # docs/method.md: 4.9 mm
    big = _tool(4.4, 0.5)
    # One tool does both modes, and tip mode cannot take this flat (2 d_1 + 2 r_t = 2.84 mm) ...
    assert limits.tip_mode_max_diameter_mm < big.diameter_mm
    with pytest.raises(ToolError, match="largest diameter for tip mode"):  # the strategy's tool check refuses it
        get_strategy("generating").check_tool(spec, big)
    # ... but its flank passes with the raised end pass the exact gouge check (the rack end's do not).
    from spur_cad.cam.strategies.generating_geometry import (
        GOUGE_TOLERANCE_MM,
        design_points,
        flank_poses,
        flank_rolls,
        gouges,
    )

    rolls, _ = flank_rolls(spec, 0.005)
    assert gouges(design_points(spec), *flank_poses(spec, big, rolls, "rack"), big).max() > GOUGE_TOLERANCE_MM
    a, y, z = flank_poses(spec, big, rolls, "raised")
    assert gouges(design_points(spec), a, y, z, big).max() <= GOUGE_TOLERANCE_MM
    # ... and so does the independent checker.
    a_deg = np.degrees(np.concatenate([a, -a]))
    sils = silhouette.place_silhouettes(np.concatenate([y, -y]), np.concatenate([z, z]), a_deg, big.diameter_mm,
                                        0.5, TOOL_LENGTH)
    assert silhouette.max_penetration_mm(_design(name, spec), sils) <= HALF_MICRON
    points, _ = silhouette.design_boundary(spec, [0], labels=("involute",))
    assert silhouette.leftover_mm(points, sils).max() <= 0.005 + HALF_MICRON


def test_limits_are_sharp_for_the_rack_end():
    """Just below the largest flank-mode diameter the passes are clean; just above, the checker finds a gouge."""
    name = "reference_z23_m4"
    spec = _gear(name)
    limits = generating_tool_limits(spec, 0.5, 0.005, spec.tip_radius_mm + 0.5)
    from spur_cad.cam.strategies.generating import flank_poses, flank_rolls

    rolls, _ = flank_rolls(spec, 0.005)
    depths = {}
    for factor in (0.99, 1.02):
        tool = _tool(limits.flank_mode_max_diameter_mm * factor, 0.5)
        a, y, z = flank_poses(spec, tool, rolls, "rack")
        sils = silhouette.place_silhouettes(np.concatenate([y, -y]), np.concatenate([z, z]),
                                            np.degrees(np.concatenate([a, -a])), tool.diameter_mm, 0.5, TOOL_LENGTH)
        depths[factor] = silhouette.max_penetration_mm(_design(name, spec), sils)
    assert depths[0.99] <= HALF_MICRON < depths[1.02]


# --------------------------------------------------------------------------- the A rule, in the IR and in G-code


@pytest.mark.parametrize("name, diameter, corner", [CASES[0], CASES[2]])
def test_no_feed_move_turns_a_and_a_indexes_only_at_the_safe_height(name, diameter, corner):
    spec, tool = _gear(name), _tool(diameter, corner)
    path, _ = _plan(spec, tool)
    start = path.start_poses()
    turns = np.abs(path.a - start[:, 3]) > 1e-12
    assert not np.any(turns & (path.kind == MoveKind.LINEAR))
    assert not path.inverse_time.any()
    safe = _safe_z(spec)
    assert np.all(path.z[turns] >= safe - 1e-9) and np.all(start[turns, 2] >= safe - 1e-9)
    # Rapids only at the safe height.
    rapid = path.kind == MoveKind.RAPID
    assert np.all(path.z[rapid] >= safe - 1e-9) and np.all(start[rapid, 2] >= safe - 1e-9)
    # Every cut runs over the whole face width plus tool radius and clearance, along X only.
    cut = path.feature != Feature.NONE
    margin = tool.diameter_mm / 2 + MACHINE.clearance_mm
    assert np.allclose(np.minimum(path.x[cut], start[cut, 0]), -margin)
    assert np.allclose(np.maximum(path.x[cut], start[cut, 0]), spec.face_width_mm + margin)
    assert np.allclose(path.y[cut], start[cut, 1]) and np.allclose(path.z[cut], start[cut, 2])
    # Below the safe height the tool only moves beside the part (X outside the face width by D/2 + clearance)
    # or along a cut.
    low = (path.z < safe - 1e-9) | (start[:, 2] < safe - 1e-9)
    beside = (np.abs(path.x - start[:, 0]) < 1e-12) & ((path.x <= -margin + 1e-9)
                                                       | (path.x >= spec.face_width_mm + margin - 1e-9))
    assert np.all(~low | beside | cut)


def test_every_space_runs_the_same_passes_from_its_base_angle():
    spec, tool = _gear("reference_z23_m4"), _tool(2.0, 0.5)
    path, result = _plan(spec, tool)
    pitch = 360.0 / spec.teeth
    first = path.space == 0
    for k in range(spec.teeth):
        rows = path.space == k
        assert rows.sum() == first.sum()
        for column in ("kind", "x", "y", "z", "feed", "feature"):
            assert np.array_equal(getattr(path, column)[rows], getattr(path, column)[first], equal_nan=column == "feed")
        assert np.allclose(path.a[rows] + k * pitch, path.a[first], atol=1e-9)
    assert np.all(np.diff(path.space) >= 0)
    assert result.passes_per_space == len(result.passes) == np.sum(first & (path.feature != Feature.NONE))


def _canonical_poses(canon: list[str]) -> list[tuple[str, np.ndarray]]:
    return [(line.split("(")[0], np.array(canon_args(line)[:4])) for line in canon
            if line.startswith(("STRAIGHT_TRAVERSE", "STRAIGHT_FEED", "ARC_FEED"))]


@pytest.mark.linuxcnc
def test_rs274_program_turns_a_only_in_rapids_at_the_safe_height(tmp_path):
    spec, tool = _gear("reference_z23_m4"), _tool(2.0, 0.5)
    path, _ = _plan(spec, tool)
    safe = _safe_z(spec)
    info = ProgramInfo("spur_cad generating test", ("gear: reference",))
    canon_by_mode = {}
    for folded in (False, True):
        program = post_program(path, PostSettings(folded=folded), info)
        if folded:
            assert program.subprograms == 1 and program.calls == spec.teeth
        assert "M3" in program.text and "G93" not in program.text
        target = tmp_path / f"generating_{folded}.ngc"
        target.write_text(program.text)
        ok, canon, messages = run_rs274(target)
        assert ok, messages
        moves = _canonical_poses(canon)
        assert len(moves) == int(path.motion_mask.sum())
        feeds = 0
        for (_, previous), (kind, pose) in itertools.pairwise(moves):
            assert kind != "ARC_FEED"
            if abs(pose[3] - previous[3]) > 1e-9:
                assert kind == "STRAIGHT_TRAVERSE", (previous, pose)
                assert previous[2] >= safe - 1e-3 and pose[2] >= safe - 1e-3, (previous, pose)
            feeds += kind == "STRAIGHT_FEED"
        assert feeds > 0
        assert not any("inverse time" in line for line in canon)
        canon_by_mode[folded] = [line for line in canon if line.startswith("STRAIGHT")]
    assert canon_by_mode[True] == canon_by_mode[False]


# --------------------------------------------------------------------------- cutting direction


def _material_sides(spec: GearSpec, path, rows: np.ndarray, tool: Tool) -> np.ndarray:
    """+1 / -1: on which side of the tool axis the design is nearest the tool (machine frame at the row's A)."""
    design = np.asarray(gear_outline(spec, 1e-4))
    sides = np.zeros(len(rows), int)
    for j, i in enumerate(rows):
        a = math.radians(path.a[i])
        c, s = math.cos(a), math.sin(a)
        machine = np.stack([design[:, 0] * c - design[:, 1] * s, design[:, 0] * s + design[:, 1] * c], axis=-1)
        sil = silhouette.tool_silhouette(tool.diameter_mm, tool.effective_corner_radius_mm, TOOL_LENGTH)
        sil = shapely.affinity.translate(sil, path.y[i], path.z[i])
        dist = shapely.distance(shapely.points(machine), sil)
        nearest = machine[int(np.argmin(dist))]
        sides[j] = 1 if nearest[0] > path.y[i] else -1
    return sides


@pytest.mark.parametrize("direction", sweep(["climb", "conventional"], fast=["conventional"]))  # 2 s each
def test_cutting_direction_is_as_asked(direction):
    """Spindle clockwise seen from above (M3): the cutting edges on the tool's side s (+1: +Y) move toward
    s * X. Climb milling: they move against the tool's travel, i.e. s * dX < 0."""
    import shapely.affinity  # noqa: F401 - used in _material_sides

    spec, tool = _gear("reference_z23_m4"), _tool(2.0, 0.5)
    path, _ = _plan(spec, tool, cutting_direction=direction)
    start = path.start_poses()
    rows = np.flatnonzero((path.space == 0) & np.isin(path.feature, [Feature.RIGHT_FLANK, Feature.LEFT_FLANK]))
    sides = _material_sides(spec, path, rows, tool)
    travel = np.sign(path.x[rows] - start[rows, 0])
    edge_against_travel = sides * travel < 0
    assert np.all(edge_against_travel) if direction == "climb" else not np.any(edge_against_travel)
    # Right flank and fillet rows have the material on +Y, left ones on -Y (the labels are right).
    assert np.all(sides[path.feature[rows] == Feature.RIGHT_FLANK] == 1)
    assert np.all(sides[path.feature[rows] == Feature.LEFT_FLANK] == -1)


# --------------------------------------------------------------------------- planted faults


def _rows_of_passes(path, passes) -> np.ndarray:
    """Rows of space 0 below the safe height at the A of the given passes."""
    a = np.array([p.a_deg for p in passes])
    return (path.space == 0) & np.any(np.abs(path.a[:, None] - a[None, :]) < 1e-9, axis=1)


def test_planted_fault_one_flank_pass_left_out():
    name = "reference_z23_m4"
    spec, tool = _gear(name), _tool(2.0, 0.5)
    scallop = 0.005
    path, result = _plan(spec, tool, scallop)
    flank = [p for p in result.passes if p.mode == "flank" and p.feature == Feature.RIGHT_FLANK]
    keep = ~_rows_of_passes(path, [flank[len(flank) // 2]])  # index, approach, plunge, cut, retract
    assert (~keep).sum() == 5
    penetration, leftover, label, *_ = _check(name, spec, tool, path, [0], rows=keep)
    assert penetration <= HALF_MICRON
    assert leftover > scallop + HALF_MICRON and label == "involute", (leftover, label)


@pytest.mark.parametrize("mode", ["flank", "tip"])
def test_planted_fault_tool_end_20um_too_low(mode):
    """With r_t = rho the tool's corner is the rack's round: 20 um lower gouges the fillet (flank passes at
    rolls where the round is generating the fillet) or the root and fillet (tip passes)."""
    name = "reference_z23_m4"
    spec, tool = _gear(name), _tool(2.6, 0.8)
    path, result = _plan(spec, tool)
    rows = _rows_of_passes(path, [p for p in result.passes if p.mode == mode]) & (path.z < _safe_z(spec))
    faulty = path.replace(z=np.where(rows, path.z - 0.020, path.z))
    penetration, *_ = _check(name, spec, tool, faulty, [0])
    assert penetration > (0.010 if mode == "flank" else 0.019), penetration
    penetration, *_ = _check(name, spec, tool, path, [0])
    assert penetration <= HALF_MICRON


def test_smaller_corner_tolerates_a_lower_flank_end():
    """With r_t < rho the corner touches the rack's round only at T and stays inside it elsewhere, so the
    flank passes' end may be 20 um low without reaching into the design by more than 0.1 um here (the
    corner sits (rho - r_t)(1 - cos x) inside the round x away from T, and lowering moves it by about
    20 um * sin x toward the fillet). This is a property of the geometry, not of the checker."""
    name = "reference_z23_m4"
    spec, tool = _gear(name), _tool(2.0, 0.5)
    path, result = _plan(spec, tool)
    rows = _rows_of_passes(path, [p for p in result.passes if p.mode == "flank"]) & (path.z < _safe_z(spec))
    faulty = path.replace(z=np.where(rows, path.z - 0.020, path.z))
    penetration, *_ = _check(name, spec, tool, faulty, [0])
    assert penetration <= 1e-4


# --------------------------------------------------------------------------- docs/method.md's figures


def test_pass_counts_match_method_figures():
    """docs/method.md (independent check, reference gear): about 22 passes per flank at 1 um and 10 at 5 um
    (D2 r0.5); tip mode with r_t = rho about 62 rolls per space at 1 um and 30 at 5 um.

    Ours: 22 and 11 per flank (rolls from the form circle to the tip inclusive, chosen greedily from the
    form circle with the exact crossing of consecutive flats, so the last flat is shorter than the others),
    65 and 31 tip-mode passes per space (the fillet's leftover is kept within 95 % of the target, sampled)."""
    spec = _gear("reference_z23_m4")
    counts = {}
    for corner, diameter in ((0.5, 2.0), (0.8, 2.6)):
        for scallop in (0.001, 0.005):
            _, result = _plan(spec, _tool(diameter, corner), scallop)
            flank = sum(1 for p in result.passes if p.mode == "flank" and p.feature == Feature.RIGHT_FLANK)
            tip = sum(1 for p in result.passes if p.mode == "tip")
            land = sum(1 for p in result.passes if p.mode == "land")
            counts[corner, scallop] = (flank, tip)
            assert result.passes_per_space == 2 * flank + tip + land
            assert 0.9 * scallop <= result.facts.flat_height_mm <= scallop
    assert abs(counts[0.5, 0.001][0] - 22) <= 2 and abs(counts[0.5, 0.005][0] - 10) <= 2
    assert abs(counts[0.8, 0.001][1] - 62) <= 5 and abs(counts[0.8, 0.005][1] - 30) <= 3


# --------------------------------------------------------------------------- tools, options, registry


def test_tool_errors_name_the_values():
    spec = _gear("reference_z23_m4")
    strategy = get_strategy("generating")
    with pytest.raises(ToolError, match=r"r_t = 1 mm is larger than the rack tip radius rho = 0.8 mm"):
        strategy.check_tool(spec, _tool(3.0, 1.0))
    with pytest.raises(ToolError, match=r"flat width d = 2 mm .* 2 d_1 = 1.83"):
        strategy.check_tool(spec, _tool(3.0, 0.5))


def test_strategy_is_registered_and_the_default_and_the_job_file_takes_its_keys():
    from spur_cad.cam.machine import MachineError
    from spur_cad.job import JobFileError, parse_job

    assert "generating" in strategy_names() and FinishingParams().strategy == "generating"
    assert parse_job("[gear]\nteeth = 23\nmodule_mm = 4.0\nface_width_mm = 20\n").finishing.strategy == "generating"
    text = ("[gear]\nteeth = 23\nmodule_mm = 4.0\nface_width_mm = 20\n[finishing]\nstrategy = 'generating'\n"
            "cutting_direction = 'conventional'\nflank_tool_end = 'raised'\n")
    job = parse_job(text)
    assert (job.finishing.cutting_direction, job.finishing.flank_tool_end) == ("conventional", "raised")
    with pytest.raises((JobFileError, MachineError), match="cutting_direction"):
        parse_job(text.replace("'conventional'", "'sideways'"))
    with pytest.raises(MachineError, match="flank_tool_end"):  # checked when made
        GeneratingParams(flank_tool_end="low")


def test_tip_lands_are_cut_only_when_the_blank_stands_above_the_tip_circle():
    name, spec, tool = "reference_z23_m4", _gear("reference_z23_m4"), _tool(2.0, 0.5)
    strategy = get_strategy("generating")
    above, result = strategy.generate(spec, tool, MACHINE, GeneratingParams(), spec.tip_radius_mm + 0.5)
    lands = [p for p in result.passes if p.mode == "land"]
    assert len(lands) >= 2 and all(p.z_mm == spec.tip_radius_mm for p in lands)
    penetration, leftover, label, *_ = _check(name, spec, tool, above, [0], labels=("tip",))
    assert penetration <= HALF_MICRON and leftover <= 0.005 + HALF_MICRON, (penetration, leftover)
    turned, result = strategy.generate(spec, tool, MACHINE, GeneratingParams(), spec.tip_radius_mm)
    assert not [p for p in result.passes if p.mode == "land"]
    assert len(turned) == len(above) - MOVES_PER_PASS * spec.teeth * len(lands)
    # planted fault: without the land passes the blank's allowance stays on the land
    land_rows = (np.abs(above.y) < 1e-9) & (above.z >= spec.tip_radius_mm - 1e-9)  # plunge, cut and retract
    assert _check(name, spec, tool, above, [0], rows=~land_rows, labels=("tip",))[1] > 0.1


def test_tiny_target_is_refused_before_planning():
    from spur_cad.errors import WorkLimitError

    spec = _gear("reference_z23_m4")
    # the smallest target the key takes, with a flat end mill (its wedges between contacts bound the passes)
    with pytest.raises(WorkLimitError, match="passes per tooth space") as caught:
        get_strategy("generating").estimate_moves(spec, Tool(diameter_mm=1.5, kind="flat"),
                                                  GeneratingParams(target_scallop_mm=1e-4))
    assert caught.value.key == "finishing.target_scallop_mm"


def test_estimate_counts_the_moves():
    spec, tool = _gear("pa25_z31_negative_shift"), _tool(1.13, 0.5)
    strategy = get_strategy("generating")
    params = GeneratingParams()
    path, _ = strategy.generate(spec, tool, MACHINE, params, spec.tip_radius_mm + 0.5)
    assert strategy.estimate_moves(spec, tool, params) == len(path)


def test_plan_cam_runs_the_generating_strategy():
    from spur_cad.cad.specs import StockSpec
    from spur_cad.cam.machine import RoughingParams
    from spur_cad.cam.plan import CamInputs, plan_cam

    base = _gear("reference_z23_m4")
    spec = GearSpec(teeth=23, module_mm=4.0, rack_tip_radius_mm=0.8, thickness_allowance_fraction=0.05,
                    face_width_mm=2.0)
    assert spec.space_width_mm == base.space_width_mm
    plan = plan_cam(CamInputs(spec, StockSpec(), None, _tool(2.0, 0.5), RoughingParams(),
                              FinishingParams(strategy="generating"), MACHINE))
    assert plan.finishing.result.strategy == "generating"
    assert plan.finishing.estimate.moves == len(plan.finishing.toolpath)
    assert plan.finishing.estimate.time_s < plan.finishing.reference_estimate.time_s


# --------------------------------------------------------------------------- what it buys (estimator)


@pytest.mark.slow  # plans perimeter finishing too (4 s)
def test_generating_takes_a_fraction_of_the_perimeter_time_on_the_reference_job():
    """Issue's acceptance bounds (feed-bound estimates, not timed): the reference job's own tools at 5 um at
    most 1/4 of perimeter finishing at 5 um, at 1 um at most 1/2 of it, with the advised tool (r_t = rho,
    the advice's diameter rounded down to 0.1 mm, four flutes) at most 1/8."""
    import dataclasses

    from spur_cad.job import load_job
    from spur_cad.pipeline import plan_cam
    from tests.gears import REFERENCE_JOB

    job = load_job(REFERENCE_JOB)
    plan = plan_cam(job)
    perimeter_s = plan.finishing.perimeter_estimate.time_s
    assert plan.finishing.perimeter_estimate.moves > 50 * plan.finishing.estimate.moves
    assert plan.finishing.estimate.time_s <= perimeter_s / 4
    fine = dataclasses.replace(job, finishing=dataclasses.replace(job.finishing, target_scallop_mm=0.001))
    assert plan_cam(fine).finishing.estimate.time_s <= perimeter_s / 2
    advice = plan.finishing.result.tool_advice
    diameter = math.floor(10 * advice.recommended_diameter_mm) / 10
    advised = dataclasses.replace(job.tools.finishing, diameter_mm=diameter,
                                  corner_radius_mm=advice.advised_corner_radius_mm, flutes=4)
    big = dataclasses.replace(job, tools=dataclasses.replace(job.tools, finishing=advised))
    assert plan_cam(big).finishing.estimate.time_s <= perimeter_s / 8


@pytest.mark.parametrize("folded", [False, True])
def test_the_table_is_clamped_for_every_pass_when_the_machine_has_clamp_codes(folded):
    import re

    spec, tool = _gear("shifted_z12_x04"), _tool(2.1, 0.5)
    machine = Machine(rotary_clamp_code="M10", rotary_unclamp_code="M11")
    path, result = get_strategy("generating").generate(spec, tool, machine, GeneratingParams(),
                                                       spec.tip_radius_mm + 0.5)
    info = ProgramInfo("clamped", (), rotary_clamp_code="M10", rotary_unclamp_code="M11")
    text = post_program(path, PostSettings(folded=folded), info).text
    lines = inlined_lines(text)  # the subprogram's text at each call, in order
    clamped, clamps, cuts = False, 0, 0
    for line in lines:
        if line == "M10":
            assert not clamped
            clamped, clamps = True, clamps + 1
        elif line == "M11":
            clamped = False
        elif re.search(r"\bA", line):
            assert not clamped, f"A moves while the table is clamped: {line}"
        elif re.match(r"X-?[\d.]+( F[\d.]+)?$", line):  # a pass along the face width
            assert clamped, f"cutting with the table unclamped: {line}"
            cuts += 1
    assert clamps == cuts == spec.teeth * result.passes_per_space


@pytest.mark.parametrize("dialect", ["linuxcnc", "fanuc", "haas", "siemens", "okuma"])
@pytest.mark.parametrize("name, diameter, corner", [CASES[0], pytest.param(*CASES[2], marks=pytest.mark.slow)])
def test_every_dialect_reads_back_the_generating_passes_flat_and_folded(dialect, name, diameter, corner):
    """Each dialect's program, read back by the tests' own G-code reader: the IR's moves in order (flat and
    folded the same), no inverse-time feed, and A changes only in rapids at the safe height."""
    from tests.gcode_reader import read_program
    from tests.test_post import DECIMALS, INFO, assert_folded_moves_as_flat, assert_same_moves

    spec, tool = _gear(name), _tool(diameter, corner)
    path, _ = _plan(spec, tool)
    linear, rotary = DECIMALS[dialect]
    moves_by_mode = {}
    for folded in (False, True):
        program = read_program(post_program(path, PostSettings(dialect=dialect, folded=folded), INFO).text, dialect)
        assert program.ended
        for move in program.moves:
            assert not move.inverse_time, move.words
            if move.start[0] is not None and move.end[3] != move.start[3]:
                assert move.rapid and min(move.start[2], move.end[2]) >= _safe_z(spec) - 1e-9, move.words
        moves = [(m.rapid, np.array(m.end)) for m in program.moves]
        assert_same_moves(moves, path, linear, rotary)
        moves_by_mode[folded] = moves
    assert_folded_moves_as_flat(moves_by_mode)
