"""The on-machine probing plan (issue 30, docs/probing.md): design points, normals and probe moves, no text.

A touch probe in the spindle measures the cut gear without unclamping it. Every point is a point of the design
flank with its unit normal n (out of the material, into the space). The ball's centre is programmed (no radius
compensation): it waits at p + (R + approach) n, a probe move goes along -n to p + (R - overtravel) n, and after
the trip it backs off to p + (R + retract) n. A is indexed only with the ball at the clearance height.

A for tooth space k is -k * 360/z: the space's symmetry axis is then vertical (+Z) and the space's points sit at
machine (Y, Z) = their gap-frame (x, y) (docs/architecture.md), the same numbers in every space. One A per space:
every point of a space shares one index of the table (its index error moves the whole space, never bends a
trace), and the vertical stylus stands in the space's opening, which widens outward. The probe moves go along the
design normals, mostly across (Y) with a downward part; each path is checked against the design outline of the
space and its neighbours (ball and stem), so a ball too large for the space is refused, not run.

Points: one per flank on the reference circle at mid face in every space (pitch); in four spaces at 90 deg a
profile trace (mid face, form circle to 95 % of the roll length to the tip: the grade's evaluation range) and a
helix trace (reference circle, the face less min(5 % b, m) at each end: the grade's range) on both flanks.
Spur gears only: a helical flank's normal leaves the transverse plane (refused with a message).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from spur_cad.cad.specs import StockSpec
from spur_cad.cam.common import safe_height_mm
from spur_cad.cam.machine import RESERVED_M_CODES, Machine
from spur_cad.errors import SpurCadError, shown
from spur_cad.geometry.kinds import EXTERNAL_SPUR, INTERNAL_SPUR
from spur_cad.geometry.sampling import even_arc_length_parameters
from spur_cad.geometry.spec import GearSpec
from spur_cad.keys import check_section, key

TIP_EXCLUDED_FRACTION = 0.05
"""The profile trace ends this fraction of the roll length short of the tip (ISO 1328's evaluation range, as
spur_cad.grade.simulated.profile_range_mm; tests/test_probe.py checks they agree)."""
TRACE_SPACES = 4
"""Profile and helix traces are taken in this many spaces, evenly round the gear (0, 90, 180, 270 deg)."""
OUTLINE_SPACING_MM = 0.01
"""Spacing of the design outline the paths are checked against (its chord error is far below a micrometre)."""
FIT_TOLERANCE_MM = 0.001
"""A ball that reaches this far into the design outline anywhere but at its point is refused."""
PATH_SAMPLES = 24
"""Positions checked along each straight move."""
PROBE_CODE = re.compile(r"M[0-9]{1,4}( P[0-9]{1,5})?")
"""A probe on/off code: one M code, with a P number for controls that switch outputs so (Haas M59 P<output>)."""

_GROUP = "Probe"


class ProbeError(SpurCadError, ValueError):
    """A [probe] setting the probing program cannot use; `field` names the key."""

    def __init__(self, message: str, field: str | None = None, section: str | None = "probe"):
        super().__init__(message, field=field, section=section)


@dataclass(frozen=True)
class ProbeSection:
    """[probe]: the on-machine probing program probe.<ext> (docs/probing.md); the ball's centre is programmed."""

    tool_number: int = key(20, low=1, high=99, label="ProbeToolNumber", group=_GROUP,
                           meaning="tool number of the touch probe (its length offset to the ball's centre)")
    stylus_diameter_mm: float = key(2.0, unit="mm", low=0.3, high=20.0, label="ProbeBallDiameter", group=_GROUP,
                                    meaning="diameter of the stylus ball (as calibrated)")
    stem_diameter_mm: float = key(1.5, unit="mm", low=0.1, high="stylus_diameter_mm", label="ProbeStemDiameter",
                                  group=_GROUP, meaning="diameter of the stylus stem above the ball (checked "
                                                        "against the teeth)")
    feed_mm_min: float = key(100.0, unit="mm/min", low=1.0, high=2000.0, label="ProbeFeed", group=_GROUP,
                             meaning="feed of the probe moves (G38.2, G31), as the probe was calibrated")
    positioning_feed_mm_min: float = key(1000.0, unit="mm/min", low=1.0, high=20000.0,
                                         label="ProbePositioningFeed", group=_GROUP,
                                         meaning="feed of every move below the clearance height that is not a "
                                                 "probe move (rapids only at the clearance height)")
    approach_mm: float = key(1.0, unit="mm", low=0.05, high=10.0, label="ProbeApproach", group=_GROUP,
                             meaning="the probe move starts this far from the contact, along the design normal")
    overtravel_mm: float = key(0.5, unit="mm", low=0.01, high=5.0, label="ProbeOvertravel", group=_GROUP,
                               meaning="the probe move ends this far past the design contact (no trip by then: "
                                       "the flank is short by more, the program stops)")
    retract_mm: float = key(0.5, unit="mm", low=0.05, high=10.0, label="ProbeRetract", group=_GROUP,
                            meaning="after the trip the ball backs off to this far from the design contact")
    pitch: bool = key(True, label="ProbePitch", group=_GROUP,
                      meaning="one point per flank on the reference circle at mid face in every space")
    profile: bool = key(True, label="ProbeProfile", group=_GROUP,
                        meaning="profile traces (mid face, form circle to tip) on both flanks of 4 spaces at "
                                "90 deg")
    helix: bool = key(True, label="ProbeHelix", group=_GROUP,
                      meaning="helix traces (reference circle, along the face) on both flanks of 4 spaces at "
                              "90 deg")
    profile_points: int = key(10, low=10, high=200, label="ProbeProfilePoints", group=_GROUP,
                              meaning="points per profile trace")
    helix_points: int = key(5, low=5, high=200, label="ProbeHelixPoints", group=_GROUP,
                            meaning="points per helix trace")
    program_number: int = key(3000, low=1, high=9999, label="ProbeProgramNumber", group=_GROUP,
                              meaning="program number (Fanuc and Haas O word)")
    probe_on_code: str = key("", label="ProbeOnCode", group=_GROUP,
                             meaning="M code switching the probe on after the tool change (with a P number "
                                     "on Haas: M59 P<output>), '': none")
    probe_off_code: str = key("", label="ProbeOffCode", group=_GROUP,
                              meaning="M code switching the probe off at the end, '': none")

    @property
    def ball_radius_mm(self) -> float:
        return self.stylus_diameter_mm / 2.0

    def __post_init__(self) -> None:
        """Raise ProbeError for a key outside its range, a bad probe code, or no check chosen, once, when the section
        is made (the probe against the gear: plan_probe)."""
        check_section(self, "probe", ProbeError)
        for name in ("probe_on_code", "probe_off_code"):
            code = getattr(self, name)
            if code and (not PROBE_CODE.fullmatch(code) or int(code.split()[0][1:]) in RESERVED_M_CODES):
                raise ProbeError(f"[probe] {name} = {shown(code, 20)} must be one M code (with a P number at "
                                 "most, e.g. 'M59 P1') that does not stop, end or call a program or drive the "
                                 "spindle, tool or coolant", field=name)
        if not (self.pitch or self.profile or self.helix):
            raise ProbeError("[probe] pitch, profile and helix are all false: nothing to probe", field="pitch")


