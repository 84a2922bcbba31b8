"""The CAM plan's types: what the CAM stage is given (CamInputs, validated once when made) and what it decided
(CamPlan: roughing, finishing, two-stage roughing and the suggestions). Split from cam/plan.py, which re-exports
them (docs/architecture.md, "The CAM plan")."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from spur_cad.cad.specs import StockSpec
from spur_cad.cam.estimate import Estimate
from spur_cad.cam.fillet_reach import finishing_spec
from spur_cad.cam.flank_roughing import FlankPlan
from spur_cad.cam.ir import Toolpath
from spur_cad.cam.machine import Machine, RoughingParams
from spur_cad.cam.recommend import ToolRecommendations
from spur_cad.cam.roughing import RoughingLevels
from spur_cad.cam.strategies import (
    REGISTRY,
    FinishingResult,
    FinishingSection,
    Strategies,
)
from spur_cad.cam.three_axis_tabs import ThreeAxisSection
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.geometry.mate import GearPair
from spur_cad.geometry.modifications import FlankModifications
from spur_cad.geometry.spec import GearSpec


@dataclass(frozen=True)
class RoughingPlan:
    """Roughing: the levels (computed once), the toolpath and its estimate, and the heights of the passes over
    each tip land (tooth axis up; none in two-stage roughing's bottom program)."""

    tool: Tool
    levels: RoughingLevels
    lowest_level_above_root_mm: float
    toolpath: Toolpath
    estimate: Estimate
    tip_heights_mm: np.ndarray = field(default_factory=lambda: np.zeros(0))  # passes over each tip land
    flank: FlankPlan | None = None  # the flank strategy's plan of one space (its engagement figures)


@dataclass(frozen=True)
class FinishingPlan:
    """Finishing: the strategy's result and toolpath, its estimate, and comparison estimates (None when
    beyond MAX_COMPARISON_MOVES): perimeter finishing at the job's target scallop (the chosen strategy's
    own estimate when that is perimeter) and the reference process's strategy."""

    tool: Tool
    result: FinishingResult
    toolpath: Toolpath
    estimate: Estimate
    reference_estimate: Estimate | None
    perimeter_estimate: Estimate | None = None


@dataclass(frozen=True)
class FlankSuggestion:
    """Roughing by flanks instead of the job's levels, with the same tool and cutting data (times with the machine's
    accelerations)."""

    flank_time_s: float
    levels_time_s: float
    passes_per_space: int


@dataclass(frozen=True)
class LevelsSuggestion:
    """Roughing by levels instead of the job's flanks, with the same tool and cutting data (times with the machine's
    accelerations)."""

    levels_time_s: float
    flank_time_s: float
    levels_per_space: int


@dataclass(frozen=True)
class TwoStage:
    """Two-stage roughing: where the bottom tool takes over and what it saves against that tool alone (times with
    the machine's accelerations)."""

    split_height_above_root_mm: float  # the roughing tool's lowest level; the bottom tool's levels are below it
    chosen: str  # "shortest time", "set" ([roughing] bottom_tool_above_root_mm) or "reach" (by flanks)
    two_stage_time_s: float
    bottom_tool_alone_time_s: float
    roughing_tool: Tool | None = None  # the larger tool (the upper program's)

    @property
    def gain_s(self) -> float:
        return self.bottom_tool_alone_time_s - self.two_stage_time_s


@dataclass(frozen=True)
class CamPlan:
    """Everything the CAM stage decided for one job (`roughing_bottom` and `two_stage`: two-stage roughing)."""

    recommendations: ToolRecommendations
    roughing: RoughingPlan | None
    finishing: FinishingPlan | None
    warnings: tuple[str, ...]
    roughing_bottom: RoughingPlan | None = None
    two_stage: TwoStage | None = None
    # two-stage roughing the job's tools allow but not used: the bottom tool alone is quicker (roughing is then that
    # tool's single program)
    two_stage_declined: TwoStage | None = None
    # roughing by flanks with one tool: two-stage roughing with a larger top tool the job does not give, when it would
    # save at least 1 - TWO_STAGE_PAYS_FRACTION of the time (its roughing_tool: the larger tool; suggested_top_tool)
    two_stage_suggested: TwoStage | None = None
    # roughing by levels (a job file's default): roughing by flanks with the same tool and cutting data, when it would
    # save at least 1 - TWO_STAGE_PAYS_FRACTION of the time (suggested_flank_roughing)
    flank_suggested: FlankSuggestion | None = None
    # roughing by flanks as a job file's default, not used: why (the flank strategy's refusal, or what it would leave
    # uncut); roughing is by levels (plan_cam)
    flank_fallback: str | None = None
    # roughing by flanks with one tool: roughing by levels with the same tool and cutting data, when it would save at
    # least 1 - TWO_STAGE_PAYS_FRACTION of the time (suggested_levels_roughing)
    levels_suggested: LevelsSuggestion | None = None


@dataclass(frozen=True)
class CamInputs:
    """What the CAM stage needs of a job (the job file's gear, stock, tools, strategies, machine)."""

    spec: GearSpec
    stock: StockSpec
    roughing_tool: Tool | None
    finishing_tool: Tool | None
    roughing: RoughingParams
    finishing: FinishingSection  # [finishing] of `strategies` (FinishingParams for the default registry)
    machine: Machine
    bottom_tool: Tool | None = None  # two-stage roughing: the smaller tool for the bottom of the spaces
    top_tool: Tool | None = None  # two-stage roughing offered: a larger tool above roughing_tool ([tools.roughing_top])
    strategies: Strategies = field(default_factory=lambda: dict(REGISTRY))  # where [finishing] strategy is found
    profile_tolerance_mm: float = 0.001  # [job] profile_tolerance_mm: the 3-axis finishing arcs' chordal tolerance
    three_axis: ThreeAxisSection = field(default_factory=ThreeAxisSection)  # [three_axis]: tabs or an onion skin
    modifications: FlankModifications | None = None  # [gear.modifications]: cut by generating or perimeter finishing
    # roughing by flanks is the job file's default, not its choice: where it cannot take the gear or tools, roughing
    # falls back to levels (plan_cam)
    levels_fallback: bool = False
    # [export] dxf or svg: the outline is written for a 2-D process (wire EDM, laser, waterjet); with no tools given
    # nothing is milled, and the end mills' sizes are not warned about
    outline_export: bool = False
    # [mate]: the gear pair; with it a finishing corner may leave the fillet below the mate's SAP (cam.fillet_reach)
    pair: GearPair | None = None

    def __post_init__(self) -> None:
        """What the job loader checks where the sections meet, checked once, here, for inputs made without it: the
        stock and [three_axis] against the gear, and each tool, which its role names (StockError, MachineError or
        ToolError naming the key); each section checked its own keys when it was made. The plan's functions and
        the generators they call trust their inputs."""
        self.stock.validate(self.spec)
        self.three_axis.validate(self.spec.face_width_mm)
        for role, tool in (("roughing", self.roughing_tool), ("finishing", self.finishing_tool),
                           ("bottom", self.bottom_tool), ("roughing_top", self.top_tool)):
            if tool is not None:
                tool.validate(role)

    @property
    def finishing_spec(self) -> GearSpec:
        """The outline the finishing strategy cuts (cam.fillet_reach.finishing_spec): the gear's, or with a [mate]
        the one a finishing corner larger than the fillet allows leaves below the SAP."""
        corner = self.finishing_tool.effective_corner_radius_mm if self.finishing_tool is not None else 0.0
        return finishing_spec(self.spec, self.pair, corner)

    @property
    def roughing_tool_set(self) -> Tool:
        """The roughing tool, which planning needs (check_cam_inputs refuses a job without one first)."""
        return _required_tool(self.roughing_tool, "roughing")

    @property
    def finishing_tool_set(self) -> Tool:
        """The finishing tool, which planning needs (check_cam_inputs refuses a job without one first)."""
        return _required_tool(self.finishing_tool, "finishing")

    @property
    def bottom_tool_set(self) -> Tool:
        """The bottom tool of two-stage roughing (asked for only when [tools.roughing_bottom] is given)."""
        return _required_tool(self.bottom_tool, "roughing_bottom")


def _required_tool(tool: Tool | None, role: str) -> Tool:
    if tool is None:
        raise ToolError(f"[tools.{role}] is required for this plan", field="diameter_mm", section=f"tools.{role}")
    return tool
