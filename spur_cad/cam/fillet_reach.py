"""How far a finishing tool's corner must follow the root fillet on the rotary table, given the real mate
(docs/cam.md, "Fillet reach and the mate").

Without a mate the finishing tool (generating or perimeter) must follow the whole rack-generated fillet, so its
corner radius may not exceed the fillet's tightest curvature radius. With a [mate], only the involute from the
mate's start of active profile (SAP) to the tip is in contact. A corner r_t larger than the fillet allows then
plays a rack with tip round r_t instead of the design's rho: the same flanks and tip line, so the same involute
above that rack's (higher) form circle, and a smaller rack tooth, so it leaves material in the fillet and never
removes any of the design. That is acceptable when

- the involute still starts at or below the SAP (the reach spec's form circle <= the SAP), and
- what it leaves in the fillet stays clear of the mate's tip corners as the pair meshes
  (spur_cad.geometry.mate_mesh.corner_intrusion_mm against the reach spec's outline, within MATE_CLEARANCE_MM).

External spur gears only: a ring or a helical gear keeps the fillet limit.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from spur_cad.errors import SpurCadError
from spur_cad.geometry.kinds import EXTERNAL_SPUR
from spur_cad.geometry.mate import GearPair, pair_facts
from spur_cad.geometry.mate_gear import mate_spec
from spur_cad.geometry.mate_mesh import corner_intrusion_mm
from spur_cad.geometry.spec import GearSpec

MATE_CLEARANCE_MM = 1e-3
"""How deep the mate's tip corners may enter what the tool leaves (the trochoid check's own bound, 1 um)."""
REACH_RESOLUTION_MM = 0.005
"""Step of the largest corner radius that reaches (rounded down to it)."""


@dataclass(frozen=True)
class FilletReach:
    """What a finishing corner of `corner_radius_mm` leaves at the root, playing a rack with that tip round."""

    corner_radius_mm: float
    form_diameter_mm: float  # where the involute it cuts starts
    sap_diameter_mm: float  # the mate's start of active profile on this gear
    mate_intrusion_mm: float  # how deep the mate's tip corners enter what it leaves in the fillet

    def __post_init__(self) -> None:
        for name in ("corner_radius_mm", "form_diameter_mm", "sap_diameter_mm", "mate_intrusion_mm"):
            value = getattr(self, name)
            if not math.isfinite(value) or value < 0.0:
                raise ValueError(f"FilletReach.{name} = {value!r} is not a finite size")

    @property
    def fits(self) -> bool:
        """The involute is cut from the SAP up, and the mate's tip path is clear of the fillet left."""
        return self.form_diameter_mm <= self.sap_diameter_mm + 1e-9 and self.mate_intrusion_mm <= MATE_CLEARANCE_MM


def fillet_limit_mm(spec: GearSpec) -> float:
    """The largest corner that follows the whole fillet: its tightest curvature radius; 0 for a sharp rack's root
    corner (no fillet), as recommend_tools' finishing_max_corner_radius_mm."""
    limit = spec.tooth_space_profile().min_fillet_curvature_radius_mm
    return limit if math.isfinite(limit) else 0.0


def reach_spec(spec: GearSpec, corner_radius_mm: float) -> GearSpec | None:
    """The gear as a rack with tip round max(rho, r_t) generates it: what a corner r_t leaves playing that rack
    (generating) or following that outline (perimeter). None when the rack tooth cannot carry such a round (its
    two tip rounds would overlap) or the outline's fillet is still tighter than r_t."""
    if corner_radius_mm <= spec.rack_tip_radius_mm:
        return spec
    try:
        reach = dataclasses.replace(spec, rack_tip_radius_mm=corner_radius_mm)
    except SpurCadError:
        return None
    if reach.tooth_space_profile().min_fillet_curvature_radius_mm < corner_radius_mm - 1e-12:
        return None
    return reach


RELAXED_BY_A_MATE = frozenset({EXTERNAL_SPUR})
"""Gear kinds whose fillet limit a mate can relax (applies): external spur gears (a ring's or a helical gear's reach
past the fillet is not worked out)."""


