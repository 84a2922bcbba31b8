"""What roughing may leave above the root for the finishing strategy to take (its bottom allowance), per finishing
strategy (docs/method.md section 3): one module that both the tool recommendations and the strategies use."""

from __future__ import annotations

from dataclasses import dataclass

from spur_cad.cam.tools import Tool

PLUNGE_CAPACITY_FRACTION = 0.5  # A_p = 0.5 d: what a finishing tool's bottom takes when it plunges
LAND_PASS_DEPTH_FRACTION = 0.5
"""Deepest cut a finishing tool takes in one pass, x its diameter: a full-width slot, and 0.5 D is the catalogue's
slotting depth (the default roughing level depth too). It bounds what stands above the tip lands when finishing
starts, and what roughing leaves above the root for finishing by generation."""


@dataclass(frozen=True)
class BottomAllowance:
    """What roughing may leave above the root for the finishing strategy to take, and the rule that sets it (the
    words follow "more than" in the messages)."""

    allowance_mm: float
    rule: str


def plunge_allowance(flat_width_mm: float, largest: bool = False) -> BottomAllowance:
    """Strategies whose flat bottom plunges at the root (perimeter, along_x): A_p = 0.5 x the finishing tool's flat
    width (`largest`: the largest flat allowed, when the job has no finishing tool)."""
    allowance = PLUNGE_CAPACITY_FRACTION * flat_width_mm
    whose = "the largest allowed" if largest else "its"
    return BottomAllowance(allowance, f"the finishing tool can plunge (A_p = {allowance:.3f} mm: "
                                      f"{PLUNGE_CAPACITY_FRACTION:g} x {whose} flat width {flat_width_mm:g} mm)")


def generating_bottom_allowance(tool: Tool | None, recommendations) -> BottomAllowance:
    """Finishing by generation's bottom allowance (its strategy's, and recommend_tools' without a strategy: the job
    file's default): generating_pass_allowance of the tool, or of the largest generating tool without one."""
    if tool is None:
        return generating_pass_allowance(recommendations.finishing_generating_max_diameter_mm, largest=True)
    return generating_pass_allowance(tool.diameter_mm)


def generating_pass_allowance(diameter_mm: float, largest: bool = False) -> BottomAllowance:
    """Finishing by generation never plunges: its straight passes take what roughing left above the root side-on,
    at most what the tool takes off in one pass as a slot, LAND_PASS_DEPTH_FRACTION x D (`largest`: the largest
    generating tool, when the job has no finishing tool)."""
    allowance = LAND_PASS_DEPTH_FRACTION * diameter_mm
    diameter = "the largest generating tool's D" if largest else "D"
    return BottomAllowance(allowance, f"the finishing tool takes off in one generating pass ({allowance:.3f} mm: "
                                      f"{LAND_PASS_DEPTH_FRACTION:g} x {diameter} {diameter_mm:.4g} mm, "
                                      "a slot's depth)")
