"""The CAM plan of a job, typed: tool recommendations, roughing (levels, toolpath, estimate),
finishing (strategy result, toolpath, estimate, and the reference process's strategy for
comparison) and warnings. Computed once per job; summary, posts, simulation, report and the
workbench read it (docs/architecture.md)."""

from __future__ import annotations

from dataclasses import dataclass

from spur_cad.cad.specs import StockSpec
from spur_cad.cam.estimate import Estimate, estimate
from spur_cad.cam.finishing import plan_finishing
from spur_cad.cam.ir import Toolpath
from spur_cad.cam.machine import FinishingParams, Machine, RoughingParams, check_travel
from spur_cad.cam.recommend import ToolRecommendations, check_roughing_reach, check_tools, recommend_tools
from spur_cad.cam.roughing import RoughingLevels, roughing_levels, roughing_toolpath
from spur_cad.cam.strategies import FinishingResult
from spur_cad.cam.tools import Tool
from spur_cad.geometry.spec import GearSpec

REFERENCE_CONTACT_SPACING_MM = 0.08
"""Contact spacing along the profile of the shop-tested reference process (fixed arc length)."""

REFERENCE_STATION_STEP_MM = 0.14
"""X step between the reference process's finishing stations. With the spacing above it defines
"the reference process's strategy" (perimeter finishing) whose time is reported beside ours."""


@dataclass(frozen=True)
class RoughingPlan:
    """Roughing: the levels (computed once), the toolpath and its estimate."""

    tool: Tool
    levels: RoughingLevels
    lowest_level_above_root_mm: float
    toolpath: Toolpath
    estimate: Estimate


@dataclass(frozen=True)
class FinishingPlan:
    """Finishing: the strategy's result and toolpath, its estimate, and the reference process's."""

    tool: Tool
    result: FinishingResult
    toolpath: Toolpath
    estimate: Estimate
    reference_estimate: Estimate


@dataclass(frozen=True)
class CamPlan:
    """Everything the CAM stage decided for one job."""

    recommendations: ToolRecommendations
    roughing: RoughingPlan | None
    finishing: FinishingPlan | None
    warnings: tuple[str, ...]


@dataclass(frozen=True)
class CamInputs:
    """What the CAM stage needs of a job (the job file's gear, stock, tools, strategies, machine)."""

    spec: GearSpec
    stock: StockSpec
    roughing_tool: Tool | None
    finishing_tool: Tool | None
    roughing: RoughingParams
    finishing: FinishingParams
    machine: Machine


def plan_cam(inputs: CamInputs) -> CamPlan:
    """Tool recommendations always; toolpaths and estimates for the tools the job gives (pure)."""
    spec, machine, stock = inputs.spec, inputs.machine, inputs.stock
    blank = stock.blank_radius_mm(spec)
    rec = recommend_tools(spec, blank, machine.clearance_mm, inputs.finishing_tool)
    check_tools(spec, rec, inputs.roughing_tool, inputs.finishing_tool)
    roughing = finishing = None
    warnings: list[str] = []
    if inputs.roughing_tool is not None:
        roughing = _plan_roughing(inputs, rec, blank)
        warnings.extend(roughing.toolpath.warnings)
    if inputs.finishing_tool is not None:
        finishing = _plan_finishing(inputs, blank)
        warnings.extend(finishing.toolpath.warnings)
    return CamPlan(rec, roughing, finishing, tuple(warnings))


def _plan_roughing(inputs: CamInputs, rec: ToolRecommendations, blank: float) -> RoughingPlan:
    spec, tool, stock = inputs.spec, inputs.roughing_tool, inputs.stock
    levels = roughing_levels(spec, tool, inputs.roughing, blank)
    lowest_above_root = levels.lowest_height_mm - spec.root_radius_mm
    if inputs.finishing_tool is not None:
        check_roughing_reach(tool, lowest_above_root, rec)
    path = roughing_toolpath(spec, tool, inputs.machine, inputs.roughing, blank, stock.back_margin_mm,
                             stock.stub_diameter_mm / 2.0, stock.front_margin_mm, levels=levels)
    check_travel(inputs.machine, path.x, path.y, path.z, path.a, "roughing")
    return RoughingPlan(tool, levels, lowest_above_root, path, estimate(path, inputs.machine))


def _plan_finishing(inputs: CamInputs, blank: float) -> FinishingPlan:
    spec, tool, machine = inputs.spec, inputs.finishing_tool, inputs.machine
    path, result = plan_finishing(spec, tool, machine, inputs.finishing, blank)
    check_travel(machine, path.x, path.y, path.z, path.a, "finishing")
    reference_section = FinishingParams(strategy="perimeter", target_scallop_mm=inputs.finishing.target_scallop_mm,
                                        step_over_mm=REFERENCE_STATION_STEP_MM)
    reference, _ = plan_finishing(spec, tool, machine, reference_section, blank,
                                  contact_spacing_mm=REFERENCE_CONTACT_SPACING_MM)
    return FinishingPlan(tool, result, path, estimate(path, machine), estimate(reference, machine))
