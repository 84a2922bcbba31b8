"""Every accepted spec of the geometry sweep builds a valid solid; failures are sorted into
categories (crash / invalid solid / wrong volume) rather than surfacing as raw exceptions."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings

from spur_cad.cad.solid import build_gear_shape, solid_volume_mm3
from spur_cad.geometry import gear_outline
from spur_cad.geometry.sampling import polygon_area
from tests.gears import gear_parameters, spec_or_category

pytestmark = pytest.mark.slow  # make test-all


def classify_solid(params: dict) -> tuple[str, str]:
    spec = spec_or_category(params, 5.0)
    if isinstance(spec, tuple):
        return spec
    try:
        shape, _ = build_gear_shape(spec)
    except Exception as exc:  # noqa: BLE001 - the category is the point
        return "crash", f"{type(exc).__name__}: {exc}"
    import cadquery as cq

    if not cq.Solid(shape).isValid():
        return "invalid solid", ""
    expected = polygon_area(gear_outline(spec, 1e-7 * spec.module_mm)) * spec.face_width_mm
    volume = solid_volume_mm3(shape)
    if abs(volume / expected - 1.0) > 1e-6:
        return "wrong volume", f"{volume} vs {expected}"
    return "valid", ""


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(gear_parameters)
def test_every_accepted_spec_builds_a_valid_solid(params):
    category, detail = classify_solid(params)
    assert category in ("valid", "rejected"), f"{category}: {detail} for {params}"
