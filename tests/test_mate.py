"""Gear pairs (spur_cad.geometry.mate) against independent figures: published worked examples at their printed
precision, and the textbook's pair formulas written out here (external and internal forms separately, without the
code's signed convention) within 1e-6 relative."""

from __future__ import annotations

import math

import numpy as np
import pytest

from spur_cad.geometry.mate import (
    GearPair,
    PairError,
    PairMember,
    pair_at_centre_distance,
    pair_facts,
    pair_problems,
)
from spur_cad.geometry.spec import GearSpec
from tests.textbook import inv, inv_inverse

REL = 1e-6


def _external_textbook(m, alpha_deg, z1, z2, x1, x2, ha1=1.0, ha2=1.0, hf1=1.25, hf2=1.25, ds1=0.0, ds2=0.0):
    """An external spur pair by the textbook (KHK / Niemann / ISO 21771 for z > 0), all magnitudes."""
    a0 = math.radians(alpha_deg)
    aw = inv_inverse(inv(a0) + 2 * math.tan(a0) * (x1 + x2) / (z1 + z2))
    a = m * (z1 + z2) / 2 * math.cos(a0) / math.cos(aw)
    r1, r2 = m * z1 / 2, m * z2 / 2
    rb1, rb2 = r1 * math.cos(a0), r2 * math.cos(a0)
    ra1, ra2 = r1 + (ha1 + x1) * m, r2 + (ha2 + x2) * m
    rf1, rf2 = r1 - (hf1 - x1) * m, r2 - (hf2 - x2) * m
    ga1, ga2 = math.sqrt(ra1**2 - rb1**2), math.sqrt(ra2**2 - rb2**2)
    eps = (ga1 + ga2 - a * math.sin(aw)) / (math.pi * m * math.cos(a0))
    sap1 = math.hypot(rb1, a * math.sin(aw) - ga2)
    sap2 = math.hypot(rb2, a * math.sin(aw) - ga1)
    rw1, rw2 = a * z1 / (z1 + z2), a * z2 / (z1 + z2)
    s1, s2 = m * (math.pi / 2 + 2 * x1 * math.tan(a0)) - ds1, m * (math.pi / 2 + 2 * x2 * math.tan(a0)) - ds2
    sw1 = 2 * rw1 * (s1 / (2 * r1) + inv(a0) - inv(aw))
    sw2 = 2 * rw2 * (s2 / (2 * r2) + inv(a0) - inv(aw))
    backlash = 2 * math.pi * rw1 / z1 - sw1 - sw2
    return dict(aw=math.degrees(aw), a=a, eps=eps, sap1=2 * sap1, sap2=2 * sap2, dw1=2 * rw1, dw2=2 * rw2,
                backlash=backlash, c1=a - ra1 - rf2, c2=a - ra2 - rf1, da1=2 * ra1, da2=2 * ra2)


def _check(facts, book):
    assert facts.working_pressure_angle_deg == pytest.approx(book["aw"], rel=REL)
    assert facts.centre_distance_mm == pytest.approx(book["a"], rel=REL)
    assert facts.transverse_contact_ratio == pytest.approx(book["eps"], rel=REL)
    assert facts.start_of_active_profile_diameter_mm == pytest.approx(book["sap1"], rel=REL)
    assert facts.mate_start_of_active_profile_diameter_mm == pytest.approx(book["sap2"], rel=REL)
    assert facts.operating_pitch_diameter_mm == pytest.approx(book["dw1"], rel=REL)
    assert facts.mate_operating_pitch_diameter_mm == pytest.approx(book["dw2"], rel=REL)
    assert facts.circumferential_backlash_mm == pytest.approx(book["backlash"], rel=REL, abs=1e-6)
    assert facts.tip_clearance_mm == pytest.approx(book["c1"], rel=REL, abs=1e-6)
    assert facts.root_clearance_mm == pytest.approx(book["c2"], rel=REL, abs=1e-6)


