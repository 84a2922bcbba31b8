"""Internal spur gears: the shaper-cut ring's exact profile against an independent envelope of the cutter's rolling
motion, the checks' one-line messages, the inspection sheet against independent formulas, the ring's B-rep."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from scipy.optimize import brentq
from shapely.geometry import Polygon

from spur_cad.errors import GearSpecError, JobFileError
from spur_cad.geometry import gear_outline, sample_profile
from spur_cad.geometry.inspection import inspection_sheet
from spur_cad.geometry.internal import InternalGearSpec
from spur_cad.geometry.spec import GearSpec
from spur_cad.job import parse_job
from tests.textbook import inv

RING = dict(teeth=60, module_mm=2.0, addendum_coefficient=0.9, rack_tip_radius_mm=0.4, shaper_cutter_teeth=20,
            rim_outer_diameter_mm=140.0, face_width_mm=10.0)


def _ring(**changes) -> InternalGearSpec:
    return InternalGearSpec(**{**RING, **changes})


def _cutter_polygon(ring: InternalGearSpec) -> np.ndarray:
    """The cutter as a dense polygon, a tooth on +y: the external gear the rack generates (spur_cad's external
    code) with its tip corners rounded independently, by a morphological opening with a disc of radius rho."""
    cutter = GearSpec(teeth=ring.shaper_cutter_teeth, module_mm=ring.module_mm,
                      pressure_angle_deg=ring.pressure_angle_deg,
                      profile_shift_coefficient=ring.shaper_cutter_profile_shift_coefficient,
                      addendum_coefficient=ring.dedendum_coefficient, dedendum_coefficient=ring.dedendum_coefficient,
                      rack_tip_radius_mm=ring.rack_tip_radius_mm)
    outline = gear_outline(cutter, 2e-5)
    turn = math.pi / cutter.teeth  # space 0 on +y -> tooth 0 on +y
    c, s = math.cos(turn), math.sin(turn)
    outline = outline @ np.array([[c, -s], [s, c]])
    rho = ring.rack_tip_radius_mm
    opened = Polygon(outline).buffer(-rho, quad_segs=512).buffer(rho, quad_segs=512)
    ring_xy = np.asarray(opened.exterior.coords)[:-1]
    angle = np.arctan2(ring_xy[:, 0], ring_xy[:, 1])
    start = int(np.argmin(np.abs(np.abs(angle) - math.pi)))  # a vertex opposite tooth 0: teeth near +y contiguous
    ring_xy, angle = np.roll(ring_xy, -start, axis=0), np.roll(angle, -start)
    keep = np.abs(angle) < 4.5 * 2.0 * math.pi / cutter.teeth
    return ring_xy[keep]


def _cutting_centre_distance_mm(ring: InternalGearSpec) -> float:
    """Textbook internal mesh without backlash (no allowance): inv(a_w) = inv(a) - 2 tan(a) (x + x_0) / (z - z_0),
    a_0 = m (z - z_0) cos(a) / (2 cos(a_w))."""
    alpha = math.radians(ring.pressure_angle_deg)
    z, z0 = ring.teeth, ring.shaper_cutter_teeth
    inv_w = inv(alpha) - 2.0 * math.tan(alpha) * (ring.profile_shift_coefficient
                                                   + ring.shaper_cutter_profile_shift_coefficient) / (z - z0)
    alpha_w = brentq(lambda a: inv(a) - inv_w, 1e-6, 1.2)
    return ring.module_mm * (z - z0) * math.cos(alpha) / (2.0 * math.cos(alpha_w))


def _placed(vertices: np.ndarray, lam: float, ring: InternalGearSpec) -> np.ndarray:
    """The cutter's vertices when its centre is at a_0 (sin l, cos l) and its pitch circle rolled without slip
    inside the ring's (the cutter turned clockwise by l (1 - z / z_0) from tooth 0 on +y)."""
    a0 = _cutting_centre_distance_mm(ring)
    turn = lam * (1.0 - ring.teeth / ring.shaper_cutter_teeth)
    c, s = math.cos(turn), math.sin(turn)
    x = vertices[:, 0] * c + vertices[:, 1] * s
    y = -vertices[:, 0] * s + vertices[:, 1] * c
    return np.stack([x + a0 * math.sin(lam), y + a0 * math.cos(lam)], -1)