def applies(spec: GearSpec, pair: GearPair | None) -> bool:
    """Whether the mate can relax the fillet limit: an external spur gear with an external mate."""
    return (pair is not None and not pair.mate.internal and spec.kind in RELAXED_BY_A_MATE
            and spec.active_profile_start_diameter_mm > 0.0)


def fillet_reach(spec: GearSpec, pair: GearPair, corner_radius_mm: float) -> FilletReach | None:
    """The reach of a corner `corner_radius_mm` on `spec` meshing with `pair`'s mate (see the module docstring);
    None when no rack can carry that round (reach_spec)."""
    reach = reach_spec(spec, corner_radius_mm)
    if reach is None:
        return None
    facts = pair_facts(pair)
    intrusion = corner_intrusion_mm(reach, mate_spec(spec, pair), facts.centre_distance_mm)
    return FilletReach(corner_radius_mm, 2.0 * reach.tooth_space_profile().form_radius_mm,
                       facts.start_of_active_profile_diameter_mm, intrusion)


def largest_reaching_corner_mm(spec: GearSpec, pair: GearPair) -> float:
    """The largest corner radius (rounded down to REACH_RESOLUTION_MM) whose reach fits, at least the fillet's
    tightest curvature radius (which follows the whole fillet). Bisection: a larger rack round is a smaller rack
    tooth, so it leaves more in the fillet and its form circle lies higher (monotone)."""
    low = fillet_limit_mm(spec)
    high = 0.6 * spec.module_mm  # the rack tip radius's own bound (GearSpec)
    top = fillet_reach(spec, pair, high)
    if top is not None and top.fits:
        return high
    while high - low > REACH_RESOLUTION_MM / 4.0:
        middle = 0.5 * (low + high)
        reach = fillet_reach(spec, pair, middle)
        if reach is not None and reach.fits:
            low = middle
        else:
            high = middle
    return max(math.floor(low / REACH_RESOLUTION_MM) * REACH_RESOLUTION_MM, fillet_limit_mm(spec))


def refusal_text(spec: GearSpec, pair: GearPair, corner_radius_mm: float, reach: FilletReach | None) -> str:
    """Why the corner does not reach with the mate, the largest that does, and what would let this one fit."""
    largest = largest_reaching_corner_mm(spec, pair)
    head = f"finishing tool corner radius {corner_radius_mm:.4f} mm does not reach with the mate"
    if reach is None:
        return (f"{head}: no rack tooth of this module, pressure angle and dedendum carries a tip round that large "
                f"(its two rounds would overlap); the largest corner radius that works is {largest:.3f} mm")
    if reach.form_diameter_mm > reach.sap_diameter_mm + 1e-9:
        why = (f"the involute it cuts starts at diameter {reach.form_diameter_mm:.3f} mm, above the mate's start of "
               f"active profile at {reach.sap_diameter_mm:.3f} mm")
    else:
        why = (f"the mate's tip corners enter what it leaves in the fillet by {1000 * reach.mate_intrusion_mm:.1f} um "
               f"(at most {1000 * MATE_CLEARANCE_MM:g} um)")
    return (f"{head}: {why}; the largest corner radius that works is {largest:.3f} mm; a mate with a smaller addendum "
            "(a higher SAP and a tip path farther from the fillet) would let a larger corner fit")


def finishing_spec(spec: GearSpec, pair: GearPair | None, corner_radius_mm: float) -> GearSpec:
    """The outline the finishing strategy cuts with a corner `corner_radius_mm`: the gear's own, unless the corner
    is tighter-than-fillet-limited and the mate lets it leave the fillet (`fillet_reach` fits): then the reach spec,
    which contains the design (a smaller rack tooth removes less), so a path exact for it cannot gouge the design,
    and has the design's involute from its form circle, at or below the SAP, up."""
    if pair is None or not applies(spec, pair):
        return spec
    if corner_radius_mm <= fillet_limit_mm(spec) + 1e-9:
        return spec
    reach = fillet_reach(spec, pair, corner_radius_mm)
    if reach is None or not reach.fits:
        return spec  # check_tools refuses the tool
    spec_reach = reach_spec(spec, corner_radius_mm)
    return spec if spec_reach is None else spec_reach
