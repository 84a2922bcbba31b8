"""The 3-axis variant ([machine] axes = 3): LinuxCNC programs through rs274, and the tool-centre path it interprets
(lines and arcs) checked at full depth against the exact outline (profile.py's segments, not the fitted arcs):
no gouge, leftover on the active involute within the scallop target, a root fillet of the tool radius at least."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

from spur_cad.cam.machine import Machine, RoughingParams
from spur_cad.cam.three_axis import check_three_axis, finishing_toolpath, roughing_toolpath
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.errors import SpurCadError
from spur_cad.geometry import GearSpec
from spur_cad.post import ProgramInfo, post_program
from spur_cad.post.settings import PostSettings
from tests.rs274_helper import canon_args, run_rs274

REFERENCE = GearSpec(teeth=23, module_mm=4.0, rack_tip_radius_mm=0.8, thickness_allowance_fraction=0.05,
                     face_width_mm=20.0)
MODULE_1 = GearSpec(teeth=30, module_mm=1.0, rack_tip_radius_mm=0.25, face_width_mm=5.0)
GOUGE_MM = 0.001
SCALLOP_TARGET_MM = 0.005
TOLERANCE_MM = 0.001  # chordal tolerance of the finishing arcs


def flat(diameter_mm: float, number: int) -> Tool:
    return Tool(diameter_mm=diameter_mm, kind="flat", tool_number=number, cutting_speed_m_min=100.0,
                feed_per_tooth_mm=0.02)


def interpreted_path(canon: list[str], spacing_mm: float = 0.002):
    """Dense XY points of the tool centre on the deepest Z of the rs274 canonical calls (STRAIGHT_FEED and
    ARC_FEED, arcs walked by their own centre and turn), and the number of arcs."""
    x = y = z = math.nan
    points, depths, arcs = [], [], 0
    for line in canon:
        if line.startswith(("STRAIGHT_FEED", "STRAIGHT_TRAVERSE")):
            nx, ny, nz = canon_args(line)[:3]
            if line.startswith("STRAIGHT_FEED") and nz == z:
                n = max(1, math.ceil(math.hypot(nx - x, ny - y) / spacing_mm))
                t = np.linspace(0.0, 1.0, n + 1)
                points.append(np.stack([x + (nx - x) * t, y + (ny - y) * t], axis=-1))
                depths.append(np.full(n + 1, z))
            x, y, z = nx, ny, nz
        elif line.startswith("ARC_FEED"):
            ex, ey, cx, cy, rotation, ez = canon_args(line)[:6]
            arcs += 1
            r = math.hypot(x - cx, y - cy)
            a0, a1 = math.atan2(y - cy, x - cx), math.atan2(ey - cy, ex - cx)
            sweep = (a1 - a0) % (2 * math.pi) if rotation > 0 else -((a0 - a1) % (2 * math.pi))
            n = max(1, math.ceil(abs(sweep) * r / spacing_mm))
            angles = a0 + sweep * np.linspace(0.0, 1.0, n + 1)
            points.append(np.stack([cx + r * np.cos(angles), cy + r * np.sin(angles)], axis=-1))
            depths.append(np.full(n + 1, ez))
            x, y, z = ex, ey, ez
    points, depths = np.concatenate(points), np.concatenate(depths)
    return points[depths == depths.min()], arcs


def exact_outline(spec: GearSpec, spacing_mm: float = 0.002):
    """The exact outline of every space (both halves of profile.py's segments), its labels and its points' radii."""
    profile = spec.tooth_space_profile()
    parts, labels = [], []
    for segment in profile.segments:
        dense = segment.points(np.linspace(segment.start, segment.end, 20001))
        length = float(np.hypot(*np.diff(dense, axis=0).T).sum())
        points = segment.points(np.linspace(segment.start, segment.end, max(2, math.ceil(length / spacing_mm))))
        parts += [points, points * np.array([-1.0, 1.0])]
        labels += [segment.label] * (2 * len(points))
    space, labels = np.concatenate(parts), np.array(labels)
    turns = 2 * math.pi * np.arange(spec.teeth) / spec.teeth
    c, s = np.cos(turns)[:, None], np.sin(turns)[:, None]
    everything = np.concatenate([np.stack([space[:, 0] * ci - space[:, 1] * si, space[:, 0] * si + space[:, 1] * ci],
                                          axis=-1) for ci, si in zip(c, s)])
    return everything, np.tile(labels, spec.teeth)


def active_start_radius_mm(spec: GearSpec) -> float:
    """Start of the active profile with the basic rack (textbook: the line of action meets the mating rack's
    addendum line (1 - x) m inside the rolling line)."""
    alpha = math.radians(spec.pressure_angle_deg)
    r = spec.reference_radius_mm
    along = r * math.sin(alpha) - (1.0 - spec.profile_shift_coefficient) * spec.module_mm / math.sin(alpha)
    return math.hypot(r * math.cos(alpha), max(along, 0.0))


def three_axis_program(spec: GearSpec, tool: Tool, tmp_path):
    check_three_axis(spec, tool, None)
    path, levels, _ = finishing_toolpath(spec, tool, Machine(), TOLERANCE_MM, spec.tip_radius_mm + 0.5)
    text = post_program(path, PostSettings(), ProgramInfo("finishing", (), writes_a=False)).text
    target = tmp_path / "finishing.ngc"
    target.write_text(text)
    return target, text, levels


@pytest.mark.linuxcnc
@pytest.mark.parametrize("spec, diameter_mm", [(REFERENCE, 2.0), (MODULE_1, 1.0)], ids=["reference_d2", "m1_d1"])
def test_finishing_cuts_the_exact_outline_with_arcs(spec, diameter_mm, tmp_path):
    program, text, levels = three_axis_program(spec, flat(diameter_mm, 2), tmp_path)
    ok, canon, messages = run_rs274(program)
    assert ok, messages
    centres, arcs = interpreted_path(canon)
    assert arcs > 0 and "G2" in text and "G3" in text
    assert min(levels) <= -spec.face_width_mm  # through the face width
    radius = diameter_mm / 2.0
    outline, labels = exact_outline(spec)
    clearance, _ = cKDTree(centres).query(outline)
    gouge = radius - clearance  # > 0: the tool circle reaches inside the exact outline
    assert gouge.max() <= GOUGE_MM, f"gouge {gouge.max() * 1000:.2f} um"
    radii = np.hypot(*outline.T)
    active = (labels == "involute") & (radii >= active_start_radius_mm(spec))
    leftover = clearance[active] - radius
    assert leftover.max() <= SCALLOP_TARGET_MM, f"leftover {leftover.max() * 1000:.2f} um on the active involute"
    # the root the tool leaves: its deepest tool circles reach the root circle but no deeper, and every concave
    # part of what is left is a tool circle (radius r) or wider: a circle of r inside the cut touches each point
    cut_bottom = (np.hypot(*centres.T) - radius).min()
    assert cut_bottom >= spec.root_radius_mm - GOUGE_MM
    root_region = labels != "tip"
    left = outline[root_region]
    offsets = np.hypot(*left.T)
    near_root = offsets < active_start_radius_mm(spec)
    _, nearest = cKDTree(centres).query(left[near_root])
    boundary = centres[nearest] + radius * (left[near_root] - centres[nearest]) / np.linalg.norm(
        left[near_root] - centres[nearest], axis=1)[:, None]  # where the tool circle touches toward the outline
    inside = cKDTree(centres).query(boundary)[0]
    assert inside.min() >= radius - GOUGE_MM  # each such point has a whole tool circle of radius r in the cut


@pytest.mark.linuxcnc
def test_roughing_program_is_accepted_and_leaves_the_finish_stock(tmp_path):
    spec, tool = MODULE_1, flat(1.0, 1)
    params = RoughingParams()
    path, levels, offsets = roughing_toolpath(spec, tool, Machine(), params, spec.tip_radius_mm + 0.5)
    program = tmp_path / "roughing.ngc"
    program.write_text(post_program(path, PostSettings(), ProgramInfo("roughing", (), writes_a=False)).text)
    ok, canon, messages = run_rs274(program)
    assert ok, messages
    centres, _ = interpreted_path(canon)
    outline, _ = exact_outline(spec)
    clearance, _ = cKDTree(centres).query(outline)
    assert clearance.min() - tool.diameter_mm / 2.0 >= params.finish_stock_mm - 0.001
    assert max(abs(z) for z in levels[:1]) <= params.max_level_depth_fraction * tool.diameter_mm + 1e-9


def test_a_tool_too_large_for_the_root_is_refused_naming_the_largest_that_works():
    with pytest.raises(ToolError, match=r"largest tool radius that works is 0\.5\d\d mm"):
        check_three_axis(MODULE_1, flat(2.0, 2), None)


def test_helical_gears_are_refused_at_the_axes_key():
    helical = GearSpec(teeth=30, module_mm=1.0, rack_tip_radius_mm=0.25, face_width_mm=5.0, helix_angle_deg=15.0)
    with pytest.raises(SpurCadError, match=r"axes = 3 cuts spur gears only") as caught:
        check_three_axis(helical, flat(1.0, 2), None)
    assert caught.value.field == "axes"


def step_volume_and_box(path) -> tuple[float, tuple[float, ...]]:
    """The volume and bounding box (x0, y0, z0, x1, y1, z1) of the solid a STEP file holds, read by OCCT."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    from tests.ocp_helper import exact_bounds, read_step

    shape = read_step(path)
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    return props.Mass(), exact_bounds(shape)


@pytest.mark.slow  # a whole 3-axis run (20 s); tests/test_three_axis_sim.py cuts the plan lying flat in the fast tier
def test_a_three_axis_job_runs_through_the_pipeline_without_a_rotary_axis(tmp_path):
    from spur_cad.job import load_job
    from spur_cad.pipeline import run_job
    from tests.gears import REFERENCE_JOB

    job_file = tmp_path / "three.toml"
    job_file.write_text(REFERENCE_JOB.read_text().replace('kind = "bull_nose"', 'kind = "flat"').replace(
        "corner_radius_mm = 0.5\n", "").replace("[machine]\n", "[machine]\naxes = 3\n").replace(
        "face_width_mm = 20.0\n", "face_width_mm = 20.0\nbore_diameter_mm = 30.0\n"))
    result = run_job(load_job(job_file))
    stock = tmp_path / "stock.step"
    stock.write_bytes(result.files["stock.step"])
    volume, box = step_volume_and_box(stock)  # the flat blank: a disk of the face width through its bore
    blank_radius = REFERENCE.tip_radius_mm + 0.5
    assert volume == pytest.approx(math.pi * (blank_radius ** 2 - 15.0 ** 2) * 20.0, rel=1e-6)
    assert box == pytest.approx((0.0, -blank_radius, -blank_radius, 20.0, blank_radius, blank_radius), abs=1e-3)
    finishing = result.files["finishing.ngc"].decode()
    roughing = result.files["roughing.ngc"].decode()
    assert "G2 " in finishing and "G3 " in finishing and "gear axis = Z" in finishing
    for program in (finishing, roughing):
        assert not [line for line in program.splitlines() if not line.startswith("(") and " A" in line]
    # the 3-axis machine's own error budget (issue 48): no index error, every flank moved into the material by half
    # the runout, the tool's radius error and half the linear accuracy; such a uniform shift changes no ISO 1328
    # deviation (differences along a flank or between flanks of one side) and thins the tooth by twice the shift
    # over cos(alpha) on the reference circle
    assert not any("error budget" in w for w in result.warnings)
    budget, machine = result.error_budget, load_job(job_file).machine
    assert budget is not None and set(budget.terms.index_error_arcsec) == {0.0}
    total_um = (-(machine.spindle_runout_um + machine.tool_runout_um) / 2.0 - machine.tool_radius_error_um
                - machine.linear_accuracy_um / 2.0)
    assert total_um < 0.0 and budget.terms.flank_shift_um["total"] == pytest.approx(total_um)
    assert budget.tooth_thickness_change_um == pytest.approx(2.0 * total_um / math.cos(math.radians(20.0)), abs=1e-3)
    assert all(abs(share) <= 1e-3 for share in budget.share_um.values()), budget.share_um
    assert budget.grading.deviations_um == pytest.approx(result.grading.deviations_um, abs=1e-3)
    assert "no index error (no rotary table indexes the spaces)" in result.files["report.html"].decode()
    report = result.files["report.html"].decode()  # the set-up sheet of the blank lying flat, not the rotary table's
    assert "blank thickness (faced to the face width)" in report and "A zero" not in report
    assert result.grading is not None and result.simulation is not None
    # the limits are the 3-axis variant's: the largest flat finishing end mill is the root analysis's (one 0.02 mm
    # larger is refused), the flutes reach through the face width; no rotary-table generating tool is offered
    limits = result.tools.recommendations
    largest = limits.finishing_flat_end_mill_max_diameter_mm
    check_three_axis(REFERENCE, flat(largest, 2), None)
    with pytest.raises(ToolError, match="largest tool radius that works"):
        check_three_axis(REFERENCE, flat(largest + 0.02, 2), None)
    assert limits.required_flute_length_mm == pytest.approx(20.5) and limits.finishing_generating_max_diameter_mm == 0
    assert "largest finishing flat end mill" in report and "by generation" not in report


def tooth_chord_from_centres(centres: np.ndarray, radius_mm: float, circle_mm: float, teeth: int) -> float:
    """Tooth 0's chord on the circle `circle_mm` as the tool circles about `centres` leave it: each edge where the
    circle's points stop being within the tool radius of a centre (bisection on the angle, 1e-9 rad)."""
    tree = cKDTree(centres)
    middle = math.pi / 2 + math.pi / teeth

    def cut(angle: float) -> bool:
        return tree.query([circle_mm * math.cos(angle), circle_mm * math.sin(angle)])[0] <= radius_mm

    edges = []
    for side in (-1.0, 1.0):
        inside, outside = middle, middle + side * math.pi / teeth  # the tooth's centre stays, the space is cut
        assert not cut(inside) and cut(outside)
        while abs(outside - inside) > 1e-9:
            half = 0.5 * (inside + outside)
            inside, outside = (inside, half) if cut(half) else (half, outside)
        edges.append(inside)
    return 2 * circle_mm * math.sin(abs(edges[1] - edges[0]) / 2)


def test_root_thickness_against_the_involute_and_the_cut_the_finishing_path_leaves():
    """At the root form circle the rack-generated chord is the involute's (textbook thickness at a radius); a tool
    that follows the rack's fillet (reference, r 1 mm < its 1.15 mm) leaves the same root; one that cannot (z 30
    m 1, r 0.5 mm > the fillet's 0.31 mm) leaves the tooth thicker at the fillet's middle, as thick as the circles
    of the finishing path's tool centres leave it (within 0.5 um: the 1 um arc fit)."""
    from spur_cad.cam.three_axis_root import root_thickness
    from spur_cad.geometry.involute import involute_function
    from tests.test_three_axis_sim import walked_centres

    following = root_thickness(REFERENCE, 1.0)
    rho, r, rb = following.form_diameter_mm / 2, REFERENCE.reference_radius_mm, REFERENCE.base_radius_mm
    alpha, alpha_rho = math.acos(rb / r), math.acos(rb / rho)
    half_angle = REFERENCE.tooth_thickness_mm / (2 * r) + involute_function(alpha) - involute_function(alpha_rho)
    assert following.rack_form_thickness_mm == pytest.approx(2 * rho * math.sin(half_angle), abs=5e-5)
    assert following.form_thickness_mm == pytest.approx(following.rack_form_thickness_mm, abs=1e-4)
    assert following.fillet_thickness_mm == pytest.approx(following.rack_fillet_thickness_mm, abs=1e-4)

    tool = flat(1.0, 2)
    leaving = root_thickness(MODULE_1, 0.5)
    assert leaving.fillet_thickness_mm > leaving.rack_fillet_thickness_mm + 0.01
    path, _, _ = finishing_toolpath(MODULE_1, tool, Machine(), TOLERANCE_MM, MODULE_1.tip_radius_mm + 0.5)
    walked = tooth_chord_from_centres(walked_centres(path, 0.0005), 0.5, leaving.fillet_diameter_mm / 2,
                                      MODULE_1.teeth)
    assert leaving.fillet_thickness_mm == pytest.approx(walked, abs=0.0005)


@pytest.mark.slow  # plans a deep slot job (10 s)
def test_finishing_steps_down_no_deeper_than_a_slot_where_roughing_cannot_reach_the_root():
    """z 30 m 1 roughed with D 2 (wider than the spaces' bottoms) and finished with D 1: the finishing tool cuts
    almost a full slot at the root (its centre's depth in what roughing leaves measured here as its distance from
    the roughing program's walked tool centres less their radius), so its step-down is the slot depth [roughing]
    allows; the reference gear (roughing reaches the root) keeps one tool diameter."""
    from spur_cad.cam.three_axis import finishing_engagement, finishing_loop, roughing_leaves
    from tests.test_three_axis_sim import walked_centres

    params, rough, finish = RoughingParams(), flat(2.0, 1), flat(1.0, 2)
    path, _, offsets = roughing_toolpath(MODULE_1, rough, Machine(), params, MODULE_1.tip_radius_mm + 0.5)
    loop = finishing_loop(MODULE_1, finish, TOLERANCE_MM)
    engagement = finishing_engagement(loop, finish, roughing_leaves(MODULE_1, rough, offsets[-1]), params)
    loop_points = np.array([s.point_at(t) for s in loop for t in np.linspace(0.0, 1.0, 20)])
    depth = cKDTree(walked_centres(path, 0.002)).query(loop_points)[0] - rough.diameter_mm / 2.0
    independent = float(np.clip(finish.diameter_mm / 2.0 + depth, 0.0, finish.diameter_mm).max()) / finish.diameter_mm
    assert independent > 0.9 and engagement.max_radial_fraction == pytest.approx(independent, abs=0.005)
    assert engagement.limited and engagement.step_down_mm == pytest.approx(params.max_level_depth_fraction * 1.0)
    _, levels, _ = finishing_toolpath(MODULE_1, finish, Machine(), TOLERANCE_MM, MODULE_1.tip_radius_mm + 0.5,
                                      engagement.step_down_mm)
    assert max(-np.diff([0.0, *levels])) <= params.max_level_depth_fraction * finish.diameter_mm + 1e-9

    rough, finish = flat(3.5, 1), flat(2.0, 2)
    path, _, offsets = roughing_toolpath(REFERENCE, rough, Machine(), params, REFERENCE.tip_radius_mm + 0.5)
    reference = finishing_engagement(finishing_loop(REFERENCE, finish, TOLERANCE_MM), finish,
                                     roughing_leaves(REFERENCE, rough, offsets[-1]), params)
    assert reference.max_radial_fraction <= params.max_radial_engagement_fraction and not reference.limited
    assert reference.step_down_mm == pytest.approx(finish.diameter_mm)