def test_shifted_external_pair_against_the_khk_sdp_worked_example():
    """KHK / SDP-SI "profile shifted spur gears" example: m 3, alpha 20, z 12/24, x 0.6/0.36. Published: inv(alpha_w)
    0.034317, alpha_w 26.0888 deg, centre distance increment factor y 0.83333, a 56.4999 mm, d_w 37.667/75.333 mm,
    tip diameters 44.840/79.400 mm (the example shortens the tips: h_a = (1 + y - x_other) m, given here as addendum
    coefficients 1 + y - (x1 + x2)), root diameters 32.100/66.660 mm, contact ratio 1.202."""
    alpha = math.radians(20.0)
    y = (12 + 24) / 2 * (math.cos(alpha) / math.cos(inv_inverse(inv(alpha) + 2 * math.tan(alpha) * 0.96 / 36)) - 1)
    ha = 1 + y - 0.96
    pair = GearPair(PairMember(12, profile_shift_coefficient=0.6, addendum_coefficient=ha),
                    PairMember(24, profile_shift_coefficient=0.36, addendum_coefficient=ha), module_mm=3.0)
    facts = pair_facts(pair)
    assert y == pytest.approx(0.83333, abs=5e-5)  # the table rounds a to 56.500 first
    assert inv(math.radians(facts.working_pressure_angle_deg)) == pytest.approx(0.034317, abs=1e-6)
    assert facts.working_pressure_angle_deg == pytest.approx(26.0888, abs=3e-4)  # KHK prints 26.0886
    assert facts.centre_distance_mm == pytest.approx(56.4999, abs=1e-4)
    assert (facts.operating_pitch_diameter_mm, facts.mate_operating_pitch_diameter_mm) == pytest.approx(
        (37.667, 75.333), abs=5e-4)
    assert (facts.tip_diameter_mm, facts.mate_tip_diameter_mm) == pytest.approx((44.840, 79.400), abs=5e-4)
    assert (facts.root_diameter_mm, facts.mate_root_diameter_mm) == pytest.approx((32.100, 66.660), abs=5e-4)
    assert facts.transverse_contact_ratio == pytest.approx(1.202, abs=5e-4)
    _check(facts, _external_textbook(3.0, 20.0, 12, 24, 0.6, 0.36, ha, ha))
    assert pair_problems(pair, facts) == []


def test_helical_pair_from_its_centre_distance_against_the_iso_21771_example():
    """A published ISO 21771:2007 worked example (eq. 62): z 31/30, m_n 3.5, alpha_n 20, beta 21 deg, a_w 116.5 mm:
    reference centre distance 114.3447280708 mm, alpha_t 21.2990642859 deg, alpha_wt 23.8707609654 deg, shift sum
    0.651877131252 (zero backlash). The pinion's x 0.291 is given; the mate's follows."""
    pair = GearPair(PairMember(31, profile_shift_coefficient=0.291), PairMember(30), module_mm=3.5,
                    helix_angle_deg=21.0, face_width_mm=40.0)
    solved = pair_at_centre_distance(pair, 116.5)
    facts = pair_facts(solved)
    assert solved.shift_sum == pytest.approx(0.651877131252, rel=1e-9)
    assert solved.mate.profile_shift_coefficient == pytest.approx(0.651877131252 - 0.291, rel=1e-9)
    assert facts.working_pressure_angle_deg == pytest.approx(23.8707609654, rel=1e-9)
    assert facts.reference_centre_distance_mm == pytest.approx(114.3447280708, rel=1e-9)
    assert facts.centre_distance_mm == pytest.approx(116.5, rel=1e-12)
    # Transverse contact ratio and overlap ratio written out (transverse module and pressure angle).
    beta, an = math.radians(21.0), math.radians(20.0)
    mt, at = 3.5 / math.cos(beta), math.atan(math.tan(an) / math.cos(beta))
    aw = math.radians(23.8707609654)
    x2 = 0.651877131252 - 0.291
    ra1, ra2 = mt * 31 / 2 + (1 + 0.291) * 3.5, mt * 30 / 2 + (1 + x2) * 3.5
    rb1, rb2 = mt * 31 / 2 * math.cos(at), mt * 30 / 2 * math.cos(at)
    eps = (math.sqrt(ra1**2 - rb1**2) + math.sqrt(ra2**2 - rb2**2) - 116.5 * math.sin(aw)) / (
        math.pi * mt * math.cos(at))
    assert facts.transverse_contact_ratio == pytest.approx(eps, rel=REL)
    assert facts.overlap_ratio == pytest.approx(40.0 * math.sin(beta) / (math.pi * 3.5), rel=1e-12)
    assert facts.total_contact_ratio == pytest.approx(eps + 40.0 * math.sin(beta) / (math.pi * 3.5), rel=REL)
    assert facts.circumferential_backlash_mm == pytest.approx(0.0, abs=1e-9)


