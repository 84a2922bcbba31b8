"""Inspection dimensions against ISO 21771 / textbook formulas and against the profile geometry itself."""

from __future__ import annotations

import math

import numpy as np
import pytest

from spur_cad.geometry import sample_profile
from spur_cad.geometry.inspection import (
    chordal_thickness,
    inspection_sheet,
    over_pins,
    recommended_pin_diameter_mm,
    recommended_span_teeth,
    span_measurement,
)
from spur_cad.geometry.sampling import full_space_points
from spur_cad.geometry.spec import GearSpec
from tests.gears import GEAR_CASES, spec_of, textbook_of
from tests.textbook import over_pins_iso, point_polyline_distance, span_iso

ALL = list(GEAR_CASES)


@pytest.mark.parametrize("name", ALL)
def test_span_measurement_matches_iso_formula(name):
    spec, g = spec_of(name), textbook_of(name)
    for k in range(2, min(6, spec.teeth - 1)):
        assert span_measurement(spec, k).length_mm == pytest.approx(span_iso(g, k), abs=1e-6)


@pytest.mark.parametrize("name", ALL)
def test_span_measured_geometrically_on_the_profile(name):
    """Two parallel anvils, k teeth apart: the width of the k-tooth group across its symmetry
    axis, taken from densely sampled flanks, equals W_k."""
    spec = spec_of(name)
    k = recommended_span_teeth(spec)
    samples = sample_profile(spec.tooth_space_profile(), 1e-7)
    flank = samples.points[np.array(samples.label_names()) == "involute"]
    pitch = 2 * math.pi / spec.teeth

    def turn_ccw(p, a):
        c, s = math.cos(a), math.sin(a)
        return np.stack([p[:, 0] * c - p[:, 1] * s, p[:, 0] * s + p[:, 1] * c], axis=-1)

    # The k teeth between space 0 and space -k (clockwise of space 0) are bounded by the right
    # flank of space 0 and the left flank of space -k; turning by k/2 pitches makes the group
    # symmetric about +y, so the anvils are vertical lines and W_k is a difference of x.
    left_boundary = turn_ccw(flank, k * pitch / 2)  # right flank of space 0
    right_boundary = turn_ccw(flank * np.array([-1.0, 1.0]), -k * pitch / 2)  # left flank of space -k
    width = right_boundary[:, 0].max() - left_boundary[:, 0].min()
    assert width == pytest.approx(span_measurement(spec, k).length_mm, abs=1e-6)


@pytest.mark.parametrize("name", ALL)
def test_over_pins_matches_textbook_formula(name):
    spec, g = spec_of(name), textbook_of(name)
    for pin in (recommended_pin_diameter_mm(spec), 1.7 * spec.module_mm):
        assert over_pins(spec, pin).dimension_mm == pytest.approx(over_pins_iso(g, pin), abs=1e-6)


@pytest.mark.parametrize("name", ALL)
def test_pin_touches_both_flanks_of_the_space(name):
    spec = spec_of(name)
    pin = recommended_pin_diameter_mm(spec)
    result = over_pins(spec, pin)
    space = full_space_points(sample_profile(spec.tooth_space_profile(), 1e-7))
    centre = np.array([[0.0, result.pin_centre_radius_mm]])
    gap = point_polyline_distance(centre, space)[0]
    assert gap == pytest.approx(pin / 2, abs=1e-6)
    assert spec.form_radius_mm < result.contact_radius_mm < spec.tip_radius_mm


@pytest.mark.parametrize("name", ALL)
def test_recommendations_touch_the_usable_involute(name):
    spec = spec_of(name)
    k = recommended_span_teeth(spec)
    contact = span_measurement(spec, k).contact_radius_mm
    assert spec.form_radius_mm < contact < spec.tip_radius_mm


def test_reference_gear_inspection_values_by_hand():
    """z=23, m=4, alpha=20, 5 % thinner: W_3 = 4 cos20 (2.5 pi + 23 inv20) - 0.05 * 2pi * cos20."""
    spec = spec_of("reference_z23_m4")
    sheet = inspection_sheet(spec)
    inv20 = math.tan(math.radians(20)) - math.radians(20)
    cos20 = math.cos(math.radians(20))
    expected = 4 * cos20 * (2.5 * math.pi + 23 * inv20) - 0.05 * 2 * math.pi * cos20
    assert sheet.span_teeth_k == 3
    assert sheet.span_measurement_mm == pytest.approx(expected, abs=1e-9)
    assert sheet.min_teeth_without_undercut == 20


def test_chordal_thickness_at_reference_circle():
    spec = spec_of("shifted_z12")
    chord = chordal_thickness(spec)
    half = spec.tooth_thickness_mm / (2 * spec.reference_radius_mm)
    assert chord.chordal_thickness_mm == pytest.approx(2 * spec.reference_radius_mm * math.sin(half), abs=1e-12)
    assert chord.chordal_height_mm == pytest.approx(spec.tip_radius_mm - spec.reference_radius_mm * math.cos(half))


@pytest.mark.parametrize("teeth, shift", [(23, -1.0), (10, -0.4), (17, -0.6), (23, -0.7), (40, -1.3)])
def test_inspection_of_strongly_negative_shift(teeth, shift):
    """Gears whose r + x m circle lies below the usable involute (it crashed the inspection before): the
    span anvils and the pins still touch the usable involute, and W_k is the textbook value for that k."""
    spec = GearSpec(teeth=teeth, module_mm=4.0, rack_tip_radius_mm=0.8, profile_shift_coefficient=shift,
                    thickness_allowance_fraction=0.05, face_width_mm=3.0)
    assert spec.reference_radius_mm + shift * spec.module_mm < spec.form_radius_mm
    sheet = inspection_sheet(spec)
    assert spec.form_radius_mm <= sheet.span_contact_radius_mm <= spec.tip_radius_mm
    assert spec.form_radius_mm <= sheet.pin_contact_radius_mm <= spec.tip_radius_mm
    k = sheet.span_teeth_k
    alpha = math.radians(20.0)
    s = spec.tooth_thickness_mm
    textbook = spec.module_mm * math.cos(alpha) * ((k - 1) * math.pi + teeth * (math.tan(alpha) - alpha)) \
        + s * math.cos(alpha)
    assert sheet.span_measurement_mm == pytest.approx(textbook, abs=1e-9)
