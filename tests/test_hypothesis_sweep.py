"""Property sweep over the issue's parameter space: every case either yields a valid simple
outline or raises GearSpecError with a message; any other outcome is a failure, sorted into a
category (crash / invalid outline) so that a report says what broke."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from shapely.geometry import Polygon

from spur_cad.geometry import gear_outline
from tests.gears import gear_parameters, helical_parameters, spec_or_category

pytestmark = pytest.mark.slow  # make test-all

def classify(params: dict) -> tuple[str, str]:
    """('rejected', message) | ('valid', '') | ('crash', repr) | ('invalid outline', why)."""
    spec = spec_or_category(params, 10.0)
    if isinstance(spec, tuple):
        return spec
    try:
        outline = gear_outline(spec, 2e-4 * spec.module_mm)
    except Exception as exc:  # noqa: BLE001
        return "crash", f"outline: {type(exc).__name__}: {exc}"
    poly = Polygon(outline)
    if not poly.is_valid:
        return "invalid outline", shapely.is_valid_reason(poly)
    radius = np.hypot(outline[:, 0], outline[:, 1])
    if not (math.isclose(radius.min(), spec.root_radius_mm, abs_tol=1e-9)
            and math.isclose(radius.max(), spec.tip_radius_mm, abs_tol=1e-9)):
        return "invalid outline", "radii outside root..tip"
    return "valid", ""


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(gear_parameters)
def test_every_spec_is_valid_or_rejected_with_a_message(params):
    category, detail = classify(params)
    assert category in ("valid", "rejected"), f"{category}: {detail} for {params}"


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(helical_parameters)
def test_every_helical_spec_is_valid_or_rejected_with_a_message(params):
    """The same property with a helix angle of 0 to 45 deg and either hand (transverse outline)."""
    category, detail = classify(params)
    assert category in ("valid", "rejected"), f"{category}: {detail} for {params}"


def test_sweep_exercises_both_outcomes():
    """The sweep space contains accepted, undercut and rejected gears (so the property test is not vacuous)."""
    base = dict(teeth=20, module_mm=2.0, pressure_angle_deg=20.0, profile_shift_coefficient=0.0,
                rack_tip_fraction=0.3, thickness_allowance_fraction=0.0)
    assert classify(base)[0] == "valid"
    assert classify({**base, "teeth": 6})[0] == "valid"
    assert classify({**base, "rack_tip_fraction": 0.45, "pressure_angle_deg": 30.0})[0] == "rejected"
    assert classify({**base, "teeth": 6, "profile_shift_coefficient": 1.0})[0] == "rejected"
    assert classify({**base, "helix_angle_deg": 30.0, "hand": "left"})[0] == "valid"
    assert classify({**base, "helix_angle_deg": 30.0, "rack_tip_fraction": 0.45, "pressure_angle_deg": 30.0})[0] == \
        "rejected"
