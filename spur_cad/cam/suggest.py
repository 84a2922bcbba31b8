"""A consistent set of tools for a gear, chosen within its limits: what a new job starts from (the workbench),
what `diameter_mm = "auto"` takes (the job file), and what a tool-fit error proposes instead of the job's tools.

The finishing tool comes first (the job's strategy suggests it: by generation r_t = rho and 95 % of the
largest diameter in 0.05 mm steps), because the roughing limit depends on it (what the strategy lets roughing
leave above the root: FinishingStrategy.bottom_allowance); then the roughing tool: the largest flat end mill
in 0.1 mm steps that passes the tool limits, reaches the bottom of the spaces with the job's roughing levels
and, beside a holding stub, turns within the back margin.
"""

from __future__ import annotations

from dataclasses import dataclass

from spur_cad.cad.specs import StockSpec
from spur_cad.cam.ir import MAX_TOOLPATH_MOVES
from spur_cad.cam.machine import RoughingParams
from spur_cad.cam.recommend import check_roughing_reach, check_tools, recommend_tools
from spur_cad.cam.roughing import estimated_roughing_moves, roughing_levels
from spur_cad.cam.strategies.base import floor_to_step
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.geometry.spec import GearSpec

ROUGHING_STEP_MM = 0.1
"""Roughing diameters are suggested in steps of this size (end mills are sold in tenths of a millimetre)."""
SMALLEST_SUGGESTED_MM = 0.2


@dataclass(frozen=True)
class ToolShape:
    """An end mill's shape: kind, diameter D and corner radius r_t (mm)."""

    kind: str
    diameter_mm: float
    corner_radius_mm: float

    def text(self) -> str:
        """'bull_nose D 2.3 mm r 0.8 mm' (the job file's words)."""
        corner = f" r {self.corner_radius_mm:g} mm" if self.corner_radius_mm > 0.0 else ""
        return f"{self.kind} D {self.diameter_mm:g} mm{corner}"


@dataclass(frozen=True)
class SuggestedTools:
    """Tools within the gear's limits: None where no tool of that role fits (a sharp rack by generation, a
    space narrower than the smallest suggested roughing tool)."""

    finishing: ToolShape | None
    roughing: ToolShape | None

    def text(self) -> str:
        """'roughing flat D 2 mm, finishing bull_nose D 2.3 mm r 0.8 mm' (the roles that have a tool)."""
        parts = [f"{role} {shape.text()}" for role, shape in (("roughing", self.roughing),
                                                              ("finishing", self.finishing)) if shape is not None]
        return ", ".join(parts) if parts else "no tool fits"


def suggested_finishing(spec: GearSpec, strategy, target_scallop_mm: float, blank_radius_mm: float,
                        clearance_mm: float) -> ToolShape | None:
    """The finishing tool the strategy suggests for the gear (None when none fits)."""
    rec = recommend_tools(spec, blank_radius_mm, clearance_mm, strategy=strategy)
    suggested = strategy.suggested_tool(spec, rec, target_scallop_mm, blank_radius_mm)
    if suggested is None:
        return None
    corner, flat = suggested
    kind = "bull_nose" if flat > 0.0 else "ball"  # a flat of 0: a ball end mill of radius rho
    return ToolShape(kind, round(flat + 2.0 * corner, 6), round(corner, 6))


def suggested_roughing(spec: GearSpec, strategy, finishing: Tool | None, roughing: RoughingParams, stock: StockSpec,
                       clearance_mm: float) -> ToolShape | None:
    """The largest flat end mill (0.1 mm steps) that passes the roughing limits with this finishing strategy and
    tool, reaches the bottom of the spaces with these roughing levels and, beside a holding stub that stands
    within the clearance of the root, turns within the back margin (stub_fits); None when even 0.2 mm does not."""
    blank_radius_mm = stock.blank_radius_mm(spec)
    rec = recommend_tools(spec, blank_radius_mm, clearance_mm, finishing, strategy=strategy)
    diameter = floor_to_step(rec.roughing_max_diameter_mm, ROUGHING_STEP_MM)
    while diameter >= SMALLEST_SUGGESTED_MM - 1e-9:
        candidate = Tool(diameter_mm=round(diameter, 6), kind="flat")
        try:
            check_tools(spec, rec, candidate, None)
            moves, _ = estimated_roughing_moves(spec, candidate, roughing, blank_radius_mm)
            if finishing is not None and moves <= MAX_TOOLPATH_MOVES:  # else the plan refuses [roughing] itself
                levels = roughing_levels(spec, candidate, roughing, blank_radius_mm)
                check_roughing_reach(candidate, levels.lowest_height_mm - spec.root_radius_mm, rec)
            if stub_fits(spec, stock, candidate, clearance_mm):
                return ToolShape("flat", candidate.diameter_mm, 0.0)
        except ToolError:
            pass
        diameter -= ROUGHING_STEP_MM
    return None


def stub_fits(spec: GearSpec, stock: StockSpec, tool: Tool, clearance_mm: float) -> bool:
    """Whether the roughing tool's passes stay clear of the holding stub: their far edge runs D + clearance beyond
    the face, into the back margin, where the stub stands within the clearance of the root circle (the roughing
    programs refuse more; a conservative test, before the levels or the flank passes are planned)."""
    reaches_root = stock.stub_diameter_mm / 2.0 + clearance_mm > spec.root_radius_mm
    return not reaches_root or stock.back_margin_mm >= tool.diameter_mm + clearance_mm - 1e-9


def suggested_tools(spec: GearSpec, strategy, target_scallop_mm: float, roughing: RoughingParams,
                    stock: StockSpec, clearance_mm: float) -> SuggestedTools:
    """Finishing then roughing tool for the gear (see the module docstring)."""
    finishing = suggested_finishing(spec, strategy, target_scallop_mm, stock.blank_radius_mm(spec), clearance_mm)
    finishing_tool = (Tool(diameter_mm=finishing.diameter_mm, kind=finishing.kind,
                           corner_radius_mm=finishing.corner_radius_mm) if finishing is not None else None)
    return SuggestedTools(finishing, suggested_roughing(spec, strategy, finishing_tool, roughing, stock,
                                                        clearance_mm))
