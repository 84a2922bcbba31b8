"""The example ring's 3-axis cut simulated (spur_cad.sim.flat) and graded (ISO 1328-1): each design point's
deviation against this test's own clearance from the walked tool centre, the removed volume against the exact
outline's hole, and faults planted where the answer is known (a profile slope ramp of 5 um toward the tip; the
finishing path 5 um off the axis)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

from spur_cad.cam.ir import MoveKind, Operation, ToolpathBuilder
from spur_cad.grade.simulated import grade_simulation
from spur_cad.pipeline import plan_cam
from spur_cad.sim.flat import simulate_flat, simulate_flat_grid
from spur_cad.sim.simulate import Cut, SimSettings
from tests.test_three_axis import GOUGE_MM, SCALLOP_TARGET_MM, exact_outline
from tests.test_three_axis_ring import ring_job
from tests.test_three_axis_sim import circle_grid, deepest_row_deviations, flat, walked_centres

SETTINGS = SimSettings(resolution_mm=0.005)


@pytest.fixture(scope="module")
def ring_cut():
    """(job, form radius the tool leaves, operations, finishing step-downs, simulated result) of the example."""
    job = ring_job()
    plan = plan_cam(job)
    operations = [Cut(p.toolpath, p.tool) for p in (plan.roughing, plan.finishing)]
    finish = plan.finishing.toolpath
    depths = np.unique(-finish.z[finish.motion_mask])
    blank = job.stock.blank_radius_mm(job.gear)
    result = simulate_flat(job.gear, blank, operations, SETTINGS, depths, job.stock.inner_diameter_mm / 2.0)
    return job, plan.finishing.result.facts.form_diameter_mm / 2.0, operations, depths, result


def test_a_round_hole_bored_in_a_ring_blank_reads_what_geometry_says():
    """A hole of radius R (normals toward the axis) in a disc with a bore of R - 0.4: uncut, each blade ends in the
    bore's air 0.4 mm out (not at the 1 mm leftover range); a full-turn arc at R - r - e leaves e everywhere and
    removes the hole less the bore, pi ((R - e)^2 - (R - 0.4)^2) per mm of the rows' slabs (to the shoelace's
    polygon)."""
    hole, tool, leftover, bore, depth = 10.0, 1.0, 0.003, 9.6, 4.0
    grid = circle_grid(hole, 3600, np.array([1.0, 3.0]))
    grid = dataclasses.replace(grid, normals=-grid.normals)
    uncut = simulate_flat_grid(grid, 20.0, [], SETTINGS, depth, None, bore)
    assert np.abs(uncut.deviation - (hole - bore)).max() < 1e-9
    builder = ToolpathBuilder(Operation.FINISHING, 1, 1000.0)
    around = hole - tool - leftover
    builder.move(MoveKind.LINEAR, around, 0.0, -5.0, 0.0, 100.0)
    builder.arc(False, around, 0.0, -5.0, 0.0, 0.0, 100.0)
    result = simulate_flat_grid(grid, 20.0, [Cut(builder.build(), flat(2 * tool, 1))], SETTINGS, depth, None, bore)
    assert np.abs(result.deviation - leftover).max() < 1e-6
    expected = math.pi * ((hole - leftover) ** 2 - bore**2) * grid.row_width.sum()  # the rows' slabs: 2 mm
    assert result.removed_volume_mm3 == pytest.approx(expected, rel=1e-5)


def deepest_row_check(result, finishing: Cut, labels: tuple[str, ...]):
    """(simulated, independent, radius) of the deepest row's design points whose feature ends with one of
    `labels`: the independent deviation is the point's distance from the walked tool centre less the tool radius."""
    grid = result.grid
    names = np.array(grid.feature_names()).astype(str)
    chosen = np.zeros(len(names), bool)
    for label in labels:
        chosen |= np.char.endswith(names, label)
    simulated, independent = deepest_row_deviations(result, finishing, chosen)
    return simulated, independent, np.tile(np.hypot(*grid.points[chosen].T), grid.teeth)