def test_acceptance_pair_z40_z40_sap_and_backlash():
    """The issue's pair: z40 m1 2 % thinner, a z40 mate at the standard centre distance: SAP d = 38.564 mm by the
    textbook (and 38.5640 by hand: sqrt(r_b^2 + (a sin(alpha) - sqrt(r_a^2 - r_b^2))^2)); backlash = the thinning
    (the operating pitch circle is the reference circle)."""
    thinning = 0.02 * math.pi / 2
    facts = pair_facts(GearPair(PairMember(40, thickness_reduction_mm=thinning), PairMember(40), module_mm=1.0))
    assert round(facts.start_of_active_profile_diameter_mm, 3) == 38.564
    _check(facts, _external_textbook(1.0, 20.0, 40, 40, 0.0, 0.0, ds1=thinning))
    assert facts.circumferential_backlash_mm == pytest.approx(thinning, rel=1e-12)
    assert facts.centre_distance_mm == pytest.approx(40.0, rel=1e-15)
    assert facts.tip_clearance_mm == pytest.approx(0.25, rel=1e-12)


@pytest.mark.parametrize("z1, z2, x1, x2, ds1, ds2", [
    (17, 53, 0.3, -0.1, 0.05, 0.02),
    (25, 25, -0.2, 0.5, 0.0, 0.1),
    (9, 40, 0.6, 0.2, 0.03, 0.0),
])
def test_shifted_pairs_against_the_textbook_and_backlash_from_the_allowances(z1, z2, x1, x2, ds1, ds2):
    """Backlash at the working centre distance (zero at nominal thicknesses): the allowances carried to the
    operating pitch circle, (ds1 + ds2) cos(alpha) / cos(alpha_w)."""
    facts = pair_facts(GearPair(PairMember(z1, profile_shift_coefficient=x1, thickness_reduction_mm=ds1),
                                PairMember(z2, profile_shift_coefficient=x2, thickness_reduction_mm=ds2),
                                module_mm=2.0, pressure_angle_deg=20.0))
    book = _external_textbook(2.0, 20.0, z1, z2, x1, x2, ds1=ds1, ds2=ds2)
    _check(facts, book)
    carried = (ds1 + ds2) * math.cos(math.radians(20.0)) / math.cos(math.radians(book["aw"]))
    assert facts.circumferential_backlash_mm == pytest.approx(carried, rel=1e-9)


