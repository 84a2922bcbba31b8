"""Property sweep over the issue's parameter space: every case either yields a valid simple
outline or raises GearSpecError with a message; any other outcome is a failure, sorted into a
category (crash / invalid outline) so that a report says what broke."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from shapely.geometry import Polygon

from spur_cad.errors import GearSpecError
from spur_cad.geometry import GearSpec, gear_outline

pytestmark = pytest.mark.slow  # make test-all

gear_parameters = st.fixed_dictionaries({
    "teeth": st.integers(6, 200),
    "module_mm": st.floats(0.3, 20.0),
    "pressure_angle_deg": st.floats(14.5, 30.0),
    "profile_shift_coefficient": st.floats(-0.5, 1.0),
    "rack_tip_fraction": st.floats(0.0, 0.45),
    "thickness_allowance_fraction": st.floats(0.0, 0.05),
})


def spec_or_category(params: dict, face_width_mm: float) -> GearSpec | tuple[str, str]:
    """The GearSpec for swept parameters (rack tip radius given as a fraction of the module), or
    the failure category: ('rejected', message) or ('crash', repr)."""
    params = dict(params)
    params["rack_tip_radius_mm"] = params.pop("rack_tip_fraction") * params["module_mm"]
    try:
        return GearSpec(face_width_mm=face_width_mm, **params)
    except GearSpecError as exc:
        return ("rejected", str(exc)) if str(exc) else ("crash", "empty GearSpecError message")
    except Exception as exc:  # noqa: BLE001 - the category is the point
        return "crash", f"{type(exc).__name__}: {exc}"


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


def test_sweep_exercises_both_outcomes():
    """The sweep space contains accepted, undercut and rejected gears (so the property test is not vacuous)."""
    base = dict(teeth=20, module_mm=2.0, pressure_angle_deg=20.0, profile_shift_coefficient=0.0,
                rack_tip_fraction=0.3, thickness_allowance_fraction=0.0)
    assert classify(base)[0] == "valid"
    assert classify({**base, "teeth": 6})[0] == "valid"
    assert classify({**base, "rack_tip_fraction": 0.45, "pressure_angle_deg": 30.0})[0] == "rejected"
    assert classify({**base, "teeth": 6, "profile_shift_coefficient": 1.0})[0] == "rejected"
