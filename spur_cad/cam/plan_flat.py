"""The CAM plan of a 3-axis job (the blank lying flat, [machine] axes = 3; spur_cad.cam.three_axis and
cam.three_axis_ring): its checks that need no toolpath, then roughing and finishing of an external gear or a ring.
Split from cam/plan.py, whose plan_cam calls plan_three_axis and which re-exports check_three_axis_inputs."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from spur_cad.cam.allowances import ToolRecommendations
from spur_cad.cam.estimate import estimate
from spur_cad.cam.machine import MachineError, check_travel
from spur_cad.cam.plan_types import CamInputs, CamPlan, FinishingPlan, RoughingPlan
from spur_cad.cam.recommend import recommend_tools
from spur_cad.cam.strategies import FinishingResult
from spur_cad.cam.tools import ToolError
from spur_cad.geometry.kinds import EXTERNAL_HELICAL, EXTERNAL_SPUR, INTERNAL_SPUR, GearKind
from spur_cad.geometry.outline2d import Arc2D


def check_three_axis_inputs(inputs: CamInputs):
    """Every check of a 3-axis job that needs no toolpath (cheap enough for a GUI to run while the user types):
    a roughing tool with a finishing one, flat end mills whose side reaches the active profile (check_three_axis),
    the tabs against the face width. Returns (the tool recommendations, the flat end mill's root analysis)."""
    from spur_cad.cam.three_axis import check_three_axis

    spec = inputs.spec
    if inputs.machine.setup.finishing_needs_roughing and inputs.finishing_tool is not None \
            and inputs.roughing_tool is None:
        raise ToolError("[machine] axes = 3 needs [tools.roughing]: finishing cuts only the finish stock around the "
                        "outline", field="diameter_mm", section="tools.roughing")
    root = check_three_axis(spec, inputs.finishing_tool, inputs.roughing_tool)
    return FLAT_PLANS[spec.kind].recommendations(inputs), root


def _external_recommendations(inputs: CamInputs) -> ToolRecommendations:
    """An external gear's tool limits lying flat (three_axis.flat_tool_recommendations)."""
    from spur_cad.cam.three_axis import flat_tool_recommendations

    spec = inputs.spec
    rotary = recommend_tools(spec, inputs.stock.blank_radius_mm(spec), inputs.machine.clearance_mm)
    return flat_tool_recommendations(spec, inputs.machine.clearance_mm, rotary.roughing_max_diameter_mm)


def _ring_recommendations(inputs: CamInputs) -> ToolRecommendations:
    """A ring's (the rotary-table strategies' recommendations do not apply to a ring)."""
    from spur_cad.cam.three_axis_ring import ring_tool_recommendations

    return ring_tool_recommendations(inputs.spec, inputs.machine.clearance_mm)


def plan_three_axis(inputs: CamInputs, tolerance_mm: float) -> CamPlan:
    """The CAM plan of a 3-axis job ([machine] axes = 3): the checks of three_axis.check_three_axis, roughing and
    finishing as spur_cad.cam.three_axis says (a ring's as spur_cad.cam.three_axis_ring says); no tool
    recommendations for the rotary-table strategies (empty; the cut is simulated by spur_cad.sim.flat, its error
    budget is the 3-axis machine's: pipeline.error_budget)."""
    rec, root = check_three_axis_inputs(inputs)
    return FLAT_PLANS[inputs.spec.kind].plan(inputs, tolerance_mm, rec, root)


def _plan_three_axis_external(inputs: CamInputs, tolerance_mm: float, rec: ToolRecommendations, root) -> CamPlan:
    """The 3-axis plan of an external gear (spur_cad.cam.three_axis)."""
    from spur_cad.cam.roughing import RoughingLevels
    from spur_cad.cam.three_axis import (
        ThreeAxisFinishingFacts,
        finishing_engagement,
        finishing_loop,
        finishing_toolpath,
        roughing_leaves,
        roughing_toolpath,
    )
    from spur_cad.cam.three_axis_root import root_thickness

    spec, machine, stock = inputs.spec, inputs.machine, inputs.stock
    blank = stock.blank_radius_mm(spec)
    roughing = finishing = None
    if inputs.roughing_tool is not None:
        tool = inputs.roughing_tool
        path, levels, offsets = roughing_toolpath(spec, tool, machine, inputs.roughing, blank, inputs.three_axis)
        check_travel(machine, path.x, path.y, path.z, path.a, "roughing")
        roughing = RoughingPlan(tool, RoughingLevels(np.array(levels), np.array(offsets[:1] * len(levels)), None),
                                0.0, path, estimate(path, machine))
    if inputs.finishing_tool is not None:
        tool = inputs.finishing_tool
        loop = finishing_loop(spec, tool, tolerance_mm)
        engagement = None if roughing is None else finishing_engagement(
            loop, tool,
            roughing_leaves(spec, inputs.roughing_tool_set, offsets[-1]), inputs.roughing)
        path, levels, segments = finishing_toolpath(spec, tool, machine, tolerance_mm, blank,
                                                    None if engagement is None else engagement.step_down_mm,
                                                    inputs.three_axis)
        check_travel(machine, path.x, path.y, path.z, path.a, "finishing")
        arcs = sum(isinstance(segment, Arc2D) for segment in loop)  # (tabs split them at some levels)
        facts = ThreeAxisFinishingFacts(tool.diameter_mm / 2.0, 2 * root.form_radius_mm, 2 * root.rack_form_radius_mm,
                                        2 * root.active_start_radius_mm, root.fillet_radius_mm, len(levels),
                                        segments, arcs, root_thickness(spec, tool.diameter_mm / 2.0), engagement)
        result = FinishingResult("three_axis", None, None, len(levels), 0.0, np.zeros(0), facts=facts,
                                 lying_flat=True)
        finishing = FinishingPlan(tool, result, path, estimate(path, machine), None, None)
    return CamPlan(rec, roughing, finishing, ())


def _plan_three_axis_ring(inputs: CamInputs, tolerance_mm: float, rec: ToolRecommendations, root) -> CamPlan:
    """The 3-axis plan of an internal gear (spur_cad.cam.three_axis_ring): the hole roughed from the centre out
    (from [stock] inner_diameter_mm's bore, or a helix into a solid blank), the toothed inner outline finished;
    no tool recommendations; simulated and graded as an external gear's 3-axis cut (spur_cad.sim.flat)."""
    from spur_cad.cam.roughing import RoughingLevels
    from spur_cad.cam.three_axis import ThreeAxisFinishingFacts, finishing_engagement
    from spur_cad.cam.three_axis_ring import (
        ring_finishing_loop,
        ring_finishing_toolpath,
        ring_roughing_leaves,
        ring_roughing_toolpath,
    )
    from spur_cad.cam.three_axis_root import root_thickness

    spec, machine = inputs.spec, inputs.machine
    if inputs.three_axis.tabs or inputs.three_axis.onion_skin_mm:
        raise MachineError("[three_axis] tabs and onion_skin_mm hold a through-cut external gear; a ring is clamped "
                           "on its rim and its hole is milled away whole: leave them out",
                           field="tabs" if inputs.three_axis.tabs else "onion_skin_mm", section="three_axis")
    roughing = finishing = None
    if inputs.roughing_tool is not None:
        tool = inputs.roughing_tool
        path, levels, offsets = ring_roughing_toolpath(spec, tool, machine, inputs.roughing,
                                                       inputs.stock.inner_diameter_mm / 2.0)
        check_travel(machine, path.x, path.y, path.z, path.a, "roughing")
        roughing = RoughingPlan(tool, RoughingLevels(np.array(levels), np.array(offsets[:1] * len(levels)), None),
                                0.0, path, estimate(path, machine))
    if inputs.finishing_tool is not None:
        tool = inputs.finishing_tool
        engagement = None if roughing is None else finishing_engagement(
            ring_finishing_loop(spec, tool, tolerance_mm), tool,
            ring_roughing_leaves(spec, inputs.roughing_tool_set, offsets[0]), inputs.roughing)
        path, levels, segments = ring_finishing_toolpath(spec, tool, machine, tolerance_mm,
                                                         None if engagement is None else engagement.step_down_mm)
        check_travel(machine, path.x, path.y, path.z, path.a, "finishing")
        arcs = int(path.arc_mask.sum()) // len(levels) - 2  # less the lead-in and lead-out arcs
        facts = ThreeAxisFinishingFacts(tool.diameter_mm / 2.0, 2 * root.form_radius_mm, 2 * root.rack_form_radius_mm,
                                        2 * root.active_start_radius_mm, root.fillet_radius_mm, len(levels),
                                        segments, arcs, root_thickness(spec, tool.diameter_mm / 2.0), engagement,
                                        "cutter")
        result = FinishingResult("three_axis", None, None, len(levels), 0.0, np.zeros(0), facts=facts,
                                 lying_flat=True)
        finishing = FinishingPlan(tool, result, path, estimate(path, machine), None, None)
    return CamPlan(rec, roughing, finishing, ())


@dataclass(frozen=True)
class FlatPlan:
    """How a gear kind is planned lying flat: its tool limits (check_three_axis_inputs) and its plan (given them and
    the finishing tool's root)."""

    recommendations: Callable[[CamInputs], ToolRecommendations]
    plan: Callable[[CamInputs, float, ToolRecommendations, Any], CamPlan]


EXTERNAL = FlatPlan(_external_recommendations, _plan_three_axis_external)
FLAT_PLANS: dict[GearKind, FlatPlan] = {EXTERNAL_SPUR: EXTERNAL, EXTERNAL_HELICAL: EXTERNAL,
                                        INTERNAL_SPUR: FlatPlan(_ring_recommendations, _plan_three_axis_ring)}
"""How each gear kind is planned lying flat (a helical gear is refused by check_three_axis first)."""
