"""The exact tooth-space profile against independent references: involute relations, the
Willis/Camus law, the generating rack as a physical body (shapely), tangency, simplicity."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from scipy.optimize import brentq
from shapely.geometry import Polygon
from shapely.ops import unary_union

from spur_cad.geometry import SEGMENT_LABELS, gear_outline, sample_profile
from tests.gears import GEAR_CASES, spec_of, textbook_of
from tests.textbook import inv
from tests.tiers import sweep

ALL = list(GEAR_CASES)
FAST_GEARS = ["reference_z23_m4", "undercut_z8", "undercut_negative_shift_z14", "pa25_sharp_rack_z17"]
"""The gears whose envelope checks (fillet and generating rack) run in the fast tier: a plain, an undercut, a
negatively shifted undercut and a sharp-rack gear; the others in `make test-all`."""


def _labelled(samples, label):
    mask = samples.labels == SEGMENT_LABELS.index(label)
    return samples.points[mask], samples.normals[mask], samples.curvature_radii[mask]


@pytest.mark.parametrize("name", ALL)
def test_involute_satisfies_analytic_relations(name):
    spec, g = spec_of(name), textbook_of(name)
    pts, normals, radii = _labelled(sample_profile(spec.tooth_space_profile(), 1e-4), "involute")
    assert len(pts) > 5
    radius = np.hypot(pts[:, 0], pts[:, 1])
    polar = np.arctan2(pts[:, 0], pts[:, 1])
    alpha_y = np.arccos(g.rb / radius)
    # Polar angle = theta_b + inv(alpha_y): the involute relation, with theta_b from the textbook.
    expected_polar = g.theta_b + np.tan(alpha_y) - alpha_y
    assert np.max(np.abs(polar - expected_polar) * radius) < 1e-9
    # Tooth thickness at every radius (arc between this flank and the neighbouring tooth's mirror flank).
    thickness = radius * (2 * math.pi / g.z - 2 * polar)
    expected = np.array([g.thickness_at(r) for r in radius])
    assert np.max(np.abs(thickness - expected)) < 1e-9
    # Normals: unit, tangent to the base circle (line of action), pointing into the space (toward -x).
    assert np.allclose(np.hypot(normals[:, 0], normals[:, 1]), 1.0, atol=1e-12)
    lever = np.abs(pts[:, 0] * normals[:, 1] - pts[:, 1] * normals[:, 0])
    assert np.max(np.abs(lever - g.rb)) < 1e-9
    assert np.all(normals[:, 0] < 0)
    # Curvature radius = distance to the base-circle tangent point = sqrt(R^2 - r_b^2) (convex: negative).
    assert np.max(np.abs(-radii - np.sqrt(radius**2 - g.rb**2))) < 1e-9
    # Ends at the tip circle.
    assert abs(radius[-1] - g.ra) < 1e-9


@pytest.mark.parametrize("name", ALL)
def test_segments_join_and_root_arc_matches_rack_flat(name):
    spec, g = spec_of(name), textbook_of(name)
    profile = spec.tooth_space_profile()
    segments = profile.segments
    for before, after in zip(segments, segments[1:]):
        end = before.points(np.array([before.end]))[0]
        start = after.points(np.array([after.start]))[0]
        assert np.linalg.norm(end - start) < 1e-9, (before.label, after.label)
    root = profile.segment("root")
    # The flat rack tip spans d_1 each side of its axis: root arc half-angle d_1 / r (docs/method.md).
    assert root.end == pytest.approx(g.corner_offset / g.r, abs=1e-12)
    assert root.radius_mm == pytest.approx(g.rf, abs=1e-12)
    tip = profile.segment("tip")
    assert tip.end == pytest.approx(math.pi / g.z)


@pytest.mark.parametrize("name", [n for n in ALL if not spec_of(n).undercut])
def test_fillet_meets_involute_tangentially(name):
    profile = spec_of(name).tooth_space_profile()
    fillet, involute = profile.segment("fillet"), profile.segment("involute")
    p_f = fillet.points(np.array([fillet.end]))[0]
    p_i = involute.points(np.array([involute.start]))[0]
    n_f = fillet.normals(np.array([fillet.end]))[0]
    n_i = involute.normals(np.array([involute.start]))[0]
    assert np.linalg.norm(p_f - p_i) < 1e-9
    assert abs(math.atan2(n_f[0] * n_i[1] - n_f[1] * n_i[0], n_f @ n_i)) < 1e-9
    assert profile.junction_is_tangent and not profile.undercut
    assert profile.form_radius_mm == pytest.approx(float(np.hypot(*p_i)), abs=1e-9)


@pytest.mark.parametrize("name", [n for n in ALL if spec_of(n).undercut])
def test_undercut_junction_is_a_transverse_intersection(name):
    g = textbook_of(name)
    profile = spec_of(name).tooth_space_profile()
    assert profile.undercut and profile.undercut_depth_mm > 0
    fillet, involute = profile.segment("fillet"), profile.segment("involute")
    p_f = fillet.points(np.array([fillet.end]))[0]
    # The junction lies on the involute (textbook polar-angle relation) to 1e-9 mm ...
    radius = float(np.hypot(*p_f))
    ay = math.acos(g.rb / radius)
    assert abs(math.atan2(p_f[0], p_f[1]) - (g.theta_b + inv(ay))) * radius < 1e-9
    # ... and the curves cross there at an angle (not tangent).
    n_f = fillet.normals(np.array([fillet.end]))[0]
    n_i = involute.normals(np.array([involute.start]))[0]
    assert abs(math.atan2(n_f[0] * n_i[1] - n_f[1] * n_i[0], n_f @ n_i)) > 1e-3


@pytest.mark.parametrize("name", sweep(ALL, fast=FAST_GEARS))
def test_fillet_obeys_willis_camus_law(name):
    """Each fillet point's normal line passes through the pitch point of some instant phi, and at
    that instant the rack's corner circle (placed by the test's own kinematics) touches the
    point: its centre is rho along the normal."""
    spec, g = spec_of(name), textbook_of(name)
    pts, normals, _ = _labelled(sample_profile(spec.tooth_space_profile(), 1e-4), "fillet")
    assert len(pts) > 3
    for p, n in zip(pts, normals):
        # Signed distance of the pitch point P(phi) = (r sin phi, r cos phi) from the normal line.
        def off_line(phi, p=p, n=n):
            q = g.pitch_point(phi) - p
            return q[0] * n[1] - q[1] * n[0]

        # The generating instant is near the angular position of the point.
        centre_angle = math.atan2(p[0], p[1])
        grid = np.linspace(centre_angle - 1.5, centre_angle + 1.5, 601)
        values = np.array([off_line(phi) for phi in grid])
        roots = [brentq(off_line, a, b, xtol=1e-15) for a, b, va, vb in
                 zip(grid, grid[1:], values, values[1:]) if va * vb <= 0]
        assert roots, "no pitch point on the normal line"
        errors = [np.linalg.norm(g.corner_centre(phi) - (p + g.rho * n)) for phi in roots]
        assert min(errors) < 1e-9


def _gear_polygon(spec, tolerance):
    return Polygon(gear_outline(spec, tolerance))


@pytest.mark.parametrize("name", sweep(ALL, fast=FAST_GEARS))
def test_generating_rack_never_enters_the_tooth_and_touches_every_point(name):
    """The space is the envelope of the rack: no rack position overlaps the tooth material
    (beyond the sampling tolerance), and every profile point is reached by some position."""
    spec, g = spec_of(name), textbook_of(name)
    tolerance = 1e-4 * spec.module_mm
    gear = _gear_polygon(spec, tolerance)
    shapely.prepare(gear)
    tooth_height = g.ra - g.r + 0.5 * g.m
    rack = g.rack_tooth_outline(tooth_height, corner_points=64)
    phis = np.linspace(-4.5 * math.pi / g.z, 4.5 * math.pi / g.z, 1801)
    placed = [g.to_gear(phi, rack) for phi in phis]
    # Penetration: how deep any rack vertex (all on the exact rack outline) reaches into the material.
    vertices = shapely.points(np.concatenate(placed))
    inside = vertices[gear.contains(vertices)]
    depth = float(gear.exterior.distance(inside).max()) if len(inside) else 0.0
    assert depth < tolerance + 1e-6 * g.m, depth
    # Coverage: every sampled point of root, fillet and involute is reached by some rack position.
    swept = unary_union([Polygon(p) for p in placed])
    samples = sample_profile(spec.tooth_space_profile(), tolerance)
    mask = samples.labels != SEGMENT_LABELS.index("tip")
    gaps = swept.distance(shapely.points(samples.points[mask]))
    # The phi step (and the corner polygon) bound how closely discrete positions approach the envelope.
    assert gaps.max() < 1e-3 * g.m, gaps.max()


@pytest.mark.parametrize("name", ALL)
def test_outline_is_simple_closed_polygon(name):
    spec, g = spec_of(name), textbook_of(name)
    outline = gear_outline(spec, 1e-3)
    poly = Polygon(outline)
    assert poly.is_valid and poly.exterior.is_simple
    assert poly.exterior.is_ccw
    radius = np.hypot(outline[:, 0], outline[:, 1])
    assert radius.min() == pytest.approx(g.rf, abs=1e-9)
    assert radius.max() == pytest.approx(g.ra, abs=1e-9)


@pytest.mark.parametrize("name", ALL)
def test_fillet_curvature_matches_finite_differences(name):
    """The analytic fillet curvature radius agrees with the circle through three close exact points."""
    profile = spec_of(name).tooth_space_profile()
    fillet = profile.segment("fillet")
    betas = np.linspace(fillet.start, fillet.end, 25)[1:-1]
    h = 1e-4
    for b in betas:
        a, m, c = fillet.points(np.array([b - h, b, b + h]))
        # circumradius of triangle a, m, c
        ab, bc, ca = np.linalg.norm(m - a), np.linalg.norm(c - m), np.linalg.norm(a - c)
        cross = (m - a)[0] * (c - a)[1] - (m - a)[1] * (c - a)[0]
        circum = ab * bc * ca / (2 * abs(cross))
        analytic = abs(fillet.curvature_radii(np.array([b]))[0])
        assert circum == pytest.approx(analytic, rel=1e-4)
        # Positive curvature radius means the centre lies along the normal, on the space side.
        normal = fillet.normals(np.array([b]))[0]
        centre_side = np.sign(cross)  # > 0: turning left, i.e. toward the normal (left of travel)
        assert centre_side == np.sign(fillet.curvature_radii(np.array([b]))[0])
        assert normal @ np.array([-(c - a)[1], (c - a)[0]]) > 0


def test_minimum_teeth_without_undercut_splits_undercut_flag():
    """Just below the textbook z_min the gear is undercut, just above it is not."""
    from spur_cad.geometry import GearSpec
    from spur_cad.geometry.inspection import minimum_teeth_without_undercut

    m, rho, alpha = 2.0, 0.5, math.radians(20)
    z_min = 2 * ((1.25 * m - rho * (1 - math.sin(alpha))) / m) / math.sin(alpha) ** 2
    below, above = math.floor(z_min), math.ceil(z_min)
    assert GearSpec(teeth=below, module_mm=m, rack_tip_radius_mm=rho).undercut
    spec_above = GearSpec(teeth=above, module_mm=m, rack_tip_radius_mm=rho)
    assert not spec_above.undercut
    assert minimum_teeth_without_undercut(spec_above) == pytest.approx(z_min, rel=1e-12)