def _right_crossings(points: np.ndarray, radii: np.ndarray, half_pitch: float) -> np.ndarray:
    """For each radius R: the largest polar angle (clockwise from +y, within one pitch of space 0) where the
    polygon's edges cross the circle R (-inf where none); the crossing solved on the straight edge."""
    a, b = points[:-1], points[1:]
    ra, rb = np.hypot(*a.T), np.hypot(*b.T)
    d = b - a
    out = np.full(len(radii), -np.inf)
    for i, radius in enumerate(radii):
        hit = (ra - radius) * (rb - radius) <= 0.0
        if not hit.any():
            continue
        pa, dd = a[hit], d[hit]
        qa, qb, qc = np.sum(dd * dd, 1), 2.0 * np.sum(pa * dd, 1), np.sum(pa * pa, 1) - radius * radius
        root = np.sqrt(np.maximum(qb * qb - 4.0 * qa * qc, 0.0))
        for t in ((-qb + root) / (2.0 * qa), (-qb - root) / (2.0 * qa)):
            ok = (t >= -1e-9) & (t <= 1.0 + 1e-9)
            p = pa[ok] + t[ok, None] * dd[ok]
            theta = np.arctan2(p[:, 0], p[:, 1])
            theta = theta[np.abs(theta) < half_pitch]
            if theta.size:
                out[i] = max(out[i], theta.max())
    return out


def _envelope_angles(ring: InternalGearSpec, radii: np.ndarray) -> np.ndarray:
    """The right edge of the region the rolling cutter sweeps, on each circle R: the largest crossing angle over
    cutter positions, from a coarse roll grid refined twice around each radius's best position."""
    cutter = _cutter_polygon(ring)
    half_pitch = math.pi / ring.teeth
    coarse = np.linspace(-0.6, 0.6, 1201)
    table = np.array([_right_crossings(_placed(cutter, lam, ring), radii, half_pitch) for lam in coarse])
    best = coarse[np.argmax(table, axis=0)]
    result = np.empty(len(radii))
    for i, radius in enumerate(radii):
        centre, width = best[i], 2e-3
        for _ in range(3):
            grid = np.linspace(centre - width, centre + width, 41)
            values = [_right_crossings(_placed(cutter, lam, ring), np.array([radius]), half_pitch)[0] for lam in grid]
            centre, width = grid[int(np.argmax(values))], width / 10.0
            result[i] = max(values)
    return result


@pytest.mark.slow  # a brute-force envelope (25 s); the ring's own profile checks below stay in the fast tier
def test_ring_profile_matches_an_independent_envelope_of_the_rolling_cutter():
    """z = 60, m = 2, cut by a 20-tooth cutter: fillet and involute within 1.5 um of the envelope (normal distance:
    the angular difference on the circle times the profile's radius and |n . e_theta|); root circle from the cutter's
    farthest reach."""
    ring = _ring()
    samples = sample_profile(ring.tooth_space_profile(), 2e-4)
    pts, normals = samples.points, samples.normals
    radius = np.hypot(*pts.T)
    theta = np.arctan2(pts[:, 0], pts[:, 1])
    e_theta = np.stack([np.cos(theta), -np.sin(theta)], -1)
    across = np.abs(np.sum(normals * e_theta, 1))
    use = (across > 0.2) & (radius > ring.tip_radius_mm + 0.01) & (radius < ring.root_radius_mm - 1e-4)
    assert use.sum() > 20
    envelope = _envelope_angles(ring, radius[use])
    deviation_mm = radius[use] * (envelope - theta[use]) * across[use]
    assert np.max(np.abs(deviation_mm)) < 1.5e-3, np.max(np.abs(deviation_mm))
    cutter = _cutter_polygon(ring)
    reach = max(np.hypot(*_placed(cutter, lam, ring).T).max() for lam in np.linspace(-1e-3, 1e-3, 21))
    assert reach == pytest.approx(ring.root_radius_mm, abs=1.5e-3)


