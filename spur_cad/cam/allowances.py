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
class ToolRecommendations:
    """Limits for the tools of one gear (mm): what cam.recommend computes and the strategies read (here, below
    both, so that neither names the other)."""

    finishing_max_flat_width_mm: float  # root arc length 2 v r_f
    finishing_max_corner_radius_mm: float  # smallest fillet curvature radius
    plunge_allowance_mm: float  # what roughing may leave above the root: the finishing strategy's bottom allowance
    roughing_max_diameter_mm: float  # space width at height r_f + that allowance
    required_flute_length_mm: float  # deepest cut below the stock surface (finishing reaches the root)
    required_stick_out_mm: float  # flute length + clearance above the blank
    # Finishing by generation (docs/cam.md), with either flank_tool_end; 0.0 when no such tool fits:
    finishing_generating_max_diameter_mm: float = 0.0  # largest tool with the advised corner radius rho
    finishing_flat_end_mill_max_diameter_mm: float = 0.0  # largest flat end mill (r_t = 0): its flat within 2 d_1
    bottom_allowance_rule: str = ""  # the rule that sets plunge_allowance_mm, in words (BottomAllowance.rule)

    def as_dict(self) -> dict[str, float]:
        """The figures (summary.json's `tools` keys), without the rule's words."""
        return {name: value for name, value in self.__dict__.items() if name != "bottom_allowance_rule"}


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