def _internal_textbook(m, alpha_deg, z1, z2, x1, x2_khk, ha1=1.0, ha2=1.0):
    """An internal pair by KHK's internal-gear table: pinion z1, ring z2 > z1, the ring's shift in KHK's sign
    (x2 > 0 moves its tips outward: its tip radius is r2 - (h_a - x2) m), inv(alpha_w) = 2 tan(alpha) (x2 - x1) /
    (z2 - z1) + inv(alpha), a = (z2 - z1) m / 2 cos(alpha) / cos(alpha_w), contact ratio (g_a1 - g_a2 + a
    sin(alpha_w)) / p_b, the ring's SAP at roll g_a1 + a sin(alpha_w), the pinion's at g_a2 - a sin(alpha_w)."""
    a0 = math.radians(alpha_deg)
    aw = inv_inverse(2 * math.tan(a0) * (x2_khk - x1) / (z2 - z1) + inv(a0))
    a = (z2 - z1) * m / 2 * math.cos(a0) / math.cos(aw)
    rb1, rb2 = m * z1 / 2 * math.cos(a0), m * z2 / 2 * math.cos(a0)
    ra1, ra2 = m * z1 / 2 + (ha1 + x1) * m, m * z2 / 2 - (ha2 - x2_khk) * m
    ga1, ga2 = math.sqrt(ra1**2 - rb1**2), math.sqrt(ra2**2 - rb2**2)
    eps = (ga1 - ga2 + a * math.sin(aw)) / (math.pi * m * math.cos(a0))
    return dict(aw=math.degrees(aw), a=a, eps=eps, sap_pinion=2 * math.hypot(rb1, ga2 - a * math.sin(aw)),
                sap_ring=2 * math.hypot(rb2, ga1 + a * math.sin(aw)), dw1=2 * a * z1 / (z2 - z1),
                dw2=2 * a * z2 / (z2 - z1), da2=2 * ra2)


@pytest.mark.parametrize("gear_is_ring", [False, True])
def test_internal_pair_against_the_khk_internal_gear_formulas(gear_is_ring):
    """KHK's internal example (m 3, z 16/24, x1 0, ring x2 +0.516 in KHK's sign, -0.516 in ISO's: inv(alpha_w)
    0.061857, centre distance increment y 0.4, a 13.2 mm) and the textbook's internal formulas, whichever gear is
    the ring."""
    pinion, ring = PairMember(16), PairMember(24, internal=True, profile_shift_coefficient=-0.516)
    pair = GearPair(ring, pinion, 3.0) if gear_is_ring else GearPair(pinion, ring, 3.0)
    facts = pair_facts(pair)
    book = _internal_textbook(3.0, 20.0, 16, 24, 0.0, 0.516)
    assert inv(math.radians(facts.working_pressure_angle_deg)) == pytest.approx(0.061857, abs=1e-6)
    assert facts.centre_distance_mm == pytest.approx(13.2, abs=1e-4)
    assert facts.working_pressure_angle_deg == pytest.approx(book["aw"], rel=REL)
    assert facts.centre_distance_mm == pytest.approx(book["a"], rel=REL)
    assert facts.transverse_contact_ratio == pytest.approx(book["eps"], rel=REL)
    saps = (book["sap_ring"], book["sap_pinion"]) if gear_is_ring else (book["sap_pinion"], book["sap_ring"])
    dws = (book["dw2"], book["dw1"]) if gear_is_ring else (book["dw1"], book["dw2"])
    assert (facts.start_of_active_profile_diameter_mm, facts.mate_start_of_active_profile_diameter_mm) == \
        pytest.approx(saps, rel=REL)
    assert (facts.operating_pitch_diameter_mm, facts.mate_operating_pitch_diameter_mm) == pytest.approx(dws, rel=REL)
    ring_tip = facts.tip_diameter_mm if gear_is_ring else facts.mate_tip_diameter_mm
    assert ring_tip == pytest.approx(book["da2"], rel=1e-12)


