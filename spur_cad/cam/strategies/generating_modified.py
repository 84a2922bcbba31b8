"""Generating finishing of modified flanks (issue 31.3, docs/cam.md "Flank modifications"): the planned passes of
the design moved by the removal spur_cad.geometry.modifications gives, each pass a polyline along X.

- **Flank mode.** A pass at involute roll t keeps its A (clamped, the design's tangent direction) and moves along
  its flank normal (machine Y: +Y into the tooth on the right flank, -Y on the left) by the removal its straight
  side must make to touch the modified flank: the design tangent line's support, I(t).n(t) - max_L Q(L).n(t),
  over dense points Q of the modified involute (exact at the reliefs' kinks, where the modified flank is convex),
  plus the lead modifications at the face position X. A helical pass touches section X at the effective roll
  t_e = t - side (dY/dX) X / r_b, so even a profile modification makes its offset vary along X.
  Spur flank passes are turned to touch the modified flank at their planned contacts (a relief turns the flank's
  tangent; a pass keeping the design's roll would touch 0.6 mm higher and leave 7 um at a 5 um target), with two
  passes at each relief's start (the kink, which the plan gives a pass of its own).
  Spur flank passes take the "raised" tool end (never lower than the planned one): a rack-end corner moved with
  its flank into the tooth would reach into the fillet, which moves less (found in the simulation: 6 um).
- **Tip mode.** The modified fillet is the design fillet moved by the form point's removal faded as
  (beta / beta_F)^2 along the form point's normal (spur_cad.geometry.modifications.modified_tooth_space_profile);
  each fillet pass moves with its contact point. Root passes are not moved (the root is not modified). Helical
  fillet passes touch a different fillet point in each section X (`helical_fillet_parameters`) and move by its
  faded removal along the form normal turned with the section. The lead modifications at X are part of the form
  point's removal there (the design's fillet moves with them, as the B-rep's sections do).
- **Helical flank passes' ends** are raised per section X (`_helical_raised_ends`): a pass seen below the form
  circle in some section has its corner on the rack's round over the fillet, and moved sideways with the lead it
  gouged the fillet (5.5 um for 10 um crowning); raised so that its straight side starts neither below the spur
  raised end at the section's effective roll nor below the form point, it leaves the fillet to the tip passes.
- **Helical sideways offsets** are reduced by the swept tool's growth with the path's slope (`_envelope_growth_mm`),
  and their dY chords lie at most CHORD_GOUGE_SHARE of the tolerance deeper than the samples (a crowning's chords
  all lie deeper).
- The offset along X is sampled every `X_SAMPLE_MM` over the face and reduced to the fewest breakpoints whose
  lines stay within the chordal tolerance ([job] profile_tolerance_mm); outside the face the end values hold.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from spur_cad.cam.ir import Feature
from spur_cad.cam.strategies.generating_geometry import RAISED_END_MARGIN_MM, GeneratingPass, flank_poses
from spur_cad.cam.strategies.generating_helical import CORNER_MATCH_MM
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.geometry.frames import part_to_machine
from spur_cad.geometry.kinds import EXTERNAL_HELICAL, EXTERNAL_SPUR, INTERNAL_SPUR, GearKind
from spur_cad.geometry.modifications import FlankModifications
from spur_cad.geometry.profile import rack_corner
from spur_cad.geometry.spec import GearSpec

X_SAMPLE_MM = 0.02
"""Face positions the removal is evaluated at before the chordal reduction."""
_FLANK_SAMPLES = 4001
CHORD_GOUGE_SHARE = 0.2
"""Helical passes: the share of [job] profile_tolerance_mm their dY chords may reach deeper than the sampled
offsets (a lead crowning's chords all lie deeper: 0.85 um of a 1 um tolerance in the simulation)."""


def simplify_polyline(x: np.ndarray, y: np.ndarray, tolerance_mm: float, above_mm: float | None = None) -> np.ndarray:
    """Indices of the fewest points (Douglas-Peucker) whose chords stay within `tolerance_mm` of every sample (and
    at most `above_mm` above them, when given: a one-sided bound for offsets whose + direction is into the tooth)."""
    above = tolerance_mm if above_mm is None else above_mm
    keep = {0, len(x) - 1}
    stack = [(0, len(x) - 1)]
    while stack:
        i, j = stack.pop()
        if j <= i + 1:
            continue
        chord = y[i] + (y[j] - y[i]) * (x[i + 1:j] - x[i]) / (x[j] - x[i])
        error = np.maximum(y[i + 1:j] - chord, (chord - y[i + 1:j]) * (tolerance_mm / above))
        k = int(np.argmax(error))
        if error[k] > tolerance_mm:
            m = i + 1 + k
            keep.add(m)
            stack += [(i, m), (m, j)]
    return np.array(sorted(keep))


def _cross(u: np.ndarray, v: np.ndarray) -> float:
    """The z component of u x v for plane vectors."""
    return float(u[0] * v[1] - u[1] * v[0])


class FlankSupport:
    """The removal a straight flank pass at design roll t makes to touch one side's modified flank (no lead)."""

    def __init__(self, spec: GearSpec, mods: FlankModifications, side: str):
        involute = spec.tooth_space_profile().involute
        flank = mods.side(side)
        self.rb = spec.base_radius_mm
        t = np.linspace(involute.start, involute.end, _FLANK_SAMPLES)
        normals = involute.normals(t)
        self.points = involute.points(t) - flank.profile_offset_mm(self.rb * t)[:, None] * normals
        self.involute = involute
        self.flank = flank

    def modified_point(self, roll: float) -> np.ndarray:
        """The modified flank's point at design roll t (gap frame, right flank)."""
        return self._modified(np.array([roll]))[0]

    def _modified(self, t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, float)
        return self.involute.points(t) - self.flank.profile_offset_mm(self.rb * t)[:, None] * self.involute.normals(t)

    def pass_roll(self, contact_roll: float, ahead: bool = True) -> float:
        """The design roll whose tangent (a straight pass's direction) is the modified flank's tangent at
        `contact_roll`: the contact roll plus the modification's turn of the tangent there (one-sided at a kink:
        `ahead` toward the tip). A tip relief turns it by about r_b C_a' / L, which moves a pass planned for the
        design's contact by r_b times that along the line of action (0.6 mm on the test gear)."""
        h = 1e-6
        t = np.array([contact_roll, contact_roll + h] if ahead else [contact_roll - h, contact_roll])
        chord = np.diff(self._modified(t), axis=0)[0]
        tangent = np.diff(self.involute.points(t), axis=0)[0]
        following = np.diff(self.involute.points(t + h), axis=0)[0]
        turn_sense = math.copysign(1.0, _cross(tangent, following))
        angle = math.atan2(_cross(tangent, chord), float(tangent @ chord))
        return float(contact_roll + turn_sense * angle)

    def removal_mm(self, rolls: np.ndarray) -> np.ndarray:
        """I(t).n(t) - max over the modified flank of Q.n(t), for design rolls t (vectorised)."""
        rolls = np.atleast_1d(np.asarray(rolls, float))
        normals = self.involute.normals(rolls)
        design = (self.involute.points(rolls) * normals).sum(axis=1)
        support = (self.points @ normals.T).max(axis=0)
        return design - support


def _face_samples(spec: GearSpec) -> np.ndarray:
    b = spec.face_width_mm
    return np.linspace(0.0, b, max(2, math.ceil(b / X_SAMPLE_MM) + 1))


def _path(x: np.ndarray, dy: np.ndarray, dz: np.ndarray, tolerance_mm: float, into_tooth: int = 0) -> tuple:
    """((x, dy, dz), ...) breakpoints of the offsets along X within the tolerance (constant: one point); with
    `into_tooth` (the sign of Y into the material) the chords of dY reach at most CHORD_GOUGE_SHARE of it deeper."""
    if np.ptp(dy) <= tolerance_mm and np.ptp(dz) <= tolerance_mm:
        mid = len(x) // 2
        return ((float(x[mid]), float(dy[mid]), float(dz[mid])),)
    lateral = (simplify_polyline(x, into_tooth * dy, tolerance_mm, CHORD_GOUGE_SHARE * tolerance_mm) if into_tooth
               else simplify_polyline(x, dy, tolerance_mm))
    keep = np.union1d(lateral, simplify_polyline(x, dz, tolerance_mm))
    return tuple((float(x[i]), float(dy[i]), float(dz[i])) for i in keep)


def _raised_ends(spec: GearSpec, tool: Tool, passes: tuple[GeneratingPass, ...]) -> dict:
    """{(side, roll): Z} of the spur flank passes with the "raised" end: a rack-end corner moved into the tooth with
    its flank would reach into the fillet, a raised one stays above the lower neighbour's flat."""
    ends = {}
    for side in (1, -1):  # each flank's own neighbours: turned passes differ between sides modified differently
        rolls = np.array(sorted({p.roll_rad for p in passes if p.mode == "flank" and p.side == side}))
        if len(rolls):
            z = flank_poses(spec, tool, rolls, "raised")[2]
            ends.update({(side, float(t)): float(zi) for t, zi in zip(rolls, z)})
    return ends


def _envelope_growth_mm(tool: Tool, planned_slope: float, slope: np.ndarray) -> np.ndarray:
    """How much farther sideways a tool swept along a path of slope dY/dX = `slope` reaches than along the planned
    one: the swept cylinder's side lies R sqrt(1 + k^2) from its axis in a section X, so a lead modification's slope
    (crowning: 4 C_beta / b at the faces) changes the reach of a helical pass by R k dk / sqrt(1 + k^2) (0.85 um for
    10 um crowning on the test gear's 3.5 mm tool)."""
    radius = tool.diameter_mm / 2.0
    return radius * (np.sqrt(1.0 + slope ** 2) - math.sqrt(1.0 + planned_slope ** 2))


def _helical_raised_ends(spec: GearSpec, tool: Tool, passes: tuple[GeneratingPass, ...], x: np.ndarray) -> dict:
    """{(side, roll): tool end Z at each face position `x`} of helical flank passes, raised per section: section X
    sees the pass at effective roll t_e (the spur pass there, contact at Z = r_b), so its end is the spur raised end
    at t_e (straight side from RAISED_END_MARGIN_MM below the crossing with the lower neighbour's flat, rolls evenly
    spaced by delta) and its straight side never starts below the form point, at Z = r_b cos(t_F - t_e) + r_b t_F
    sin(t_F - t_e) in that pass's frame (below it the corner would follow the rack's round over the fillet, which the
    tip passes cut and which moves less than the flank); never lower than the planned line."""
    rb, r_t = spec.base_radius_mm, tool.effective_corner_radius_mm
    t_form = spec.tooth_space_profile().involute.start
    ends = {}
    for side in (1, -1):
        flank = [p for p in passes if p.mode == "flank" and p.side == side]
        if len(flank) < 2:
            continue
        delta = float(np.median(np.abs(np.diff([p.roll_rad for p in flank]))))
        for p in flank:
            t_e = p.roll_rad - side * p.dy_per_x * x / rb
            need = rb * (t_e * math.cos(delta) - (t_e - delta)) / math.sin(delta) - RAISED_END_MARGIN_MM
            form = rb * np.cos(t_form - t_e) + rb * t_form * np.sin(t_form - t_e)
            ends[side, p.roll_rad] = np.maximum.reduce([p.z_mm + x * p.dz_per_x, need - r_t, form - r_t])
    return ends


def _touching_modified_contacts(spec: GearSpec, tool: Tool, passes: tuple[GeneratingPass, ...],
                                mods: FlankModifications, supports: dict) -> tuple[tuple[GeneratingPass, ...], dict]:
    """Spur flank passes turned so that each touches the modified flank at its planned contact roll (the pass's
    design roll plus the modification's turn of the tangent there, FlankSupport.pass_roll); at a relief's start
    (a kink) two passes, the tangents just below and just above it, both touching the kink. Also {(side, roll):
    how far each pass's tool end must go below its end for the design (mm): as far as its contact lies below the
    design's contact of that roll (a relief's contacts lie 0.6 mm lower on the test gear; the raised end alone
    leaves 7 um there)}."""
    rb = spec.base_radius_mm
    passes = tuple(_densified(passes, supports, rb))
    kinks = {+1: {k / rb for k in mods.right.profile_kinks_roll_mm()},
             -1: {k / rb for k in mods.left.profile_kinks_roll_mm()}}
    out, lowered = [], {}
    for p in passes:
        if p.mode != "flank":
            out.append(p)
            continue
        at_kink = any(abs(p.roll_rad - k) < 1e-12 for k in kinks[p.side])
        ahead_first = p.side > 0  # the right flank's passes run tip -> root, the left's root -> tip
        sides = ((True, False) if ahead_first else (False, True)) if at_kink else (True,)
        support = supports[p.side]
        for ahead in sides:
            t = support.pass_roll(p.roll_rad, ahead)
            a, y, z = (float(v[0]) for v in flank_poses(spec, tool, np.array([t]), "rack"))
            contacts = np.array([support.involute.points(np.array(t)), support.modified_point(p.roll_rad)])
            design_z, contact_z = part_to_machine(contacts, math.degrees(a))[:, 1]
            lowered[p.side, t] = max(design_z - contact_z, 0.0)
            out.append(replace(p, roll_rad=t, a_deg=p.side * math.degrees(a), y_mm=p.side * y, z_mm=z))
    return tuple(out), lowered


def _densified(passes: tuple[GeneratingPass, ...], supports: dict, base_radius_mm: float) -> list[GeneratingPass]:
    """Spur flank passes with contacts added between two planned ones wherever the modification turns the flank's
    tangent between them (a parabolic relief's curvature): the passes' tangents then turn by (gap + turn), and the
    scallop between them grows with its square (a 20 um parabolic relief over 2 mm: 7.8 um at a 5 um target).
    Each gap gets as many equal pieces as (gap + turn) / gap; kinks' jumps are their own passes' business."""
    out: list[GeneratingPass] = []
    previous: dict[int, GeneratingPass] = {}
    for p in passes:
        q = previous.get(p.side) if p.mode == "flank" else None
        if q is not None and p.roll_rad != q.roll_rad:
            low, high = sorted((q.roll_rad, p.roll_rad))
            support = supports[p.side]
            turned = support.pass_roll(high, ahead=False) - support.pass_roll(low, ahead=True)
            pieces = max(1, math.ceil(turned / (high - low) - 1e-9))
            for j in range(1, pieces):
                roll = q.roll_rad + (p.roll_rad - q.roll_rad) * j / pieces
                out.append(replace(p, roll_rad=roll, contact_radius_mm=base_radius_mm * math.hypot(1.0, roll)))
        if p.mode == "flank":
            previous[p.side] = p
        out.append(p)
    return out


def helical_fillet_parameters(spec: GearSpec, tool: Tool, p: GeneratingPass, x: np.ndarray,
                              fillet) -> np.ndarray:
    """The fillet parameter (the normal-section angle b on the rack round, 0 at the root, clipped to beta_F) that a
    helical tip-mode pass touches in each section X: the round itself (r_t = rho) touches section X where the
    fillet's generating roll equals the section's effective roll side (phi + turn(X)); a smaller corner touches
    only at its own contact angle b, read back from its position (corner centre = round centre + (rho - r_t)
    (sin b, -cos b); the contacts on the flank line above T lie beyond beta_F)."""
    rho, r_t = spec.rack_tip_radius_mm, tool.effective_corner_radius_mm
    if abs(r_t - rho) <= CORNER_MATCH_MM:
        grid = np.linspace(fillet.start, fillet.end, 2001)
        rolls = fillet.roll_angle(grid)
        if not np.all(np.diff(rolls) < 0.0):
            raise ToolError("generating finishing of a modified helical gear: the fillet's generating roll is not "
                            "monotonic in the rack round's angle; its tip passes cannot follow the modified fillet",
                            section="gear.modifications")
        effective = p.side * (p.roll_rad + np.array([spec.section_turn_rad(xi) for xi in x]))
        return np.interp(effective, rolls[::-1], grid[::-1])  # beyond the ends: the ends
    corner = rack_corner(spec)
    across = (p.side * (p.y_mm + spec.reference_radius_mm * p.roll_rad) * math.cos(spec.helix_angle_rad)
              - (corner.normal_corner_offset_mm - tool.flat_width_mm / 2.0))
    up = p.z_mm - (spec.root_radius_mm + rho - r_t)
    b = math.atan2(across, -up)
    return np.full(len(x), min(max(b, 0.0), fillet.end))


@dataclass(frozen=True)
class _Ends:
    """The passes to move and where their tool ends go: {(side, roll): how far below its planned end a spur flank
    pass's tool end goes (lowered) / the raised end it never goes below (raised)}; {(side, roll): the tool end Z at
    each face position} of helical flank passes (per_section)."""

    passes: tuple[GeneratingPass, ...]
    lowered: dict
    raised: dict
    per_section: dict


def _spur_ends(spec: GearSpec, tool: Tool, passes: tuple[GeneratingPass, ...], mods: FlankModifications,
               supports: dict, x: np.ndarray) -> _Ends:
    """Spur flank passes turned to touch the modified flank at their planned contacts, their ends raised."""
    passes, lowered = _touching_modified_contacts(spec, tool, passes, mods, supports)
    return _Ends(passes, lowered, _raised_ends(spec, tool, passes), {})


def _helical_ends(spec: GearSpec, tool: Tool, passes: tuple[GeneratingPass, ...], mods: FlankModifications,
                  supports: dict, x: np.ndarray) -> _Ends:
    """Helical flank passes keep their rolls; their ends are raised per section X."""
    return _Ends(passes, {}, {}, _helical_raised_ends(spec, tool, passes, x))


def _swept_dy(tool: Tool, p: GeneratingPass, dy: np.ndarray, x: np.ndarray, side: int) -> np.ndarray:
    """A helical pass's sideways offsets less the swept tool's growth with the path's slope."""
    return dy - side * _envelope_growth_mm(tool, p.dy_per_x, p.dy_per_x + np.gradient(dy, x))


@dataclass(frozen=True)
class _Following:
    """How one gear kind's planned passes follow the modified flanks (see the module docstring):
    - `ends`: the passes to move and their tool ends;
    - `moves_tip_pass`: whether a tip-mode pass follows the modified fillet (spur: its fillet passes, which carry a
      fillet parameter; helical: every one but the root's);
    - `fillet_parameter`: the fillet parameter a tip-mode pass touches (spur: its own; helical: per section X);
    - `swept_dy`: the sideways offsets as cut (a helical pass's less the swept tool's growth);
    - `into_tooth`: the sign of Y into the material that bounds the dY chords (0: both ways within the tolerance)."""

    ends: Callable[[GearSpec, Tool, tuple[GeneratingPass, ...], FlankModifications, dict, np.ndarray], _Ends]
    moves_tip_pass: Callable[[GeneratingPass], bool]
    fillet_parameter: Callable[[GearSpec, Tool, GeneratingPass, np.ndarray, Any], Any]
    swept_dy: Callable[[Tool, GeneratingPass, np.ndarray, np.ndarray, int], np.ndarray]
    into_tooth: Callable[[int], int]


_SPUR = _Following(_spur_ends, lambda p: not math.isnan(p.beta_rad), lambda spec, tool, p, x, fillet: p.beta_rad,
                   lambda tool, p, dy, x, side: dy, lambda side: 0)
_HELICAL = _Following(_helical_ends, lambda p: p.feature != Feature.ROOT, helical_fillet_parameters, _swept_dy,
                      lambda side: side)
FOLLOWING: dict[GearKind, _Following] = {EXTERNAL_SPUR: _SPUR, EXTERNAL_HELICAL: _HELICAL, INTERNAL_SPUR: _SPUR}
"""How each gear kind's passes follow modified flanks (a ring's flanks are not modified: as a spur gear's)."""


def modified_passes(spec: GearSpec, tool: Tool, passes: tuple[GeneratingPass, ...], mods: FlankModifications,
                    tolerance_mm: float) -> tuple[GeneratingPass, ...]:
    """`passes` (one space's, planned for the design) moved onto the modified flanks (see the module docstring)."""
    following = FOLLOWING[spec.kind]
    profile = spec.tooth_space_profile()
    fillet = profile.fillet
    involute = profile.involute
    x = _face_samples(spec)
    supports = {+1: FlankSupport(spec, mods, "right"), -1: FlankSupport(spec, mods, "left")}
    sides = {+1: mods.right, -1: mods.left}
    form_normal = involute.normals(np.array(involute.start))
    form_removal = {s: float(sides[s].profile_offset_mm(spec.base_radius_mm * involute.start)) for s in sides}
    ends = following.ends(spec, tool, passes, mods, supports, x)
    out = []
    for p in ends.passes:
        side = p.side
        lead = sides[side].lead_offset_mm(x)
        if p.mode == "flank":
            rolls = p.roll_rad - side * p.dy_per_x * x / spec.base_radius_mm
            removal = supports[side].removal_mm(rolls) + lead
            dy, dz = following.swept_dy(tool, p, side * removal, x, side), np.zeros_like(x)
            if (side, p.roll_rad) in ends.per_section:
                dz = ends.per_section[side, p.roll_rad] - (p.z_mm + x * p.dz_per_x)
        elif p.mode == "tip" and fillet is not None and fillet.end > 0.0 and following.moves_tip_pass(p):
            beta = following.fillet_parameter(spec, tool, p, x, fillet)
            removal = (form_removal[side] + lead) * (beta / fillet.end) ** 2
            normal = form_normal * np.array([1.0 if side > 0 else -1.0, 1.0])
            # section X lies turned by its turn (0 for a spur gear): the form normal turns with it
            turns = math.radians(p.a_deg) + np.array([spec.section_turn_rad(xi) for xi in x])
            moved = -removal[:, None] * np.stack([normal[0] * np.cos(turns) - normal[1] * np.sin(turns),
                                                  normal[0] * np.sin(turns) + normal[1] * np.cos(turns)], axis=-1)
            dy, dz = following.swept_dy(tool, p, moved[:, 0], x, side), moved[:, 1]
        else:
            out.append(p)
            continue
        z = (max(p.z_mm, ends.raised.get((p.side, p.roll_rad), p.z_mm))
             - ends.lowered.get((p.side, p.roll_rad), 0.0) if p.mode == "flank" else p.z_mm)
        out.append(replace(p, z_mm=z, path=_path(x, dy, dz, tolerance_mm, following.into_tooth(side))))
    return tuple(out)