@dataclass(frozen=True)
class ProbePoint:
    """One probed point: the design point and normal in the machine's (Y, Z) at A = `a_deg` (the space's axis
    vertical), at X = `x_mm`; `kind` is 'pitch', 'profile' or 'helix', `side` 'right' or 'left'."""

    space: int
    side: str
    kind: str
    x_mm: float
    a_deg: float
    point: tuple[float, float]  # design point (Y, Z)
    normal: tuple[float, float]  # unit design normal (Y, Z), out of the material
    radius_mm: float  # the point's distance from the gear axis


@dataclass(frozen=True)
class ProbeMoves:
    """The ball centre's positions (Y, Z) for one point: start of the probe move, its end, the back-off."""

    start: tuple[float, float]
    target: tuple[float, float]
    retract: tuple[float, float]
    link_via_clearance: bool  # reach `start` from the clearance height (else straight from the last back-off)


@dataclass(frozen=True)
class ProbePlan:
    """The points in program order, their moves, the clearance height (ball centre) and the trace spaces."""

    points: tuple[ProbePoint, ...]
    moves: tuple[ProbeMoves, ...]
    clearance_z_mm: float
    trace_spaces: tuple[int, ...]
    section: ProbeSection


def trace_spaces(teeth: int) -> tuple[int, ...]:
    """The TRACE_SPACES spaces nearest to 0, 90, 180 and 270 deg (distinct for every z >= 5)."""
    return tuple(sorted({round(j * teeth / TRACE_SPACES) % teeth for j in range(TRACE_SPACES)}))


