"""Inspection dimensions of the designed (allowance-thinned) gear: span measurement, dimension
over pins or balls, chordal tooth thickness, minimum teeth without undercut (ISO 21771 terms).

All use the design tooth thickness `s` (allowance applied), so they are what the
inspector should measure on the finished part.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from spur_cad.errors import require_instance
from spur_cad.geometry.internal import InternalGearSpec, as_ring
from spur_cad.geometry.involute import inverse_involute_function, involute_function
from spur_cad.geometry.kinds import EXTERNAL_HELICAL, EXTERNAL_SPUR, INTERNAL_SPUR, GearKind
from spur_cad.geometry.spec import GearSpec

if TYPE_CHECKING:
    from spur_cad.geometry.modifications import FlankModifications

PIN_DIAMETER_STEP_MM = 0.01  # gauge pins are stocked in 0.01 mm steps


@dataclass(frozen=True)
class SpanMeasurement:
    """Base tangent length W_k over k teeth, and the radius where the anvils touch the flanks."""

    teeth_spanned: int
    length_mm: float
    contact_radius_mm: float


@dataclass(frozen=True)
class OverPinsMeasurement:
    """Dimension over two pins (balls) of diameter D placed in opposite (or nearly opposite) spaces."""

    pin_diameter_mm: float
    dimension_mm: float
    pin_centre_radius_mm: float
    contact_radius_mm: float


@dataclass(frozen=True)
class ChordalThickness:
    """Chordal tooth thickness and chordal height (from the tip) at a measuring radius."""

    measuring_radius_mm: float
    chordal_thickness_mm: float
    chordal_height_mm: float


def base_thickness_mm(spec: GearSpec) -> float:
    """Tooth thickness on the base circle (arc): s_b = r_b (s/r + 2 inv(alpha))."""
    return spec.base_radius_mm * (spec.tooth_thickness_mm / spec.reference_radius_mm
                                  + 2.0 * involute_function(spec.pressure_angle_rad))


def span_measurement(spec: GearSpec, teeth_spanned: int) -> SpanMeasurement:
    """W_k = (k - 1) p_b + s_b (transverse); the anvils touch the flanks at radius sqrt(r_b^2 + (W_k/2)^2).
    Helical gears are measured in the normal section: W_kn = W_kt cos(beta_b)."""
    if not 1 <= teeth_spanned < spec.teeth:
        raise ValueError(f"teeth spanned must be between 1 and {spec.teeth - 1}, got {teeth_spanned}")
    transverse = (teeth_spanned - 1) * spec.base_pitch_mm + base_thickness_mm(spec)
    contact = math.hypot(spec.base_radius_mm, transverse / 2.0)
    length = transverse * math.cos(spec.base_helix_angle_rad) if spec.kind.measured_in == "normal" else transverse
    return SpanMeasurement(teeth_spanned, length, contact)


def span_min_face_width_mm(spec: GearSpec, span: SpanMeasurement) -> float:
    """Face width a helical gear needs for the anvils to sit on both flanks: b > W_kn sin(beta_b) (0: spur)."""
    return span.length_mm * math.sin(spec.base_helix_angle_rad)


def recommended_span_teeth(spec: GearSpec) -> int:
    """k whose anvil contact lies nearest the middle of the involute flank, within form..tip radius.

    Starts from the ISO 21771 rule (contact near radius r + x m) and moves k until the contact
    radius is on the usable involute.
    """
    alpha = spec.pressure_angle_rad
    x = spec.profile_shift_coefficient
    # ISO 21771 aims the anvils at radius r + x m; with a large negative shift that circle can lie below
    # the usable involute (even below the base circle), so the aim is kept on the involute.
    aim = min(max(spec.reference_radius_mm + x * spec.module_mm, spec.form_radius_mm), spec.tip_radius_mm)
    alpha_x = math.acos(spec.base_radius_mm / aim)
    k_exact = spec.teeth / math.pi * (math.tan(alpha_x) - 2.0 * x * math.tan(alpha) / spec.teeth
                                      - involute_function(alpha)) + 0.5
    low, high = spec.form_radius_mm, spec.tip_radius_mm
    middle = 0.5 * (low + high)
    candidates = [k for k in range(1, spec.teeth) if low < span_measurement(spec, k).contact_radius_mm < high]
    if not candidates:
        return max(1, min(spec.teeth - 1, round(k_exact)))
    return min(candidates, key=lambda k: (abs(k - k_exact) > 0.5, abs(span_measurement(spec, k).contact_radius_mm
                                                                         - middle)))


def over_pins(spec: GearSpec, pin_diameter_mm: float) -> OverPinsMeasurement:
    """Dimension over pins: inv(a_M) = D / d_b + s / (m z) + inv(alpha) - pi / z, r_M = r_b / cos(a_M).

    Even teeth: M = 2 r_M + D; odd teeth: M = 2 r_M cos(pi / (2 z)) + D.
    """
    if pin_diameter_mm <= 0.0:
        raise ValueError(f"pin diameter must be positive, got {pin_diameter_mm}")
    rb = spec.base_radius_mm
    # Helical gears (balls): the ball's transverse section is an ellipse; its effective size on the base
    # circle is D / cos(beta_b) (ISO 21771: inv(a_Mt) = D / (m_n z cos(a_n)) + ...).
    normal = spec.kind.measured_in == "normal"
    ball = pin_diameter_mm / math.cos(spec.base_helix_angle_rad) if normal else pin_diameter_mm
    inv_alpha_m = (ball / (2.0 * rb) + spec.tooth_thickness_mm / (2.0 * spec.reference_radius_mm)
                   + involute_function(spec.pressure_angle_rad) - math.pi / spec.teeth)
    alpha_m = inverse_involute_function(inv_alpha_m)
    centre_radius = rb / math.cos(alpha_m)
    if spec.teeth % 2 == 0:
        dimension = 2.0 * centre_radius + pin_diameter_mm
    else:
        dimension = 2.0 * centre_radius * math.cos(math.pi / (2.0 * spec.teeth)) + pin_diameter_mm
    # The pin touches the flank where the roll angle is a_M - theta_b (see docs/geometry.md).
    roll = alpha_m - spec.base_half_space_angle_rad
    contact = rb * math.hypot(1.0, roll)
    return OverPinsMeasurement(pin_diameter_mm, dimension, centre_radius, contact)


def recommended_pin_diameter_mm(spec: GearSpec) -> float:
    """Pin touching the flanks at radius r + x m (ISO practice), rounded to gauge-pin steps.

    The contact at roll t_c = tan(a_c) puts the pin centre at pressure angle a_M = theta_b + t_c,
    so D = 2 r_b (tan(a_M) - t_c). If that contact is off the usable involute, the middle of
    the flank is used instead.
    """
    rb = spec.base_radius_mm
    target = spec.reference_radius_mm + spec.profile_shift_coefficient * spec.module_mm
    if not spec.form_radius_mm < target < spec.tip_radius_mm:
        target = 0.5 * (spec.form_radius_mm + spec.tip_radius_mm)
    roll = math.sqrt((target / rb) ** 2 - 1.0)
    diameter = 2.0 * rb * (math.tan(spec.base_half_space_angle_rad + roll) - roll)
    if spec.kind.measured_in == "normal":
        diameter *= math.cos(spec.base_helix_angle_rad)
    return max(PIN_DIAMETER_STEP_MM, round(diameter / PIN_DIAMETER_STEP_MM) * PIN_DIAMETER_STEP_MM)


def chordal_thickness(spec: GearSpec, measuring_radius_mm: float | None = None) -> ChordalThickness:
    """Chord across the tooth at a radius (default: reference circle) and its height below the tip.

    Helical gears, at the reference circle: the normal chordal thickness, measured on the virtual
    spur gear of radius r_v = r / cos^2(beta) with the normal thickness s_n = s_t cos(beta):
    chord 2 r_v sin(psi), height h_a + r_v (1 - cos(psi)), psi = s_n / (2 r_v)."""
    radius = spec.reference_radius_mm if measuring_radius_mm is None else measuring_radius_mm
    if spec.kind.measured_in == "normal" and measuring_radius_mm is None:
        cos_beta = math.cos(spec.helix_angle_rad)
        virtual = radius / cos_beta**2
        psi = spec.tooth_thickness_mm * cos_beta / (2.0 * virtual)
        return ChordalThickness(radius, 2.0 * virtual * math.sin(psi),
                                spec.tip_radius_mm - radius + virtual * (1.0 - math.cos(psi)))
    half_angle = spec.tooth_thickness_at_radius_mm(radius) / (2.0 * radius)
    return ChordalThickness(radius, 2.0 * radius * math.sin(half_angle),
                            spec.tip_radius_mm - radius * math.cos(half_angle))


def minimum_teeth_without_undercut(spec: GearSpec) -> float:
    """Smallest (real) tooth count the rack generates without undercut, at this shift and tip radius.

    No undercut while the rack flank's lowest straight point stays within the interference
    point: (h_f* - x) m - rho (1 - sin(alpha)) <= r sin^2(alpha), with r = m z / 2.
    The rack's round lies in the normal section (alpha_n), the flank in the transverse one (alpha_t) and
    r = z m_n / (2 cos beta); a spur gear's beta = 0 makes alpha_n = alpha_t and cos beta = 1, bit for bit.
    """
    height = ((spec.dedendum_coefficient - spec.profile_shift_coefficient) * spec.module_mm
              - spec.rack_tip_radius_mm * (1.0 - math.sin(spec.normal_pressure_angle_rad)))
    return 2.0 * height * math.cos(spec.helix_angle_rad) / (spec.module_mm * math.sin(spec.pressure_angle_rad) ** 2)


@dataclass(frozen=True)
class InspectionSheet:
    """The inspection values a report or summary shows (mm; see `inspection_sheet`)."""

    span_teeth_k: int
    span_measurement_mm: float | None  # None: the face is too narrow for a span over k teeth (helical)
    span_contact_radius_mm: float
    span_min_face_width_mm: float
    pin_diameter_mm: float
    dimension_over_pins_mm: float
    pin_contact_radius_mm: float
    chordal_thickness_mm: float
    chordal_height_mm: float
    chordal_measuring_radius_mm: float
    tooth_thickness_mm: float
    thickness_reduction_mm: float
    min_teeth_without_undercut: int
    min_teeth_without_undercut_exact: float
    pins_between: bool = False  # internal gear: dimension_over_pins_mm is the dimension BETWEEN pins


def between_pins(spec: InternalGearSpec, pin_diameter_mm: float) -> OverPinsMeasurement:
    """Internal gear: dimension between two pins in opposite (or nearly opposite) spaces. The pin centre lies on
    the involute parallel to the flank, turned by D / (2 r_b) toward the space axis: inv(a_M) = e / (2 r) +
    inv(alpha) - D / (2 r_b), r_M = r_b / cos(a_M); even teeth M = 2 r_M - D, odd M = 2 r_M cos(pi / (2 z)) - D
    (KHK's formula with e = m (pi/2 - 2 x tan(alpha)) when there is no allowance)."""
    if pin_diameter_mm <= 0.0:
        raise ValueError(f"pin diameter must be positive, got {pin_diameter_mm}")
    rb = spec.base_radius_mm
    inv_alpha_m = spec.base_half_space_angle_rad - pin_diameter_mm / (2.0 * rb)
    if inv_alpha_m <= 0.0:
        raise ValueError(f"a pin of {pin_diameter_mm} mm does not fit the space above the base circle")
    alpha_m = inverse_involute_function(inv_alpha_m)
    centre_radius = rb / math.cos(alpha_m)
    factor = 1.0 if spec.teeth % 2 == 0 else math.cos(math.pi / (2.0 * spec.teeth))
    contact = rb * math.hypot(1.0, alpha_m + spec.base_half_space_angle_rad)  # roll t_c = a_M + theta_b
    return OverPinsMeasurement(pin_diameter_mm, 2.0 * centre_radius * factor - pin_diameter_mm, centre_radius,
                               contact)


def recommended_inside_pin_diameter_mm(spec: InternalGearSpec) -> float:
    """Pin touching the ring's flanks at radius r - x m (the middle of the flank when that is off the involute):
    roll t_c there, a_M = t_c - theta_b, D = 2 r_b (t_c - tan(a_M)); rounded to gauge-pin steps."""
    rb = spec.base_radius_mm
    target = spec.reference_radius_mm - spec.profile_shift_coefficient * spec.module_mm
    if not spec.tip_radius_mm < target < spec.form_radius_mm:
        target = 0.5 * (spec.tip_radius_mm + spec.form_radius_mm)
    roll = math.sqrt((target / rb) ** 2 - 1.0)
    diameter = 2.0 * rb * (roll - math.tan(roll - spec.base_half_space_angle_rad))
    return max(PIN_DIAMETER_STEP_MM, round(diameter / PIN_DIAMETER_STEP_MM) * PIN_DIAMETER_STEP_MM)


def internal_inspection_facts(spec: InternalGearSpec) -> InspectionSheet:
    """An internal gear's sheet: dimension between pins and chordal thickness at the reference circle (height
    from the tip circle, which lies inside it); no span (base tangent length): calipers' anvils cannot sit on a
    ring's flanks, so it is given as None (and k = 0)."""
    pin = recommended_inside_pin_diameter_mm(spec)
    pins = between_pins(spec, pin)
    radius = spec.reference_radius_mm
    half_angle = spec.tooth_thickness_at_radius_mm(radius) / (2.0 * radius)
    return InspectionSheet(
        span_teeth_k=0, span_measurement_mm=None, span_contact_radius_mm=0.0, span_min_face_width_mm=0.0,
        pin_diameter_mm=pin, dimension_over_pins_mm=pins.dimension_mm, pin_contact_radius_mm=pins.contact_radius_mm,
        chordal_thickness_mm=2.0 * radius * math.sin(half_angle),
        chordal_height_mm=radius * math.cos(half_angle) - spec.tip_radius_mm, chordal_measuring_radius_mm=radius,
        tooth_thickness_mm=spec.tooth_thickness_mm, thickness_reduction_mm=spec.thickness_reduction_mm,
        min_teeth_without_undercut=0, min_teeth_without_undercut_exact=0.0, pins_between=True)


def inspection_sheet(spec: GearSpec) -> InspectionSheet:
    """The inspection values the report, summary.json's `inspection` and scripts read (one typed result), as the
    gear's kind is measured (_SHEETS): an external gear's (`external_inspection_facts`), a ring's
    (`internal_inspection_facts`)."""
    require_instance(spec, GearSpec, "spec")
    sheet = _SHEETS.get(spec.kind)
    if sheet is None:
        raise ValueError(f"no inspection sheet is known for a {spec.kind.name} gear (geometry/inspection.py, _SHEETS)")
    return sheet(spec)


def external_inspection_facts(spec: GearSpec) -> InspectionSheet:
    """An external gear's sheet: span over k teeth, dimension over pins and chordal thickness. Helical gears: span
    and chordal thickness in the normal section, over balls; the span's k is lowered until the anvils fit the face
    width (b > W sin(beta_b)), and the span is None when not even k = 1 fits (measure over balls)."""
    k = recommended_span_teeth(spec)
    span = span_measurement(spec, k)
    while k > 1 and span_min_face_width_mm(spec, span) >= spec.face_width_mm:  # helical: the anvils must fit
        k -= 1
        span = span_measurement(spec, k)
    span_fits = span_min_face_width_mm(spec, span) < spec.face_width_mm
    pin = recommended_pin_diameter_mm(spec)
    pins = over_pins(spec, pin)
    chord = chordal_thickness(spec)
    z_min = minimum_teeth_without_undercut(spec)
    return InspectionSheet(
        span_teeth_k=k, span_measurement_mm=span.length_mm if span_fits else None,
        span_contact_radius_mm=span.contact_radius_mm, span_min_face_width_mm=span_min_face_width_mm(spec, span),
        pin_diameter_mm=pins.pin_diameter_mm, dimension_over_pins_mm=pins.dimension_mm,
        pin_contact_radius_mm=pins.contact_radius_mm, chordal_thickness_mm=chord.chordal_thickness_mm,
        chordal_height_mm=chord.chordal_height_mm, chordal_measuring_radius_mm=chord.measuring_radius_mm,
        tooth_thickness_mm=spec.tooth_thickness_mm, thickness_reduction_mm=spec.thickness_reduction_mm,
        min_teeth_without_undercut=math.ceil(z_min - 1e-9), min_teeth_without_undercut_exact=z_min)


def _ring_inspection_facts(spec: GearSpec) -> InspectionSheet:
    return internal_inspection_facts(as_ring(spec))


_SHEETS: dict[GearKind, Callable[[GearSpec], InspectionSheet]] = {
    EXTERNAL_SPUR: external_inspection_facts, EXTERNAL_HELICAL: external_inspection_facts,
    INTERNAL_SPUR: _ring_inspection_facts}
"""Each gear kind's inspection sheet, by the kind object."""


MODIFICATION_NAMES = (  # (FlankModification field, ISO 21771 name as the sheet shows it)
    ("tip_relief_mm", "tip relief C_a"), ("root_relief_mm", "root relief C_f"),
    ("profile_crowning_mm", "profile crowning C_alpha"), ("profile_slope_mm", "profile slope f_Halpha"),
    ("lead_crowning_mm", "lead crowning C_beta"), ("front_end_relief_mm", "end relief C_I (front face)"),
    ("back_end_relief_mm", "end relief C_II (back face)"), ("helix_slope_mm", "helix slope f_Hbeta"),
)
UNMODIFIED_WITHIN_UM = 0.05
"""A contact whose removal is within this counts as on the unmodified flank."""


@dataclass(frozen=True)
class ModificationInspection:
    """The flank modifications as the inspection sheet lists them ({ISO name: (right, left) in um}, with the
    reliefs' start diameters) and the removal where the span anvils and the pins (balls) touch each flank (um,
    transverse; the anvils and pins of a spur gear rest on the least-removed point along the face, a helical
    gear's are taken at mid-face); `span_modified_mm`: the span the modified gear reads (None: no span)."""

    amounts_um: dict[str, tuple[float, float]]
    tip_relief_start_diameters_mm: tuple[float, float]
    root_relief_start_diameters_mm: tuple[float, float]
    span_removal_um: tuple[float, float]
    pin_removal_um: tuple[float, float]
    span_modified_mm: float | None

    @property
    def measured_unmodified(self) -> bool:
        """The span and pin contacts lie where every flank is unmodified (within UNMODIFIED_WITHIN_UM)."""
        return max(map(abs, (*self.span_removal_um, *self.pin_removal_um))) <= UNMODIFIED_WITHIN_UM


def modification_inspection(spec: GearSpec, mods: FlankModifications, sheet: InspectionSheet) -> ModificationInspection:
    """What the inspection sheet says about `spec`'s flank modifications: their amounts, and whether the span and
    pin measurements of `sheet` are taken where the flanks are unmodified (else how much they read less)."""
    sides = (right, left) = (mods.right, mods.left)
    amounts = {name: tuple(1000.0 * getattr(side, attr) for side in sides) for attr, name in MODIFICATION_NAMES
               if any(getattr(side, attr) for side in sides)}

    def diameter(roll_mm: float) -> float:
        return 2.0 * math.hypot(spec.base_radius_mm, roll_mm) if roll_mm else 0.0

    along_face = spec.kind.gauge_contact_x_mm(spec.face_width_mm)  # where the gauge touches each flank

    def removal_um(contact_radius_mm: float) -> tuple[float, float]:
        roll = math.sqrt(max(contact_radius_mm**2 - spec.base_radius_mm**2, 0.0))
        found = []
        for side in sides:
            lead = side.lead_offset_mm(along_face).min()
            found.append(1000.0 * float(side.profile_offset_mm(roll) + lead))
        return found[0], found[1]

    span = removal_um(sheet.span_contact_radius_mm)
    factor = math.cos(spec.base_helix_angle_rad)  # transverse removal -> the normal-section span
    span_modified = (None if sheet.span_measurement_mm is None
                     else sheet.span_measurement_mm - (span[0] + span[1]) / 1000.0 * factor)
    return ModificationInspection(
        amounts_um=amounts,
        tip_relief_start_diameters_mm=(diameter(right.tip_relief_start_roll_mm),
                                       diameter(left.tip_relief_start_roll_mm)),
        root_relief_start_diameters_mm=(diameter(right.root_relief_start_roll_mm),
                                        diameter(left.root_relief_start_roll_mm)),
        span_removal_um=span, pin_removal_um=removal_um(sheet.pin_contact_radius_mm), span_modified_mm=span_modified)
