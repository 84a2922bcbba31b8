"""Helical gears cut: roughing along the lead against the textbook lead (dA = -hand 360 dX / p_z), the
simulator's helical design against the B-rep, the simulated roughing against its promise (the design is
never touched, the finish stock kept), a wrong hand caught, and LinuxCNC's interpreter on the program."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from spur_cad.cam.ir import Feature, MoveKind
from spur_cad.geometry.frames import turn_points
from spur_cad.job import parse_job
from spur_cad.pipeline import job_stock, plan_cam
from spur_cad.sim import Cut, SimSettings, simulate, subset
from tests.gears import with_roughing_strategy
from tests.textbook import HelicalTextbook
from tests.tiers import sweep

HELICAL_EXAMPLE = Path(__file__).resolve().parents[1] / "resources" / "examples" / "helical_gear.toml"
RES = 0.005


def _job(hand: str = "right"):
    """The helical example roughing by levels (given: the default is flank, whose passes turn A by their segment's
    turn as well; test_flank_roughing checks the helical example's flank roughing)."""
    job = parse_job(with_roughing_strategy(HELICAL_EXAMPLE.read_text(), "levels"), str(HELICAL_EXAMPLE))
    if hand != job.gear.hand:
        job = dataclasses.replace(job, gear=dataclasses.replace(job.gear, hand=hand))
    return job


def _book(spec) -> HelicalTextbook:
    return HelicalTextbook(spec.teeth, spec.module_mm, spec.pressure_angle_deg, spec.helix_angle_deg,
                           x=spec.profile_shift_coefficient, rho=spec.rack_tip_radius_mm,
                           allowance_fraction=spec.thickness_allowance_fraction)


@pytest.fixture(scope="module", params=["right", "left"])
def roughed(request):
    job = _job(request.param)
    plan = plan_cam(job)
    return job, plan


def test_every_cutting_pass_follows_the_textbook_lead(roughed):
    job, plan = roughed
    path = plan.roughing.toolpath
    lead = _book(job.gear).lead
    hand = 1.0 if job.gear.hand == "right" else -1.0
    start = path.start_poses()
    passes = (path.feature == Feature.LEVEL) & (path.kind == MoveKind.LINEAR) & (path.x != start[:, 0])
    assert passes.sum() > 1000
    dx, da = path.x[passes] - start[passes, 0], path.a[passes] - start[passes, 3]
    np.testing.assert_allclose(da, -hand * 360.0 * dx / lead, rtol=1e-12, atol=1e-12)
    assert path.inverse_time[passes].all()
    # Every move of a space keeps the space under the tool: A + turn(X) is the space's index angle.
    k = path.space[passes]
    np.testing.assert_allclose(path.a[passes] + hand * 360.0 * path.x[passes] / lead, -k * 360.0 / job.gear.teeth,
                               atol=1e-9)


def test_simulated_roughing_keeps_the_finish_stock_and_a_wrong_hand_gouges(roughed):
    job, plan = roughed
    stock = job_stock(job)
    settings = SimSettings(resolution_mm=RES)
    tool = job.tools.roughing
    result = simulate(job.gear, stock, [Cut(plan.roughing.toolpath, tool)], settings)
    dev = result.deviation[:, :, result.gear_rows]
    finish_stock = job.roughing.finish_stock_mm
    assert dev.min() >= finish_stock - RES / 2, dev.min()  # the design is never touched, the finish stock kept
    flanks = np.isin(result.grid.feature_names(), ["right involute", "left involute"])
    # Flanks: the planned staircase (flank allowance) plus what the helix costs the passes' reach (docs/cam.md).
    assert dev[:, flanks].max() <= 1.25 * job.roughing.flank_allowance_mm
    assert result.uncut_points == 0
    # Planted fault: the lowest level of one space programmed for the other hand cuts into the flanks by far
    # more than the stock (the same moves for the right hand do not). A wrong hand does not follow this
    # design's lead, so the simulator samples its poses: one level keeps that quick.
    other = "left" if job.gear.hand == "right" else "right"
    wrong = plan_cam(dataclasses.replace(job, gear=dataclasses.replace(job.gear, hand=other))).roughing.toolpath
    for path, gouges in ((plan.roughing.toolpath, False), (wrong, True)):
        lowest = (path.space == 3) & (path.station == path.station[path.space == 3].max())
        lowest[np.nonzero(lowest)[0][0] - 1] = True  # the move to the level's start
        result = simulate(job.gear, stock, [Cut(subset(path, lowest), tool)], settings)
        assert result.max_gouge_mm > 0.3 if gouges else result.max_gouge_mm == 0.0, result.max_gouge_mm


@pytest.mark.slow
def test_the_simulated_design_lies_on_the_brep_at_every_row():
    """The simulator's helical rows (the transverse points turned by its twist) against the B-rep's surface."""
    import cadquery as cq
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape
    from OCP.gp import gp_Pnt

    from spur_cad.cad.solid import build_gear_shape
    from spur_cad.sim.design import design_grid

    for hand in ("right", "left"):
        spec = dataclasses.replace(_job().gear, hand=hand)
        shape, _ = build_gear_shape(spec)
        grid = design_grid(spec, 0.3, 0.0, spec.face_width_mm)
        compound = cq.Compound.makeCompound([f for f in cq.Shape.cast(shape).Faces()
                                             if abs(f.normalAt().x) < 0.99]).wrapped
        worst = 0.0
        for x in (0.0, 7.0, spec.face_width_mm):
            points = turn_points(grid.points, grid.twist_rad_per_mm * x)
            for y, z in points[::7]:
                extrema = BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeVertex(gp_Pnt(x, y, z)).Vertex(), compound)
                extrema.Perform()
                worst = max(worst, extrema.Value())
        assert worst < 1e-3, (hand, worst)