def helix_range_mm(spec: GearSpec) -> tuple[float, float]:
    """The helix trace's range along X: the face less, at each end, the smaller of 5 % of b and one module."""
    cut = min(0.05 * spec.face_width_mm, spec.module_mm)
    return cut, spec.face_width_mm - cut


def _flank_point(spec: GearSpec, radius_mm: float, side: str) -> tuple[np.ndarray, np.ndarray]:
    """Space 0's involute point at `radius_mm` on `side` and its normal, in the gap frame (= machine Y, Z)."""
    involute = spec.tooth_space_profile().involute
    t = math.sqrt(max((radius_mm / spec.base_radius_mm) ** 2 - 1.0, 0.0))
    t = min(max(t, involute.start), involute.end)
    point, normal = involute.points(np.array([t]))[0], involute.normals(np.array([t]))[0]
    mirror = np.array([1.0, 1.0]) if side == "right" else np.array([-1.0, 1.0])
    return point * mirror, normal * mirror


def design_points(spec: GearSpec, probe: ProbeSection) -> list[ProbePoint]:
    """Every point in program order: per space (A = -k * 360/z), the pitch points, then in trace spaces the
    profile traces (form circle, or [mate]'s start of active profile when above it, -> tip) and the helix
    traces (front -> back); right flank before left."""
    rb = spec.base_radius_mm
    start_radius = max(spec.form_radius_mm, spec.active_profile_start_diameter_mm / 2.0)  # [mate]'s SAP when given
    roll_form = math.sqrt(max(start_radius ** 2 - rb ** 2, 0.0))
    roll_tip = math.sqrt(spec.tip_radius_mm ** 2 - rb ** 2)
    rolls = np.linspace(roll_form, roll_form + (1.0 - TIP_EXCLUDED_FRACTION) * (roll_tip - roll_form),
                        probe.profile_points)
    profile_radii = np.sqrt(rolls ** 2 + rb ** 2)
    helix_x = np.linspace(*helix_range_mm(spec), probe.helix_points)
    mid, r = spec.face_width_mm / 2.0, spec.reference_radius_mm
    traced = trace_spaces(spec.teeth)
    found = []

    def add(k: int, side: str, kind: str, x: float, radius: float) -> None:
        p, n = _flank_point(spec, radius, side)
        found.append(ProbePoint(k, side, kind, float(x), -k * 360.0 / spec.teeth, (float(p[0]), float(p[1])),
                                (float(n[0]), float(n[1])), float(np.hypot(*p))))

    for k in range(spec.teeth):
        if probe.pitch:
            for side in ("right", "left"):
                add(k, side, "pitch", mid, r)
        if k not in traced:
            continue
        for side in ("right", "left"):
            if probe.profile:
                for radius in profile_radii:
                    add(k, side, "profile", mid, radius)
            if probe.helix:
                for x in helix_x:
                    add(k, side, "helix", x, r)
    return found


def design_outline(spec: GearSpec) -> np.ndarray:
    """(M, 2) the design outline of space 0 in the gap frame, tooth centre to tooth centre (the material around
    the space the ball works in), every OUTLINE_SPACING_MM."""
    pieces = []
    for segment in spec.tooth_space_profile().segments:
        if segment.end > segment.start:
            pieces.append(segment.points(even_arc_length_parameters(segment, OUTLINE_SPACING_MM)))
    half = np.concatenate(pieces)
    return np.concatenate([half, half * np.array([-1.0, 1.0])])


def _strip(outline: np.ndarray, centres: np.ndarray, half_width_mm: float) -> np.ndarray:
    """The outline points within `half_width_mm` in Y of the centres' Y range (the rest cannot be nearer)."""
    low, high = centres[:, 0].min() - half_width_mm, centres[:, 0].max() + half_width_mm
    return outline[(outline[:, 0] >= low) & (outline[:, 0] <= high)]


def _nearest_mm(outline: np.ndarray, centres: np.ndarray, reach_mm: float) -> np.ndarray:
    """Distance from each centre (N, 2) to the nearest outline point, exact up to `reach_mm` (inf beyond)."""
    outline = _strip(outline, centres, reach_mm)
    if len(outline) == 0:
        return np.full(len(centres), np.inf)
    return np.hypot(centres[:, None, 0] - outline[None, :, 0], centres[:, None, 1] - outline[None, :, 1]).min(axis=1)


