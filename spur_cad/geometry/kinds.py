"""Gear kinds as types: what kind of gear a GearSpec is, and what that kind can do.

Every layer used to ask a spec `is_helical` or `is_internal` and branch. A kind is one frozen object
that declares its capabilities once (its teeth point out or in, its transverse section is the same
at every X or turns along a helix, how its solid is made, in which section it is measured, which
finishing strategies cut it); code asks the kind (`spec.kind`), never the flags. The flags themselves
are read only here and in the modules that define the specs (geometry/spec.py, geometry/internal.py):
tests/test_kinds.py checks that over spur_cad/ and workbench/.

A new kind (a rack, a spline) is one more instance here with its spec class returning it from
`kind` (docs/architecture.md, "How to add a gear kind").
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np

SOLIDS = ("extrude", "sweep")
"""How cad/solid.py makes the toothed body: the section extruded along X, or swept along the helix."""

SECTIONS = ("transverse", "normal")
CUTTING_NEEDS = ("helical teeth", "teeth inward")
"""What a kind may ask of a set-up's tool (GearKind.cutting_needs; spur_cad.cam.setups.MachineSetup.reaches)."""
"""The section a kind's inspection sizes (span, balls, chordal thickness) are measured in."""


class _Helix(Protocol):
    """What a kind reads of a spec (spur_cad.geometry.spec, which imports this module: the kinds name no spec
    type, so the two make no loop)."""

    @property
    def hand_sign(self) -> int: ...
    @property
    def helix_angle_rad(self) -> float: ...
    @property
    def reference_radius_mm(self) -> float: ...


class _Strategy(Protocol):
    """What a kind asks of a finishing strategy (spur_cad.cam.strategies): whether it cuts helical teeth."""

    @property
    def helical(self) -> bool: ...


@dataclass(frozen=True)
class GearKind:
    """One kind of gear and its declared capabilities (validated once, here).

    - `prismatic`: the transverse section is the same at every X (spur teeth); else it turns along a helix
      by hand X tan(beta) / r (`section_turn_rad`), and the generating rack is given in the normal section.
    - `teeth_inward`: a ring: the teeth point toward the axis, the profile's roll parameters run negative
      (`roll_sign`), a rim lies outside the root circle, and the tool reaches the spaces only lying flat.
    - `solid`: "extrude" or "sweep" (SOLIDS).
    - `measured_in`: "transverse" or "normal" (SECTIONS): span, balls and chordal thickness.
    - `cut_straight`: a wire, laser or waterjet can cut its teeth (a 2-D outline is the part).
    """

    name: str
    prismatic: bool
    teeth_inward: bool
    solid: str
    measured_in: str

    def __post_init__(self) -> None:
        if self.solid not in SOLIDS:
            raise ValueError(f"gear kind {self.name!r}: solid = {self.solid!r} is not one of {SOLIDS}")
        if self.measured_in not in SECTIONS:
            raise ValueError(f"gear kind {self.name!r}: measured_in = {self.measured_in!r} is not one of {SECTIONS}")
        if (self.solid == "extrude") != self.prismatic:
            raise ValueError(f"gear kind {self.name!r}: only a prismatic kind is extruded (a helical one is swept)")
        if (self.measured_in == "transverse") != self.prismatic:
            raise ValueError(f"gear kind {self.name!r}: a helical kind is measured in the normal section")

    @property
    def helical(self) -> bool:
        """The teeth wind round the axis (the opposite of prismatic)."""
        return not self.prismatic

    @property
    def roll_sign(self) -> int:
        """+1 when the profile's roll length runs root to tip positive (teeth outward), -1 for a ring."""
        return -1 if self.teeth_inward else 1

    @property
    def follows_modifications(self) -> bool:
        """Flank modifications ([modifications]: reliefs, crowning, slopes) are defined for its flanks: external
        teeth (a ring's are not modified)."""
        return not self.teeth_inward

    @property
    def cut_straight(self) -> bool:
        """A 2-D outline (DXF/SVG for a wire, laser or waterjet) is the whole part: straight teeth."""
        return self.prismatic

    def section_turn_rad(self, spec: _Helix, x_mm: float) -> float:
        """Angle by which the transverse section at axial position X is turned about the axis, in the positive A
        sense: 0 for a prismatic kind; a helix: hand_sign X tan(beta) / r (right hand turns with +X)."""
        if self.prismatic:
            return 0.0
        return spec.hand_sign * x_mm * math.tan(spec.helix_angle_rad) / spec.reference_radius_mm

    def lead_mm(self, spec: _Helix) -> float:
        """p_z = 2 pi r / tan(beta), one turn of the helix on the reference cylinder; inf for a prismatic kind."""
        if self.prismatic:
            return math.inf
        return 2.0 * math.pi * spec.reference_radius_mm / math.tan(spec.helix_angle_rad)

    @property
    def cutting_needs(self) -> frozenset[str]:
        """What a set-up's tool must reach to cut this kind (CUTTING_NEEDS): helical teeth winding round the axis,
        teeth pointing inward (a ring's spaces open toward the axis). A set-up cuts the kind when it reaches all."""
        return frozenset(need for need, present in zip(CUTTING_NEEDS, (not self.prismatic, self.teeth_inward))
                         if present)

    def accepts_strategy(self, strategy: _Strategy) -> bool:
        """Whether a finishing strategy can finish this kind (a helical kind needs a strategy declared helical)."""
        return self.prismatic or strategy.helical

    # --- asked by geometry/inspection.py (H6, issue 45) -----------------------------------------------------------
    def gauge_contact_x_mm(self, face_width_mm: float) -> np.ndarray:
        """Face positions X (0: front face) where a span anvil or a pin (ball) touches a flank, for the removal a
        modified flank shows the gauge: a straight tooth touches along the whole face (401 points; the gauge rests
        on the least-removed one), a helical tooth at one point, taken at mid-face."""
        if self.prismatic:
            return np.linspace(0.0, face_width_mm, 401)
        return np.array([face_width_mm / 2.0])

    # --- asked by the job loader, the pipeline, the mate, the 2-D outline and the report (H4, issue 45) ---------
    @property
    def has_rim(self) -> bool:
        """A ring: a rim lies outside the root circle. Its 2-D outline is the rim circle and the toothed hole, its
        mate meshes inside it (spur_cad.geometry.mate.PairMember.internal), a 3-axis program roughs its hole."""
        return self.teeth_inward


EXTERNAL_SPUR = GearKind("external spur", prismatic=True, teeth_inward=False, solid="extrude",
                         measured_in="transverse")
EXTERNAL_HELICAL = GearKind("external helical", prismatic=False, teeth_inward=False, solid="sweep",
                            measured_in="normal")
INTERNAL_SPUR = GearKind("internal spur", prismatic=True, teeth_inward=True, solid="extrude",
                         measured_in="transverse")

KINDS: dict[str, GearKind] = {kind.name: kind for kind in (EXTERNAL_SPUR, EXTERNAL_HELICAL, INTERNAL_SPUR)}
"""Every kind spur_cad makes, by name."""