@pytest.mark.slow  # a ring simulated lying flat (12 s); the runout test below stays in the fast tier
def test_the_ring_cut_is_within_the_scallop_target_inside_the_form_circle_the_tool_leaves(ring_cut):
    """On the involute from the tool's form circle to the tip: no gouge beyond 1 um, leftover within the 5 um
    scallop target, each point as the independent clearance says (0.2 um); nowhere a gouge beyond 1 um. The root
    fillet's leftover (up to 0.22 mm along the normal) is where the D 2 tool cannot reach (the cutter's fillet is
    smaller than its radius): each root blade ends on the edge of the walked tool's disk, so it is the tool's reach,
    not a flank error."""
    job, form_radius, operations, _, result = ring_cut
    finishing = operations[-1]
    simulated, independent, radius = deepest_row_check(result, finishing, ("involute",))
    inside = (radius <= form_radius) & (radius >= job.gear.tip_radius_mm + 0.05)
    assert simulated[inside].min() >= -GOUGE_MM and simulated[inside].max() <= SCALLOP_TARGET_MM
    assert np.abs(simulated - independent)[inside].max() < 0.0002
    assert result.max_gouge_mm <= GOUGE_MM
    grid, tool_radius = result.grid, finishing.tool.diameter_mm / 2.0
    names = np.array(grid.feature_names()).astype(str)
    root = np.char.endswith(names, "fillet") | np.char.endswith(names, "root")
    tree = cKDTree(walked_centres(finishing.path))
    for k in range(grid.teeth):  # the blade's end (along the normal) lies on the edge the tool's disk leaves
        leftover = result.deviation[k, root, -1]
        ends = grid.space_points(k)[root] + leftover[:, None] * grid.space_normals(k)[root]
        assert 0.15 < leftover.max() < 0.25
        assert np.abs(tree.query(ends)[0] - tool_radius).max() < 0.0002


@pytest.mark.slow  # a ring simulated lying flat (8 s); the runout test stays in the fast tier
def test_the_ring_removed_volume_is_its_hole(ring_cut):
    """A solid disc: what is cut is the hole, the exact outline's area (shoelace of the dense outline, this test's)
    times the face width, less the leftover in the roots (at most 0.224 mm over each space's root and fillets);
    the blank's disc less the section (an external gear's figure) is not it."""
    job, _, _, _, result = ring_cut
    spec = job.gear
    space = spec.tooth_space_profile()
    points, _ = exact_outline(spec, 0.01)
    order = np.argsort(np.arctan2(points[:, 1], points[:, 0]), kind="stable")
    ring = points[order]
    hole = 0.5 * abs(float(np.sum(ring[:, 0] * np.roll(ring[:, 1], -1) - np.roll(ring[:, 0], -1) * ring[:, 1])))
    root_length = sum(float(np.hypot(*np.diff(s.points(np.linspace(s.start, s.end, 2001)), axis=0).T).sum())
                      for s in space.segments if s.label in ("root", "fillet")) * 2.0 * spec.teeth
    design = hole * spec.face_width_mm
    assert 0.0 < design - result.removed_volume_mm3 < root_length * 0.224 * spec.face_width_mm
    assert design - result.removed_volume_mm3 < 0.01 * design


def involute_ramp_mm(result, spec, form_radius_mm: float, amount_mm: float) -> np.ndarray:
    """Deviation (M,) adding `amount_mm` of material at the tip, 0 at `form_radius_mm`, linear in roll length."""
    grid = result.grid
    names = np.array(grid.feature_names()).astype(str)
    radius = np.hypot(*grid.points.T)
    roll = np.sqrt(np.maximum(radius**2 - spec.base_radius_mm**2, 0.0))
    form = math.sqrt(form_radius_mm**2 - spec.base_radius_mm**2)
    tip = math.sqrt(spec.tip_radius_mm**2 - spec.base_radius_mm**2)
    return np.where(np.char.endswith(names, "involute"), amount_mm * (form - roll) / (form - tip), 0.0)


def test_the_ring_is_graded_and_a_planted_profile_slope_reads_about_5_um_toward_the_tip(ring_cut):
    """The clean cut grades class 1 (an ideal machine) with |f_Ha| and F_a below 1 um. 5 um of material planted
    toward the tip (0 at the tool's form circle, linear in roll length) reads as f_Ha of + 4.75 um (the range ends
    5 % short of the tip), + as an external gear's (material rising toward the tip), F_a as much, class 5 for f_Ha:
    the clean class fails."""
    job, form_radius, _, _, result = ring_cut
    spec = job.gear
    clean = grade_simulation(spec, result, form_radius)
    assert clean.overall_class == 1
    assert abs(clean.deviations_um["f_Ha"]) < 1.0 and clean.deviations_um["F_a"] < 1.0
    ramp = involute_ramp_mm(result, spec, form_radius, 0.005)
    planted = dataclasses.replace(result, deviation=result.deviation + ramp[None, :, None])
    graded = grade_simulation(spec, planted, form_radius)
    assert graded.deviations_um["f_Ha"] == pytest.approx(4.75, abs=0.5)
    assert graded.deviations_um["F_a"] == pytest.approx(4.75, abs=0.8)
    assert graded.classes["f_Ha"] == 5 and graded.overall_class >= 5