def _stem_hits(outline: np.ndarray, centres: np.ndarray, stem_radius_mm: float) -> bool:
    """True when an outline point stands in the vertical stem above any ball centre."""
    outline = _strip(outline, centres, stem_radius_mm)
    above = outline[None, :, 1] > centres[:, None, 1]
    return bool(np.any(above & (np.abs(outline[None, :, 0] - centres[:, None, 0]) < stem_radius_mm)))


def _segment(a, b) -> np.ndarray:
    s = np.linspace(0.0, 1.0, PATH_SAMPLES)[:, None]
    return np.asarray(a)[None, :] * (1.0 - s) + np.asarray(b)[None, :] * s


def _clear(outline: np.ndarray, centres: np.ndarray, ball_mm: float, stem_mm: float, gap_mm: float) -> bool:
    return bool(np.all(_nearest_mm(outline, centres, ball_mm + gap_mm) >= ball_mm + gap_mm)
                and not _stem_hits(outline, centres, stem_mm))


PROBED_KINDS = frozenset({EXTERNAL_SPUR, INTERNAL_SPUR})
"""Gear kinds [probe] plans for: straight teeth, whose flank normals lie in the transverse plane (a helical flank's
leaves it)."""


def plan_probe(spec: GearSpec, stock: StockSpec, machine: Machine, probe: ProbeSection) -> ProbePlan:
    """The probing plan of `spec` as cut from `stock`; ProbeError (naming the key) for a helical gear or a
    ball that does not reach a point without touching the design elsewhere."""
    if spec.kind not in PROBED_KINDS:
        raise ProbeError(f"[probe] probes spur gears only: [gear] helix_angle_deg = {spec.helix_angle_deg:g} (a "
                         "helical flank's normal leaves the transverse plane); leave [probe] out")
    ball, stem = probe.ball_radius_mm, probe.stem_diameter_mm / 2.0
    gap = 0.5 * min(probe.approach_mm, probe.retract_mm)
    clearance = safe_height_mm(stock.blank_radius_mm(spec), machine) + ball
    outline = design_outline(spec)
    points = design_points(spec, probe)
    moves, last = [], None
    for number, pt in enumerate(points, start=1):
        p, n = np.array(pt.point), np.array(pt.normal)
        start, contact = p + (ball + probe.approach_mm) * n, p + ball * n
        target, retract = p + (ball - probe.overtravel_mm) * n, p + (ball + probe.retract_mm) * n
        where = (f"point {number} (space {pt.space}, {pt.side} flank, {pt.kind}, radius {pt.radius_mm:.3f} mm)")
        approach_path = _segment(start, contact)
        if (np.min(_nearest_mm(outline, approach_path, ball)) < ball - FIT_TOLERANCE_MM
                or _stem_hits(outline, approach_path, stem)):
            raise ProbeError(f"[probe] stylus_diameter_mm = {probe.stylus_diameter_mm:g}: the ball (or its stem, "
                             f"stem_diameter_mm = {probe.stem_diameter_mm:g}) touches the gear elsewhere before "
                             f"it reaches {where}; use a smaller ball", field="stylus_diameter_mm")
        descent = _segment(np.array([start[0], clearance]), start)
        ascent = _segment(retract, np.array([retract[0], clearance]))
        if not (_clear(outline, descent, ball, stem, gap) and _clear(outline, ascent, ball, stem, gap)):
            raise ProbeError(f"[probe] stylus_diameter_mm = {probe.stylus_diameter_mm:g}: the ball cannot go "
                             f"straight down to {where} and back up keeping {gap:g} mm (half the smaller of "
                             "approach_mm and retract_mm) from the gear; use a smaller ball",
                             field="stylus_diameter_mm")
        direct = (last is not None and last[0].space == pt.space  # a spur gear's section is the same at every X
                  and _clear(outline, _segment(last[1], start), ball, stem, gap))
        moves.append(ProbeMoves(tuple(start), tuple(target), tuple(retract), not direct))
        last = (pt, retract)
    return ProbePlan(tuple(points), tuple(moves), clearance, trace_spaces(spec.teeth), probe)
