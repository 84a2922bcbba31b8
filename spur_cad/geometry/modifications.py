"""Flank modifications (micro-geometry, ISO 21771 / VDI 2607): how far each flank lies below the design involute.

A modification is an amount of material removed from the design flank, measured along the flank's normal
in the transverse plane (as ISO 1328 evaluates profile and helix deviations; on a helical gear the offset
along the 3-D surface normal is that times cos(beta_b)), as a function of the roll length L (transverse,
L = sqrt(r^2 - r_b^2), from the base circle along the line of action) and of the face position X
(0 at the front face, b at the back face). Positive removes material (moves the flank into the tooth);
the two slopes are signed and are zero at mid-profile and mid-face, so they add material on one half.

Profile (L_F: the usable involute's start at the form circle, L_a: the tip circle, L_alpha = L_a - L_F):
  tip relief C_a from L_Ca (tip_relief_start_diameter) to the tip, linear or parabolic in (L - L_Ca);
  root relief C_f from L_Cf (root_relief_start_diameter) down to the form circle, likewise;
  profile crowning C_alpha: C_alpha (2 (L - L_m) / L_alpha)^2, zero at mid-profile L_m;
  profile slope f_Halpha: the material grows by f_Halpha from the form circle to the tip: -f_Halpha (L - L_m) / L_alpha.
Lead (b: the face width):
  lead crowning C_beta: C_beta (2 (X - b/2) / b)^2;
  end relief C_I over L_I at the front face, C_II over L_II at the back face, linear to the face;
  helix slope f_Hbeta: the material grows by f_Hbeta from the front face to the back: -f_Hbeta (X - b/2) / b.
The amounts add up. Flank sides: "right" is the flank on the +x side of a tooth space in the gap frame
(spur_cad.geometry.frames; machine +Y of space 0 at A = 0), "left" its mirror (as the simulation's and the
probe's flank sides). Pure numpy; see docs/geometry.md.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from spur_cad.errors import GearSpecError
from spur_cad.geometry.profile import CircularArc, Involute, Segment, ToothSpaceProfile
from spur_cad.geometry.roots import brentq
from spur_cad.geometry.sampling import ProfileSamples, sample_profile, segment_parameters

SIDES = ("right", "left")
RELIEF_SHAPES = ("linear", "parabolic")
END_RELIEF_FACES = ("both", "front", "back")
MAX_AMOUNT_MODULES = 0.1
"""No modification amount may exceed this fraction of the module (micro-geometry, not a different gear)."""


@dataclass(frozen=True)
class FlankModification:
    """One flank side's modifications in mm, anchored to its gear's usable involute and face width.

    Profile: tip relief C_a (`tip_relief_mm`) from roll length L_Ca, root relief C_f from L_Cf (each linear or
    parabolic), profile crowning C_alpha, profile slope f_Halpha (signed). Lead: lead crowning C_beta, end relief
    C_I / C_II over L_I / L_II at the front / back face, helix slope f_Hbeta (signed). Anchors: L_F (form circle),
    L_a (tip circle), b (face width). Build it with `flank_modification`.
    """

    form_roll_mm: float  # L_F
    tip_roll_mm: float  # L_a
    face_width_mm: float  # b
    tip_relief_mm: float = 0.0  # C_a
    tip_relief_start_roll_mm: float = 0.0  # L_Ca
    tip_relief_parabolic: bool = False
    root_relief_mm: float = 0.0  # C_f
    root_relief_start_roll_mm: float = 0.0  # L_Cf
    root_relief_parabolic: bool = False
    profile_crowning_mm: float = 0.0  # C_alpha
    profile_slope_mm: float = 0.0  # f_Halpha
    lead_crowning_mm: float = 0.0  # C_beta
    front_end_relief_mm: float = 0.0  # C_I
    front_end_relief_length_mm: float = 0.0  # L_I
    back_end_relief_mm: float = 0.0  # C_II
    back_end_relief_length_mm: float = 0.0  # L_II
    helix_slope_mm: float = 0.0  # f_Hbeta

    @property
    def has_profile(self) -> bool:
        """Some modification varies along the profile."""
        return any((self.tip_relief_mm, self.root_relief_mm, self.profile_crowning_mm, self.profile_slope_mm))

    @property
    def has_lead(self) -> bool:
        """Some modification varies along the face width (the flank is no longer a prism or a helicoid)."""
        return any((self.lead_crowning_mm, self.front_end_relief_mm, self.back_end_relief_mm, self.helix_slope_mm))

    def profile_offset_mm(self, roll_length_mm) -> np.ndarray:
        """The profile modifications' removal at roll length L (any L: beyond the tip the reliefs continue)."""
        roll = np.asarray(roll_length_mm, dtype=float)
        span = self.tip_roll_mm - self.form_roll_mm
        middle = 0.5 * (self.tip_roll_mm + self.form_roll_mm)
        offset = self.profile_crowning_mm * (2.0 * (roll - middle) / span) ** 2 \
            - self.profile_slope_mm * (roll - middle) / span
        if self.tip_relief_mm:
            length = self.tip_roll_mm - self.tip_relief_start_roll_mm
            s = np.maximum(roll - self.tip_relief_start_roll_mm, 0.0) / length
            offset = offset + self.tip_relief_mm * (s * s if self.tip_relief_parabolic else s)
        if self.root_relief_mm:
            length = self.root_relief_start_roll_mm - self.form_roll_mm
            s = np.maximum(self.root_relief_start_roll_mm - roll, 0.0) / length
            offset = offset + self.root_relief_mm * (s * s if self.root_relief_parabolic else s)
        return offset

    def lead_offset_mm(self, x_face_mm) -> np.ndarray:
        """The lead modifications' removal at face position X (0: front face, b: back face)."""
        x = np.asarray(x_face_mm, dtype=float)
        b = self.face_width_mm
        offset = self.lead_crowning_mm * (2.0 * (x - b / 2.0) / b) ** 2 - self.helix_slope_mm * (x - b / 2.0) / b
        if self.front_end_relief_mm:
            length = self.front_end_relief_length_mm
            offset = offset + self.front_end_relief_mm * np.maximum(length - x, 0.0) / length
        if self.back_end_relief_mm:
            length = self.back_end_relief_length_mm
            offset = offset + self.back_end_relief_mm * np.maximum(x - (b - length), 0.0) / length
        return offset

    def profile_kinks_roll_mm(self) -> tuple[float, ...]:
        """Roll lengths inside the usable involute where the removal has a kink (the reliefs' starts)."""
        kinks = []
        if self.root_relief_mm:
            kinks.append(self.root_relief_start_roll_mm)
        if self.tip_relief_mm:
            kinks.append(self.tip_relief_start_roll_mm)
        return tuple(k for k in kinks if self.form_roll_mm < k < self.tip_roll_mm)

    def lead_kinks_mm(self) -> tuple[float, ...]:
        """Face positions inside the face width where the removal has a kink (the end reliefs' starts)."""
        kinks = []
        if self.front_end_relief_mm:
            kinks.append(self.front_end_relief_length_mm)
        if self.back_end_relief_mm:
            kinks.append(self.face_width_mm - self.back_end_relief_length_mm)
        return tuple(sorted(k for k in set(kinks) if 0.0 < k < self.face_width_mm))