def _corner_intrusion_mm(z1, z2, m, x1, x2_iso, a, steps=12001):
    """Brute force, independent of any formula for tip interference: turn the pinion (z1, centre at distance a
    inside the ring z2, both at zero backlash in the symmetric start position: a pinion tooth and a ring space
    centred on the line of centres) through three pinion pitches on each side, and follow both pinions' tip
    corners in the ring's frame and the ring's tip corners in the pinion's frame. Returns how deep (mm along the
    arc) any corner enters the other gear's tooth (its involute thickness at the corner's radius); <= 0: clear."""
    alpha = math.radians(20.0)
    r1, r2 = m * z1 / 2, m * z2 / 2
    rb1, rb2 = r1 * math.cos(alpha), r2 * math.cos(alpha)
    ra1, ra2 = r1 + (1 + x1) * m, r2 - (1 + x2_iso) * m
    s1, s2 = m * (math.pi / 2 + 2 * x1 * math.tan(alpha)), m * (math.pi / 2 + 2 * x2_iso * math.tan(alpha))

    def npinv(angle):
        return np.tan(angle) - angle

    def half_pinion(r):  # half tooth angle of the pinion at radius r (external involute)
        return s1 / (2 * r1) + inv(alpha) - npinv(np.arccos(np.clip(rb1 / r, -1, 1)))

    def half_ring(r):  # half tooth angle of the ring at radius r (internal: thicker outward)
        return s2 / (2 * r2) - inv(alpha) + npinv(np.arccos(np.clip(rb2 / r, -1, 1)))

    phi1 = np.linspace(-3 * 2 * math.pi / z1, 3 * 2 * math.pi / z1, steps)
    phi2 = phi1 * z1 / z2
    centre = np.array([0.0, a])
    deepest = -math.inf
    tip1 = half_pinion(ra1)
    for corner in (tip1, -tip1):  # pinion corners in the ring's frame
        for k in range(z1):
            ang = corner + k * 2 * math.pi / z1 + phi1
            px, py = centre[0] - ra1 * np.sin(ang), centre[1] + ra1 * np.cos(ang)
            c, s = np.cos(-phi2), np.sin(-phi2)
            qx, qy = c * px - s * py, s * px + c * py
            r = np.hypot(qx, qy)
            polar = np.arctan2(-qx, qy)  # from +y, counter-clockwise
            rel = (polar - math.pi / z2) % (2 * math.pi / z2)
            rel = np.minimum(rel, 2 * math.pi / z2 - rel)  # angle from the nearest ring tooth's centre
            inside = r >= ra2
            depth = (half_ring(r) - rel) * r
            if np.any(inside):
                deepest = max(deepest, float(np.max(depth[inside])))
    tip2 = half_ring(ra2)
    for corner in (tip2, -tip2):  # ring corners in the pinion's frame
        for k in range(z2):
            ang = math.pi / z2 + corner + k * 2 * math.pi / z2 + phi2
            px, py = -ra2 * np.sin(ang), ra2 * np.cos(ang)
            px, py = px - centre[0], py - centre[1]
            c, s = np.cos(-phi1), np.sin(-phi1)
            qx, qy = c * px - s * py, s * px + c * py
            r = np.hypot(qx, qy)
            polar = np.arctan2(-qx, qy)
            rel = polar % (2 * math.pi / z1)
            rel = np.minimum(rel, 2 * math.pi / z1 - rel)  # from the nearest pinion tooth's centre
            inside = (r <= ra1) & (r >= rb1)
            depth = (half_pinion(r) - rel) * r
            if np.any(inside):
                deepest = max(deepest, float(np.max(depth[inside])))
    return deepest


@pytest.mark.parametrize("z1, z2, x1, x2, refused", [
    (20, 25, 0.5, -0.5, True), (20, 28, 0.5, -0.5, False), (30, 35, 0.0, 0.0, True), (30, 38, 0.0, 0.0, True),
    (30, 40, 0.0, 0.0, False), (20, 25, 0.0, -0.5, False), (16, 24, 0.0, -0.516, False)])
