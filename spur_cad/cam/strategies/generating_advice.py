"""Finishing by generation, its tool advice: the largest tools for a corner radius and the flute length the
passes need (summary.json `tools.generating_advice`, docs/cam.md)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from spur_cad.cam.strategies.generating_geometry import GeneratingPass, GeneratingToolLimits, generating_tool_limits
from spur_cad.cam.strategies.generating_plan import GeneratingParams, GeneratingPlan
from spur_cad.cam.tools import Tool
from spur_cad.geometry.kinds import EXTERNAL_HELICAL, EXTERNAL_SPUR, INTERNAL_SPUR, GearKind
from spur_cad.geometry.profile import rack_corner
from spur_cad.geometry.spec import GearSpec


def passes_flute_length_mm(passes: tuple[GeneratingPass, ...], tool: Tool, blank_radius_mm: float,
                           face_width_mm: float = 0.0) -> float:
    """Flute length the passes need: for each pass, from the tool end up to the blank circle above the
    tool's point nearest the axis (conservative: the stock before roughing); helical passes at both faces."""
    y = np.array([p.y_mm + x * p.dy_per_x for p in passes for x in (0.0, face_width_mm)])
    z = np.array([p.z_mm + x * p.dz_per_x for p in passes for x in (0.0, face_width_mm)])
    half = tool.diameter_mm / 2.0
    near = np.maximum(np.abs(y) - half, 0.0)
    return float(np.max(np.sqrt(np.maximum(blank_radius_mm**2 - near**2, 0.0)) - z))


@dataclass(frozen=True)
class GeneratingAdvice:
    """summary.json's `tools.generating_advice`: limits for this tool's corner radius, the largest tool with
    the advised corner radius (rho), and the flute length this tool's passes need (mm). Helical gears have
    no flank-mode or recommended figures (None, left out of the summary)."""

    advised_corner_radius_mm: float
    max_corner_radius_mm: float
    flank_mode_max_diameter_mm: float | None
    flank_mode_max_diameter_raised_end_mm: float | None
    tip_mode_max_diameter_mm: float
    max_diameter_mm: float
    recommended_diameter_mm: float | None
    recommended_flute_length_mm: float | None
    required_flute_length_mm: float


def tool_advice(spec: GearSpec, tool: Tool, params: GeneratingParams, plan: GeneratingPlan,
                blank_radius_mm: float) -> GeneratingAdvice:
    """Limits for this tool's corner radius, the largest tool with the advised corner radius (rho), and the
    flute length this tool's passes need."""
    return ADVICE[spec.kind](spec, tool, params, plan, blank_radius_mm)


def _helical_advice(spec: GearSpec, tool: Tool, params: GeneratingParams, plan: GeneratingPlan,
                    blank_radius_mm: float) -> GeneratingAdvice:
    """A helical gear: any corner up to rho (rho advised: fewest passes); the tip mode bounds the diameter."""
    rho, d_n = spec.rack_tip_radius_mm, rack_corner(spec).normal_corner_offset_mm
    widest_mm = 2.0 * d_n + 2.0 * tool.effective_corner_radius_mm
    return GeneratingAdvice(rho, rho, None, None, widest_mm, widest_mm, None, None,
                            passes_flute_length_mm(plan.passes, tool, blank_radius_mm, spec.face_width_mm))


def _spur_advice(spec: GearSpec, tool: Tool, params: GeneratingParams, plan: GeneratingPlan,
                 blank_radius_mm: float) -> GeneratingAdvice:
    """A spur gear: the limits of both modes for this tool's corner and for the advised one."""
    end = params.flank_tool_end
    own = generating_tool_limits(spec, tool.effective_corner_radius_mm, params.target_scallop_mm, blank_radius_mm,
                                 end)
    advised = generating_tool_limits(spec, spec.rack_tip_radius_mm, params.target_scallop_mm, blank_radius_mm, end)

    def largest(limits: GeneratingToolLimits) -> float:
        flank = limits.flank_mode_max_diameter_mm if end == "rack" else limits.flank_mode_max_diameter_raised_mm
        return min(flank, limits.tip_mode_max_diameter_mm)

    return GeneratingAdvice(advised.advised_corner_radius_mm, own.max_corner_radius_mm,
                            own.flank_mode_max_diameter_mm, own.flank_mode_max_diameter_raised_mm,
                            own.tip_mode_max_diameter_mm, largest(own), largest(advised),
                            advised.required_flute_length_mm,
                            passes_flute_length_mm(plan.passes, tool, blank_radius_mm))


ADVICE: dict[GearKind, Callable[[GearSpec, Tool, GeneratingParams, GeneratingPlan, float], GeneratingAdvice]] = {
    EXTERNAL_SPUR: _spur_advice, EXTERNAL_HELICAL: _helical_advice, INTERNAL_SPUR: _spur_advice}
"""tool_advice for each gear kind."""