@dataclass(frozen=True)
class FlankModifications:
    """The modifications of both flank sides ("right", "left"; see the module docstring)."""

    right: FlankModification
    left: FlankModification

    def side(self, side: str) -> FlankModification:
        if side not in SIDES:
            raise ValueError(f"flank side must be 'right' or 'left', got {side!r}")
        return self.right if side == "right" else self.left

    @property
    def has_lead(self) -> bool:
        return self.right.has_lead or self.left.has_lead

    @property
    def is_zero(self) -> bool:
        return not any((m.has_profile or m.has_lead) for m in (self.right, self.left))


def normal_offset_mm(mods: FlankModifications, side: str, roll_length_mm, x_face_mm) -> np.ndarray:
    """Material removed from the design flank of `side` (mm, positive into the tooth, along the flank normal in
    the transverse plane) at roll length L (mm) and face position X (mm); vectorised, L and X broadcast."""
    flank = mods.side(side)
    return flank.profile_offset_mm(roll_length_mm) + flank.lead_offset_mm(x_face_mm)


def roll_length_mm(base_radius_mm: float, diameter_mm) -> np.ndarray:
    """Roll length L = sqrt(r^2 - r_b^2) of a diameter d = 2 r on the involute (transverse)."""
    radius = np.asarray(diameter_mm, dtype=float) / 2.0
    return np.sqrt(np.maximum(radius * radius - base_radius_mm * base_radius_mm, 0.0))