def _canonical(canon):
    from tests.rs274_helper import canon_args

    moves = []
    for line in canon:
        if line.startswith(("STRAIGHT_FEED", "STRAIGHT_TRAVERSE")):
            x, y, z, a = canon_args(line)[:4]
            moves.append((line.split("(")[0], (x, y, z, a)))
    return moves


@pytest.mark.linuxcnc
def test_rs274_reads_the_helical_roughing_program_with_the_lead_in_inverse_time(tmp_path):
    from spur_cad.post import PostSettings, ProgramInfo, post_program
    from tests.rs274_helper import run_rs274
    from tests.test_post import canonical_straight_moves, relative_path_length

    job = _job()
    path = plan_cam(job).roughing.toolpath
    lead = _book(job.gear).lead
    feed = job.tools.roughing.feed_mm_min(job.machine)
    info = ProgramInfo("spur_cad helical roughing test", ("gear: helical",))
    canon_by_mode = {}
    for folded in (False, True):
        program = post_program(path, PostSettings(folded=folded), info)
        assert "G93" in program.text
        target = tmp_path / f"helical_roughing_{folded}.ngc"
        target.write_text(program.text)
        ok, canon, messages = run_rs274(target)
        assert ok, messages
        rounded = np.round(path.poses()[path.motion_mask], 4)
        moving = 1 + int(np.any(rounded[1:] != rounded[:-1], axis=1).sum())  # the post leaves out null moves
        assert len(_canonical(canon)) == moving
        along = 0
        for feed_move, inverse, rate, pose, end in canonical_straight_moves(canon):
            dx, da = (end - pose)[[0, 3]] if pose is not None else (0.0, 0.0)
            if feed_move and abs(dx) > 1.0 and np.all(end[1:3] == pose[1:3]):
                assert da == pytest.approx(-360.0 * dx / lead, abs=2e-4)  # 4 decimals of A
                assert inverse  # X and A together: inverse time, taking the relative path at the tool's feed
                minutes = float(np.linalg.norm(end[:3] - pose[:3])) / rate  # rs274 reports a cartesian rate
                assert minutes == pytest.approx(relative_path_length(pose, end) / feed, rel=2e-3)
                along += 1
        assert along > 1000
        canon_by_mode[folded] = [line for line in canon if line.startswith("STRAIGHT")]
    assert canon_by_mode[True] == canon_by_mode[False]


# --------------------------------------------------------------------------- finishing by generation
#
# The independent check: the tool (a bull-nose, written here from its definition) swept along each cutting
# move of tooth space 0, against exact design points of that space turned by the textbook helix
# (X h tan(beta) / r) at the front, middle and back sections. The distance from a point to a convex tool
# moving along a segment is convex along the segment: a golden-section search finds it.

SECTIONS = (0.0, 10.0, 20.0)
_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


@pytest.fixture(scope="module")
def finished():
    job = _job()
    return job, plan_cam(job)


def _tool_gap(p: np.ndarray, radius: float, r_t: float) -> np.ndarray:
    """Distance from the bull-nose tool (tip centre at the origin, axis +Z, shank up) minus 0 (< 0 inside)."""
    core = radius - r_t
    e = np.maximum(np.hypot(p[..., 0], p[..., 1]) - core, 0.0)
    v = np.maximum(r_t - p[..., 2], 0.0)
    return np.hypot(e, v) - r_t


def _sweep_gap(points: np.ndarray, starts: np.ndarray, ends: np.ndarray, radius: float, r_t: float) -> np.ndarray:
    """(points, moves) smallest tool gap over each straight move (convex in the move parameter)."""
    lo, hi = np.zeros((len(points), len(starts))), np.ones((len(points), len(starts)))

    def gap(s):
        at = starts[None, :, :] + s[..., None] * (ends - starts)[None, :, :]
        return _tool_gap(points[:, None, :] - at, radius, r_t)

    for _ in range(70):
        a, b = hi - _GOLDEN * (hi - lo), lo + _GOLDEN * (hi - lo)
        left = gap(a) < gap(b)
        hi, lo = np.where(left, b, hi), np.where(left, lo, a)
    return np.minimum(gap(0.5 * (lo + hi)), np.minimum(gap(np.zeros_like(lo)), gap(np.ones_like(lo))))


