"""The gear outline as arcs and lines, and its offset, against independent references: the exact profile
evaluated densely here (not the project's sampler), distances to arcs computed here by a chord-side test
(not the module's angle test), and the true offset curve as the set of points |d| from the exact outline."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial import cKDTree
from shapely.geometry import Point as ShapelyPoint
from shapely.geometry import Polygon

from spur_cad.geometry import GearSpec
from spur_cad.geometry.outline2d import Arc2D, Line2D, fit_biarcs, gear_outline_arcs, offset_outline
from spur_cad.job import load_job
from tests.gears import REFERENCE_JOB

TOLERANCE_MM = 0.001


def _gear(name: str) -> GearSpec:
    if name == "reference":
        return load_job(REFERENCE_JOB).gear
    if name == "undercut_m1_z12":
        return GearSpec(teeth=12, module_mm=1.0, rack_tip_radius_mm=0.25)
    return GearSpec(teeth=60, module_mm=2.0, rack_tip_radius_mm=0.76, thickness_allowance_mm=0.05)


GEARS = ["reference", "undercut_m1_z12", "z60_m2"]


@pytest.fixture(scope="module", params=GEARS)
def gear(request):
    spec = _gear(request.param)
    return spec, gear_outline_arcs(spec, TOLERANCE_MM)


# --- independent references ----------------------------------------------------------------------

def _exact_space(spec: GearSpec, per_segment: int = 4000) -> tuple[np.ndarray, np.ndarray]:
    """Tooth space 0 as dense points and outward normals (out of the material), counter-clockwise from the
    right tooth centre line to the left one, from each exact segment evaluated on an even parameter grid."""
    pts, nrm = [], []
    for segment in spec.tooth_space_profile().segments:
        t = np.linspace(segment.start, segment.end, per_segment)
        pts.append(segment.points(t))
        nrm.append(segment.normals(t))  # into the space = out of the material
    right, right_n = np.concatenate(pts), np.concatenate(nrm)
    mirror = np.array([-1.0, 1.0])
    return (np.concatenate([right[::-1], right * mirror]), np.concatenate([right_n[::-1], right_n * mirror]))


def _turn(points: np.ndarray, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return points @ np.array([[c, s], [-s, c]])


def _exact_neighbourhood(spec: GearSpec) -> np.ndarray:
    """Spaces -1, 0, 1 as one ordered dense polyline (enough to measure distances from space 0's region)."""
    space, _ = _exact_space(spec)
    pitch = 2.0 * math.pi / spec.teeth
    return np.concatenate([_turn(space, k * pitch) for k in (-1, 0, 1)])  # space k: turned k pitches ccw


def _polyline_distance(points: np.ndarray, polyline: np.ndarray) -> np.ndarray:
    """Exact distance from points to a dense ordered polyline (segments next to the 6 nearest vertices)."""
    tree = cKDTree(polyline)
    _, nearest = tree.query(points, k=6)
    best = np.full(len(points), np.inf)
    for column in nearest.T:
        for lo in (column - 1, column):
            lo = np.clip(lo, 0, len(polyline) - 2)
            a, b = polyline[lo], polyline[lo + 1]
            d = b - a
            u = np.clip(np.einsum("ij,ij->i", points - a, d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300), 0, 1)
            best = np.minimum(best, np.hypot(*(points - a - u[:, None] * d).T))
    return best


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """z of the 2-D cross product (b may be (N, 2))."""
    return a[0] * b[..., 1] - a[1] * b[..., 0]


def _arc_middle(arc: Arc2D) -> np.ndarray:
    """The arc's midpoint: the chord's right side for a counter-clockwise arc, its left side otherwise."""
    s, e, c = np.asarray(arc.start_xy), np.asarray(arc.end_xy), np.asarray(arc.center_xy)
    r = float(np.hypot(*(s - c)))
    chord = e - s
    if np.hypot(*chord) == 0.0:  # full circle
        return 2.0 * c - s
    side = np.array([chord[1], -chord[0]]) / np.hypot(*chord)
    return c + (r if arc.counterclockwise else -r) * side


def _distance_to(points: np.ndarray, segment) -> np.ndarray:
    """Distance to a line segment, or to an arc: radial where the foot on the circle lies on the arc's side of
    its chord, else the nearer end."""
    s, e = np.asarray(segment.start_xy), np.asarray(segment.end_xy)
    ends = np.minimum(np.hypot(*(points - s).T), np.hypot(*(points - e).T))
    if isinstance(segment, Line2D):
        d = e - s
        u = np.clip((points - s) @ d / (d @ d), 0.0, 1.0)
        return np.hypot(*(points - s - u[:, None] * d).T)
    c = np.asarray(segment.center_xy)
    r = float(np.hypot(*(s - c)))
    rel = points - c
    dist_c = np.hypot(*rel.T)
    foot = c + rel * (r / np.maximum(dist_c, 1e-300))[:, None]
    chord = e - s
    side_mid = np.sign(_cross(chord, _arc_middle(segment) - s))
    on_arc = np.sign(_cross(chord, foot - s)) == side_mid
    if np.hypot(*chord) == 0.0:
        on_arc = np.ones(len(points), bool)
    return np.where(on_arc, np.abs(dist_c - r), ends)


def _distance_to_outline(points: np.ndarray, segments) -> np.ndarray:
    best = np.full(len(points), np.inf)
    for segment in segments:
        best = np.minimum(best, _distance_to(points, segment))
    return best


def _samples(segments, per_segment: int = 9, closed: bool = True) -> np.ndarray:
    """Points along each segment, both ends included (closed) or the end left out (a ring for a polygon)."""
    t = np.linspace(0.0, 1.0, per_segment) if closed else np.linspace(0.0, 1.0, per_segment)[:-1]
    return np.array([seg.point_at(float(u)) for seg in segments for u in t])


def _near_space_zero(segments, spec: GearSpec) -> list:
    """Segments with a point within half a pitch of space 0's axis (+y)."""
    half = math.pi / spec.teeth
    keep = []
    for seg in segments:
        pts = _samples([seg], 3)
        theta = np.arctan2(pts[:, 0], pts[:, 1])
        if np.any(np.abs(theta) <= 1.5 * half):
            keep.append(seg)
    return keep


def _in_space_zero(points: np.ndarray, spec: GearSpec) -> np.ndarray:
    return np.abs(np.arctan2(points[:, 0], points[:, 1])) <= math.pi / spec.teeth


def _tangent_at(segment, at_end: bool) -> np.ndarray:
    if isinstance(segment, Line2D):
        d = np.subtract(segment.end_xy, segment.start_xy)
        return d / np.hypot(*d)
    p = np.asarray(segment.end_xy if at_end else segment.start_xy)
    radial = (p - np.asarray(segment.center_xy)) / np.hypot(*(p - np.asarray(segment.center_xy)))
    left = np.array([-radial[1], radial[0]])
    return left if segment.counterclockwise else -left


# --- the outline ---------------------------------------------------------------------------------

def test_outline_is_closed_exactly_and_counterclockwise(gear):
    spec, outline = gear
    segs = outline.segments
    for a, b in zip(segs, segs[1:] + segs[:1]):
        assert a.end_xy == b.start_xy
    for seg in segs:
        if isinstance(seg, Arc2D):
            r0 = math.dist(seg.start_xy, seg.center_xy)
            assert math.dist(seg.end_xy, seg.center_xy) == pytest.approx(r0, abs=1e-9)
    polygon = Polygon(_samples(segs, 5, closed=False))
    assert polygon.is_valid
    assert polygon.exterior.is_ccw
    # every tooth accounted for: the exact outline's area (dense reference) within the tolerance band
    space, _ = _exact_space(spec)
    pitch = 2.0 * math.pi / spec.teeth
    exact = Polygon(np.concatenate([_turn(space[1:], k * pitch) for k in range(spec.teeth)]))
    assert abs(polygon.area - exact.area) < exact.length * TOLERANCE_MM


def test_every_exact_point_lies_within_tolerance_of_the_arcs(gear):
    spec, outline = gear
    space, _ = _exact_space(spec)
    distance = _distance_to_outline(space, _near_space_zero(outline.segments, spec))
    assert distance.max() <= TOLERANCE_MM
    # and the other way round: the arcs stay within the tolerance of the exact curve
    pts = _samples(_near_space_zero(outline.segments, spec), 17)
    pts = pts[_in_space_zero(pts, spec)]
    assert _polyline_distance(pts, _exact_neighbourhood(spec)).max() <= TOLERANCE_MM


def test_root_and_tip_are_single_exact_arcs(gear):
    spec, outline = gear
    on_axis = [s for s in outline.segments if isinstance(s, Arc2D) and s.center_xy == (0.0, 0.0)]
    radii = sorted({round(math.dist(s.start_xy, (0.0, 0.0)), 9) for s in on_axis})
    assert radii == [pytest.approx(spec.root_radius_mm, abs=1e-9), pytest.approx(spec.tip_radius_mm, abs=1e-9)]
    assert len(on_axis) == 2 * spec.teeth


def test_joints_are_tangent_except_at_the_tip_corners_and_the_undercut(gear):
    spec, outline = gear
    segs = outline.segments
    corners = []
    for a, b in zip(segs, segs[1:] + segs[:1]):
        turn = math.degrees(abs(math.asin(np.clip(_cross(_tangent_at(a, True), _tangent_at(b, False)), -1, 1))))
        if turn > 1e-6:
            corners.append(math.dist(a.end_xy, (0.0, 0.0)))
    corners = np.array(corners)
    at_tip = np.isclose(corners, spec.tip_radius_mm, atol=1e-9)
    at_junction = np.isclose(corners, spec.form_radius_mm, atol=1e-6)
    assert at_tip.sum() == 2 * spec.teeth
    assert at_junction.sum() == (2 * spec.teeth if spec.undercut else 0)
    assert np.all(at_tip | at_junction)


def test_fit_biarcs_fits_a_circle_and_a_sine_within_tolerance():
    t = np.linspace(0.0, 1.5, 400)
    circle = np.stack([5 * np.cos(t), 5 * np.sin(t)], axis=-1)
    tangents = np.stack([-np.sin(t), np.cos(t)], axis=-1)
    arcs = fit_biarcs(circle, tangents, 1e-4)
    assert len(arcs) == 2  # a circle is fitted by one biarc of two arcs on it
    assert all(abs(math.dist(a.center_xy, (0, 0)) < 1e-9) for a in arcs)
    x = np.linspace(0.0, 6.0, 3000)
    sine = np.stack([x, np.sin(x)], axis=-1)
    tan = np.stack([np.ones_like(x), np.cos(x)], axis=-1)
    tan /= np.hypot(*tan.T)[:, None]
    arcs = fit_biarcs(sine, tan, 1e-4)
    dense_x = np.linspace(0.0, 6.0, 20001)
    assert _distance_to_outline(np.stack([dense_x, np.sin(dense_x)], axis=-1), arcs).max() <= 1e-4
    for a, b in zip(arcs, arcs[1:]):
        assert a.end_xy == b.start_xy
        assert np.allclose(_tangent_at(a, True), _tangent_at(b, False), atol=1e-9)


# --- the offset ----------------------------------------------------------------------------------

@pytest.mark.parametrize("distance_mm", [0.15, -0.15, 0.02])
def test_offset_is_the_set_of_points_at_the_distance(gear, distance_mm):
    spec, outline = gear
    offset = offset_outline(outline, distance_mm)
    segs = offset.segments
    for a, b in zip(segs, segs[1:] + segs[:1]):
        assert a.end_xy == b.start_xy
    exact = _exact_neighbourhood(spec)
    # every offset point is |d| from the exact outline, on the right side
    pts = _samples(_near_space_zero(segs, spec), 9)
    pts = pts[_in_space_zero(pts, spec)]
    assert np.abs(_polyline_distance(pts, exact) - abs(distance_mm)).max() <= 0.001
    space, _ = _exact_space(spec)
    pitch = 2.0 * math.pi / spec.teeth
    gear_polygon = Polygon(np.concatenate([_turn(space[1:], k * pitch) for k in range(spec.teeth)]))
    inside = np.array([gear_polygon.contains(ShapelyPoint(p)) for p in pts[::7]])
    assert np.all(inside == (distance_mm < 0))
    # every exact point moved along its normal lies on the offset, unless it fell into a trimmed loop
    space, normals = _exact_space(spec)
    moved = space + distance_mm * normals
    on_true_offset = _polyline_distance(moved, exact) >= abs(distance_mm) - 1e-7
    assert on_true_offset.mean() > 0.9
    distance = _distance_to_outline(moved[on_true_offset], _near_space_zero(segs, spec))
    assert distance.max() <= 0.001


@pytest.mark.parametrize(("name", "distance_mm"), [("reference", 3.0), ("undercut_m1_z12", 0.5),
                                                   ("undercut_m1_z12", -0.6)])
def test_offset_removes_arcs_that_shrink_to_nothing(name, distance_mm):
    """Larger than the fillet's (or, inward, the flank's) curvature radius: those arcs go, the rest still lies
    exactly |d| from the outline, on the right side."""
    spec = _gear(name)
    outline = gear_outline_arcs(spec, TOLERANCE_MM)
    offset = offset_outline(outline, distance_mm)
    assert len(offset.segments) < len(outline.segments)
    pts = _samples(_near_space_zero(offset.segments, spec), 9)
    pts = pts[_in_space_zero(pts, spec)]
    assert np.abs(_polyline_distance(pts, _exact_neighbourhood(spec)) - abs(distance_mm)).max() <= 0.001


def test_offset_that_breaks_the_outline_is_refused():
    outline = gear_outline_arcs(_gear("undercut_m1_z12"), TOLERANCE_MM)
    for distance_mm in (3.0, -1.0):  # spaces filled outward; teeth eaten inward
        with pytest.raises(ValueError, match="breaks the outline"):
            offset_outline(outline, distance_mm)
    with pytest.raises(ValueError, match="finite"):
        offset_outline(outline, float("nan"))
