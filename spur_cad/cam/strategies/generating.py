"""Finishing by generation (docs/method.md): the end mill plays the generating rack, A is clamped for every
pass and every pass is one straight move along X. This module is the strategy the registry holds: its facts
for the summary and the report, and the toolpath of the planned passes. The method's geometry is in
generating_geometry (spur) and generating_helical, the passes in generating_plan, the tool advice in
generating_advice.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from spur_cad.cam.allowances import BottomAllowance, generating_bottom_allowance
from spur_cad.cam.common import PLUNGE_FEED_FRACTION, safe_height_mm
from spur_cad.cam.contacts import SpacePoses, TransversePoses
from spur_cad.cam.estimate import Estimate
from spur_cad.cam.ir import Feature, MoveKind, Operation, Toolpath, ToolpathBuilder
from spur_cad.cam.machine import Machine
from spur_cad.cam.strategies.base import FinishingResult, estimate_by_generating, floor_to_step
from spur_cad.cam.strategies.generating_advice import passes_flute_length_mm, tool_advice
from spur_cad.cam.strategies.generating_flat import flat_deviation_mm
from spur_cad.cam.strategies.generating_geometry import (
    LAND_ALLOWANCE_MM,
    MOVES_PER_PASS,
    GeneratingPass,
    GeneratingToolLimits,
    check_generating_tool,
    flank_poses,
    flank_rolls,
    generating_tool_limits,
    land_angles,
    rough_passes_per_space,
)
from spur_cad.cam.strategies.generating_modified import modified_passes
from spur_cad.cam.strategies.generating_plan import (
    GeneratingParams,
    GeneratingPlan,
    plan_generating,
    planned_passes_per_space,
)
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.geometry.kinds import EXTERNAL_HELICAL, EXTERNAL_SPUR, INTERNAL_SPUR, GearKind
from spur_cad.geometry.modifications import FlankModifications
from spur_cad.geometry.profile import rack_corner
from spur_cad.geometry.spec import GearSpec

if TYPE_CHECKING:  # annotations only: computed by cam.recommend, above the strategies
    from spur_cad.cam.allowances import ToolRecommendations


@dataclass(frozen=True)
class GeneratingFacts:
    """summary.json's generating facts (after `strategy`) and the report's sentence about them."""

    passes_per_space: int
    flat_height_mm: float
    flank_passes_per_flank: int
    tip_mode_passes_per_space: int
    land_passes_per_space: int
    tip_mode_leftover_mm: float
    cutting_direction: str
    flank_tool_end: str

    def report_text(self) -> str:
        return (f"Finishing: generating, {self.passes_per_space} straight passes per tooth space with A clamped: "
                f"{self.flank_passes_per_flank} per flank (generating flat height "
                f"{1000 * self.flat_height_mm:.2f} \u00b5m), {self.tip_mode_passes_per_space} on fillets and root "
                f"(largest sampled leftover {1000 * self.tip_mode_leftover_mm:.2f} \u00b5m), "
                f"{self.land_passes_per_space} on the tip land; {self.cutting_direction} milling, flank tool end "
                f"'{self.flank_tool_end}'.")




def _pass_direction(side: int, cutting_direction: str) -> int:
    """+1 (toward +X) or -1: climb when the side's cutting edges (moving toward +side X) meet the feed."""
    climb = -side
    return climb if cutting_direction == "climb" else -climb


def _space_poses(plan: GeneratingPlan) -> SpacePoses:
    """The passes as transverse poses for the report figure: right side (flank, fillet), root, left side."""
    def poses(selected: list[GeneratingPass]) -> TransversePoses:
        return TransversePoses(np.array([p.y_mm for p in selected]), np.array([p.z_mm for p in selected]),
                               np.array([p.a_deg for p in selected]),
                               np.array([p.contact_radius_mm for p in selected]))

    right = poses([p for p in plan.passes if p.feature == Feature.RIGHT_FLANK])
    root = poses([p for p in plan.passes if p.feature == Feature.ROOT])
    empty = TransversePoses(np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0))
    return SpacePoses(right, root, right.mirrored(), empty)


def _spur_suggested_flat(spec: GearSpec, corner_mm: float, target_scallop_mm: float, blank_radius_mm: float) -> float:
    """95 % of the largest tool with this corner that fits both modes with the rack end, in 0.05 mm steps, less
    the corner: its flat width."""
    limits = generating_tool_limits(spec, corner_mm, target_scallop_mm, blank_radius_mm)
    largest = min(limits.tip_mode_max_diameter_mm, limits.flank_mode_max_diameter_mm)
    return floor_to_step(0.95 * largest, 0.05) - 2.0 * corner_mm


def _helical_suggested_flat(spec: GearSpec, corner_mm: float, target_scallop_mm: float,
                            blank_radius_mm: float) -> float:
    """95 % of the rack's normal tip flat, in 0.05 mm steps."""
    return floor_to_step(0.95 * 2.0 * rack_corner(spec).normal_corner_offset_mm, 0.05)


