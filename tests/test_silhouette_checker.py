"""Tests of the 2-D silhouette checker itself (tests/silhouette.py), on synthetic poses with known answers.

Every expected value below is derived by hand (support functions of the tool, sagitta of two
tangents to a circle, the docs/architecture.md rotation written out), never by the checker's own code.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from shapely.geometry import Point, Polygon

from spur_cad.cam.ir import Feature, MoveKind, Operation, Toolpath, ToolpathBuilder
from spur_cad.geometry import GearSpec, gear_outline, tooth_space_samples
from tests.silhouette import (
    ARC_TOLERANCE_MM,
    cutting_direction_ok,
    design_boundary,
    leftover_mm,
    max_penetration_mm,
    penetration_depths_mm,
    rapid_clearances_mm,
    rapids_clear_of_circle,
    silhouettes_in_part_frame,
    tool_silhouette,
)

UM = 1e-3  # one micrometre in mm


def reference_spec() -> GearSpec:
    return GearSpec(teeth=23, module_mm=4.0, rack_tip_radius_mm=0.8, thickness_allowance_fraction=0.05,
                    face_width_mm=20.0)


def machine_from_part(p: np.ndarray, a_deg: float) -> np.ndarray:
    """docs/architecture.md, literally: a part point (y, z) is at (y cos A - z sin A, y sin A + z cos A)."""
    a = math.radians(a_deg)
    y, z = np.asarray(p, float).T
    return np.stack([y * math.cos(a) - z * math.sin(a), y * math.sin(a) + z * math.cos(a)], axis=-1)


def circle_polygon(radius: float, sagitta_mm: float = 1e-6) -> Polygon:
    """A disc as a polygon whose vertices lie exactly on the circle, one of them at the top (0, R)."""
    n = math.ceil(math.pi / math.acos(1.0 - sagitta_mm / radius))
    angles = math.pi / 2.0 + 2.0 * math.pi * np.arange(n) / n
    return Polygon(np.stack([radius * np.cos(angles), radius * np.sin(angles)], axis=-1))


def path(*moves: tuple) -> Toolpath:
    """Toolpath from (kind, y, z, a[, feature]) tuples (x = 5, the middle of the face)."""
    builder = ToolpathBuilder(Operation.FINISHING, tool_number=1, spindle_rpm=10000.0)
    for move in moves:
        kind, y, z, a = move[:4]
        feature = move[4] if len(move) > 4 else Feature.NONE
        feed = float("nan") if kind == MoveKind.RAPID else 500.0
        builder.move(kind, 5.0, y, z, a, feed, feature=feature)
    return builder.build()


def poses(*yza: tuple[float, float, float]) -> Toolpath:
    return path(*[(MoveKind.LINEAR, y, z, a) for y, z, a in yza])


# --------------------------------------------------------------------------- the tool shape


@pytest.mark.parametrize("diameter, corner", [(6.0, 0.0), (6.0, 1.0), (4.0, 2.0), (10.0, 0.3)])
def test_silhouette_contains_the_true_tool_and_exceeds_it_by_at_most_the_arc_tolerance(diameter, corner):
    length = 25.0
    sil = tool_silhouette(diameter, corner, length)
    assert sil.is_valid
    exact_area = diameter * length - 2.0 * corner**2 * (1.0 - math.pi / 4.0)
    arc_length = math.pi * corner  # two quarter circles
    assert exact_area - 1e-9 <= sil.area <= exact_area + arc_length * ARC_TOLERANCE_MM
    assert sil.bounds == pytest.approx((-diameter / 2, 0.0, diameter / 2, length), abs=1e-12)
    half_flat = diameter / 2 - corner
    if corner > 0:
        # Dense exact points of both corner arcs are inside (or on) the polygon ...
        theta = np.linspace(0.0, math.pi / 2.0, 20001)
        right = np.stack([half_flat + corner * np.sin(theta), corner - corner * np.cos(theta)], axis=-1)
        left = right * np.array([-1.0, 1.0])
        for arc in (right, left):
            assert shapely.distance(sil, shapely.points(arc)).max() <= 1e-12
        # ... and every polygon vertex in a corner zone is no further than the tolerance outside the circle.
        v = np.asarray(sil.exterior.coords)
        corner_zone = (np.abs(v[:, 0]) > half_flat + 1e-12) & (v[:, 1] < corner - 1e-12)
        centre = np.stack([np.sign(v[corner_zone, 0]) * half_flat, np.full(corner_zone.sum(), corner)], axis=-1)
        excess = np.hypot(*(v[corner_zone] - centre).T) - corner
        assert excess.min() >= -1e-12
        assert excess.max() <= ARC_TOLERANCE_MM * (1 + 1e-9)
    # The flat bottom is exactly at the tip (Z = 0). Circumscribing makes it reach past d/2 to where the first
    # tangent meets it, r tan(step/2) <= sqrt(2 r tol) further, a point still within tol of the true corner.
    bottom = np.asarray(sil.exterior.coords)
    bottom = bottom[np.abs(bottom[:, 1]) < 1e-12]
    assert half_flat <= np.abs(bottom[:, 0]).max() <= half_flat + math.sqrt(2 * corner * ARC_TOLERANCE_MM)


def test_ball_silhouette_is_a_half_disc_on_a_rectangle():
    sil = tool_silhouette(4.0, 2.0, 10.0)
    assert sil.is_valid
    assert sil.distance(Point(0.0, 0.0)) == 0.0
    assert sil.contains(Point(0.0, 1e-6))
    assert not sil.contains(Point(0.0, -1e-6))
    # The point at 45 deg on the ball lies on the true sphere section: inside, within the tolerance of the boundary.
    p = Point(2.0 * math.sin(math.pi / 4), 2.0 - 2.0 * math.cos(math.pi / 4))
    assert sil.exterior.distance(p) <= ARC_TOLERANCE_MM


def test_invalid_tools_are_rejected():
    with pytest.raises(ValueError):
        tool_silhouette(4.0, 2.5, 10.0)
    with pytest.raises(ValueError):
        tool_silhouette(-1.0, 0.0, 10.0)


# --------------------------------------------------------------------------- placing the tool


def test_pose_with_a_30_degrees_lands_where_hand_computation_says():
    # Tip at machine (Y, Z) = (3, 50), A = +30: part point = (3 cos30 + 50 sin30, -3 sin30 + 50 cos30).
    tp = poses((3.0, 50.0, 30.0))
    (sil,) = silhouettes_in_part_frame(tp, 4.0, 0.0, 10.0)
    tip = np.array([27.598076211353316, 41.80127018922193])
    corners = np.asarray(sil.exterior.coords)[:-1]
    # Flat tool: its bottom corners are at machine (3 -+ 2, 50); the tip is their midpoint.
    assert corners[:2].mean(axis=0) == pytest.approx(tip, abs=1e-12)
    # The tool (seen from the part) sits 30 deg clockwise from +Z: the part turned 30 deg counter-clockwise.
    assert math.degrees(math.atan2(tip[0], tip[1])) == pytest.approx(30.0 + math.degrees(math.atan2(3.0, 50.0)))
    # Turning the part back by +A (the forward rotation of docs/architecture.md) gives the tool at its machine pose.
    machine = machine_from_part(corners, 30.0)
    assert machine == pytest.approx(np.array([[1.0, 50.0], [5.0, 50.0], [5.0, 60.0], [1.0, 60.0]]), abs=1e-12)


def test_silhouettes_agree_with_shapely_affinity_for_random_poses():
    rng = np.random.default_rng(7)
    n = 50
    y, z, a = rng.uniform(-20, 20, n), rng.uniform(30, 70, n), rng.uniform(-200, 200, n)
    tp = poses(*zip(y, z, a))
    sils = silhouettes_in_part_frame(tp, 5.0, 1.2, 15.0)
    base = tool_silhouette(5.0, 1.2, 15.0)
    for sil, yi, zi, ai in zip(sils, y, z, a):
        expected = shapely.affinity.rotate(shapely.affinity.translate(base, yi, zi), -ai, origin=(0, 0))
        assert sil.symmetric_difference(expected).area < 1e-9


def test_mask_and_substeps_select_poses():
    tp = path((MoveKind.RAPID, 0.0, 60.0, 0.0), (MoveKind.LINEAR, 0.0, 50.0, 0.0),
              (MoveKind.CLAMP_ROTARY, 0.0, 50.0, 0.0), (MoveKind.LINEAR, 0.0, 50.0, 40.0))
    assert len(silhouettes_in_part_frame(tp, 4.0, 0.0, 10.0)) == 3  # markers are not motion rows
    only_last = np.array([False, False, False, True])
    sils = silhouettes_in_part_frame(tp, 4.0, 0.0, 10.0, mask=only_last, substeps=4)
    assert len(sils) == 4
    # Interpolated linearly in A: 10, 20, 30, 40 deg; the tip lies at polar angle A clockwise from +Z.
    for sil, a in zip(sils, (10.0, 20.0, 30.0, 40.0)):
        tip = np.asarray(sil.exterior.coords)[:2].mean(axis=0)
        assert tip == pytest.approx([50.0 * math.sin(math.radians(a)), 50.0 * math.cos(math.radians(a))], abs=1e-12)
    # Row indices select the same poses as a boolean mask (np.nonzero(...)[0] is a common way to write one).
    by_index = silhouettes_in_part_frame(tp, 4.0, 0.0, 10.0, mask=np.nonzero(only_last)[0], substeps=4)
    assert [p.equals_exact(q, 0.0) for p, q in zip(by_index, sils)] == [True] * 4
    rows_1_3 = silhouettes_in_part_frame(tp, 4.0, 0.0, 10.0, mask=np.array([1, 3]))
    tips = [np.asarray(p.exterior.coords)[:2].mean(axis=0) for p in rows_1_3]
    assert tips == [pytest.approx([0.0, 50.0], abs=1e-12),
                    pytest.approx([50.0 * math.sin(math.radians(40.0)), 50.0 * math.cos(math.radians(40.0))],
                                  abs=1e-12)]
    with pytest.raises(ValueError):
        silhouettes_in_part_frame(tp, 4.0, 0.0, 10.0, mask=np.array([True, False]))


# --------------------------------------------------------------------------- penetration


@pytest.mark.parametrize("a_deg", [0.0, 17.0])
def test_flat_tool_resting_on_a_circle_and_lowered_by_20_um(a_deg):
    radius = 40.0
    disc = circle_polygon(radius)
    resting = poses((0.0, radius, a_deg))
    assert max_penetration_mm(disc, silhouettes_in_part_frame(resting, 6.0, 0.0, 20.0)) <= 0.01 * UM
    lowered = poses((0.0, radius - 20 * UM, a_deg))
    assert max_penetration_mm(disc, silhouettes_in_part_frame(lowered, 6.0, 0.0, 20.0)) == pytest.approx(
        20 * UM, abs=0.1 * UM)
    # Lifted off: nothing.
    lifted = poses((0.0, radius + 1 * UM, a_deg))
    assert max_penetration_mm(disc, silhouettes_in_part_frame(lifted, 6.0, 0.0, 20.0)) == 0.0


def test_flat_bottom_across_a_sharp_design_corner_is_caught_without_any_tool_vertex_inside():
    # A tooth-tip-like corner: apex (0, 10), half angle 40 deg. The flat bottom (width 6) chops it by 30 um;
    # no tool vertex is inside the design, only the design's apex is inside the tool.
    half = math.radians(40.0)
    apex = np.array([0.0, 10.0])
    design = Polygon([apex, apex + 12 * np.array([math.sin(half), -math.cos(half)]),
                      apex + 12 * np.array([-math.sin(half), -math.cos(half)])])
    tp = poses((0.0, 10.0 - 30 * UM, 0.0))
    sil = silhouettes_in_part_frame(tp, 6.0, 0.0, 20.0)
    assert not shapely.contains_xy(design, *np.asarray(sil[0].exterior.coords).T).any()
    assert max_penetration_mm(design, sil) == pytest.approx(30 * UM, abs=1e-9)


@pytest.mark.parametrize("depth_um", [0.0, 15.0])
def test_bull_nose_corner_on_an_inclined_line_seen_through_a_30_degree_turn(depth_um):
    # In the machine frame the part's edge is the line p . n = c with n = (sin b, cos b), material below it.
    # Lowest point of a bull-nose (D, r_t, d = D - 2 r_t) along n, for 0 < b < 90 deg: its left corner,
    #   min_tool p . n = Y sin b + Z cos b - (d/2) sin b + r_t cos b - r_t.
    diameter, corner, beta, c, a_deg = 6.0, 1.0, math.radians(35.0), 45.0, 30.0
    half_flat = diameter / 2 - corner
    n_machine = np.array([math.sin(beta), math.cos(beta)])
    y0 = 1.7
    z0 = (c - depth_um * UM - y0 * math.sin(beta) + half_flat * math.sin(beta) - corner * math.cos(beta)
          + corner) / math.cos(beta)
    # The same line in the part frame: turn the normal back by -A (p . n is unchanged by a rotation).
    n_part = np.array([n_machine[0] * math.cos(math.radians(a_deg)) + n_machine[1] * math.sin(math.radians(a_deg)),
                       -n_machine[0] * math.sin(math.radians(a_deg)) + n_machine[1] * math.cos(math.radians(a_deg))])
    t = np.array([n_part[1], -n_part[0]])
    on_line = c * n_part
    design = Polygon([on_line + 100 * t, on_line - 100 * t, on_line - 100 * t - 100 * n_part,
                      on_line + 100 * t - 100 * n_part])
    sils = silhouettes_in_part_frame(poses((y0, z0, a_deg)), diameter, corner, 30.0)
    depth = max_penetration_mm(design, sils)
    # Circumscribed corners: never under-reports, over-reports by at most the arc tolerance.
    assert depth_um * UM - 1e-9 <= depth <= depth_um * UM + ARC_TOLERANCE_MM + 1e-9
    # The checker is sensitive to the sense of A: turning the other way puts the tool elsewhere.
    wrong = silhouettes_in_part_frame(poses((y0, z0, -a_deg)), diameter, corner, 30.0)
    assert abs(max_penetration_mm(design, wrong) - depth) > 0.5


def test_penetration_per_silhouette_points_at_the_offending_pose():
    disc = circle_polygon(30.0)
    tp = poses((0.0, 30.5, 0.0), (0.0, 29.99, 45.0), (0.0, 30.0, 90.0))
    depths = penetration_depths_mm(disc, silhouettes_in_part_frame(tp, 4.0, 0.0, 10.0))
    assert depths[0] == 0.0 and depths[2] <= 0.01 * UM
    assert depths[1] == pytest.approx(0.01, abs=0.1 * UM)


# --------------------------------------------------------------------------- leftover


def test_leftover_between_two_flat_poses_on_a_circle_is_the_sagitta():
    # Two flat bottoms tangent to a circle of radius R at polar angles +-phi from +Z meet above the top;
    # the top point (0, R) is R (1 - cos phi) from each tangent line (the foot lies on the flat bottom
    # because R sin phi < D/2).
    radius, phi_deg, diameter = 40.0, 2.0, 6.0
    phi = math.radians(phi_deg)
    tp = poses((0.0, radius, phi_deg), (0.0, radius, -phi_deg))
    angles = math.pi / 2 + np.linspace(-phi, phi, 401)
    points = np.stack([radius * np.cos(angles), radius * np.sin(angles)], axis=-1)
    left = leftover_mm(points, silhouettes_in_part_frame(tp, diameter, 0.0, 20.0))
    assert left.max() == pytest.approx(radius * (1 - math.cos(phi)), rel=1e-9)
    assert np.argmax(left) == 200  # at the top
    assert left[0] <= 1e-9 and left[-1] <= 1e-9  # the contact points
    # Interpolating the rotary move in eight steps leaves cusps of an eighth of the angle.
    fine = leftover_mm(points, silhouettes_in_part_frame(tp, diameter, 0.0, 20.0, substeps=8))
    assert fine.max() == pytest.approx(radius * (1 - math.cos(phi / 8)), rel=1e-6)


def test_leftover_is_zero_inside_and_the_distance_outside():
    tp = poses((0.0, 0.0, 0.0), (20.0, 0.0, 0.0))
    sils = silhouettes_in_part_frame(tp, 4.0, 0.0, 10.0)
    points = np.array([[0.0, 5.0], [0.5, 0.0], [10.0, 5.0], [0.0, -3.0], [20.0, 13.0], [-5.0, 2.0]])
    assert leftover_mm(points, sils) == pytest.approx([0.0, 0.0, 8.0, 3.0, 3.0, 3.0], abs=1e-12)
    assert np.all(np.isinf(leftover_mm(points, [])))


# --------------------------------------------------------------------------- rapids


def test_rapid_clearance_of_a_pure_rotary_rapid_is_analytic():
    # A flat tool (D 6) at machine (Y, Z) = (10, 60) turning the part through 90 deg: the nearest tool
    # point to the axis is the bottom's inner corner (7, 60), whatever A is.
    tp = path((MoveKind.RAPID, 10.0, 60.0, 0.0), (MoveKind.RAPID, 10.0, 60.0, 90.0))
    assert rapids_clear_of_circle(tp, 6.0, 0.0, 30.0, 50.0) == pytest.approx(math.hypot(7.0, 60.0) - 50.0)


def test_rapid_through_the_stock_is_reported_only_when_the_move_is_interpolated():
    # Both ends are clear (tip at (-+70, 40): nearest point (-+67, 40)), the middle passes through the disc.
    tp = path((MoveKind.RAPID, -70.0, 40.0, 0.0), (MoveKind.RAPID, 70.0, 40.0, 0.0))
    assert rapids_clear_of_circle(tp, 6.0, 0.0, 30.0, 50.0, substeps=1) == pytest.approx(math.hypot(67, 40) - 50)
    assert rapids_clear_of_circle(tp, 6.0, 0.0, 30.0, 50.0, substeps=8) == pytest.approx(40.0 - 50.0)


def test_only_rapids_are_checked_and_rows_are_named():
    tp = path((MoveKind.RAPID, 0.0, 60.0, 0.0), (MoveKind.LINEAR, 0.0, 45.0, 0.0),  # a cut may touch the stock
              (MoveKind.RAPID, 0.0, 60.0, 0.0), (MoveKind.RAPID, 0.0, 60.0, 180.0), (MoveKind.RAPID, 0.0, 51.0, 180.0))
    rows, clearance = rapid_clearances_mm(tp, 6.0, 0.0, 30.0, 50.0)
    assert list(rows) == [0, 2, 3, 4]
    # Row 2 starts at the end of the cut (Z 45) and retracts: its start pose is inside the disc.
    assert clearance == pytest.approx([10.0, -5.0, 10.0, 1.0])
    assert rapids_clear_of_circle(path((MoveKind.LINEAR, 0.0, 0.0, 0.0)), 6.0, 0.0, 30.0, 50.0) == math.inf


# --------------------------------------------------------------------------- cutting direction


def _radius_pose(radius: float, y: float, a: float) -> tuple[float, float, float]:
    return y, math.sqrt(radius**2 - y**2), a


def test_cutting_direction_flags_runs_whose_radius_increases():
    R, L = Feature.RIGHT_FLANK, Feature.LEFT_FLANK
    moves = [(MoveKind.RAPID, *_radius_pose(55.0, 2.0, 10.0))]
    moves += [(MoveKind.LINEAR, *_radius_pose(r, 2.0 + 0.1 * i, 10.0 - i), R) for i, r in enumerate((50, 48, 45))]
    moves += [(MoveKind.RAPID, *_radius_pose(55.0, -2.0, -10.0))]
    moves += [(MoveKind.LINEAR, *_radius_pose(r, -2.0, -10.0 + i), L) for i, r in enumerate((45, 47, 50))]  # climbs
    moves += [(MoveKind.RAPID, *_radius_pose(44.0, 1.0, 30.0))]  # starts below the run's first point
    moves += [(MoveKind.LINEAR, *_radius_pose(r, 1.0, 30.0 - i), R) for i, r in enumerate((49, 46))]
    tp = path(*moves)
    assert cutting_direction_ok(tp, Feature.RIGHT_FLANK) == [True, False]
    assert cutting_direction_ok(tp, Feature.RIGHT_FLANK, include_start=False) == [True, True]
    assert cutting_direction_ok(tp, Feature.LEFT_FLANK) == [False]
    assert cutting_direction_ok(tp, Feature.ROOT) == []


# --------------------------------------------------------------------------- a real gear


def test_design_boundary_lies_on_the_gear_outline_in_the_right_spaces():
    spec = reference_spec()
    outline = Polygon(gear_outline(spec, 1e-5))
    points, labels = design_boundary(spec, [0, 3], labels=("involute",))
    assert set(labels) == {"involute"}
    assert shapely.distance(outline.exterior, shapely.points(points)).max() <= 1.1e-5
    pitch = 360.0 / spec.teeth
    polar_from_z = np.degrees(np.arctan2(-points[:, 0], points[:, 1]))  # counter-clockwise from +Z
    half = len(points) // 2
    assert np.all(np.abs(polar_from_z[:half]) < pitch / 2)
    assert np.all(np.abs(polar_from_z[half:] - 3 * pitch) < pitch / 2)
    # Both halves: as many points left of the space's axis as right of it.
    assert np.sum(polar_from_z[:half] > 0) == np.sum(polar_from_z[:half] < 0)
    everything, all_labels = design_boundary(spec, [0])
    assert set(all_labels) == {"root", "fillet", "involute"}
    assert np.sum(np.abs(everything[:, 0]) < 1e-12) == 1  # the point on the axis appears once


def test_real_gear_flat_tools_in_tooth_space_0_and_space_7():
    spec = reference_spec()
    gear = Polygon(gear_outline(spec, 1e-5))
    rf = spec.root_radius_mm
    pitch = 360.0 / spec.teeth
    for a in (0.0, -7 * pitch):  # space 7 is brought under the tool by A = -7 pitches
        # A 3 mm tool halfway up the space, well clear of both fillets (space half-width there > 2.4 mm).
        assert max_penetration_mm(gear, silhouettes_in_part_frame(poses((0.0, 43.5, a)), 3.0, 0.0, 30.0)) == 0.0
        # A 1.2 mm tool fits on the root arc (half-width 0.82 mm): resting on it, then 30 um below it.
        resting = silhouettes_in_part_frame(poses((0.0, rf, a)), 1.2, 0.0, 30.0)
        assert max_penetration_mm(gear, resting) <= 0.02 * UM
        lowered = silhouettes_in_part_frame(poses((0.0, rf - 30 * UM, a)), 1.2, 0.0, 30.0)
        assert max_penetration_mm(gear, lowered) == pytest.approx(30 * UM, abs=0.05 * UM)
        # The 3 mm tool lowered onto the root reaches into both fillets, far deeper than 30 um.
        assert max_penetration_mm(gear, silhouettes_in_part_frame(poses((0.0, rf, a)), 3.0, 0.0, 30.0)) > 0.1


@pytest.mark.parametrize("depth_um", [0.0, 10.0])
def test_real_gear_ball_pressed_into_the_flank_along_its_normal(depth_um):
    spec = reference_spec()
    gear = Polygon(gear_outline(spec, 1e-5))
    samples = tooth_space_samples(spec, 1e-4)
    involute = np.flatnonzero(samples.labels == 2)
    i = involute[len(involute) // 2]
    p, n = samples.points[i], samples.normals[i]  # normal points into the space
    r = 1.0
    centre = p + (r - depth_um * UM) * n
    tip_part = centre - np.array([0.0, r])
    pitch = 360.0 / spec.teeth
    depths = []
    for k in (0, 5):
        a = -k * pitch  # space k under the tool: the tool's machine pose is that of space 0 at A = 0
        tip_machine = machine_from_part(tip_part[None], 0.0)[0]
        sils = silhouettes_in_part_frame(poses((tip_machine[0], tip_machine[1], a)), 2 * r, r, 30.0)
        depths.append(max_penetration_mm(gear, sils))
    for depth in depths:
        assert depth == pytest.approx(depth_um * UM, abs=0.05 * UM)


def test_real_gear_many_tangent_ball_poses_leave_small_cusps_and_do_not_gouge():
    # Thousands of poses over all 23 spaces: a ball (r 1) tangent at every involute sample of the right flank.
    spec = reference_spec()
    gear = Polygon(gear_outline(spec, 1e-5))
    samples = tooth_space_samples(spec, 1e-4)
    involute = samples.labels == 2
    r = 1.0
    tips = samples.points[involute] + r * samples.normals[involute] - np.array([0.0, r])
    pitch = 360.0 / spec.teeth
    ys, zs, as_ = [], [], []
    for k in range(spec.teeth):
        ys.append(tips[:, 0])
        zs.append(tips[:, 1])
        as_.append(np.full(len(tips), -k * pitch))
    tp = poses(*zip(np.concatenate(ys), np.concatenate(zs), np.concatenate(as_)))
    sils = silhouettes_in_part_frame(tp, 2 * r, r, 30.0)
    assert len(sils) > 2000
    assert max_penetration_mm(gear, sils) <= 0.05 * UM
    points, _ = design_boundary(spec, range(spec.teeth), labels=("involute",), tolerance_mm=1e-4)
    left = leftover_mm(points, sils)
    right_flank = np.zeros(len(points), bool)
    per_space = len(points) // spec.teeth
    right_flank.reshape(spec.teeth, per_space)[:, :int(involute.sum())] = True
    # Contact points sampled at 0.1 um chordal tolerance on a flank of curvature radius >= 8 mm: consecutive
    # contacts are at most sqrt(8 * 1e-4 * rho) apart and the cusp between two ball positions is below 1 um.
    assert left[right_flank].max() < 1 * UM
    # The left flanks were never cut: the leftover there is large.
    assert left[~right_flank].min() > 0.5