def test_internal_tip_interference_agrees_with_a_brute_force_mesh(z1, z2, x1, x2, refused):
    """The ring pair's trochoid (tip) interference refusal agrees with following every tip corner through the
    mesh (pairs without involute interference, some just either side of the limit: margins -0.045 and +0.21 deg)."""
    pair = GearPair(PairMember(z1, profile_shift_coefficient=x1),
                    PairMember(z2, internal=True, profile_shift_coefficient=x2), 1.0)
    facts = pair_facts(pair)
    intrusion = _corner_intrusion_mm(z1, z2, 1.0, x1, x2, facts.centre_distance_mm)
    problems = [str(p) for p in pair_problems(pair, facts)]
    assert not any("involute interference" in p for p in problems)
    assert any("tip interference" in p for p in problems) == refused
    assert (intrusion > 1e-6) == refused, intrusion


def test_a_mate_whose_sap_lies_well_above_the_generated_form_circle():
    """z40 m2, standard rack (tip radius 0.38 m), with a z14 mate shifted +0.4: the mate's tip meets the flank
    0.5 mm or more (in diameter) above the form circle the rack generates; no interference."""
    spec = GearSpec(teeth=40, module_mm=2.0, rack_tip_radius_mm=0.76, thickness_allowance_fraction=0.02)
    form = 2 * spec.form_radius_mm
    pair = GearPair(PairMember(40, thickness_reduction_mm=spec.thickness_reduction_mm, form_diameter_mm=form),
                    PairMember(14, profile_shift_coefficient=0.4), 2.0)
    facts = pair_facts(pair)
    book = _external_textbook(2.0, 20.0, 40, 14, 0.0, 0.4, ds1=spec.thickness_reduction_mm)
    _check(facts, book)
    assert facts.start_of_active_profile_diameter_mm - form >= 0.5
    assert pair_problems(pair, facts) == []


def test_centre_distance_round_trip_and_unreachable_distances():
    pair = GearPair(PairMember(12, profile_shift_coefficient=0.6), PairMember(24, profile_shift_coefficient=0.36), 3.0)
    a = pair_facts(pair).centre_distance_mm
    solved = pair_at_centre_distance(GearPair(pair.gear, PairMember(24), 3.0), a)
    assert solved.mate.profile_shift_coefficient == pytest.approx(0.36, abs=1e-12)
    base_sum = 3.0 * 36 / 2 * math.cos(math.radians(20.0))  # (d_b1 + d_b2) / 2: no pressure angle below it
    for impossible in (base_sum - 0.01, 70.0):
        with pytest.raises(PairError, match="cannot be reached") as caught:
            pair_at_centre_distance(pair, impossible)
        assert caught.value.field == "centre_distance_mm" and caught.value.section == "mate"


def test_refusals_name_the_problem():
    low_addendum = GearPair(PairMember(40, addendum_coefficient=0.5), PairMember(40, addendum_coefficient=0.5), 1.0)
    ratio = _external_textbook(1.0, 20.0, 40, 40, 0.0, 0.0, 0.5, 0.5)["eps"]
    assert ratio < 1.0
    assert [str(p) for p in pair_problems(low_addendum)] == [
        f"the transverse contact ratio {ratio:.4f} is below 1: the pair does not mesh continuously; more teeth, a "
        "larger addendum or a smaller centre distance"]
    # A z8 mate without shift: this gear's tips reach past the mate's base tangent point (involute interference).
    problems = pair_problems(GearPair(PairMember(60), PairMember(8), 1.0))
    assert any("involute interference: this gear's tips reach the mate's flank past" in str(p) for p in problems)
    # The mate's tips reach below this gear's form circle (given): root interference, at the addendum.
    facts = pair_facts(GearPair(PairMember(40), PairMember(40), 1.0))
    above_sap = facts.start_of_active_profile_diameter_mm + 0.01
    problems = pair_problems(GearPair(PairMember(40, form_diameter_mm=above_sap), PairMember(40), 1.0))
    assert len(problems) == 1 and problems[0].field == "addendum_coefficient"
    assert "root interference: the mate's tips reach this gear's fillet" in str(problems[0])
    assert pair_problems(GearPair(PairMember(40, form_diameter_mm=above_sap - 0.02), PairMember(40), 1.0)) == []