SUGGESTED_FLAT: dict[GearKind, Callable[[GearSpec, float, float, float], float]] = {
    EXTERNAL_SPUR: _spur_suggested_flat, EXTERNAL_HELICAL: _helical_suggested_flat,
    INTERNAL_SPUR: _spur_suggested_flat}
"""The suggested tool's flat width (mm) for each gear kind (spec, corner radius, target scallop, blank radius)."""


class GeneratingStrategy:
    """See the module docstring."""

    name = "generating"
    description = "the tool as the generating rack: A clamped, one straight pass along X per roll"
    params_type = GeneratingParams
    helical = True  # through the normal rack (generating_helical)
    simultaneous_rotary = False  # A is clamped for every pass; it indexes only at the safe height
    follows_modifications = True  # the planned passes moved onto the modified flanks (generating_modified)
    corrects_slopes = True  # each flank pass is a straight line along X: spur-cad correct moves it (correct.py)
    lying_flat = False

    def largest_tool(self, recommendations: ToolRecommendations) -> tuple[str, float]:
        """The largest tool with the advised corner radius rho."""
        return "finishing_generating_max_diameter_mm", recommendations.finishing_generating_max_diameter_mm

    def bottom_allowance(self, tool: Tool | None, recommendations: ToolRecommendations) -> BottomAllowance:
        """The passes never plunge: near the root they take what roughing left above it side-on, one roll at a
        time, at most a slot's depth, LAND_PASS_DEPTH_FRACTION x D (without a tool: of the largest generating
        tool, recommendations.finishing_generating_max_diameter_mm)."""
        return generating_bottom_allowance(tool, recommendations)

    def suggested_tool(self, spec: GearSpec, recommendations: ToolRecommendations, target_scallop_mm: float,
                       blank_radius_mm: float) -> tuple[float, float] | None:
        """The advised corner radius (the rack tip radius: tip mode exact) and a diameter at 95 % of the
        largest that fits both modes with the rack end, in 0.05 mm steps (helical: 95 % of the rack's normal
        tip flat); a flat of 0 is a ball end mill of radius rho."""
        corner = spec.rack_tip_radius_mm
        if corner <= 0.0:  # a sharp rack: no tool with a corner can play it
            return None
        flat = SUGGESTED_FLAT[spec.kind](spec, corner, target_scallop_mm, blank_radius_mm)
        return (corner, flat) if flat >= 0.0 else None

    def check_tool(self, spec: GearSpec, tool: Tool) -> None:
        check_generating_tool(spec, tool)

    def estimate(self, spec: GearSpec, tool: Tool, machine: Machine, params: GeneratingParams,
                 blank_radius_mm: float) -> Estimate:
        return estimate_by_generating(self, spec, tool, machine, params, blank_radius_mm)

    def estimate_moves(self, spec: GearSpec, tool: Tool, params: GeneratingParams) -> int:
        """Counted with the land passes (an upper bound when the blank is turned to the tip diameter), without
        the clamp rows (which are no motion)."""
        return spec.teeth * MOVES_PER_PASS * planned_passes_per_space(spec, tool, params)

    def generate(self, spec: GearSpec, tool: Tool, machine: Machine, params: GeneratingParams,
                 blank_radius_mm: float, modifications: FlankModifications | None = None,
                 profile_tolerance_mm: float = 0.001) -> tuple[Toolpath, FinishingResult]:
        """The passes planned for the design, moved onto the modified flanks when `modifications` are given
        (generating_modified; their offsets along X as lines within `profile_tolerance_mm`), with a flank pass at
        each relief's start roll (spur gears: the kink cut exactly)."""
        kinks = () if modifications is None else tuple(sorted({
            k / spec.base_radius_mm for side in (modifications.right, modifications.left)
            for k in side.profile_kinks_roll_mm()}))
        plan = plan_generating(spec, tool, params, lands=blank_radius_mm > spec.tip_radius_mm + LAND_ALLOWANCE_MM,
                               kink_rolls_rad=kinks)
        if modifications is not None:
            plan = replace(plan, passes=modified_passes(spec, tool, plan.passes, modifications,
                                                                profile_tolerance_mm))
        toolpath = passes_toolpath(spec, tool, machine, params, plan.passes, blank_radius_mm)
        advice = tool_advice(spec, tool, params, plan, blank_radius_mm)
        if tool.flute_length_mm and tool.flute_length_mm < advice.required_flute_length_mm:
            raise ToolError(f"finishing tool flute_length_mm = {tool.flute_length_mm:g} is shorter than the "
                            f"{advice.required_flute_length_mm:.3f} mm the generating passes need",
                            field="flute_length_mm", section="tools.finishing")
        facts = GeneratingFacts(plan.passes_per_space, plan.flat_height_mm, plan.flank_passes_per_flank,
                                plan.tip_passes_per_space, plan.land_passes_per_space, plan.tip_leftover_mm,
                                params.cutting_direction, params.flank_tool_end)
        result = FinishingResult(self.name, params, _space_poses(plan), 1, 0.0, np.zeros(0),
                                 passes_per_space=plan.passes_per_space,
                                 passes=plan.passes, facts=facts, tool_advice=advice)
        return toolpath, result


