"""Specifications of the blank features and the stock (plain dataclasses, no CAD kernel import).

The job file's [stock] section is a StockSpec; the bore/keyway keys of [gear] form BlankFeatures.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from spur_cad.errors import GearSpecError, StockError
from spur_cad.geometry.internal import as_ring
from spur_cad.geometry.spec import GearSpec
from spur_cad.keys import check_section, key


@dataclass(frozen=True)
class GearSolidReport:
    """Facts about a built solid that the summary and tests use (here, without the kernel, so that a CadResult
    built in a worker process unpickles without importing OCP)."""

    fit_tolerance_mm: float
    fillet_max_deviation_mm: float
    involute_max_deviation_mm: float
    fillet_poles: int
    involute_poles: int
    edges_per_space: int


@dataclass(frozen=True)
class BlankFeatures:
    """Optional bore (through, on the gear axis) and keyway (on the bore's +Z side, under tooth space 0).

    `keyway_depth_mm` is measured from the bore surface outward (hub keyway depth t2).
    """

    bore_diameter_mm: float = 0.0
    keyway_width_mm: float = 0.0
    keyway_depth_mm: float = 0.0

    def __post_init__(self) -> None:
        """Raise GearSpecError for features that cannot exist (a size not a number or negative, a keyway half given,
        without a bore or as wide as it), once, when they are made; against the gear: validate."""
        for name in ("bore_diameter_mm", "keyway_width_mm", "keyway_depth_mm"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise GearSpecError(f"{name} must be a number, got {type(value).__name__}", field=name)
            if not math.isfinite(value) or value < 0.0:
                raise GearSpecError(f"{name} = {value:g} mm must be zero (none) or positive", field=name)
        has_width, has_depth = self.keyway_width_mm > 0.0, self.keyway_depth_mm > 0.0
        if has_width != has_depth:
            raise GearSpecError("a keyway needs both keyway_width_mm and keyway_depth_mm", field="keyway_width_mm")
        if has_width:
            if self.bore_diameter_mm <= 0.0:
                raise GearSpecError("a keyway needs a bore (bore_diameter_mm)", field="keyway_width_mm")
            if self.keyway_width_mm >= self.bore_diameter_mm:
                raise GearSpecError(f"keyway width {self.keyway_width_mm:g} mm must be smaller than the bore "
                                    f"diameter {self.bore_diameter_mm:g} mm", field="keyway_width_mm")

    def validate(self, spec: GearSpec) -> None:
        """Raise GearSpecError unless the features suit the gear: none in a ring, a wall of at least one module under
        the root. Checked where the features meet the gear (the job loader, gear_shape), not again below."""
        if spec.kind.teeth_inward and (self.bore_diameter_mm > 0.0 or self.keyway_width_mm > 0.0):
            raise GearSpecError("an internal gear has no bore or keyway (its inside is the teeth; the rim is "
                                "rim_outer_diameter_mm)", field="bore_diameter_mm")
        wall = spec.module_mm
        if self.bore_diameter_mm > 0.0 and self.bore_diameter_mm / 2.0 > spec.root_radius_mm - wall:
            raise GearSpecError(
                f"bore diameter {self.bore_diameter_mm:g} mm leaves less than one module ({wall:g} mm) of wall under "
                f"the root circle (root diameter {2 * spec.root_radius_mm:.3f} mm)", field="bore_diameter_mm")
        if self.keyway_width_mm > 0.0:
            top = self.bore_diameter_mm / 2.0 + self.keyway_depth_mm
            if top > spec.root_radius_mm - wall:
                raise GearSpecError(
                    f"keyway reaches radius {top:.3f} mm, leaving less than one module ({wall:g} mm) of wall under "
                    f"the root circle ({spec.root_radius_mm:.3f} mm)", field="keyway_depth_mm")


@dataclass(frozen=True)
class StockSpec:
    """[stock]: blank cylinder of tip diameter + 2 x radial allowance, from X = -front margin to
    face width + back margin, optionally continued by a holding stub toward the chuck (+X)."""

    radial_allowance_mm: float = key(0.5, unit="mm", low=0.0, high=50.0, label="RadialAllowance", group="Stock",
                                     meaning="blank radius = tip radius + this allowance")
    blank_diameter_mm: float = key(0.0, unit="mm", low=0.0, high=20000.0, label="BlankDiameter", group="Stock",
                                   meaning="the blank's diameter as turned, 0: tip diameter + 2 x radial_allowance_mm; "
                                           "smaller than the tip diameter is refused")
    inner_diameter_mm: float = key(0.0, unit="mm", low=0.0, high=20000.0, label="InnerDiameter", group="Stock",
                                   meaning="internal gears: the bore the blank comes with (a tube or a turned ring), "
                                           "below the tip diameter; 0: a solid disc (3-axis roughing enters it "
                                           "by a helix at the centre)")
    front_margin_mm: float = key(1.0, unit="mm", low=0.0, high=500.0, label="FrontMargin", group="Stock",
                                 meaning="blank beyond the front face X = 0")
    back_margin_mm: float = key(1.0, unit="mm", low=0.0, high=500.0, label="BackMargin", group="Stock",
                                meaning="blank beyond the back face X = b")
    density_kg_dm3: float = key(7.85, unit="kg/dm^3", low=0.5, high=25.0, label="Density", group="Stock",
                                meaning="density of the blank's material (steel 7.85), for the part weight "
                                        "([machine] max_part_weight_kg)")
    stub_diameter_mm: float = key(0.0, unit="mm", low=0.0, high=2000.0, label="StubDiameter", group="Holding stub",
                                  meaning="diameter of the holding stub toward the chuck (+X), 0: none")
    stub_length_mm: float = key(0.0, unit="mm", low=0.0, high=1000.0, label="StubLength", group="Holding stub",
                                meaning="length of the holding stub, 0: none")

    def __post_init__(self) -> None:
        """Raise StockError for keys outside their ranges or a half-given stub, once, when the section is made."""
        check_section(self, "stock", StockError)
        if (self.stub_diameter_mm > 0.0) != (self.stub_length_mm > 0.0):
            raise StockError("a holding stub needs both stub_diameter_mm and stub_length_mm",
                             field="stub_diameter_mm")

    def validate(self, spec: GearSpec) -> None:
        """Raise StockError for a blank that does not suit the gear (below its tip or rim, a bore in an external
        gear's blank, a stub wider than the blank). Checked where the stock meets the gear (the job loader,
        stock_shape, CamInputs), not again below."""
        if spec.kind.teeth_inward:
            rim = as_ring(spec).rim_outer_diameter_mm
            if 0.0 < self.blank_diameter_mm < rim - 1e-9:
                raise StockError(f"blank_diameter_mm = {self.blank_diameter_mm:g} is smaller than the internal gear's "
                                 f"rim_outer_diameter_mm ({rim:g} mm)", field="blank_diameter_mm")
        tip_diameter = 2.0 * spec.tip_radius_mm
        if self.inner_diameter_mm > 0.0 and not spec.kind.teeth_inward:
            raise StockError("inner_diameter_mm is an internal gear's blank bore (an external gear's bore is [gear] "
                             "bore_diameter_mm)", field="inner_diameter_mm")
        if spec.kind.teeth_inward and self.inner_diameter_mm > tip_diameter - 1e-9:
            raise StockError(f"inner_diameter_mm = {self.inner_diameter_mm:g} is not below the ring's tip diameter "
                             f"{tip_diameter:.4f} mm: the teeth would be short", field="inner_diameter_mm")
        if not spec.kind.teeth_inward and 0.0 < self.blank_diameter_mm < tip_diameter - 1e-9:
            short = (tip_diameter - self.blank_diameter_mm) / 2.0
            raise StockError(f"blank_diameter_mm = {self.blank_diameter_mm:g} is smaller than the tip diameter "
                             f"{tip_diameter:.4f} mm: the teeth would be {short:.4f} mm short of the tip circle",
                             field="blank_diameter_mm")
        if self.stub_diameter_mm > 2.0 * self.blank_radius_mm(spec):
            raise StockError(f"stub diameter {self.stub_diameter_mm:g} mm is larger than the blank "
                                f"({2 * self.blank_radius_mm(spec):.3f} mm)", field="stub_diameter_mm")

    def blank_x_range_mm(self, spec: GearSpec) -> tuple[float, float]:
        """X of the blank cylinder's front and back faces (-front margin, face width + back margin); the holding
        stub continues it from the back face toward the chuck."""
        return -self.front_margin_mm, spec.face_width_mm + self.back_margin_mm

    def blank_radius_mm(self, spec: GearSpec) -> float:
        """The blank's radius: half the given blank diameter, else tip radius (an internal gear: rim radius) +
        radial allowance."""
        if self.blank_diameter_mm > 0.0:
            return self.blank_diameter_mm / 2.0
        outside = as_ring(spec).rim_outer_diameter_mm / 2.0 if spec.kind.teeth_inward else spec.tip_radius_mm
        return outside + self.radial_allowance_mm