def test_a_finishing_path_5_um_off_the_axis_reads_as_runout(ring_cut):
    """The finishing path shifted 5 um along X: the toothed outline off the axis by e = 5 um moves each flank on
    the reference circle by e sin(its polar angle) along the circle, so the total cumulative pitch deviation reads
    2 e = 10 um on both sides (within 1 um), and the flanks facing the shift are cut into by about e sin(alpha)."""
    job, form_radius, operations, depths, result = ring_cut
    roughing, finishing = operations
    shift = 0.005
    moved = dataclasses.replace(finishing.path, x=finishing.path.x + shift,
                                center_x=finishing.path.center_x + shift)
    blank = job.stock.blank_radius_mm(job.gear)
    off = simulate_flat(job.gear, blank, [roughing, Cut(moved, finishing.tool)], SETTINGS, depths)
    graded = grade_simulation(job.gear, off, form_radius)
    for side in ("right", "left"):
        assert graded.pitch[side].F_p_um == pytest.approx(2e3 * shift, abs=1.0)
    assert off.max_gouge_mm > 0.5 * shift * math.sin(math.radians(20.0))
    assert graded.overall_class > grade_simulation(job.gear, result, form_radius).overall_class


def test_a_measured_ring_grades_a_planted_profile_slope_with_its_sign():
    """`spur-cad grade`'s grader on a ring: points on every involute of the example ring (another spacing than the
    grader's, turned and shifted as a scan is), with +8 um of profile slope planted on one right flank (material
    rising toward the tip, the tip being the circle toward the axis; ISO 21771's signed roll lengths), and one
    left flank 10 um ahead. The slope reads +8 um, not its mirror, and the pitch 10 um."""
    from spur_cad.grade.measured import MeasuredPoints, grade_measured
    from spur_cad.grade.simulated import helix_range_mm, profile_range_mm, profile_roll_mm
    from spur_cad.sim.design import design_grid

    spec = ring_job().gear
    grid = design_grid(spec, 0.037, 0.0, 0.0, np.zeros(0))
    names = np.array(grid.feature_names())
    roll = profile_roll_mm(spec, np.hypot(grid.points[:, 0], grid.points[:, 1]))
    start, end = profile_range_mm(spec)
    lo, hi = helix_range_mm(spec.face_width_mm, spec.module_mm)
    cos_alpha = spec.base_radius_mm / spec.reference_radius_mm
    turn, centre = math.radians(2.0), (0.04, -0.02)
    xs, ys, axial = [], [], []
    for k in range(spec.teeth):
        for x in np.linspace(lo, hi, 3):
            points, normals = grid.row_points(k, x)
            dev = np.zeros(len(points))
            if k == 2:
                right = names == "right involute"
                dev[right] += 8.0e-3 * (roll[right] - start) / (end - start)
            if k == 5:
                dev[names == "left involute"] += 10.0e-3 * cos_alpha
            on_flank = np.char.endswith(names, "involute")
            moved = (points + dev[:, None] * normals)[on_flank]
            xs.append(math.cos(turn) * moved[:, 0] - math.sin(turn) * moved[:, 1] + centre[0])
            ys.append(math.sin(turn) * moved[:, 0] + math.cos(turn) * moved[:, 1] + centre[1])
            axial.append(np.full(len(moved), x))
    grading = grade_measured(spec, MeasuredPoints(np.concatenate(xs), np.concatenate(ys), np.concatenate(axial)))
    found = grading.deviations_um
    assert found["f_Ha"] == pytest.approx(8.0, abs=0.5)  # its sign: + is material rising toward the tip
    assert found["f_pt"] == pytest.approx(10.0, abs=0.5)
    assert abs(found["f_Hb"]) < 0.5