def passes_toolpath(spec: GearSpec, tool: Tool, machine: Machine, params: GeneratingParams,
                    passes: tuple[GeneratingPass, ...], blank_radius_mm: float) -> Toolpath:
    """The finishing toolpath of one space's passes run in every space: what `generate` builds from its plan, and
    what spur-cad correct builds from passes it has moved (spur_cad.correct.correct)."""
    builder = ToolpathBuilder(Operation.FINISHING, tool.tool_number, tool.spindle_rpm(machine))
    _passes(builder, spec, tool, machine, passes, params, safe_height_mm(blank_radius_mm, machine))
    return builder.build()


def _path_offset(p: GeneratingPass, x: float, y: float, z: float) -> tuple[float, float]:
    """(Y, Z) of the pass line at X moved by its modification offset there (held beyond the path's ends)."""
    xs = [q[0] for q in p.path]
    return (y + float(np.interp(x, xs, [q[1] for q in p.path])), z + float(np.interp(x, xs, [q[2] for q in p.path])))


def _passes(builder: ToolpathBuilder, spec: GearSpec, tool: Tool, machine: Machine, passes: tuple[GeneratingPass, ...],
            params: GeneratingParams, safe_z: float) -> None:
    """Every space runs the same passes relative to its base angle -k * 360/z (foldable)."""
    feed = tool.feed_mm_min(machine)
    fast = machine.max_feed_mm_min
    margin = tool.diameter_mm / 2.0 + machine.clearance_mm
    x_front, x_back = -margin, spec.face_width_mm + margin
    clamp = bool(machine.rotary_clamp_code and machine.rotary_unclamp_code)
    rows = []
    for p in passes:
        direction = _pass_direction(p.side, params.cutting_direction)
        x0, x1 = (x_front, x_back) if direction > 0 else (x_back, x_front)
        y0, y1 = p.y_mm + x0 * p.dy_per_x, p.y_mm + x1 * p.dy_per_x
        z0, z1 = p.z_mm + x0 * p.dz_per_x, p.z_mm + x1 * p.dz_per_x
        rows.append((MoveKind.RAPID, x0, y0, safe_z, p.a_deg, math.nan, Feature.NONE))
        if clamp:
            rows.append((MoveKind.CLAMP_ROTARY, x0, y0, safe_z, p.a_deg, math.nan, Feature.NONE))
        if machine.clearance_mm > 0.0:
            rows.append((MoveKind.LINEAR, x0, y0, z0 + machine.clearance_mm, p.a_deg, fast, Feature.NONE))
        if p.path:  # a modified flank: the line moved by the offsets at the breakpoints, in travel order
            (y0, z0), (y1, z1) = _path_offset(p, x0, y0, z0), _path_offset(p, x1, y1, z1)
        rows.append((MoveKind.LINEAR, x0, y0, z0, p.a_deg, PLUNGE_FEED_FRACTION * feed, Feature.NONE))
        for xb, dyb, dzb in (p.path if direction > 0 else p.path[::-1]) if len(p.path) > 1 else ():
            rows.append((MoveKind.LINEAR, xb, p.y_mm + xb * p.dy_per_x + dyb, p.z_mm + xb * p.dz_per_x + dzb,
                         p.a_deg, feed, p.feature))
        rows.append((MoveKind.LINEAR, x1, y1, z1, p.a_deg, feed, p.feature))
        rows.append((MoveKind.LINEAR, x1, y1, safe_z, p.a_deg, fast, Feature.NONE))
        if clamp:
            rows.append((MoveKind.UNCLAMP_ROTARY, x1, y1, safe_z, p.a_deg, math.nan, Feature.NONE))
    kind, x, y, z, a_rel, feeds, feature = (np.array(c) for c in zip(*rows))
    teeth, pitch_deg, per_space = spec.teeth, 360.0 / spec.teeth, len(rows)
    space = np.repeat(np.arange(teeth), per_space)
    builder.extend(np.tile(kind.astype(np.int8), teeth), np.tile(x, teeth), np.tile(y, teeth), np.tile(z, teeth),
                   np.tile(a_rel, teeth) - space * pitch_deg, np.tile(feeds, teeth), False, space, -1,
                   np.tile(feature.astype(np.int8), teeth))


__all__ = ["GeneratingParams", "GeneratingPass", "GeneratingPlan", "GeneratingStrategy", "GeneratingToolLimits",
           "check_generating_tool", "flank_poses", "flank_rolls", "flat_deviation_mm", "generating_tool_limits",
           "land_angles", "passes_flute_length_mm", "passes_toolpath", "tool_advice",
           "plan_generating", "rough_passes_per_space"]
