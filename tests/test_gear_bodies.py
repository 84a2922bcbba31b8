"""What differs between the bodies of the gear kinds (cad/specs.py's _BODIES, cad/solid.py's _BODY_SHAPES,
geometry/outline2d.py's _OUTLINES, geometry/rack.py's _RACKS; issue 45: the code asks a table keyed by the kind
object, not a flag): an external gear is a disc turned to its tip circle with a bore under its root, a ring is
turned to its rim and clamped on its blank's bore, and each refuses what belongs to the other. Sizes are checked
against the job's own numbers (rim, tip and bore diameters) and the flat blank's volume against pi (R^2 - r^2) b."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest

from spur_cad.cad.solid import build_flat_stock_shape, solid_volume_mm3
from spur_cad.cad.specs import BlankFeatures, StockSpec, gear_body
from spur_cad.errors import GearSpecError, StockError
from spur_cad.geometry.internal import InternalGearSpec
from spur_cad.geometry.kinds import GearKind
from spur_cad.geometry.outline2d import gear_outline_arcs, gear_outline_loops, internal_gear_outline_arcs
from spur_cad.geometry.rack import generating_rack
from spur_cad.geometry.spec import GearSpec

RING = InternalGearSpec(teeth=60, module_mm=2.0, addendum_coefficient=0.9, rack_tip_radius_mm=0.4,
                        shaper_cutter_teeth=20, rim_outer_diameter_mm=140.0, face_width_mm=10.0)
EXTERNAL = GearSpec(teeth=20, module_mm=2.0, face_width_mm=8.0)
HELICAL = GearSpec(teeth=20, module_mm=2.0, face_width_mm=8.0, helix_angle_deg=15.0)


def test_a_ring_blank_is_turned_to_its_rim_and_lies_flat_on_its_blank_bore():
    stock = StockSpec(radial_allowance_mm=0.5, inner_diameter_mm=60.0)
    stock.validate(RING)
    assert stock.blank_radius_mm(RING) == 140.0 / 2.0 + 0.5  # the rim, not the tip circle (116.4 mm)
    assert stock.flat_bore_diameter_mm(RING, BlankFeatures()) == 60.0
    volume = solid_volume_mm3(build_flat_stock_shape(RING, stock))
    assert volume == pytest.approx(math.pi * (70.5**2 - 30.0**2) * 10.0, rel=1e-6)


@pytest.mark.parametrize("spec", [EXTERNAL, HELICAL], ids=["spur", "helical"])
def test_an_external_blank_is_turned_to_its_tip_and_lies_flat_on_the_gears_bore(spec):
    stock, features = StockSpec(radial_allowance_mm=0.5), BlankFeatures(bore_diameter_mm=10.0)
    stock.validate(spec)
    features.validate(spec)
    assert stock.blank_radius_mm(spec) == spec.tip_radius_mm + 0.5
    assert stock.flat_bore_diameter_mm(spec, features) == 10.0
    volume = solid_volume_mm3(build_flat_stock_shape(spec, stock, features))
    assert volume == pytest.approx(math.pi * ((spec.tip_radius_mm + 0.5) ** 2 - 5.0**2) * 8.0, rel=1e-6)


def test_a_ring_refuses_a_bore_a_blank_inside_its_rim_and_a_blank_bore_outside_its_tip():
    tip_diameter = 2.0 * RING.tip_radius_mm
    with pytest.raises(GearSpecError, match="no bore or keyway") as bore:
        BlankFeatures(bore_diameter_mm=10.0).validate(RING)
    assert bore.value.field == "bore_diameter_mm"
    with pytest.raises(StockError, match="rim_outer_diameter_mm") as blank:  # above the tip, inside the rim
        StockSpec(blank_diameter_mm=139.0).validate(RING)
    assert blank.value.field == "blank_diameter_mm"
    with pytest.raises(StockError, match="tip diameter") as inner:
        StockSpec(inner_diameter_mm=tip_diameter + 0.1).validate(RING)
    assert inner.value.field == "inner_diameter_mm"
    StockSpec(inner_diameter_mm=tip_diameter - 0.1, blank_diameter_mm=140.0).validate(RING)


@pytest.mark.parametrize("spec", [EXTERNAL, HELICAL], ids=["spur", "helical"])
def test_an_external_gear_refuses_a_blank_bore_and_a_blank_inside_its_tip(spec):
    tip_diameter = 2.0 * spec.tip_radius_mm
    with pytest.raises(StockError, match="internal gear's blank bore") as inner:
        StockSpec(inner_diameter_mm=10.0).validate(spec)
    assert inner.value.field == "inner_diameter_mm"
    with pytest.raises(StockError, match="smaller than the tip diameter") as blank:
        StockSpec(blank_diameter_mm=tip_diameter - 0.1).validate(spec)
    assert blank.value.field == "blank_diameter_mm"
    StockSpec(blank_diameter_mm=tip_diameter).validate(spec)


def test_the_outline_has_the_loops_of_the_kind_and_each_single_kind_function_refuses_the_other():
    assert len(gear_outline_loops(EXTERNAL, 1e-2)) == 1
    rim, teeth = gear_outline_loops(RING, 1e-2)
    assert rim.segments[0].radius_mm == 70.0 and (rim, teeth) == internal_gear_outline_arcs(RING, 1e-2)
    with pytest.raises(ValueError, match="two loops"):
        gear_outline_arcs(RING, 1e-2)
    with pytest.raises(ValueError, match="not an internal gear"):
        internal_gear_outline_arcs(EXTERNAL, 1e-2)


def test_a_kind_no_table_knows_is_named_in_one_line():
    """A new kind (say a rack) must be entered in each table: until it is, the tables say so by its name."""
    rack = SimpleNamespace(kind=GearKind("straight rack", prismatic=True, teeth_inward=False, solid="extrude",
                                         measured_in="transverse"))
    for ask in (gear_body, generating_rack, lambda spec: gear_outline_loops(spec, 1e-2)):
        with pytest.raises(ValueError, match="straight rack"):
            ask(rack)
