"""Helical gears against independent references: textbook / ISO 21771 quantities from the normal
section (tests/textbook.py's HelicalTextbook, written from scratch), the transverse section against a
brute-force envelope of the transverse rack (the normal rack stretched by 1 / cos(beta), elliptic tip
rounds), the B-rep against exact helicoid points at several X both ways, span/ball/chordal formulas,
and the job file and command line."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from shapely.geometry import Polygon
from shapely.ops import unary_union

from spur_cad.errors import GearSpecError
from spur_cad.geometry import GearSpec, gear_outline, sample_profile
from spur_cad.geometry.inspection import (
    chordal_thickness,
    inspection_sheet,
    minimum_teeth_without_undercut,
    over_pins,
    span_measurement,
    span_min_face_width_mm,
)
from spur_cad.geometry.profile import SEGMENT_LABELS
from tests.textbook import HelicalTextbook, inv, inv_inverse
from tests.tiers import sweep

# name: (z, m_n, alpha_n, beta, x, rho, allowance fraction, hand)
HELICAL = {
    "reference_15_right": (23, 4.0, 20.0, 15.0, 0.0, 0.8, 0.05, "right"),
    "z31_30_left_shifted": (31, 2.0, 20.0, 30.0, 0.3, 0.5, 0.0, "left"),
    "z12_20_undercut": (12, 3.0, 20.0, 20.0, 0.0, 0.6, 0.02, "right"),
    "z40_25pa_10": (40, 1.5, 25.0, 10.0, -0.2, 0.3, 0.0, "right"),
}


def spec_of(name: str, face_width: float = 20.0) -> GearSpec:
    z, mn, an, beta, x, rho, frac, hand = HELICAL[name]
    return GearSpec(teeth=z, module_mm=mn, pressure_angle_deg=an, profile_shift_coefficient=x,
                    rack_tip_radius_mm=rho, thickness_allowance_fraction=frac, face_width_mm=face_width,
                    helix_angle_deg=beta, hand=hand)


def book_of(name: str) -> HelicalTextbook:
    z, mn, an, beta, x, rho, frac, _ = HELICAL[name]
    return HelicalTextbook(z, mn, an, beta, x=x, rho=rho, allowance_fraction=frac)


@pytest.mark.parametrize("name", sorted(HELICAL))
def test_transverse_quantities_match_the_textbook(name):
    spec, g = spec_of(name), book_of(name)
    assert spec.transverse_module_mm == pytest.approx(g.mt, rel=1e-14)
    assert spec.pressure_angle_rad == pytest.approx(g.alpha_t, rel=1e-14)
    for ours, theirs in ((spec.reference_radius_mm, g.r), (spec.base_radius_mm, g.rb), (spec.tip_radius_mm, g.ra),
                         (spec.root_radius_mm, g.rf), (spec.tooth_thickness_mm, g.st), (spec.lead_mm, g.lead)):
        assert ours == pytest.approx(theirs, rel=1e-13)
    assert spec.base_helix_angle_rad == pytest.approx(g.beta_b, rel=1e-13)
    assert spec.describe()["overlap_ratio"] == pytest.approx(20.0 * math.sin(g.beta) / (math.pi * g.mn))
    # the section turns by X tan(beta) / r, the sign by the hand
    sign = 1 if HELICAL[name][7] == "right" else -1
    assert spec.section_turn_rad(7.0) == pytest.approx(sign * 7.0 * math.tan(g.beta) / g.r)


@pytest.mark.parametrize("name", sweep(sorted(HELICAL), fast=["z12_20_undercut"]))  # 5 s each
def test_transverse_section_is_the_envelope_of_the_elliptic_rack_within_1um(name):
    """No position of the transverse rack (the normal rack stretched by 1 / cos(beta)) enters the tooth by more
    than 1 um, and every sampled point of root, fillet and involute is reached within 1 um."""
    spec, g = spec_of(name), book_of(name)
    tolerance = 1e-5
    gear = Polygon(gear_outline(spec, tolerance))
    shapely.prepare(gear)
    rack = g.transverse_rack_outline(g.ra - g.r + 0.5 * g.mn, corner_points=256)
    phis = np.linspace(-4.5 * math.pi / g.z, 4.5 * math.pi / g.z, 3601)
    placed = [g.to_gear(phi, rack) for phi in phis]
    vertices = shapely.points(np.concatenate(placed))
    inside = vertices[gear.contains(vertices)]
    depth = float(gear.exterior.distance(inside).max()) if len(inside) else 0.0
    assert depth < 1e-3 + tolerance, depth
    swept = unary_union([Polygon(p) for p in placed])
    samples = sample_profile(spec.tooth_space_profile(), tolerance)
    mask = samples.labels != SEGMENT_LABELS.index("tip")
    gaps = swept.distance(shapely.points(samples.points[mask]))
    assert gaps.max() < 1e-3, gaps.max()


def test_a_helix_angle_of_zero_is_the_spur_gear_bit_for_bit():
    spur = GearSpec(teeth=23, module_mm=4.0, rack_tip_radius_mm=0.8, thickness_allowance_fraction=0.05,
                    face_width_mm=20.0)
    zero = GearSpec(teeth=23, module_mm=4.0, rack_tip_radius_mm=0.8, thickness_allowance_fraction=0.05,
                    face_width_mm=20.0, helix_angle_deg=0.0, hand="left")
    assert spur.tooth_space_profile() == zero.tooth_space_profile()
    assert sample_profile(spur.tooth_space_profile(), 1e-4).points.tobytes() == \
        sample_profile(zero.tooth_space_profile(), 1e-4).points.tobytes()
    assert inspection_sheet(spur) == inspection_sheet(zero)


# --------------------------------------------------------------------------- inspection


@pytest.mark.parametrize("name", sorted(HELICAL))
def test_span_balls_and_chordal_thickness_match_the_textbook(name):
    spec, g = spec_of(name), book_of(name)
    an, at = g.alpha_n, g.alpha_t
    for k in (2, 3, 4):
        nominal = g.mn * math.cos(an) * ((k - 0.5) * math.pi + g.z * inv(at)) + 2 * g.x * g.mn * math.sin(an)
        expected = nominal - g.delta_st * math.cos(g.beta) * math.cos(an)  # the thinning, normal, on the tangent
        assert span_measurement(spec, k).length_mm == pytest.approx(expected, rel=1e-12)
    diameter = 1.7 * g.mn
    inv_phi = (inv(at) + diameter / (g.mn * g.z * math.cos(an)) - math.pi / (2 * g.z)
               + 2 * g.x * math.tan(an) / g.z - g.delta_st / (g.mt * g.z))
    d_m = g.mt * g.z * math.cos(at) / math.cos(inv_inverse(inv_phi))
    expected = d_m + diameter if g.z % 2 == 0 else d_m * math.cos(math.pi / (2 * g.z)) + diameter
    assert over_pins(spec, diameter).dimension_mm == pytest.approx(expected, rel=1e-12)
    if g.allowance_fraction == 0.0:  # the virtual-gear formula for the nominal normal chordal thickness
        zv = g.z / math.cos(g.beta) ** 3
        psi = math.pi / (2 * zv) + 2 * g.x * math.tan(an) / zv
        chord = chordal_thickness(spec)
        assert chord.chordal_thickness_mm == pytest.approx(zv * g.mn * math.sin(psi), rel=1e-12)
        assert chord.chordal_height_mm == pytest.approx((1 + g.x) * g.mn + zv * g.mn / 2 * (1 - math.cos(psi)),
                                                        rel=1e-12)
    # undercut threshold: (h_f - x) m_n - rho (1 - sin a_n) = r sin^2(a_t) at z_min
    z_min = 2 * math.cos(g.beta) * ((g.hf - g.x) * g.mn - g.rho * (1 - math.sin(an))) / (g.mn * math.sin(at) ** 2)
    assert minimum_teeth_without_undercut(spec) == pytest.approx(z_min, rel=1e-12)
    assert spec.undercut == (g.z < z_min)


def test_the_span_needs_enough_face_width_and_is_left_out_when_none_fits():
    wide = spec_of("reference_15_right", 20.0)
    sheet = inspection_sheet(wide)
    k = sheet.span_teeth_k
    assert sheet.span_measurement_mm == pytest.approx(span_measurement(wide, k).length_mm)
    length = span_measurement(wide, k).length_mm
    assert sheet.span_min_face_width_mm == pytest.approx(length * math.sin(book_of("reference_15_right").beta_b))
    narrow = spec_of("reference_15_right", 3.0)
    sheet = inspection_sheet(narrow)
    assert sheet.span_teeth_k < k
    fits = span_min_face_width_mm(narrow, span_measurement(narrow, sheet.span_teeth_k)) < 3.0
    assert (sheet.span_measurement_mm is None) == (not fits)
    thin = spec_of("reference_15_right", 0.5)
    assert inspection_sheet(thin).span_measurement_mm is None


# --------------------------------------------------------------------------- B-rep


@pytest.fixture(scope="module")
def helical_solid():
    from spur_cad.cad.solid import build_gear_shape

    spec = spec_of("reference_15_right")
    shape, report = build_gear_shape(spec)
    return spec, shape


def _lateral_faces(shape):
    import cadquery as cq

    return [f for f in cq.Shape.cast(shape).Faces() if abs(f.normalAt().x) < 0.99]


@pytest.mark.slow
@pytest.mark.parametrize("hand", ["right", "left"])
def test_brep_sections_are_the_transverse_outline_turned_by_the_helix_within_half_a_micron(hand, helical_solid):
    """Both ways, at the front, middle and back: exact outline points turned by X tan(beta) / r lie on the
    solid's lateral faces, and points sampled on those faces, turned back by their own X, lie on the outline."""
    import cadquery as cq
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape
    from OCP.gp import gp_Pnt

    from spur_cad.cad.solid import build_gear_shape
    from tests.textbook import point_polyline_distance

    spec, shape = helical_solid
    if hand == "left":
        spec = spec_of("reference_15_right").__class__(**{**_fields(spec), "hand": "left"})
        shape, _ = build_gear_shape(spec)
    g = book_of("reference_15_right")
    sign = 1 if hand == "right" else -1
    faces = _lateral_faces(shape)
    reach = 1.5 * math.pi / g.z + spec.face_width_mm * math.tan(g.beta) / g.r
    near = [f for f in faces if abs(math.atan2(f.Center().y, f.Center().z)) < reach]  # around tooth space 0
    compound = cq.Compound.makeCompound(near).wrapped
    exact = gear_outline(spec, 1e-6)  # chords within 0.001 um
    space = exact[np.abs(np.arctan2(exact[:, 0], exact[:, 1])) < 1.2 * math.pi / g.z]  # around space 0
    worst_on = 0.0
    for x in (0.0, 10.0, 20.0):
        turn = sign * x * math.tan(g.beta) / g.r
        c, s = math.cos(turn), math.sin(turn)
        for p in space[:: max(1, len(space) // 150)]:
            y, z = p[0] * c - p[1] * s, p[0] * s + p[1] * c
            extrema = BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeVertex(gp_Pnt(x, y, z)).Vertex(), compound)
            extrema.Perform()
            worst_on = max(worst_on, extrema.Value())
    assert worst_on < 5e-4, worst_on
    # the other way: surface points, turned back by their own X, on the exact outline
    closed = np.vstack([exact, exact[:1]])
    samples = []
    for face in faces[:: max(1, len(faces) // 40)]:
        u0, u1, v0, v1 = face._uvBounds()
        for u in np.linspace(0.05, 0.95, 5):
            for v in np.linspace(0.0, 1.0, 5):
                p = face.positionAt(u0 + u * (u1 - u0), v0 + v * (v1 - v0))  # surface parameters
                samples.append((p.x, p.y, p.z))
    samples = np.array(samples)
    assert np.ptp(samples[:, 0]) > 10.0  # the samples cover the face width
    turn = -sign * samples[:, 0] * math.tan(g.beta) / g.r
    back = np.stack([samples[:, 1] * np.cos(turn) - samples[:, 2] * np.sin(turn),
                     samples[:, 1] * np.sin(turn) + samples[:, 2] * np.cos(turn)], axis=-1)
    assert point_polyline_distance(back, closed).max() < 5e-4
    # a wrong hand would be off by millimetres (the planted fault)
    wrong = np.stack([samples[:, 1] * np.cos(-turn) - samples[:, 2] * np.sin(-turn),
                      samples[:, 1] * np.sin(-turn) + samples[:, 2] * np.cos(-turn)], axis=-1)
    far = samples[:, 0] > samples[:, 0].min() + 0.5 * np.ptp(samples[:, 0])
    assert point_polyline_distance(wrong[far], closed).max() > 0.1


def _fields(spec: GearSpec) -> dict:
    import dataclasses

    return {f.name: getattr(spec, f.name) for f in dataclasses.fields(spec) if not f.name.startswith("_")}


def test_brep_is_valid_its_volume_is_area_times_width_and_step_round_trips(helical_solid, tmp_path):
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
    from OCP.TopAbs import TopAbs_SHELL
    from OCP.TopExp import TopExp_Explorer

    from spur_cad.cad.solid import front_face_area_mm2, solid_volume_mm3
    from tests.ocp_helper import read_step

    spec, shape = helical_solid
    assert BRepCheck_Analyzer(shape).IsValid()
    shells = TopExp_Explorer(shape, TopAbs_SHELL)
    assert shells.More()
    shells.Next()
    assert not shells.More()  # one shell
    area = Polygon(gear_outline(spec, 1e-7)).area
    volume = solid_volume_mm3(shape)
    assert volume == pytest.approx(area * spec.face_width_mm, rel=1e-6)  # OCP integrates the swept faces
    assert front_face_area_mm2(shape) == pytest.approx(area, rel=1e-6)  # summary.json's volume / b
    path = tmp_path / "helical.step"
    writer = STEPControl_Writer()
    writer.Transfer(shape, STEPControl_AsIs)
    writer.Write(str(path))
    back = read_step(path)
    assert BRepCheck_Analyzer(back).IsValid() and solid_volume_mm3(back) == pytest.approx(volume, rel=1e-6)


# --------------------------------------------------------------------------- job file and command line


HELICAL_JOB = """[job]
name = "helical"
[gear]
teeth = 23
module_mm = 4.0
rack_tip_radius_mm = 0.8
face_width_mm = 20.0
helix_angle_deg = 15.0
hand = "left"
"""


def test_job_file_takes_helix_and_hand_and_refuses_bad_values():
    from spur_cad.job import JobFileError, parse_job

    job = parse_job(HELICAL_JOB)
    assert job.gear.helix_angle_deg == 15.0 and job.gear.hand == "left" and job.gear.is_helical
    with pytest.raises((JobFileError, GearSpecError), match="hand"):
        parse_job(HELICAL_JOB.replace('"left"', '"up"'))
    with pytest.raises((JobFileError, GearSpecError), match="helix_angle_deg") as caught:
        parse_job(HELICAL_JOB.replace("15.0", "50.0"), "h.toml")
    assert "h.toml:8" in str(caught.value)


@pytest.mark.slow
def test_spur_cad_run_writes_the_helical_job_and_refuses_a_wrong_corner_naming_the_key(tmp_path):
    import json
    from pathlib import Path

    from tests.test_cli import run_cli

    example = Path(__file__).resolve().parents[1] / "resources" / "examples" / "helical_gear.toml"
    result = run_cli("run", str(example), "--out", str(tmp_path / "out"))
    assert result.returncode == 0, result.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["gear"]["helix_angle_deg"] == 15.0 and summary["gear"]["hand"] == "right"
    g = book_of("reference_15_right")
    assert summary["gear"]["lead_mm"] == pytest.approx(g.lead)
    assert summary["roughing"]["moves"] > 1000 and summary["finishing"]["strategy"] == "generating"
    simulation = summary["simulation"]
    assert simulation["max_gouge_mm"] <= 0.005 and simulation["max_leftover_mm"] <= 0.005 + 0.005
    assert simulation["uncut_points"] == 0
    assert summary["finishing"]["perimeter_time_s"] is None  # perimeter is for spur gears only
    assert "G93" in (tmp_path / "out" / "roughing.ngc").read_text()
    assert "G93" not in (tmp_path / "out" / "finishing.ngc").read_text()
    assert f"(helix: beta = 15 deg right hand [m and alpha normal], lead {g.lead:.4f} mm: along it A changes by " \
        f"{-360.0 / g.lead:+.6f} deg per mm of X)" in \
        (tmp_path / "out" / "finishing.ngc").read_text()
    assert summary["inspection"]["span_measurement_mm"] == pytest.approx(
        span_measurement(spec_of("reference_15_right"), summary["inspection"]["span_teeth_k"]).length_mm)
    area = Polygon(gear_outline(spec_of("reference_15_right"), 1e-6)).area
    assert summary["cad"]["gear_volume_mm3"] == pytest.approx(area * 20.0, rel=1e-6)
    assert (tmp_path / "out" / "gear.step").stat().st_size > 100_000
    report = (tmp_path / "out" / "report.html").read_text()
    assert f"normal section; needs face width &gt; {summary['inspection']['span_min_face_width_mm']:.2f} mm" in report
    assert f'<th>lead</th><td class="num">{summary["gear"]["lead_mm"]:.3f}</td><td class="unit">mm</td>' in report
    job = tmp_path / "helical.toml"
    with_tools = HELICAL_JOB + "[tools.finishing]\nkind = 'bull_nose'\ndiameter_mm = 2.0\ncorner_radius_mm = 0.9\n"
    job.write_text(with_tools)
    result = run_cli("run", str(job), "--out", str(tmp_path / "out2"))
    assert result.returncode == 2 and len(result.stderr.strip().splitlines()) == 1, result.stderr
    line = 1 + with_tools.splitlines().index("corner_radius_mm = 0.9")
    assert f"helical.toml:{line}: " in result.stderr, result.stderr
    assert "larger than the rack tip radius rho = 0.8" in result.stderr, result.stderr
    assert not (tmp_path / "out2").exists()