@pytest.mark.parametrize("changes", [{}, {"teeth": 61, "profile_shift_coefficient": 0.2}])
def test_dimension_between_pins_against_khk_and_the_exact_profile(changes):
    """KHK's internal-gear formula inv(phi) = pi/(2z) + inv(a) - D/(z m cos a) - 2 x tan(a)/z, M = d_b/cos(phi) - D
    (odd z: times cos(90/z deg)); and the pin placed on the space axis at r_M touches the exact flank (D/2 from
    it, nowhere closer)."""
    ring = _ring(**changes)
    sheet = inspection_sheet(ring)
    z, m, x, pin = ring.teeth, ring.module_mm, ring.profile_shift_coefficient, sheet.pin_diameter_mm
    alpha = math.radians(ring.pressure_angle_deg)
    phi = brentq(lambda a: inv(a) - (math.pi / (2 * z) + inv(alpha) - pin / (z * m * math.cos(alpha))
                                     - 2 * x * math.tan(alpha) / z), 1e-6, 1.2)
    db = z * m * math.cos(alpha)
    factor = 1.0 if z % 2 == 0 else math.cos(math.pi / (2 * z))
    assert sheet.pins_between and sheet.span_measurement_mm is None
    assert sheet.dimension_over_pins_mm == pytest.approx(db / math.cos(phi) * factor - pin, abs=1e-9)
    centre = np.array([0.0, db / (2.0 * math.cos(phi))])
    flank = sample_profile(ring.tooth_space_profile(), 1e-5).points
    distance = np.hypot(*(flank - centre).T)
    assert distance.min() == pytest.approx(pin / 2.0, abs=2e-5)
    assert ring.tip_radius_mm < sheet.pin_contact_radius_mm < ring.form_radius_mm


@pytest.mark.parametrize("changes, key, words", [
    ({"addendum_coefficient": 1.0}, "addendum_coefficient", "involute interference"),
    ({"shaper_cutter_teeth": 50}, "shaper_cutter_teeth", "trimming"),
    ({"mating_pinion_teeth": 55}, "mating_pinion_teeth", "tip interference"),
    ({"rim_outer_diameter_mm": 128.0}, "rim_outer_diameter_mm", "rim"),
    ({"helix_angle_deg": 10.0}, "helix_angle_deg", "spur only"),
])
def test_checks_give_one_line_at_the_key(changes, key, words):
    with pytest.raises(GearSpecError) as caught:
        _ring(**changes)
    assert caught.value.field == key and words in str(caught.value) and "\n" not in str(caught.value)


def test_rotary_table_refuses_an_internal_gear_at_the_key():
    text = "\n".join(["[gear]", "teeth = 60", "module_mm = 2.0", "face_width_mm = 10.0", "addendum_coefficient = 0.9",
                      "rack_tip_radius_mm = 0.4", "internal = true", "shaper_cutter_teeth = 20",
                      "rim_outer_diameter_mm = 140.0", ""])
    assert parse_job(text, "ring.toml").gear.is_internal  # no tools: geometry, inspection, CAD only
    with pytest.raises(JobFileError) as caught:
        parse_job(text + "[tools.finishing]\ndiameter_mm = 2.0\n", "ring.toml")
    assert str(caught.value).startswith("ring.toml:7: internal = true: the rotary table cannot cut an internal gear")
    assert parse_job(text + "[tools.finishing]\ndiameter_mm = 2.0\n[machine]\naxes = 3\n", "ring.toml").gear.is_internal


