"""Public functions check their arguments and raise spur_cad's own errors naming the argument
(never AttributeError/OverflowError from deep inside, never an empty solid)."""

from __future__ import annotations

import pytest

import spur_cad
from spur_cad.errors import ArgumentError, GearSpecError, SpurCadError
from spur_cad.geometry.inspection import inspection_sheet
from spur_cad.geometry.sampling import sample_profile


def reference_spec() -> spur_cad.GearSpec:
    return spur_cad.GearSpec(teeth=23, module_mm=4.0, rack_tip_radius_mm=0.8, face_width_mm=3.0)


@pytest.mark.parametrize("kwargs, field", [
    ({"module_mm": 10**400}, "module_mm"),
    ({"module_mm": "4"}, "module_mm"),
    ({"module_mm": float("nan")}, "module_mm"),
    ({"face_width_mm": float("inf")}, "face_width_mm"),
    ({"face_width_mm": 1e-9}, "face_width_mm"),
    ({"teeth": 23.0}, "teeth"),
    ({"teeth": True}, "teeth"),
])
def test_gear_spec_refuses_what_is_not_a_meaningful_number(kwargs, field):
    with pytest.raises(GearSpecError) as info:
        spur_cad.GearSpec(**{"teeth": 23, "module_mm": 4.0, **kwargs})
    assert info.value.field == field
    assert field in str(info.value) and len(str(info.value)) < 200


@pytest.mark.parametrize("call, argument", [
    (lambda: spur_cad.gear_shape(None), "spec"),
    (lambda: spur_cad.stock_shape("x"), "spec"),
    (lambda: spur_cad.gear_shape(reference_spec(), "bore"), "features"),
    (lambda: spur_cad.stock_shape(reference_spec(), {"radial_allowance_mm": 1.0}), "stock"),
    (lambda: inspection_sheet(None), "spec"),
    (lambda: spur_cad.gear_shape(reference_spec(), spur_cad.BlankFeatures(bore_diameter_mm="30")), "bore_diameter_mm"),
    (lambda: spur_cad.to_build123d(None), "source"),
    (lambda: spur_cad.gear_shape(reference_spec(), frame="world"), "frame"),
    (lambda: spur_cad.to_build123d(reference_spec(), frame=None), "frame"),
    (lambda: sample_profile(None), "profile"),
    (lambda: sample_profile(reference_spec().tooth_space_profile(), "0.001"), "tolerance_mm"),
])
def test_public_functions_name_the_bad_argument(call, argument):
    with pytest.raises(SpurCadError) as info:
        call()
    assert isinstance(info.value, (ArgumentError, GearSpecError))
    assert argument in str(info.value)


@pytest.mark.cadquery
def test_the_cadquery_front_end_names_the_bad_argument_and_refuses_an_empty_workplane():
    for call, argument in ((lambda: spur_cad.make_gear(None), "spec"), (lambda: spur_cad.make_stock("x"), "spec"),
                           (lambda: spur_cad.make_gear(reference_spec(), frame="world"), "frame")):
        with pytest.raises(ArgumentError, match=argument):
            call()
    import cadquery as cq

    with pytest.raises(ArgumentError, match="no solid"):
        spur_cad.to_build123d(cq.Workplane("XY"))

