"""Gear pairs after ISO 21771: what the mate decides (docs/geometry.md, "Gear pairs").

A pair is this gear (`GearPair.gear`) and its mate (`GearPair.mate`), each a `PairMember`; at most one of them is
internal (a ring). Teeth, radii and diameters are positive numbers here, as everywhere in spur_cad; the formulas
use ISO 21771's signed convention inside (an internal gear's z, d, d_a, d_f negative, and the centre distance of
an internal pair negative), which writes every relation once for external and internal pairs:

    inv(alpha_wt) = inv(alpha_t) + 2 tan(alpha_n) (x_1 + x_2) / (z_1 + z_2)
    a = m_t (z_1 + z_2) / 2 cos(alpha_t) / cos(alpha_wt)            (zero backlash at nominal thicknesses)
    d_w1 = 2 a z_1 / (z_1 + z_2),  d_a = d + 2 (h_a* + x) m_n,  d_f = d - 2 (h_f* - x) m_n
    roll length at the mate's tip (start of active profile): rho_1 = a sin(alpha_wt) - sign(z_2) rho_a2

The profile shift coefficient keeps ISO's meaning for a ring too (x > 0 thickens its teeth: its tips move toward
the axis), as in spur_cad.geometry.internal. Helical pairs use transverse values (m_t, alpha_t) and have the
overlap ratio b sin(beta) / (pi m_n). There is no tip shortening: the tip diameters are d + 2 (h_a* + x) m_n.

Everything here is plain arithmetic on validated frozen dataclasses: `pair_facts` computes, `pair_problems` says
what makes the pair unusable (interference, contact ratio below 1), `pair_at_centre_distance` finds the mate's
shift that a given centre distance needs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from spur_cad.errors import SpurCadError
from spur_cad.geometry.involute import inverse_involute_function, involute_function

MIN_TEETH = 5
MAX_TEETH = 1000
MIN_RING_PINION_DIFFERENCE = 5
"""A ring needs at least this many teeth more than its pinion (fewer: the tips interfere at any addendum)."""
SHIFT_RANGE = (-2.0, 3.0)
"""Profile shift coefficients a pair accepts (the job file's range for [gear] and [mate])."""
MIN_CONTACT_RATIO = 1.0
"""A pair whose transverse (spur) or total (helical) contact ratio is below this does not transmit motion
continuously: refused."""
INTERFERENCE_TOLERANCE_MM = 1e-6
"""How far (radially) the mate's tip contact may lie past a form circle before it counts as interference: the
basic rack's own start of active profile lies exactly on the form circle its standard tip radius generates."""


class PairError(SpurCadError, ValueError):
    """A gear pair that cannot be made or would not run; `field` names the [mate] key to blame."""

    def __init__(self, message: str, field: str | None = None):
        super().__init__(message, field=field, section="mate")


def _check_number(name: str, value: object, low: float, high: float, *, low_open: bool = False) -> None:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise PairError(f"{name} must be a finite number, got {value!r}", field=name)
    if value < low or value > high or (low_open and value == low):
        raise PairError(f"{name} = {value:g} is outside the accepted range {'(' if low_open else '['}{low:g}, "
                        f"{high:g}]", field=name)


@dataclass(frozen=True)
class PairMember:
    """One gear of a pair, as ISO 21771's pair relations need it (module and angles are the pair's).

    `thickness_reduction_mm`: how much thinner than nominal its teeth are on the reference circle (transverse arc,
    all allowances together): it sets the backlash. `form_diameter_mm`: where its involute starts on the part
    (the generated form circle; a ring's is its largest involute diameter); None: the base circle (an external
    gear) or the root circle (a ring), i.e. the whole involute is there. `root_diameter_mm`: the actual root
    diameter when it is not d - 2 (h_f* - x) m_n (a ring cut by a shaper cutter); None: that formula.
    """

    teeth: int
    internal: bool = False
    profile_shift_coefficient: float = 0.0
    addendum_coefficient: float = 1.0
    dedendum_coefficient: float = 1.25
    thickness_reduction_mm: float = 0.0
    form_diameter_mm: float | None = None
    root_diameter_mm: float | None = None

    def __post_init__(self) -> None:
        if isinstance(self.teeth, bool) or not isinstance(self.teeth, int):
            raise PairError(f"teeth must be a whole number, got {self.teeth!r}", field="teeth")
        if not MIN_TEETH <= self.teeth <= MAX_TEETH:
            raise PairError(f"teeth = {self.teeth} is outside the accepted range {MIN_TEETH}..{MAX_TEETH}",
                            field="teeth")
        if not isinstance(self.internal, bool):
            raise PairError(f"internal must be true or false, got {self.internal!r}", field="internal")
        _check_number("profile_shift_coefficient", self.profile_shift_coefficient, *SHIFT_RANGE)
        _check_number("addendum_coefficient", self.addendum_coefficient, 0.0, 2.5, low_open=True)
        _check_number("dedendum_coefficient", self.dedendum_coefficient, 0.0, 3.0, low_open=True)
        _check_number("thickness_reduction_mm", self.thickness_reduction_mm, 0.0, 1e4)
        for name in ("form_diameter_mm", "root_diameter_mm"):
            if getattr(self, name) is not None:
                _check_number(name, getattr(self, name), 0.0, 1e5, low_open=True)

    @property
    def sign(self) -> int:
        """ISO 21771's sign of z and of the diameters: -1 for a ring."""
        return -1 if self.internal else 1


@dataclass(frozen=True)
class GearPair:
    """This gear and its mate on parallel axes, both generated by one rack (normal module `module_mm`, normal
    pressure angle `pressure_angle_deg`, helix angle `helix_angle_deg` on the reference cylinders, opposite hands
    for an external helical pair, the same hand for an internal one). `face_width_mm` is the common face width
    (the overlap ratio's b)."""

    gear: PairMember
    mate: PairMember
    module_mm: float
    pressure_angle_deg: float = 20.0
    helix_angle_deg: float = 0.0
    face_width_mm: float = 0.0

    def __post_init__(self) -> None:
        for name, value in (("gear", self.gear), ("mate", self.mate)):
            if not isinstance(value, PairMember):
                raise PairError(f"{name} must be a PairMember, got {type(value).__name__}")
        _check_number("module_mm", self.module_mm, 0.05, 100.0)
        _check_number("pressure_angle_deg", self.pressure_angle_deg, 0.0, 45.0, low_open=True)
        _check_number("helix_angle_deg", self.helix_angle_deg, 0.0, 45.0)
        _check_number("face_width_mm", self.face_width_mm, 0.0, 1e5)
        if self.gear.internal and self.mate.internal:
            raise PairError("two internal gears cannot mesh: a ring's mate is an external pinion", field="internal")
        ring, pinion = (self.gear, self.mate) if self.gear.internal else (self.mate, self.gear)
        if ring.internal and ring.teeth - pinion.teeth < MIN_RING_PINION_DIFFERENCE:
            raise PairError(f"a {ring.teeth}-tooth ring and a {pinion.teeth}-tooth pinion: the ring needs at least "
                            f"{MIN_RING_PINION_DIFFERENCE} teeth more than its pinion", field="teeth")

    # --- the rack's quantities (transverse for a helical pair) -----------------------------------------------
    @property
    def normal_pressure_angle_rad(self) -> float:
        return math.radians(self.pressure_angle_deg)

    @property
    def helix_angle_rad(self) -> float:
        return math.radians(self.helix_angle_deg)

    @property
    def transverse_module_mm(self) -> float:
        return self.module_mm / math.cos(self.helix_angle_rad)

    @property
    def transverse_pressure_angle_rad(self) -> float:
        return math.atan(math.tan(self.normal_pressure_angle_rad) / math.cos(self.helix_angle_rad))

    @property
    def base_helix_angle_rad(self) -> float:
        return math.asin(math.sin(self.helix_angle_rad) * math.cos(self.normal_pressure_angle_rad))

    @property
    def signed_teeth_sum(self) -> int:
        """z_1 + z_2 with a ring's teeth negative (negative for an internal pair)."""
        return self.gear.sign * self.gear.teeth + self.mate.sign * self.mate.teeth

    @property
    def shift_sum(self) -> float:
        return self.gear.profile_shift_coefficient + self.mate.profile_shift_coefficient


@dataclass(frozen=True)
class PairFacts:
    """A pair's ISO 21771 quantities, in mm and degrees, all positive (centre distance and diameters are
    magnitudes). "gear" is this gear, "mate" the other one."""

    internal: bool  # an internal pair (either gear a ring)
    working_pressure_angle_deg: float  # transverse, alpha_wt
    centre_distance_mm: float  # the working centre distance a_w (zero backlash at nominal thicknesses)
    reference_centre_distance_mm: float  # m_t |z_1 + z_2| / 2
    shift_sum: float  # x_1 + x_2 (ISO signs)
    operating_pitch_diameter_mm: float
    mate_operating_pitch_diameter_mm: float
    tip_diameter_mm: float
    mate_tip_diameter_mm: float
    root_diameter_mm: float
    mate_root_diameter_mm: float
    base_diameter_mm: float
    mate_base_diameter_mm: float
    tip_clearance_mm: float  # this gear's tip to the mate's root circle
    root_clearance_mm: float  # the mate's tip to this gear's root circle
    circumferential_backlash_mm: float  # j_wt on the operating pitch circle
    normal_backlash_mm: float  # j_bn = j_wt cos(alpha_wt) cos(beta_b)
    transverse_contact_ratio: float  # epsilon_alpha
    overlap_ratio: float  # epsilon_beta (0 for spur)
    total_contact_ratio: float  # epsilon_gamma
    start_of_active_profile_diameter_mm: float  # this gear's SAP: where the mate's tip meets its flank
    mate_start_of_active_profile_diameter_mm: float
    start_of_active_profile_roll_mm: float  # this gear's roll length (from its base tangent point) at its SAP,
    #                                          negative when the mate's tip reaches past the tangent point
    mate_start_of_active_profile_roll_mm: float


def working_pressure_angle_rad(pair: GearPair) -> float:
    """alpha_wt from inv(alpha_wt) = inv(alpha_t) + 2 tan(alpha_n) (x_1 + x_2) / (z_1 + z_2) (signed z)."""
    value = involute_function(pair.transverse_pressure_angle_rad) + (
        2.0 * math.tan(pair.normal_pressure_angle_rad) * pair.shift_sum / pair.signed_teeth_sum)
    if value <= 0.0:
        raise PairError(f"the shift sum x_1 + x_2 = {pair.shift_sum:g} leaves no working pressure angle "
                        f"(inv(alpha_wt) = {value:.6g} <= 0): the teeth cannot mesh; use less negative shift",
                        field="profile_shift_coefficient")
    return inverse_involute_function(value)


def _roll_mm(diameter_mm: float, base_diameter_mm: float) -> float:
    """Roll length sqrt(r^2 - r_b^2) of a circle of `diameter_mm` on the involute of a base circle (0 inside)."""
    return math.sqrt(max(diameter_mm * diameter_mm - base_diameter_mm * base_diameter_mm, 0.0)) / 2.0


def _diameters(pair: GearPair, member: PairMember) -> tuple[float, float, float, float]:
    """Signed reference, tip, root and base diameters (ISO 21771: negative for a ring)."""
    m, s = pair.module_mm, member.sign
    d = s * pair.transverse_module_mm * member.teeth
    d_a = d + 2.0 * (member.addendum_coefficient + member.profile_shift_coefficient) * m
    d_f = d - 2.0 * (member.dedendum_coefficient - member.profile_shift_coefficient) * m
    if member.root_diameter_mm is not None:
        d_f = s * member.root_diameter_mm
    return d, d_a, d_f, d * math.cos(pair.transverse_pressure_angle_rad)


def _thickness_on_mm(pair: GearPair, member: PairMember, diameter_mm: float, alpha_y_rad: float) -> float:
    """Transverse arc tooth thickness on the (signed) circle `diameter_mm` of pressure angle alpha_y: ISO 21771
    s_y = d_y (s / d + inv(alpha_t) - inv(alpha_y)) with s the design thickness on the reference circle."""
    d = member.sign * pair.transverse_module_mm * member.teeth
    s = pair.transverse_module_mm * (math.pi / 2.0 + 2.0 * member.profile_shift_coefficient
                                     * math.tan(pair.normal_pressure_angle_rad)) - member.thickness_reduction_mm
    inv_t = involute_function(pair.transverse_pressure_angle_rad)
    return diameter_mm * (s / d + inv_t - involute_function(alpha_y_rad))


def pair_facts(pair: GearPair) -> PairFacts:
    """The pair's working pressure angle, centre distance, pitch diameters, clearances, backlash, contact ratios
    and starts of active profile (see the module docstring)."""
    alpha_t, alpha_wt = pair.transverse_pressure_angle_rad, working_pressure_angle_rad(pair)
    g, q = pair.gear, pair.mate
    z_sum = pair.signed_teeth_sum
    a = pair.transverse_module_mm * z_sum / 2.0 * math.cos(alpha_t) / math.cos(alpha_wt)  # signed
    d1, da1, df1, db1 = _diameters(pair, g)
    d2, da2, df2, db2 = _diameters(pair, q)
    dw1, dw2 = 2.0 * a * g.sign * g.teeth / z_sum, 2.0 * a * q.sign * q.teeth / z_sum
    pitch_w = math.pi * dw1 / (g.sign * g.teeth)  # the same on both operating pitch circles
    backlash = pitch_w - _thickness_on_mm(pair, g, dw1, alpha_wt) - _thickness_on_mm(pair, q, dw2, alpha_wt)
    roll_a1, roll_a2 = _roll_mm(da1, db1), _roll_mm(da2, db2)
    along = a * math.sin(alpha_wt)  # signed: T_1 T_2 for an external pair
    roll_sap1 = g.sign * (along - q.sign * roll_a2)
    roll_sap2 = q.sign * (along - g.sign * roll_a1)
    path = abs(roll_a1 - roll_sap1)  # the path of contact g_alpha, from the mate's tip to this gear's tip
    base_pitch = math.pi * pair.transverse_module_mm * math.cos(alpha_t)
    eps_alpha = path / base_pitch
    eps_beta = pair.face_width_mm * math.sin(pair.helix_angle_rad) / (math.pi * pair.module_mm)
    return PairFacts(
        internal=g.internal or q.internal,
        working_pressure_angle_deg=math.degrees(alpha_wt),
        centre_distance_mm=abs(a),
        reference_centre_distance_mm=abs(pair.transverse_module_mm * z_sum / 2.0),
        shift_sum=pair.shift_sum,
        operating_pitch_diameter_mm=abs(dw1), mate_operating_pitch_diameter_mm=abs(dw2),
        tip_diameter_mm=abs(da1), mate_tip_diameter_mm=abs(da2),
        root_diameter_mm=abs(df1), mate_root_diameter_mm=abs(df2),
        base_diameter_mm=abs(db1), mate_base_diameter_mm=abs(db2),
        tip_clearance_mm=a - da1 / 2.0 - df2 / 2.0,  # signed a, d: right for rings too
        root_clearance_mm=a - da2 / 2.0 - df1 / 2.0,
        circumferential_backlash_mm=backlash,
        normal_backlash_mm=backlash * math.cos(alpha_wt) * math.cos(pair.base_helix_angle_rad),
        transverse_contact_ratio=eps_alpha,
        overlap_ratio=eps_beta,
        total_contact_ratio=eps_alpha + eps_beta,
        start_of_active_profile_diameter_mm=2.0 * math.hypot(db1 / 2.0, roll_sap1),
        mate_start_of_active_profile_diameter_mm=2.0 * math.hypot(db2 / 2.0, roll_sap2),
        start_of_active_profile_roll_mm=roll_sap1,
        mate_start_of_active_profile_roll_mm=roll_sap2,
    )


def tip_thickness_mm(pair: GearPair, member: PairMember) -> float:
    """A member's transverse arc tooth thickness on its tip circle (<= 0: pointed teeth)."""
    _, d_a, _, d_b = _diameters(pair, member)
    return _thickness_on_mm(pair, member, d_a, math.acos(min(d_b / d_a, 1.0)))


def _ring_tip_margin_rad(pair: GearPair, facts: PairFacts) -> float:
    """Internal pairs: trochoid (tip) interference as the pinion leaves mesh, KHK's condition
    theta_1 z_1 / z_2 + inv(alpha_wt) - inv(alpha_a2) - theta_2 >= 0 with
    cos(theta_1') = (r_a2^2 - r_a1^2 - a^2) / (2 a r_a1), theta_1 = theta_1' + inv(alpha_a1) - inv(alpha_wt),
    theta_2 = acos((a^2 + r_a2^2 - r_a1^2) / (2 a r_a2)); pinion 1, ring 2, all positive. -1 (interference)
    when the tip circles do not cross."""
    pinion_is_gear = not pair.gear.internal
    z1, z2 = (pair.gear.teeth, pair.mate.teeth) if pinion_is_gear else (pair.mate.teeth, pair.gear.teeth)
    ra1 = (facts.tip_diameter_mm if pinion_is_gear else facts.mate_tip_diameter_mm) / 2.0
    ra2 = (facts.mate_tip_diameter_mm if pinion_is_gear else facts.tip_diameter_mm) / 2.0
    rb1 = (facts.base_diameter_mm if pinion_is_gear else facts.mate_base_diameter_mm) / 2.0
    rb2 = (facts.mate_base_diameter_mm if pinion_is_gear else facts.base_diameter_mm) / 2.0
    a, inv_w = facts.centre_distance_mm, involute_function(math.radians(facts.working_pressure_angle_deg))
    cos_t1 = (ra2**2 - ra1**2 - a**2) / (2.0 * a * ra1)
    cos_t2 = (a**2 + ra2**2 - ra1**2) / (2.0 * a * ra2)
    if not (-1.0 <= cos_t1 <= 1.0 and -1.0 <= cos_t2 <= 1.0) or ra2 <= rb2 or ra1 <= rb1:
        return -1.0
    theta1 = math.acos(cos_t1) + involute_function(math.acos(rb1 / ra1)) - inv_w
    theta2 = math.acos(cos_t2)
    return theta1 * z1 / z2 + inv_w - involute_function(math.acos(rb2 / ra2)) - theta2


def pair_problems(pair: GearPair, facts: PairFacts | None = None) -> list[PairError]:
    """What makes the pair unusable, each a one-line PairError blaming a [mate] key, most basic first: pointed
    teeth, negative tip clearance, involute interference (a tip reaching past the other gear's base tangent
    point or below its form circle: contact on the fillet), trochoid (tip) interference of an internal pair,
    a contact ratio below MIN_CONTACT_RATIO (the total one for a helical pair). Empty: the pair runs."""
    facts = facts or pair_facts(pair)
    problems: list[PairError] = []
    for who, member, field in (("this gear", pair.gear, "teeth"), ("the mate", pair.mate,
                                                                   "profile_shift_coefficient")):
        if tip_thickness_mm(pair, member) <= 0.0:
            problems.append(PairError(f"{who}'s teeth are pointed (tip thickness <= 0 at its tip diameter "
                                      f"{abs(_diameters(pair, member)[1]):.3f} mm); less profile shift or a smaller "
                                      "addendum", field=field))
    for clearance, text in ((facts.tip_clearance_mm, "this gear's tips reach the mate's root circle"),
                            (facts.root_clearance_mm, "the mate's tips reach this gear's root circle")):
        if clearance < 0.0:
            problems.append(PairError(f"{text} (clearance {clearance:.4f} mm < 0 at centre distance "
                                      f"{facts.centre_distance_mm:.4f} mm); smaller addendum or larger centre "
                                      "distance", field="addendum_coefficient"))
    for member, roll, sap, whose, field in (
            (pair.gear, facts.start_of_active_profile_roll_mm, facts.start_of_active_profile_diameter_mm,
             "the mate's tips reach this gear's", "addendum_coefficient"),
            (pair.mate, facts.mate_start_of_active_profile_roll_mm, facts.mate_start_of_active_profile_diameter_mm,
             "this gear's tips reach the mate's", "teeth")):
        if roll < 0.0:
            problems.append(PairError(f"involute interference: {whose} flank past its base circle's tangent point "
                                      f"(by {-roll:.4f} mm along the line of action); a smaller addendum, more "
                                      "profile shift or more teeth", field=field))
        elif member.form_diameter_mm is not None:
            below = member.form_diameter_mm - sap if not member.internal else sap - member.form_diameter_mm
            if below > INTERFERENCE_TOLERANCE_MM:
                where = "below" if not member.internal else "beyond"
                problems.append(PairError(
                    f"root interference: {whose} fillet (active profile from diameter {sap:.4f} mm, {where} the "
                    f"form circle {member.form_diameter_mm:.4f} mm where the involute starts); smaller addendum, "
                    "more profile shift or a smaller rack tip radius", field=field))
    if facts.internal:
        margin = _ring_tip_margin_rad(pair, facts)
        if margin < 0.0:
            problems.append(PairError(f"tip interference: the pinion's tips strike the ring's tips as they leave "
                                      f"mesh (margin {math.degrees(margin):.4f} deg < 0); a smaller pinion, a "
                                      "shorter addendum or more ring profile shift", field="teeth"))
    ratio, which = ((facts.total_contact_ratio, "total") if facts.overlap_ratio > 0.0 else  # spur: eps_beta = 0
                    (facts.transverse_contact_ratio, "transverse"))
    if ratio < MIN_CONTACT_RATIO:
        problems.append(PairError(f"the {which} contact ratio {ratio:.4f} is below {MIN_CONTACT_RATIO:g}: the pair "
                                  "does not mesh continuously; more teeth, a larger addendum or a smaller centre "
                                  "distance", field="addendum_coefficient"))
    return problems


def pair_at_centre_distance(pair: GearPair, centre_distance_mm: float) -> GearPair:
    """The pair with the mate's profile shift set so that it meshes without backlash (nominal thicknesses) at
    `centre_distance_mm`: cos(alpha_wt) = m_t (z_1 + z_2) cos(alpha_t) / (2 a), then the shift sum from the
    involute relation. PairError at centre_distance_mm when no mate shift within SHIFT_RANGE reaches it (naming
    the centre distances that can be reached)."""
    _check_number("centre_distance_mm", centre_distance_mm, 0.0, 1e5, low_open=True)
    z_sum = pair.signed_teeth_sum
    reference = pair.transverse_module_mm * z_sum / 2.0  # signed
    cos_w = reference * math.cos(pair.transverse_pressure_angle_rad) / (math.copysign(centre_distance_mm, z_sum))
    shift_sum = math.nan
    if cos_w <= 1.0:
        alpha_wt = math.acos(cos_w)
        shift_sum = (involute_function(alpha_wt) - involute_function(pair.transverse_pressure_angle_rad)) * z_sum / (
            2.0 * math.tan(pair.normal_pressure_angle_rad))
    mate_shift = shift_sum - pair.gear.profile_shift_coefficient
    if not SHIFT_RANGE[0] <= mate_shift <= SHIFT_RANGE[1]:
        reach = []
        for x in SHIFT_RANGE:
            try:
                reach.append(pair_facts(replace(pair, mate=replace(pair.mate, profile_shift_coefficient=x)))
                             .centre_distance_mm)
            except PairError:
                reach.append(abs(reference) * math.cos(pair.transverse_pressure_angle_rad))
        low, high = sorted(reach)
        why = (f"the base circles leave no working pressure angle below "
               f"{abs(reference) * math.cos(pair.transverse_pressure_angle_rad):.4f} mm" if math.isnan(shift_sum)
               else f"it needs a mate shift of {mate_shift:.4f}")
        raise PairError(f"centre_distance_mm = {centre_distance_mm:g} mm cannot be reached: {why}; mate shifts "
                        f"{SHIFT_RANGE[0]:g} to {SHIFT_RANGE[1]:g} reach {low:.4f} to {high:.4f} mm",
                        field="centre_distance_mm")
    return replace(pair, mate=replace(pair.mate, profile_shift_coefficient=mate_shift))