@pytest.mark.slow  # the ring's B-rep and STEP (20 s); test_cad checks the external gear's in the fast tier
def test_ring_solid_is_valid_exact_and_survives_step(tmp_path):
    """The B-rep ring: OCP-valid; its face is pi R_rim^2 less the area inside the toothed outline (a prism: the
    volume is that times b); its mid-face section lies within 1 um of the exact outline and the rim circle; the
    STEP file reads back valid with the same face and bounding box."""
    import shapely
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Section
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.gp import gp_Dir, gp_Pln, gp_Pnt
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    from spur_cad.cad.solid import build_gear_shape, build_stock_shape, front_face_area_mm2
    from spur_cad.cad.step import step_files
    from spur_cad.geometry.sampling import polygon_area
    from tests.ocp_helper import exact_bounds, read_step

    ring = _ring()
    shape, _ = build_gear_shape(ring)
    assert BRepCheck_Analyzer(shape).IsValid()
    dense = gear_outline(ring, 1e-7)
    rim = ring.rim_outer_diameter_mm / 2.0
    area = math.pi * rim**2 - abs(polygon_area(dense))  # chords 0.1 um inside the outline: 3e-8 relative
    assert front_face_area_mm2(shape) == pytest.approx(area, rel=5e-8)
    section = BRepAlgoAPI_Section(shape, gp_Pln(gp_Pnt(5.0, 0, 0), gp_Dir(1, 0, 0)))
    points = []
    explorer = TopExp_Explorer(section.Shape(), TopAbs_EDGE)
    while explorer.More():
        curve = BRepAdaptor_Curve(TopoDS.Edge(explorer.Current()))
        for u in np.linspace(curve.FirstParameter(), curve.LastParameter(), 25):
            p = curve.Value(u)
            points.append((p.Y(), p.Z()))
        explorer.Next()
    points = np.array(points)
    on_rim = np.abs(np.hypot(*points.T) - rim) < 1e-6
    lines = shapely.linestrings(np.stack([dense, np.roll(dense, -1, axis=0)], axis=1))
    _, distance = shapely.STRtree(lines).query_nearest(shapely.points(points[~on_rim]), return_distance=True,
                                                       all_matches=False)
    assert on_rim.sum() > 0 and distance.max() < 1e-3
    files = step_files(shape, build_stock_shape(ring))
    (tmp_path / "gear.step").write_bytes(files["gear.step"])
    back = read_step(tmp_path / "gear.step")
    assert BRepCheck_Analyzer(back).IsValid()
    assert front_face_area_mm2(back) == pytest.approx(area, rel=5e-8)
    _, y_min, _, x_max, y_max, _ = exact_bounds(back)
    assert (y_min, y_max, x_max) == pytest.approx((-rim, rim, ring.face_width_mm), abs=1e-6)


def _loop_points(loop, per_segment: int = 12) -> np.ndarray:
    return np.concatenate([np.array([s.point_at(t) for t in np.linspace(0.0, 1.0, per_segment)])
                           for s in loop.segments])


def test_internal_outline_arcs_and_their_offset_lie_on_the_exact_curves():
    """internal_gear_outline_arcs: the rim circle counter-clockwise, the toothed loop clockwise (material on the
    left), closed, within 1 um of the exact outline; offset by 0.1 mm away from the material, every point lies
    0.1 mm from the exact inner outline (within 1 um) and the rim grows by 0.1 mm."""
    from spur_cad.geometry.outline2d import internal_gear_outline_arcs, offset_outline
    from spur_cad.geometry.sampling import polygon_area

    ring = _ring()
    rim, teeth = internal_gear_outline_arcs(ring, 1e-3)
    dense = gear_outline(ring, 1e-7)
    tree = shapely.STRtree(shapely.linestrings(np.stack([dense, np.roll(dense, -1, axis=0)], axis=1)))

    def distance_to_exact(xy: np.ndarray) -> np.ndarray:
        return tree.query_nearest(shapely.points(xy), return_distance=True, all_matches=False)[1]

    points = _loop_points(teeth)
    assert polygon_area(points) < 0.0 < polygon_area(_loop_points(rim))
    assert distance_to_exact(points).max() < 1e-3
    assert np.hypot(*_loop_points(rim).T) == pytest.approx(70.0, abs=1e-12)
    grown_rim, grown_teeth = offset_outline(rim, 0.1), offset_outline(teeth, 0.1)
    assert np.hypot(*_loop_points(grown_rim).T) == pytest.approx(70.1, abs=1e-12)
    moved = _loop_points(grown_teeth)
    assert np.abs(distance_to_exact(moved) - 0.1).max() < 1e-3
    assert shapely.Polygon(gear_outline(ring, 1e-4)).contains(shapely.points(moved)).all()  # into the air


def test_report_sheet_says_between_pins_and_no_span():
    from types import SimpleNamespace

    from spur_cad.report.sheet import inspection_rows

    ring = _ring()
    result = SimpleNamespace(inspection=inspection_sheet(ring), modifications=None, gear=ring, kind=ring.kind)
    rows = {row.label: row.value for row in inspection_rows(result)}
    assert rows["span measurement"].startswith("not for an internal gear")
    assert float(rows["dimension between pins (balls)"]) == pytest.approx(inspection_sheet(ring).dimension_over_pins_mm,
                                                                          abs=1e-4)
    assert not any("over pins" in label or "undercut" in label for label in rows)
