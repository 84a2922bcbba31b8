"""Specifications of the blank features and the stock (plain dataclasses, no CAD kernel import).

The job file's [stock] section is a StockSpec; the bore/keyway keys of [gear] form BlankFeatures.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from spur_cad.errors import GearSpecError, StockError
from spur_cad.geometry.internal import as_ring
from spur_cad.geometry.kinds import EXTERNAL_HELICAL, EXTERNAL_SPUR, INTERNAL_SPUR, GearKind
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
        gear_body(spec).check_features(self, spec)


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
        gear_body(spec).check_stock(self, spec)
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
        return gear_body(spec).outside_radius_mm(spec) + self.radial_allowance_mm

    def flat_bore_diameter_mm(self, spec: GearSpec, features: BlankFeatures) -> float:
        """The bore of the blank lying flat ([machine] axes = 3; 0: none): a ring's blank bore ([stock]
        inner_diameter_mm), an external gear's [gear] bore (it is clamped on it)."""
        return gear_body(spec).flat_bore_diameter_mm(self, features)


# --- what differs between the bodies of the gear kinds -----------------------------------------------------------

@dataclass(frozen=True)
class _Disc:
    """An external gear's body: a disc toothed on its outside (the tip circle); its bore and keyway are [gear]
    features cut under the root circle, its blank a cylinder at least as wide as the tip circle."""

    def check_features(self, features: BlankFeatures, spec: GearSpec) -> None:
        wall = spec.module_mm
        if features.bore_diameter_mm > 0.0 and features.bore_diameter_mm / 2.0 > spec.root_radius_mm - wall:
            raise GearSpecError(
                f"bore diameter {features.bore_diameter_mm:g} mm leaves less than one module ({wall:g} mm) of wall "
                f"under the root circle (root diameter {2 * spec.root_radius_mm:.3f} mm)", field="bore_diameter_mm")
        if features.keyway_width_mm > 0.0:
            top = features.bore_diameter_mm / 2.0 + features.keyway_depth_mm
            if top > spec.root_radius_mm - wall:
                raise GearSpecError(
                    f"keyway reaches radius {top:.3f} mm, leaving less than one module ({wall:g} mm) of wall under "
                    f"the root circle ({spec.root_radius_mm:.3f} mm)", field="keyway_depth_mm")

    def check_stock(self, stock: StockSpec, spec: GearSpec) -> None:
        tip_diameter = 2.0 * spec.tip_radius_mm
        if stock.inner_diameter_mm > 0.0:
            raise StockError("inner_diameter_mm is an internal gear's blank bore (an external gear's bore is [gear] "
                             "bore_diameter_mm)", field="inner_diameter_mm")
        if 0.0 < stock.blank_diameter_mm < tip_diameter - 1e-9:
            short = (tip_diameter - stock.blank_diameter_mm) / 2.0
            raise StockError(f"blank_diameter_mm = {stock.blank_diameter_mm:g} is smaller than the tip diameter "
                             f"{tip_diameter:.4f} mm: the teeth would be {short:.4f} mm short of the tip circle",
                             field="blank_diameter_mm")

    def outside_radius_mm(self, spec: GearSpec) -> float:
        return spec.tip_radius_mm

    def flat_bore_diameter_mm(self, stock: StockSpec, features: BlankFeatures) -> float:
        return features.bore_diameter_mm


@dataclass(frozen=True)
class _Ring:
    """An internal gear's body: a ring toothed on its inside, its outside the rim (rim_outer_diameter_mm); no bore
    or keyway (its inside is the teeth), its blank at least as wide as the rim and its blank bore ([stock]
    inner_diameter_mm) inside the tip circle."""

    def check_features(self, features: BlankFeatures, spec: GearSpec) -> None:
        if features.bore_diameter_mm > 0.0 or features.keyway_width_mm > 0.0:
            raise GearSpecError("an internal gear has no bore or keyway (its inside is the teeth; the rim is "
                                "rim_outer_diameter_mm)", field="bore_diameter_mm")

    def check_stock(self, stock: StockSpec, spec: GearSpec) -> None:
        rim = as_ring(spec).rim_outer_diameter_mm
        if 0.0 < stock.blank_diameter_mm < rim - 1e-9:
            raise StockError(f"blank_diameter_mm = {stock.blank_diameter_mm:g} is smaller than the internal gear's "
                             f"rim_outer_diameter_mm ({rim:g} mm)", field="blank_diameter_mm")
        tip_diameter = 2.0 * spec.tip_radius_mm
        if stock.inner_diameter_mm > tip_diameter - 1e-9:
            raise StockError(f"inner_diameter_mm = {stock.inner_diameter_mm:g} is not below the ring's tip diameter "
                             f"{tip_diameter:.4f} mm: the teeth would be short", field="inner_diameter_mm")

    def outside_radius_mm(self, spec: GearSpec) -> float:
        return as_ring(spec).rim_outer_diameter_mm / 2.0

    def flat_bore_diameter_mm(self, stock: StockSpec, features: BlankFeatures) -> float:
        return stock.inner_diameter_mm


_BODIES: dict[GearKind, _Disc | _Ring] = {EXTERNAL_SPUR: _Disc(), EXTERNAL_HELICAL: _Disc(), INTERNAL_SPUR: _Ring()}
"""Each gear kind's body, by the kind object: its outside, what a bore may be, what its blank must be."""


def gear_body(spec: GearSpec) -> _Disc | _Ring:
    """The body of `spec`'s kind (ValueError naming a kind no body is known for)."""
    body = _BODIES.get(spec.kind)
    if body is None:
        raise ValueError(f"no body is known for a {spec.kind.name} gear (cad/specs.py, _BODIES)")
    return body