def flank_modification(values: dict, base_radius_mm: float, form_radius_mm: float, tip_radius_mm: float,
                       module_mm: float, face_width_mm: float) -> FlankModification:
    """One side's modifications from its job-file values ([gear.modifications] keys: um and mm), checked against
    the gear: raises GearSpecError(field=key) for a start diameter off the usable involute (form to tip diameter),
    reliefs that overlap, end reliefs longer than the face, an amount beyond 10 % of the module."""
    limit_um = MAX_AMOUNT_MODULES * module_mm * 1000.0
    for name, value in values.items():
        if name.endswith("_um") and abs(value) > limit_um:
            raise GearSpecError(f"{name} = {value:g} um is beyond 10 % of the module ({limit_um:g} um): flank "
                                "modifications are micro-geometry", field=name)
    form_d, tip_d = 2.0 * form_radius_mm, 2.0 * tip_radius_mm
    rolls = {}
    for relief in ("tip_relief", "root_relief"):
        start_d = values[f"{relief}_start_diameter_mm"]
        if values[f"{relief}_um"] == 0.0:
            rolls[relief] = 0.0
            continue
        if not form_d < start_d < tip_d:
            raise GearSpecError(f"{relief}_start_diameter_mm = {start_d:g} must lie on the usable involute, between "
                                f"the form diameter {form_d:.4f} and the tip diameter {tip_d:.4f} mm (give it with "
                                f"{relief}_um)", field=f"{relief}_start_diameter_mm")
        rolls[relief] = float(roll_length_mm(base_radius_mm, start_d))
    if values["tip_relief_um"] and values["root_relief_um"] and \
            values["root_relief_start_diameter_mm"] > values["tip_relief_start_diameter_mm"]:
        raise GearSpecError(f"the root relief (from {values['root_relief_start_diameter_mm']:g} mm down) and the tip "
                            f"relief (from {values['tip_relief_start_diameter_mm']:g} mm up) overlap: together they "
                            "are longer than the usable involute", field="root_relief_start_diameter_mm")
    faces = values["end_relief_faces"]
    amount, length = values["end_relief_um"], values["end_relief_length_mm"]
    front = amount if faces in ("both", "front") else 0.0
    back = amount if faces in ("both", "back") else 0.0
    if amount:
        total = length * (2 if faces == "both" else 1)
        if not 0.0 < length or total > face_width_mm:
            raise GearSpecError(f"end_relief_length_mm = {length:g} must be above 0 and the reliefs ({faces} faces) no "
                                f"longer than the face width {face_width_mm:g} mm", field="end_relief_length_mm")
    return FlankModification(
        form_roll_mm=float(roll_length_mm(base_radius_mm, form_d)),
        tip_roll_mm=float(roll_length_mm(base_radius_mm, tip_d)), face_width_mm=face_width_mm,
        tip_relief_mm=values["tip_relief_um"] / 1000.0, tip_relief_start_roll_mm=rolls["tip_relief"],
        tip_relief_parabolic=values["tip_relief_shape"] == "parabolic",
        root_relief_mm=values["root_relief_um"] / 1000.0, root_relief_start_roll_mm=rolls["root_relief"],
        root_relief_parabolic=values["root_relief_shape"] == "parabolic",
        profile_crowning_mm=values["profile_crowning_um"] / 1000.0,
        profile_slope_mm=values["profile_slope_um"] / 1000.0, lead_crowning_mm=values["lead_crowning_um"] / 1000.0,
        front_end_relief_mm=front / 1000.0, front_end_relief_length_mm=length if front else 0.0,
        back_end_relief_mm=back / 1000.0, back_end_relief_length_mm=length if back else 0.0,
        helix_slope_mm=values["helix_slope_um"] / 1000.0)


