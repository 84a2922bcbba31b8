"""GearSpec: derived quantities and the specific messages for bad input."""

from __future__ import annotations

import dataclasses
import math

import pytest

from spur_cad.errors import GearSpecError
from spur_cad.geometry import GearSpec, inverse_involute_function, involute_function
from tests.gears import spec_of

REFERENCE = dict(teeth=23, module_mm=4.0, rack_tip_radius_mm=0.8, thickness_allowance_fraction=0.05,
                 face_width_mm=20.0)


def test_reference_gear_radii_by_hand():
    spec = GearSpec(**REFERENCE)
    assert spec.reference_radius_mm == 46.0
    assert spec.base_radius_mm == pytest.approx(46.0 * math.cos(math.radians(20)), abs=1e-12)
    assert spec.tip_radius_mm == 50.0
    assert spec.root_radius_mm == 41.0
    assert spec.pitch_mm == pytest.approx(4 * math.pi)
    assert spec.tooth_thickness_mm == pytest.approx(0.95 * 2 * math.pi, abs=1e-12)
    assert spec.space_width_mm == pytest.approx(4 * math.pi - 0.95 * 2 * math.pi, abs=1e-12)
    assert spec.root_radius_mm < spec.base_radius_mm < spec.form_radius_mm < spec.reference_radius_mm


def test_spec_is_immutable_and_hashable():
    spec = GearSpec(**REFERENCE)
    with pytest.raises(dataclasses.FrozenInstanceError):
        spec.teeth = 24  # type: ignore[misc]
    assert spec == GearSpec(**REFERENCE) and hash(spec) == hash(GearSpec(**REFERENCE))


def test_involute_function_inverse_round_trip():
    for angle in (1e-4, 0.1, math.radians(20), 1.2):
        assert inverse_involute_function(involute_function(angle)) == pytest.approx(angle, rel=1e-12)


@pytest.mark.parametrize(
    "changes, field, words",
    [
        (dict(teeth=3), "teeth", "too few teeth"),
        (dict(teeth=23.0), "teeth", "whole number"),
        (dict(teeth=True), "teeth", "whole number"),
        (dict(module_mm=0.0), "module_mm", "module_mm = 0"),
        (dict(module_mm=-4.0), "module_mm", "outside the accepted range"),
        (dict(module_mm=float("nan")), "module_mm", "outside"),
        (dict(pressure_angle_deg=0.0), "pressure_angle_deg", "(0, 45)"),
        (dict(pressure_angle_deg=45.0), "pressure_angle_deg", "(0, 45)"),
        (dict(face_width_mm=0.0), "face_width_mm", "face_width_mm"),
        (dict(rack_tip_radius_mm=-0.1), "rack_tip_radius_mm", "rack_tip_radius_mm"),
        (dict(rack_tip_radius_mm=2.3), "rack_tip_radius_mm", "too large for the rack tooth"),
        (dict(profile_shift_coefficient=1.5), "profile_shift_coefficient", "pointed"),
        (dict(thickness_allowance_fraction=0.6), "thickness_allowance_fraction", "thickness_allowance_fraction"),
        (dict(dedendum_coefficient=2.0, addendum_coefficient=0.05, rack_tip_radius_mm=0.0, teeth=6,
              profile_shift_coefficient=-0.5), "addendum_coefficient", "no involute flank"),
        (dict(module_mm="4"), "module_mm", "must be a number"),
    ],
)
def test_bad_input_gets_a_specific_message(changes, field, words):
    with pytest.raises(GearSpecError) as info:
        GearSpec(**{**REFERENCE, **changes})
    if field is not None:
        assert info.value.field == field
    assert words in str(info.value)


def test_tip_below_form_circle_is_rejected():
    # Few teeth, negative shift, short addendum: the undercut lifts the form circle above the tip.
    with pytest.raises(GearSpecError, match="not above the form radius") as info:
        GearSpec(teeth=6, module_mm=1.0, profile_shift_coefficient=-0.5, addendum_coefficient=0.2)
    assert info.value.field == "addendum_coefficient"


def test_undercut_is_allowed_and_reported():
    spec = spec_of("undercut_z8")
    assert spec.undercut and spec.undercut_depth_mm > 0
    assert spec.describe()["undercut"] is True


def test_thickness_allowances_combine():
    nominal = GearSpec(teeth=30, module_mm=2.0, profile_shift_coefficient=0.3)
    thinned = GearSpec(teeth=30, module_mm=2.0, profile_shift_coefficient=0.3, thickness_allowance_fraction=0.02,
                       thickness_allowance_mm=0.05)
    expected = 2.0 * (math.pi / 2 + 2 * 0.3 * math.tan(math.radians(20)))
    assert nominal.tooth_thickness_mm == pytest.approx(expected, abs=1e-12)
    assert thinned.tooth_thickness_mm == pytest.approx(expected * 0.98 - 0.05, abs=1e-12)