def test_member_and_pair_validation():
    with pytest.raises(PairError, match="teeth = 4"):
        PairMember(4)
    with pytest.raises(PairError, match="profile_shift_coefficient must be a finite number"):
        PairMember(20, profile_shift_coefficient=math.nan)
    with pytest.raises(PairError, match="two internal gears"):
        GearPair(PairMember(30, internal=True), PairMember(40, internal=True), 1.0)
    with pytest.raises(PairError, match="at least 5 teeth more"):
        GearPair(PairMember(20), PairMember(24, internal=True), 1.0)


def test_an_internal_pair_given_by_its_centre_distance():
    """KHK's internal form: cos(alpha_w) = (z_2 - z_1) m cos(alpha) / (2 a), x_2 - x_1 = (z_2 - z_1) (inv(alpha_w) -
    inv(alpha)) / (2 tan(alpha)) in KHK's sign (the ring's ISO shift is its negative)."""
    a = 15.4
    solved = pair_at_centre_distance(GearPair(PairMember(30, profile_shift_coefficient=0.1),
                                              PairMember(60, internal=True), 1.0), a)
    alpha = math.radians(20.0)
    aw = math.acos(30 * math.cos(alpha) / (2 * a))
    x2_khk = 0.1 + 30 * (inv(aw) - inv(alpha)) / (2 * math.tan(alpha))
    assert solved.mate.profile_shift_coefficient == pytest.approx(-x2_khk, rel=1e-9)
    facts = pair_facts(solved)
    assert facts.centre_distance_mm == pytest.approx(a, rel=1e-12)
    assert facts.working_pressure_angle_deg == pytest.approx(math.degrees(aw), rel=1e-9)
    book = _internal_textbook(1.0, 20.0, 30, 60, 0.1, x2_khk)
    assert facts.transverse_contact_ratio == pytest.approx(book["eps"], rel=REL)
    assert facts.mate_start_of_active_profile_diameter_mm == pytest.approx(book["sap_ring"], rel=REL)


@pytest.mark.parametrize("z1, x1, z2, x2, ha2", [(15, 0.3, 15, 0.3, 1.2), (30, 0.0, 20, 0.0, 1.28)])
def test_the_followed_tip_corners_reach_as_deep_as_the_clearance_says(z1, x1, z2, x2, ha2):
    """spur_cad.geometry.mate_mesh follows the mate's tip corners through the mesh: where the only fault is a tip
    clearance c < 0 (the corner passes the line of centres below the root circle), they enter this gear by -c (3 um:
    the mesh's steps and the outline's sampling); a sound pair's corners never enter either gear."""
    from spur_cad.geometry.mate_mesh import trochoid_intrusion_mm  # noqa: PLC0415
    from spur_cad.mate_section import MateSection, gear_pair  # noqa: PLC0415

    spec = GearSpec(teeth=z1, module_mm=1.0, profile_shift_coefficient=x1, rack_tip_radius_mm=0.2, face_width_mm=5)
    pair = gear_pair(spec, MateSection(teeth=z2, profile_shift_coefficient=x2, addendum_coefficient=ha2))
    facts = pair_facts(pair)
    assert facts.root_clearance_mm < 0.0
    into_gear, into_mate = trochoid_intrusion_mm(spec, pair, facts)
    assert into_gear == pytest.approx(-facts.root_clearance_mm, abs=3e-3) and into_mate == 0.0
    sound = gear_pair(spec, MateSection(teeth=z2, profile_shift_coefficient=x2))
    assert trochoid_intrusion_mm(spec, sound, pair_facts(sound)) == (0.0, 0.0)