# --- the modified profile ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class ModifiedSegment:
    """A profile segment moved into the tooth: point - offset(parameter) x `direction`, where the direction is
    the segment's own normal (into the space) or, for the root fillet, the fixed normal at the form point
    (`fixed_normal`). Duck-types the exact segments for sampling and B-spline fitting; normals and chord
    bounds are numerical (the offsets are micrometres on millimetre curves)."""

    base: Segment
    offset: Callable[[np.ndarray], Any]  # parameters -> removal (mm): an array like them, or a number
    fixed_normal: tuple[float, float] | None = None

    @property
    def label(self) -> str:
        return self.base.label

    @property
    def start(self) -> float:
        return self.base.start

    @property
    def end(self) -> float:
        return self.base.end

    def points(self, t) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        direction = (np.broadcast_to(np.array(self.fixed_normal), (*t.shape, 2)) if self.fixed_normal is not None
                     else self.base.normals(t))
        return self.base.points(t) - np.asarray(self.offset(t))[..., None] * direction

    def normals(self, t) -> np.ndarray:
        """Into the space: the tangent (one-sided differences at the segment's ends) turned left."""
        t = np.asarray(t, dtype=float)
        h = 1e-7 * max(1.0, abs(self.end - self.start))
        ahead, behind = np.minimum(t + h, self.end), np.maximum(t - h, self.start)
        tangent = (self.points(ahead) - self.points(behind)) / (ahead - behind)[..., None]
        tangent = tangent / np.linalg.norm(tangent, axis=-1, keepdims=True)
        return np.stack([-tangent[..., 1], tangent[..., 0]], axis=-1)

    def curvature_radii(self, t) -> np.ndarray:
        """The design segment's (micrometre offsets change it by micrometres)."""
        return self.base.curvature_radii(t)

    def _sampled(self, a, b, count: int = 17):
        a, b = np.atleast_1d(np.asarray(a, float)), np.atleast_1d(np.asarray(b, float))
        grid = a[:, None] + (b - a)[:, None] * np.linspace(0.0, 1.0, count)[None, :]
        return self.points(grid)

    def chord_error_bound(self, a, b) -> np.ndarray:
        """Largest distance of 17 points per interval from its chord, with a 25 % margin (sampled, not proven)."""
        pts = self._sampled(a, b)
        chord = pts[:, -1:] - pts[:, :1]
        length = np.linalg.norm(chord, axis=-1)
        rel = pts - pts[:, :1]
        with np.errstate(invalid="ignore", divide="ignore"):
            cross = np.abs(rel[..., 0] * chord[..., 1] - rel[..., 1] * chord[..., 0]) / length
        distance = np.where(length > 0.0, cross, np.linalg.norm(rel, axis=-1))
        return 1.25 * distance.max(axis=1)

    def arc_length_bound(self, a, b) -> np.ndarray:
        pts = self._sampled(a, b)
        return 1.25 * np.linalg.norm(np.diff(pts, axis=1), axis=-1).sum(axis=1)


def modified_tooth_space_profile(profile: ToothSpaceProfile, flank: FlankModification,
                                 x_face_mm: float) -> ToothSpaceProfile:
    """The right half of a tooth space with `flank`'s modifications at face position X: the involute split at the
    reliefs' starts and carried on to where the moved flank meets the tip circle; the root fillet moved by the
    form point's removal along the form point's normal, faded in as (beta / beta_F)^2 from the root circle (so the
    outline stays closed and the root circle unchanged); root arc unchanged; tip arc from the new flank end."""
    involute = profile.involute
    rb = involute.base_radius_mm
    lead = float(flank.lead_offset_mm(x_face_mm))

    def involute_offset(t):
        return flank.profile_offset_mm(rb * np.asarray(t)) + lead

    def radius_minus_tip(t: float) -> float:
        return float(np.hypot(*ModifiedSegment(involute, involute_offset).points(np.array([t]))[0])) \
            - profile.tip_radius_mm

    t_tip = involute.end
    hi = t_tip + 0.05
    while radius_minus_tip(hi) < 0.0:
        hi += 0.05
    lo = t_tip - 0.05
    while radius_minus_tip(lo) > 0.0:
        lo -= 0.05
    t_end = brentq(radius_minus_tip, lo, hi, xtol=1e-14)
    cuts = [involute.start, *(k / rb for k in flank.profile_kinks_roll_mm() if k / rb < t_end), t_end]
    segments: list = []
    for seg in profile.segments:
        if seg.label == "fillet":
            t_form = involute.start
            removal = float(involute_offset(t_form))
            normal_x, normal_y = (float(v) for v in involute.normals(np.array(t_form)))
            span = seg.end - seg.start
            def fillet_removal_mm(beta: np.ndarray, s: float = span, r: float = removal) -> np.ndarray:
                return r * (np.asarray(beta) / s) ** 2

            segments.append(ModifiedSegment(seg, fillet_removal_mm, fixed_normal=(normal_x, normal_y)))
        elif isinstance(seg, Involute):
            for a, b in zip(cuts, cuts[1:]):
                segments.append(ModifiedSegment(replace(seg, start=a, end=b), involute_offset))
        elif isinstance(seg, CircularArc) and seg.label == "tip":
            x, y = segments[-1].points(np.array([t_end]))[0]
            segments.append(CircularArc("tip", seg.radius_mm, math.atan2(x, y), seg.end))
        else:
            segments.append(seg)
    return replace(profile, segments=tuple(segments))




def sample_modified_profile(profile: ToothSpaceProfile, tolerance_mm: float) -> tuple[ProfileSamples, np.ndarray]:
    """`sample_profile` of a modified profile and the unmodified points under its samples (each sample's design
    segment at the same parameter; the unmodified tip arc point where the modified flank meets it)."""
    samples = sample_profile(profile, tolerance_mm)
    design = []
    for index, segment in enumerate(profile.segments):
        params = segment_parameters(segment, tolerance_mm)
        design.append(getattr(segment, "base", segment).points(params[1:] if index > 0 else params))
    return samples, np.concatenate(design)