def _space_points(spec):
    """Exact points of tooth space 0 (both halves) in the part frame at section 0, and which are tip lands on
    the +Y side (the land passes of space 0 finish that land; the other is the neighbour's)."""
    from spur_cad.geometry import sample_profile

    samples = sample_profile(spec.tooth_space_profile(), 1e-4)
    labels = np.array(samples.label_names())
    right = samples.points
    points = np.concatenate([right, right * np.array([-1.0, 1.0])])
    labels = np.concatenate([labels, labels])
    keep = (labels != "tip") | (points[:, 0] > 0.0)
    return points[keep][::3]


def _cutting_moves(path, space: int = 0):
    start = path.start_poses()
    rows = np.nonzero((path.space == space) & (path.kind == MoveKind.LINEAR) & (path.feature != Feature.NONE))[0]
    assert np.all(path.a[rows] == start[rows, 3])  # A clamped: no cutting move turns it
    return start[rows], path.poses()[rows]


def _sweep_check(job, path):
    """(deepest penetration, largest leftover) of the design at the three sections, mm."""
    spec, tool = job.gear, job.tools.finishing
    book = _book(spec)
    hand = 1.0 if spec.hand == "right" else -1.0
    starts, ends = _cutting_moves(path)
    a = np.radians(starts[:, 3])
    base = _space_points(spec)
    deepest, leftover = 0.0, 0.0
    for x in SECTIONS:
        section = turn_points(base, hand * x * math.tan(book.beta) / book.r)
        gaps = np.empty((len(section), len(starts)))
        for i, angle in enumerate(a):  # the point seen from the machine at this move's A
            turned = turn_points(section, angle)
            points = np.column_stack([np.full(len(turned), x), turned])
            gaps[:, i] = _sweep_gap(points, starts[i:i + 1, :3], ends[i:i + 1, :3], tool.diameter_mm / 2.0,
                                    tool.effective_corner_radius_mm)[:, 0]
        deepest = max(deepest, float(-gaps.min()))
        leftover = max(leftover, float(np.maximum(gaps, 0.0).min(axis=1).max()))
    return deepest, leftover


def _other_gear_job(name: str):
    """The example job with one of tests/test_helical.py's gears and a tool of corner rho, 90 % of the widest."""
    from spur_cad.geometry.profile import rack_corner
    from tests.test_helical import spec_of

    job = _job()
    spec = spec_of(name)
    rho = spec.rack_tip_radius_mm
    diameter = 0.9 * (2.0 * rack_corner(spec).normal_corner_offset_mm + 2.0 * rho)
    tool = dataclasses.replace(job.tools.finishing, diameter_mm=diameter, corner_radius_mm=rho)
    # a blank the tool can take off the tips in one pass (at most half its diameter above the tip circle), on a stub
    # thinner than the gear's root (the example's 80 mm stub is larger than these gears' blanks: CamInputs refuses it)
    stock = dataclasses.replace(job.stock, radial_allowance_mm=min(job.stock.radial_allowance_mm, 0.4 * diameter),
                                stub_diameter_mm=min(job.stock.stub_diameter_mm, 1.6 * spec.root_radius_mm))
    return dataclasses.replace(job, gear=spec, stock=stock,
                               tools=dataclasses.replace(job.tools, finishing=tool, roughing=None))


@pytest.mark.slow
@pytest.mark.parametrize("name", ["example_right", "example_left", "z31_30_left_shifted", "z12_20_undercut",
                                  "z40_25pa_10"])
def test_every_finishing_pass_against_the_design_at_three_sections(name):
    """Acceptance: no penetration beyond 0.5 um, leftover within target + 0.5 um, at the front, middle and
    back sections (the design turned by the textbook helix), on the example (both hands) and three more gears."""
    job = _job(name.removeprefix("example_")) if name.startswith("example") else _other_gear_job(name)
    job = dataclasses.replace(job, gear=dataclasses.replace(job.gear, face_width_mm=20.0))
    deepest, leftover = _sweep_check(job, plan_cam(job).finishing.toolpath)
    assert deepest <= 0.0005, deepest
    assert leftover <= job.finishing.target_scallop_mm + 0.0005, leftover


@pytest.mark.slow
def test_the_sweep_check_finds_planted_faults(finished):
    """A tip-mode pass 3 um too low gouges; a flank pass left out leaves more than the target."""
    from spur_cad.sim import shifted

    job, plan = finished
    path = plan.finishing.toolpath
    tip_rows = (path.space == 0) & (path.feature == Feature.ROOT)
    deepest, _ = _sweep_check(job, shifted(path, tip_rows, dz=-0.003))
    assert deepest > 0.0025
    flank = np.nonzero((path.space == 0) & (path.feature == Feature.RIGHT_FLANK) & (path.kind == MoveKind.LINEAR)
                       & (path.y != path.start_poses()[:, 1]) & (path.z != path.start_poses()[:, 2]))[0]
    keep = np.ones(len(path), bool)
    keep[flank[len(flank) // 2]] = False
    _, leftover = _sweep_check(job, subset(path, keep))
    assert leftover > job.finishing.target_scallop_mm + 0.001


def test_finishing_passes_are_straight_along_the_rack_tooth(finished):
    """Every cutting move keeps A; flank passes run at the base helix angle in plan view (dY/dX =
    -h tan(beta_b)) and tip-mode passes along the rack tooth (dY/dX = -h tan(beta), Z fixed)."""
    job, plan = finished
    book = _book(job.gear)
    starts, ends = _cutting_moves(plan.finishing.toolpath)
    slope = (ends[:, 1] - starts[:, 1]) / (ends[:, 0] - starts[:, 0])
    flat = ends[:, 2] == starts[:, 2]
    assert np.allclose(slope[~flat], -math.tan(book.beta_b), rtol=1e-12)
    steep = flat & (slope != 0.0)  # tip mode (lands run along X)
    assert steep.sum() > 50 and np.allclose(slope[steep], -math.tan(book.beta), rtol=1e-12)


def test_simulated_helical_job_is_within_target_and_resolution(finished):
    """Three spaces roughed and finished, the middle one measured over the whole face width."""
    job, plan = finished
    spaces = [0, 1, 2]

    def of(path):
        return subset(path, np.isin(path.space, spaces))

    result = simulate(job.gear, job_stock(job), [Cut(of(plan.roughing.toolpath), job.tools.roughing),
                                                 Cut(of(plan.finishing.toolpath), job.tools.finishing)],
                      SimSettings(resolution_mm=RES))
    middle = result.deviation[1][:, result.gear_rows]
    assert -middle.min() <= RES
    assert middle.max() <= job.finishing.target_scallop_mm + RES


def test_helical_finishing_tools_and_strategies_are_refused_with_their_reason():
    from spur_cad.cam.tools import ToolError
    from spur_cad.errors import SpurCadError

    job = _job()
    larger = dataclasses.replace(job.tools.finishing, corner_radius_mm=0.9)
    with pytest.raises(ToolError, match="larger than the rack tip radius rho = 0.8") as error:
        plan_cam(dataclasses.replace(job, tools=dataclasses.replace(job.tools, finishing=larger)))
    assert error.value.field == "corner_radius_mm"
    wide = dataclasses.replace(job.tools.finishing, diameter_mm=3.6)
    with pytest.raises(ToolError, match="wider than the rack's normal tip flat"):
        plan_cam(dataclasses.replace(job, tools=dataclasses.replace(job.tools, finishing=wide)))
    perimeter = dataclasses.replace(job.finishing, strategy="perimeter")
    with pytest.raises(SpurCadError, match="is for spur gears; a helical gear .* strategy = \"generating\""):
        plan_cam(dataclasses.replace(job, finishing=perimeter))


@pytest.mark.parametrize("dialect", sweep(["linuxcnc", "fanuc", "haas", "siemens", "okuma"],
                                         fast=["linuxcnc", "fanuc"]))
def test_every_dialect_reads_back_the_helical_programs_flat_and_folded(dialect, finished):
    from spur_cad.post import PostSettings, post_program
    from tests.gcode_reader import read_program
    from tests.test_post import DECIMALS, INFO, assert_folded_moves_as_flat, assert_same_moves

    job, plan = finished
    linear, rotary = DECIMALS[dialect]
    for path in (plan.roughing.toolpath, plan.finishing.toolpath):
        moves_by_mode = {}
        for folded in (False, True):
            program = read_program(post_program(path, PostSettings(dialect=dialect, folded=folded), INFO).text,
                                   dialect)
            assert program.ended
            moves = [(m.rapid, np.array(m.end)) for m in program.moves]
            assert_same_moves(moves, path, linear, rotary)
            moves_by_mode[folded] = moves
        assert_folded_moves_as_flat(moves_by_mode)


@pytest.mark.linuxcnc
def test_rs274_runs_the_helical_finishing_program_with_a_clamped_in_every_feed_move(finished, tmp_path):
    from spur_cad.post import PostSettings, ProgramInfo, post_program
    from tests.rs274_helper import run_rs274
    from tests.test_post import assert_same_moves, canonical_moves

    job, plan = finished
    path = plan.finishing.toolpath
    canon_by_mode = {}
    for folded in (False, True):
        program = post_program(path, PostSettings(folded=folded), ProgramInfo("helical finishing test", ()))
        assert "G93" not in program.text
        target = tmp_path / f"finishing_{folded}.ngc"
        target.write_text(program.text)
        ok, canon, messages = run_rs274(target)
        assert ok, messages
        moves = canonical_moves(canon)
        assert_same_moves(moves, path, 4, 4)
        for (_, before), (rapid, after) in zip(moves, moves[1:]):
            if not rapid:
                assert after[3] == before[3]
        canon_by_mode[folded] = [line for line in canon if line.startswith("STRAIGHT")]
    assert canon_by_mode[True] == canon_by_mode[False]


def test_a_tiny_helical_target_is_refused_quickly_naming_the_key():
    import time

    from spur_cad.cam.machine import MachineError
    from spur_cad.errors import WorkLimitError

    job = _job()
    started = time.perf_counter()
    for target in (1e-9, 1e-7):  # below the key's range: refused by the work bound or the range
        with pytest.raises((MachineError, WorkLimitError), match="target_scallop_mm") as error:
            tiny = dataclasses.replace(job.finishing, target_scallop_mm=target)  # the range: refused when made
            plan_cam(dataclasses.replace(job, finishing=tiny))
        assert error.value.field == "target_scallop_mm"
    assert time.perf_counter() - started < 60.0  # a bound on the refusal, not a performance target


def test_helical_roughing_needs_a_table_that_turns_while_cutting():
    from spur_cad.errors import SpurCadError

    job = _job()
    indexing = dataclasses.replace(job.machine, rotary_simultaneous=False)
    with pytest.raises(SpurCadError, match="rotary_simultaneous = false") as error:
        plan_cam(dataclasses.replace(job, machine=indexing))
    assert error.value.field == "rotary_simultaneous"


def test_a_small_helix_angle_is_swept_as_finely_as_a_large_one():
    """At 0.05 deg the design turns little along X: the lead sweep's slice spacing must still follow the tool
    (an earlier spacing from the turn alone grew to the tool's width and the sweep cut nothing)."""
    job = _job()
    job = dataclasses.replace(job, gear=dataclasses.replace(job.gear, helix_angle_deg=0.05))
    path = plan_cam(dataclasses.replace(job, tools=dataclasses.replace(job.tools, finishing=None))).roughing.toolpath
    space = subset(path, path.space == 3)
    result = simulate(job.gear, job_stock(job), [Cut(space, job.tools.roughing)], SimSettings(resolution_mm=RES))
    dev = result.deviation[3][:, result.gear_rows]
    flanks = np.isin(result.grid.feature_names(), ["right involute", "left involute"])
    assert dev.min() >= job.roughing.finish_stock_mm - RES / 2
    assert dev[flanks].max() <= 1.25 * job.roughing.flank_allowance_mm


def test_the_helical_simulation_gives_the_same_bits_on_any_number_of_threads(finished):
    """The helical kernel clips disjoint blocks of rows on threads: one thread and three (blocks that split the
    tool's width and the passes) must leave every blade at exactly the same place."""
    job, plan = finished

    def of(path):
        return subset(path, np.isin(path.space, [0]))

    cuts = [Cut(of(plan.roughing.toolpath), job.tools.roughing), Cut(of(plan.finishing.toolpath), job.tools.finishing)]
    one, three = (simulate(job.gear, job_stock(job), cuts, SimSettings(resolution_mm=0.01), threads=threads)
                  for threads in (1, 3))
    assert one.poses_clipped == three.poses_clipped > 10_000
    assert np.array_equal(one.deviation, three.deviation)
    # the space was cut: the blades hold different lengths (finished flanks; a tip land roughed to the finish stock)
    assert np.ptp(one.deviation[0]) > job.roughing.finish_stock_mm


# Issue 31.4: a helical gear whose rack tip radius (0.6 mm) is not a stock corner, finished with a 0.5 mm corner.
SMALL_CORNER_RHO_MM, SMALL_CORNER_MM = 0.6, 0.5


@pytest.fixture(scope="module")
def small_corner():
    job = _job()
    gear = dataclasses.replace(job.gear, rack_tip_radius_mm=SMALL_CORNER_RHO_MM)
    tool = dataclasses.replace(job.tools.finishing, corner_radius_mm=SMALL_CORNER_MM)
    job = dataclasses.replace(job, gear=gear, tools=dataclasses.replace(job.tools, finishing=tool))
    return job, plan_cam(job)


def _corner_passes(path, z_of_contact: float):
    """Rows of space 0's right-fillet cutting moves whose tip height is `z_of_contact` (one contact angle)."""
    return ((path.space == 0) & (path.feature == Feature.RIGHT_FLANK) & (path.kind == MoveKind.LINEAR)
            & np.isclose(path.z, z_of_contact, rtol=0.0, atol=1e-9))


@pytest.mark.slow  # a second helical plan (5 s)
def test_a_smaller_corner_finishes_a_helical_gear_without_gouge_within_the_target(small_corner):
    """The exact sweep of every finishing move of space 0 against the design at three sections: no penetration
    beyond 0.5 um, the leftover within the target + 0.5 um; the corner's passes sit at several heights (one per
    contact on the rack: r_f + (rho - r_t)(1 - cos b) on the round, a little higher on the flank above T)."""
    job, plan = small_corner
    path = plan.finishing.toolpath
    deepest, leftover = _sweep_check(job, path)
    assert deepest <= 0.0005, deepest
    assert leftover <= job.finishing.target_scallop_mm + 0.0005, leftover
    tip = [p for p in plan.finishing.result.passes if p.mode == "tip" and p.feature == Feature.RIGHT_FLANK]
    heights = np.unique(np.round([p.z_mm for p in tip], 9))
    rf = job.gear.root_radius_mm
    assert len(heights) >= 3 and heights.min() == pytest.approx(rf, abs=1e-9)
    assert heights.max() < rf + SMALL_CORNER_RHO_MM - SMALL_CORNER_MM + 0.1
    # the report's bound: rolls for 95 % of 70 % of the target, 30 % between the corner's contact angles
    assert plan.finishing.result.facts.tip_mode_leftover_mm == pytest.approx(0.965 * job.finishing.target_scallop_mm)


@pytest.mark.slow
def test_the_smaller_corner_check_finds_planted_faults(small_corner):
    """The corner's passes 3 um too low gouge the fillet; the passes of one contact angle left out leave more
    than the target."""
    from spur_cad.sim import shifted

    job, plan = small_corner
    path = plan.finishing.toolpath
    fillet = (path.space == 0) & (path.feature == Feature.RIGHT_FLANK) & (path.z < job.gear.root_radius_mm + 0.2)
    deepest, _ = _sweep_check(job, shifted(path, fillet, dz=-0.003))
    assert deepest > 0.0025
    heights = sorted({round(p.z_mm, 9) for p in plan.finishing.result.passes
                      if p.mode == "tip" and p.feature == Feature.RIGHT_FLANK})
    _, leftover = _sweep_check(job, subset(path, ~_corner_passes(path, heights[len(heights) // 2])))
    assert leftover > job.finishing.target_scallop_mm + 0.001, leftover


@pytest.mark.slow
@pytest.mark.parametrize("name, fraction", [("z31_30_left_shifted", 0.5), ("z12_20_undercut", 0.3),
                                            ("z40_25pa_10", 0.5)])
def test_smaller_corners_finish_other_helical_gears_at_three_sections(name, fraction):
    """Corners of a fraction of rho on a shifted, an undercut and a 25 deg gear (the first two found contacts
    missing: the angles seen between two rolls, 8.9 um left; the flank line just above T, 6.6 um)."""
    from spur_cad.geometry.profile import rack_corner

    job = _other_gear_job(name)
    r_t = fraction * job.gear.rack_tip_radius_mm
    tool = dataclasses.replace(job.tools.finishing, corner_radius_mm=r_t,
                               diameter_mm=1.8 * rack_corner(job.gear).normal_corner_offset_mm + 2.0 * r_t)
    stock = dataclasses.replace(job.stock, radial_allowance_mm=min(job.stock.radial_allowance_mm,
                                                                   0.4 * tool.diameter_mm))
    job = dataclasses.replace(job, gear=dataclasses.replace(job.gear, face_width_mm=20.0), stock=stock,
                              tools=dataclasses.replace(job.tools, finishing=tool))
    deepest, leftover = _sweep_check(job, plan_cam(job).finishing.toolpath)
    assert deepest <= 0.0005, deepest
    assert leftover <= job.finishing.target_scallop_mm + 0.0005, leftover


@pytest.mark.slow  # a whole simulation (5 s); the smaller corner's plan is checked above in the fast tier
def test_the_smaller_corner_job_simulated_is_within_target_and_resolution(small_corner):
    """Three spaces roughed and finished with the 0.5 mm corner, the middle one measured over the whole face."""
    job, plan = small_corner

    def of(path):
        return subset(path, np.isin(path.space, [0, 1, 2]))

    result = simulate(job.gear, job_stock(job), [Cut(of(plan.roughing.toolpath), job.tools.roughing),
                                                 Cut(of(plan.finishing.toolpath), job.tools.finishing)],
                      SimSettings(resolution_mm=RES))
    middle = result.deviation[1][:, result.gear_rows]
    assert -middle.min() <= RES
    assert middle.max() <= job.finishing.target_scallop_mm + RES


def test_the_smaller_corner_advice_and_recommendations_accept_any_corner_up_to_rho(small_corner):
    """The advice gives this corner's largest diameter (2 d_n + 2 r_t), the recommendations a flat end mill's
    refusal that asks for 0 < r_t <= rho, and a corner above rho is refused naming rho."""
    from spur_cad.cam.recommend import check_tools, generating_max_diameter_mm, recommend_tools
    from spur_cad.cam.strategies import get_strategy
    from spur_cad.cam.tools import Tool, ToolError
    from spur_cad.geometry.profile import rack_corner

    job, plan = small_corner
    spec = job.gear
    d_n = rack_corner(spec).normal_corner_offset_mm
    advice = plan.finishing.result.tool_advice
    assert advice.advised_corner_radius_mm == SMALL_CORNER_RHO_MM
    assert advice.tip_mode_max_diameter_mm == pytest.approx(2.0 * d_n + 2.0 * SMALL_CORNER_MM, abs=1e-12)
    assert generating_max_diameter_mm(spec, SMALL_CORNER_MM, 0.005, spec.tip_radius_mm) == pytest.approx(
        2.0 * d_n + 2.0 * SMALL_CORNER_MM, abs=1e-12)
    rec = recommend_tools(spec, spec.tip_radius_mm + 0.5, 1.0)
    with pytest.raises(ToolError, match=r"corner radius 0 < r_t <= the rack tip radius rho = 0.6 mm") as error:
        check_tools(spec, rec, None, Tool(diameter_mm=1.0, kind="flat", flutes=2))
    assert "equal" not in str(error.value)
    with pytest.raises(ToolError, match=r"r_t = 0.7 mm is larger than the rack tip radius rho = 0.6 mm"):
        get_strategy("generating").check_tool(spec, Tool(diameter_mm=2.0, kind="bull_nose", corner_radius_mm=0.7))


@pytest.mark.linuxcnc
def test_rs274_runs_the_smaller_corner_finishing_program(small_corner, tmp_path):
    from spur_cad.post import PostSettings, ProgramInfo, post_program
    from tests.rs274_helper import run_rs274
    from tests.test_post import assert_same_moves, canonical_moves

    _, plan = small_corner
    path = plan.finishing.toolpath
    program = post_program(path, PostSettings(folded=True), ProgramInfo("helical small corner test", ()))
    target = tmp_path / "finishing.ngc"
    target.write_text(program.text)
    ok, canon, messages = run_rs274(target)
    assert ok, messages
    assert_same_moves(canonical_moves(canon), path, 4, 4)


@pytest.mark.parametrize("name, corner_fraction", [("reference_15_right", 1.0), ("z31_30_left_shifted", 0.5),
                                                   ("z12_20_undercut", 0.3), ("z40_25pa_10", 1.0)])
def test_the_work_bound_counts_the_passes_the_plan_places(name, corner_fraction):
    """The move check counts a helical gear's passes without placing them (planned_passes_per_space): the count
    is the plan's, with and without land passes, for corners of rho and smaller."""
    from spur_cad.cam.strategies.generating_plan import GeneratingParams, plan_generating, planned_passes_per_space
    from spur_cad.geometry.profile import rack_corner

    job = _other_gear_job(name)
    r_t = corner_fraction * job.gear.rack_tip_radius_mm
    tool = dataclasses.replace(job.tools.finishing, corner_radius_mm=r_t,
                               diameter_mm=1.8 * rack_corner(job.gear).normal_corner_offset_mm + 2.0 * r_t)
    params = GeneratingParams(target_scallop_mm=job.finishing.target_scallop_mm)
    for lands in (True, False):
        planned = plan_generating(job.gear, tool, params, lands=lands)
        assert planned_passes_per_space(job.gear, tool, params, lands=lands) == planned.passes_per_space
        assert planned.land_passes_per_space > 0 or not lands


def test_a_helical_job_places_its_flank_passes_once(monkeypatch):
    """Planning the helical example places its flank passes (a bisection per pass) once, for the toolpath; the
    work bound before it counts them (it placed them a second time before)."""
    from spur_cad.cam.strategies import generating_helical

    calls = []
    placed = generating_helical._flank_passes
    monkeypatch.setattr(generating_helical, "_flank_passes", lambda *args: calls.append(1) or placed(*args))
    plan_cam(_job())
    assert len(calls) == 1


@pytest.mark.parametrize("name", ["reference_15_right", "z31_30_left_shifted", "z12_20_undercut"])
def test_the_pruned_searches_give_the_bits_of_searches_over_every_point(name):
    """The flank passes' lowest ends drop hull points that can no longer decide a bisection step, and the tip
    spacing's check drops fillet points already reached: both against the plain searches over every point
    (written here): the ends within the bisections' own resolution, the check exactly."""
    from spur_cad.cam.strategies import generating_helical as gh
    from spur_cad.cam.tools import Tool
    from spur_cad.geometry.profile import rack_corner
    from spur_cad.geometry.sampling import sample_profile
    from tests.test_helical import spec_of

    spec = spec_of(name)
    tool = Tool(diameter_mm=1.8 * rack_corner(spec).normal_corner_offset_mm + 2.0 * spec.rack_tip_radius_mm,
                kind="bull_nose", corner_radius_mm=spec.rack_tip_radius_mm)
    points = gh.tool_hull_points(tool, spec.tip_radius_mm - spec.root_radius_mm + 2.0 * tool.diameter_mm)
    involute = spec.tooth_space_profile().segment("involute")
    for side in (1, -1):
        gamma = side * spec.pressure_angle_rad
        sy, _ = gh.pass_slopes(spec, gamma)
        for t in np.linspace(involute.start, involute.end, 5):
            a = side * (involute.base_angle_rad + t)
            y0 = -side * (spec.base_radius_mm * t + tool.diameter_mm / 2.0 * math.sqrt(1.0 + sy * sy))
            pruned = gh._lowest_end(spec, points, a, a - gamma, y0, side, tool)
            low, high = pruned - 1.0, pruned + 1.0  # the plain bisection, from a bracket of its own

            def fits(z0, y0=y0, a=a, gamma=gamma):
                return (gh.rack_clearance_mm(spec, points + np.array([0.0, y0, z0]), a, a - gamma)
                        <= gh.CLEARANCE_TOLERANCE_MM)

            assert fits(high) and not fits(low)
            for _ in range(60):
                mid = 0.5 * (low + high)
                low, high = (low, mid) if fits(mid) else (mid, high)
            assert abs(high - pruned) <= 1e-12, (high, pruned)  # both bisections end within 1e-13 mm
    samples = sample_profile(spec.tooth_space_profile(), 1e-3 * spec.module_mm)
    keep = np.isin(samples.label_names(), ["fillet", "root"])
    fillet = samples.points[keep][:: max(1, int(keep.sum()) // 120)]
    outline = gh._rack_tip_boundary(spec)
    rolls = np.linspace(-0.3, 0.3, 25)
    nearest = np.full(len(fillet), np.inf)
    for phi in rolls:  # every point against every outline, as dense polylines' vertex-free segment distances
        c, s = math.cos(-phi), math.sin(-phi)
        moved = outline - np.array([spec.reference_radius_mm * phi, 0.0])
        part = np.stack([moved[:, 0] * c - moved[:, 1] * s, moved[:, 0] * s + moved[:, 1] * c], axis=-1)
        for p0, p1 in zip(part[:-1], part[1:]):
            edge = p1 - p0
            u = np.clip(((fillet - p0) @ edge) / (edge @ edge), 0.0, 1.0)
            nearest = np.minimum(nearest, np.hypot(*(fillet - p0 - u[:, None] * edge).T))
    worst = float(nearest.max())
    assert gh._tip_rolls_within(spec, rolls, fillet, outline, worst * (1.0 + 1e-9))
    assert not gh._tip_rolls_within(spec, rolls, fillet, outline, worst * (1.0 - 1e-9))


def test_a_chunk_group_that_misses_the_tool_has_no_chunk_that_meets_it():
    """The helical kernel tests a circle around 8 consecutive chunks before their own circles (CHUNK_GROUP): every
    chunk's circle must lie in its group's, and whenever the group misses the tool's section (its distance beyond
    group_reach, the design's spread included), each of its chunks must miss it too (beyond chunk_reach), so that
    passing over the group changes no blade. Random chunks along a curve and random tool sections, turned designs
    and spreads."""
    from spur_cad.sim.kernel import _chunk_gap, chunk_groups, chunk_reach, group_reach

    rng = np.random.default_rng(27)
    missing_groups = meeting_chunks = 0
    for _ in range(200):
        n = int(rng.integers(1, 60))
        along = np.cumsum(rng.uniform(0.05, 0.6, n))
        centres = np.stack([along * np.cos(along / 9.0) + 30.0, along * np.sin(along / 9.0)], axis=-1)
        radii = rng.uniform(0.05, 0.8, n)
        start, centre, radius = chunk_groups(centres, radii)
        assert start[0] == 0 and start[-1] == n and np.all(np.diff(start) > 0)
        for g in range(len(radius)):
            members = np.arange(start[g], start[g + 1])
            assert np.all(np.hypot(*(centres[members] - centre[g]).T) + radii[members] <= radius[g])
        for _ in range(40):
            turn = rng.uniform(-np.pi, np.pi)
            c, s = np.cos(turn), np.sin(turn)
            near = centre[rng.integers(len(radius))]  # a section near one group: gaps about its reach
            y = c * near[0] - s * near[1] + rng.uniform(-4.0, 4.0)
            z = s * near[0] + c * near[1] + rng.uniform(-4.0, 4.0)
            half_flat, corner = rng.uniform(0.0, 2.0), rng.uniform(0.0, 1.5)
            spread = rng.choice([0.0, rng.uniform(0.0, 0.1)])
            for g in range(len(radius)):
                gy, gz = centre[g]
                if _chunk_gap(c, s, gy, gz, y, z, half_flat, corner) <= group_reach(gy, gz, radius[g], spread):
                    continue
                missing_groups += 1
                meeting_chunks += sum(_chunk_gap(c, s, *centres[ci], y, z, half_flat, corner)
                                      <= chunk_reach(*centres[ci], radii[ci], spread)
                                      for ci in range(start[g], start[g + 1]))
    assert missing_groups > 1000
    assert meeting_chunks == 0
