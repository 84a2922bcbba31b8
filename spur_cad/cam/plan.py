"""The CAM plan of a job, typed: tool recommendations, roughing (levels, toolpath, estimate),
finishing (strategy result, toolpath, estimate, and for comparison the estimates of the
perimeter strategy and of the reference process's strategy) and warnings. Computed once per
job; summary, posts, simulation, report and the workbench read it (docs/architecture.md)."""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from spur_cad.cad.specs import StockSpec
from spur_cad.cam.common import check_moves
from spur_cad.cam.contacts import ContactCounts, contact_counts
from spur_cad.cam.estimate import Estimate, estimate, move_seconds
from spur_cad.cam.fillet_reach import finishing_spec
from spur_cad.cam.finishing import generate_finishing
from spur_cad.cam.flank_roughing import UNCUT_MM2, FlankPlan
from spur_cad.cam.ir import Toolpath
from spur_cad.cam.machine import Machine, MachineError, RoughingParams, check_travel
from spur_cad.cam.machine_limits import check_machine_limits
from spur_cad.cam.recommend import (
    LAND_PASS_DEPTH_FRACTION,
    ToolRecommendations,
    check_roughing_reach,
    check_tools,
    flank_polyline,
    recommend_tools,
    small_tool_warnings,
    space_half_width_mm,
)
from spur_cad.cam.roughing import (
    RoughingLevels,
    check_helical_roughing_machine,
    estimated_roughing_moves,
    flank_plan_for,
    lowest_roughing_level,
    roughing_levels,
    roughing_toolpath,
    tip_heights_mm,
)
from spur_cad.cam.strategies import (
    COMPARISON_STRATEGY,
    REGISTRY,
    FinishingParams,
    FinishingResult,
    FinishingSection,
    Strategies,
    get_strategy,
    params_from_section,
)
from spur_cad.cam.three_axis_tabs import ThreeAxisSection
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.errors import SpurCadError, StockError, WorkLimitError, shown
from spur_cad.geometry.mate import GearPair
from spur_cad.geometry.modifications import FlankModifications
from spur_cad.geometry.outline2d import Arc2D
from spur_cad.geometry.spec import GearSpec

MAX_CONTACTS_PER_FLANK = 20_000
"""Largest number of finishing contact poses per flank (each is placed and gouge-checked)."""

REFERENCE_CONTACT_SPACING_MM = 0.08
"""Contact spacing along the profile of the shop-tested reference process (fixed arc length)."""

REFERENCE_STATION_STEP_MM = 0.14
"""X step between the reference process's finishing stations. With the spacing above it defines
"the reference process's strategy" (perimeter finishing) whose time is reported beside ours."""

MAX_COMPARISON_MOVES = 2_000_000
"""Largest toolpath a comparison time is given for (perimeter, reference process's strategy; estimated from
two stations' worth, PerimeterStrategy.estimate); beyond it the comparison is left out (None)."""


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
        """Every section and tool checked once, here, as the job loader checks them (MachineError or ToolError
        naming the key): the plan's functions and the generators they call trust their inputs."""
        self.machine.validate()
        self.roughing.validate()
        self.finishing.validate()
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


def check_cam_inputs(inputs: CamInputs) -> tuple[ToolRecommendations, RoughingLevels | None]:
    """Every check that needs no toolpath (cheap enough for a GUI to run while the user types): tool
    recommendations, tool limits, the finishing strategy's fit to the machine and its work bound, the
    roughing work bound and the roughing reach. Returns the
    recommendations and the roughing levels (None without a roughing tool)."""
    spec, machine, stock = inputs.spec, inputs.machine, inputs.stock
    strategy = get_strategy(inputs.finishing.strategy, inputs.strategies)
    if inputs.finishing_tool is not None and not spec.kind.accepts_strategy(strategy):
        helical = " or ".join(f'"{name}"' for name, other in inputs.strategies.items() if other.helical)
        raise MachineError(f"[finishing] strategy = {shown(inputs.finishing.strategy)} is for spur gears; a "
                           f"helical gear (helix_angle_deg = {spec.helix_angle_deg:g}) is finished by "
                           f"strategy = {helical}",
                           field="strategy", section="finishing")
    blank = stock.blank_radius_mm(spec)
    check_blank_allowance(spec, stock, inputs.finishing_tool,
                          inputs.roughing if inputs.roughing_tool is not None else None)
    rec = recommend_tools(spec, blank, machine.clearance_mm, inputs.finishing_tool,
                          inputs.finishing.target_scallop_mm, strategy)
    if inputs.bottom_tool is not None:
        check_two_stage_tools(spec, rec, inputs.roughing_tool, inputs.bottom_tool, inputs.finishing_tool, inputs.pair)
    else:
        conflicts = tool_conflicts(inputs, rec)
        if conflicts:
            raise conflicts_error(inputs, conflicts)
    if inputs.finishing_tool is not None:
        check_finishing_work(inputs.finishing_spec, inputs.finishing_tool, machine, inputs.finishing,
                             inputs.strategies)
    if inputs.roughing_tool is None:
        return rec, None
    tool = inputs.roughing_tool
    check_helical_roughing_machine(spec, machine)
    moves, driver = estimated_roughing_moves(spec, tool, inputs.roughing, blank)
    check_moves("roughing", moves, "roughing", driver)
    levels = roughing_levels(spec, tool, inputs.roughing, blank)
    deepest = tool
    if inputs.bottom_tool is not None:
        deepest = inputs.bottom_tool
        moves, driver = estimated_roughing_moves(spec, deepest, inputs.roughing, blank)
        check_moves("roughing with the bottom tool", moves, "roughing", driver)
    if inputs.finishing_tool is not None:
        lowest = levels if deepest is tool else roughing_levels(spec, deepest, inputs.roughing, blank)
        try:
            check_roughing_reach(deepest, lowest.lowest_height_mm - spec.root_radius_mm, rec)
        except ToolError as exc:
            raise ToolError(str(exc), field=exc.field,
                            section="tools.bottom" if deepest is not tool else exc.section) from None
    return rec, levels


def tool_conflicts(inputs: CamInputs, rec: ToolRecommendations) -> list[ToolError]:
    """Every way the job's roughing and finishing tools do not fit the gear, each tool checked on its own (its
    limits; the finishing strategy's rule for its shape; the roughing tool's reach to the bottom of the
    spaces), so that one message can name them all."""
    spec, blank = inputs.spec, inputs.stock.blank_radius_mm(inputs.spec)
    conflicts: list[ToolError] = []

    def collect(check: Callable[[], None]) -> bool:
        try:
            check()
        except ToolError as exc:
            conflicts.append(exc)
            return False
        return True

    finishing, roughing = inputs.finishing_tool, inputs.roughing_tool
    if finishing is not None and collect(lambda: check_tools(spec, rec, None, finishing, inputs.pair)):
        strategy = get_strategy(inputs.finishing.strategy, inputs.strategies)
        collect(lambda: strategy.check_tool(inputs.finishing_spec, finishing))
    if roughing is not None and collect(lambda: check_tools(spec, rec, roughing, None)) and finishing is not None:
        moves, driver = estimated_roughing_moves(spec, roughing, inputs.roughing, blank)
        check_moves("roughing", moves, "roughing", driver)  # the levels' work bounded before they are made
        collect(lambda: check_roughing_reach(roughing, roughing_levels(spec, roughing, inputs.roughing, blank)
                                             .lowest_height_mm - spec.root_radius_mm, rec))
    return conflicts


def conflicts_error(inputs: CamInputs, conflicts: list[ToolError]) -> ToolError:
    """One ToolError for every conflict, blaming the first one's key, with a set of tools that fits the gear (the
    suggestion comes first: a long message is cut at its end)."""
    from spur_cad.cam.suggest import suggested_tools

    strategy = get_strategy(inputs.finishing.strategy, inputs.strategies)
    try:
        suggestion = suggested_tools(inputs.spec, strategy, inputs.finishing.target_scallop_mm, inputs.roughing,
                                     inputs.stock, inputs.machine.clearance_mm)
    except SpurCadError:  # the suggestion's own limits (a work bound, say): the conflicts still come first
        suggestion = None
    if suggestion is None:
        fits = "no set of tools to suggest"
    elif suggestion.finishing or suggestion.roughing:
        fits = f"tools that fit: {suggestion.text()} (or \"auto\" sizes)"
    else:
        fits = "no tool fits this gear"
    first = conflicts[0]
    if len(conflicts) == 1:
        return ToolError(f"{first}; {fits}", field=first.field, section=first.section)
    listed = "; ".join(f"{i}) {_short(exc)}" for i, exc in enumerate(conflicts, 1))
    return ToolError(f"{len(conflicts)} tool conflicts; {fits}: {listed}", field=first.field, section=first.section)


def _short(conflict: ToolError) -> str:
    """A conflict's first clause without its parenthesised explanations (the list of several must fit a line)."""
    text = str(conflict).split("; ")[0]
    while (shorter := re.sub(r"\s*\([^()]*\)", "", text)) != text:
        text = shorter
    return text


def check_two_stage_tools(spec: GearSpec, rec: ToolRecommendations, roughing_tool: Tool | None, bottom: Tool,
                          finishing: Tool | None, pair: GearPair | None = None) -> None:
    """Two-stage roughing: the bottom tool meets the roughing tool's limits (it reaches the bottom of the space);
    the roughing tool is a flat end mill larger than it, with no limit of its own but fitting the space."""
    if roughing_tool is None:
        raise ToolError("[tools.bottom] needs [tools.roughing]: the bottom tool roughs below the roughing tool's "
                        "levels", field="diameter_mm", section="tools.bottom")
    check_tools(spec, rec, None, finishing, pair)
    try:
        check_tools(spec, rec, bottom, None)
    except ToolError as exc:
        raise ToolError(f"[tools.bottom] {exc}", field=exc.field, section="tools.bottom") from None
    if roughing_tool.kind != "flat":
        raise ToolError(f"roughing tool kind '{roughing_tool.kind}': roughing uses a flat end mill", field="kind",
                        section="tools.roughing")
    if bottom.diameter_mm >= roughing_tool.diameter_mm:
        raise ToolError(f"[tools.bottom] diameter_mm = {bottom.diameter_mm:g} must be smaller than the roughing "
                        f"tool's {roughing_tool.diameter_mm:g} mm (two-stage roughing: the larger tool roughs the "
                        "upper levels, the smaller one the bottom)", field="diameter_mm", section="tools.bottom")


def check_blank_allowance(spec: GearSpec, stock: StockSpec, finishing_tool: Tool | None,
                          roughing: RoughingParams | None = None) -> None:
    """What stands above the tip circle when finishing starts is taken off the tips by the finishing tool in one
    pass (land passes, the perimeter's tip sweep): refuse more than that tool's slotting depth
    (LAND_PASS_DEPTH_FRACTION x its diameter). Without a roughing tool that is the blank's allowance; with one
    (`roughing`, its [roughing] section), roughing's tip passes leave at most [roughing] finish_stock_mm."""
    if finishing_tool is None:
        return
    allowance = stock.blank_radius_mm(spec) - spec.tip_radius_mm
    limit = LAND_PASS_DEPTH_FRACTION * finishing_tool.diameter_mm
    if roughing is not None:
        if min(allowance, roughing.finish_stock_mm) > limit + 1e-9:
            raise MachineError(f"[roughing] finish_stock_mm = {roughing.finish_stock_mm:g}: roughing leaves that much "
                               f"on the tip lands, more than the finishing tool takes off them in one pass "
                               f"({limit:.3f} mm: {LAND_PASS_DEPTH_FRACTION:g} x D {finishing_tool.diameter_mm:g} "
                               "mm, a slot's depth)", field="finish_stock_mm", section="roughing")
        return
    if allowance > limit + 1e-9:
        name = "blank_diameter_mm" if stock.blank_diameter_mm > 0.0 else "radial_allowance_mm"
        raise StockError(f"{name}: the blank stands {allowance:.3f} mm above the tip circle, more than the finishing "
                         f"tool takes off the tips in one pass ({limit:.3f} mm: {LAND_PASS_DEPTH_FRACTION:g} x D "
                         f"{finishing_tool.diameter_mm:g} mm, a slot's depth); turn the blank to at most "
                         f"{2 * (spec.tip_radius_mm + limit):.3f} mm", field=name)


def plan_cam(inputs: CamInputs, checkpoint: Callable[[], None] | None = None) -> CamPlan:
    """Tool recommendations always; toolpaths and estimates for the tools the job gives (pure).
    `checkpoint()` is called between the steps (a front end may stop there).

    Roughing by flanks as a job file's default (`inputs.levels_fallback`): where the flank strategy is refused or
    leaves material beyond the flank allowance, the job is planned by levels instead (refused only where levels are
    refused too), and CamPlan.flank_fallback says why."""
    if not (inputs.levels_fallback and inputs.roughing.strategy == "flank"
            and inputs.roughing_tool is not None and inputs.machine.setup.rotary_axis):
        return _plan_cam(inputs, checkpoint)
    try:
        plan = _plan_cam(inputs, checkpoint)
    except SpurCadError as exc:  # levels decide: their plan, or their own refusal
        reason = str(exc)
    else:
        uncut = [planned.flank.uncut_mm2 for planned in (plan.roughing, plan.roughing_bottom)
                 if planned is not None and planned.flank is not None and planned.flank.uncut_mm2 > UNCUT_MM2]
        if not uncut:
            return plan
        reason = (f"it would leave {max(uncut):.3g} mm^2 of each tooth space's section farther than "
                  "flank_allowance_mm from the design")
    plan = _plan_cam(by_levels(inputs), checkpoint)
    return dataclasses.replace(plan, flank_fallback=reason)


def _plan_cam(inputs: CamInputs, checkpoint: Callable[[], None] | None = None) -> CamPlan:
    """plan_cam by the strategy `inputs` name."""
    check = checkpoint if checkpoint is not None else (lambda: None)
    if not inputs.machine.setup.rotary_axis:  # the blank lying flat (spur_cad.cam.three_axis)
        return _plan_three_axis(inputs, inputs.profile_tolerance_mm)
    rec, levels = check_cam_inputs(inputs)
    blank = inputs.stock.blank_radius_mm(inputs.spec)
    roughing = finishing = None
    tools = {role: tool for role, tool in (("roughing", inputs.roughing_tool), ("finishing", inputs.finishing_tool))
             if tool is not None}
    warnings: list[str] = list(check_machine_limits(inputs.spec, inputs.stock, inputs.machine, tools))
    strategy = get_strategy(inputs.finishing.strategy, inputs.strategies)
    if tools or not inputs.outline_export:  # a job that mills, or may (its recommendations choose the tools)
        warnings.extend(small_tool_warnings(rec, inputs.machine.smallest_end_mill_mm, strategy.name,
                                            strategy.largest_tool(rec),
                                            inputs.finishing_tool.kind if inputs.finishing_tool is not None else None))
    bottom = two_stage = declined = suggested = by_flanks = by_levels_instead = None
    if levels is not None and (inputs.bottom_tool is not None or inputs.top_tool is not None):
        check()
        roughing, bottom, two_stage, declined, notes = _plan_tool_pair(inputs, levels, blank)
        warnings.extend(notes + roughing.toolpath.warnings + (bottom.toolpath.warnings if bottom else ()))
    elif levels is not None:
        check()
        roughing = _plan_roughing(inputs, levels, blank)
        warnings.extend(roughing.toolpath.warnings)
        check()
        suggested = suggested_top_tool(inputs, roughing, blank)
        check()
        by_flanks = suggested_flank_roughing(inputs, roughing, blank)
        check()
        by_levels_instead = suggested_levels_roughing(inputs, roughing, blank)
    if inputs.finishing_tool is not None:
        check()
        finishing = _plan_finishing(inputs, blank, check)
        warnings.extend(finishing.toolpath.warnings)
    return CamPlan(rec, roughing, finishing, tuple(warnings), bottom, two_stage, declined, suggested, by_flanks,
                   levels_suggested=by_levels_instead)


def suggested_levels_roughing(inputs: CamInputs, roughing: RoughingPlan, blank: float) -> LevelsSuggestion | None:
    """Roughing by flanks with one tool (the job files' default): roughing by levels with the same tool, cutting data
    and allowances (the same levels: the flank plan's lowest level is theirs), when it takes at most
    TWO_STAGE_PAYS_FRACTION of `roughing`'s time; else None (suggested_flank_roughing the other way round). A gear
    whose flank passes are held to a light engagement and a short axial depth may rough quicker by levels."""
    if inputs.roughing.strategy != "flank" or roughing.flank is None:
        return None
    levels_inputs = by_levels(inputs)
    try:  # bounded as the job's own roughing would be
        moves, driver = estimated_roughing_moves(inputs.spec, roughing.tool, levels_inputs.roughing, blank)
        check_moves("roughing by levels", moves, "roughing", driver)
        levels = _plan_roughing(levels_inputs, roughing.levels, blank)
    except SpurCadError:  # levels cannot rough this space with this tool (a work bound, the travel): no suggestion
        return None
    if _seconds(levels) > TWO_STAGE_PAYS_FRACTION * _seconds(roughing):
        return None
    return LevelsSuggestion(_seconds(levels), _seconds(roughing), len(levels.levels.heights_mm))


def suggested_flank_roughing(inputs: CamInputs, roughing: RoughingPlan, blank: float) -> FlankSuggestion | None:
    """Roughing by levels with one tool (a job file's default strategy): roughing by flanks with the same tool,
    cutting data and allowances, when it takes at most TWO_STAGE_PAYS_FRACTION of `roughing`'s time and leaves
    nothing uncut; else None. Not for helical gears (a flank plan of theirs takes seconds)."""
    if inputs.roughing.strategy != "levels" or inputs.spec.kind.helical:
        return None
    flank_inputs = dataclasses.replace(inputs, roughing=dataclasses.replace(inputs.roughing, strategy="flank"))
    try:  # bounded as the job's own roughing would be
        moves, driver = estimated_roughing_moves(inputs.spec, roughing.tool, flank_inputs.roughing, blank)
        check_moves("roughing by flanks", moves, "roughing", driver)
        flank = _plan_roughing(flank_inputs, roughing.levels, blank)
    except SpurCadError:  # the flank strategy cannot rough this space with this tool: nothing to suggest
        return None
    if flank.flank is None or flank.flank.uncut_mm2 > UNCUT_MM2 \
            or _seconds(flank) > TWO_STAGE_PAYS_FRACTION * _seconds(roughing):
        return None
    return FlankSuggestion(_seconds(flank), _seconds(roughing), len(flank.flank.passes))


def suggested_top_tool(inputs: CamInputs, roughing: RoughingPlan, blank: float) -> TwoStage | None:
    """Roughing by flanks with the job's one tool: two-stage roughing by flanks with a larger top tool above it, when
    it takes at most TWO_STAGE_PAYS_FRACTION of `roughing`'s time (both estimated with accelerations); else None.
    One size is planned (each costs a flank plan of both tools): the largest whole-millimetre flat end mill no wider
    than the space at the reference circle (suggested_two_stage's range), with the job tool's cutting data and
    flutes 3 D long (or the job tool's length). Not for helical gears (a plan of theirs takes seconds) nor by
    levels (the workbench's suggested_two_stage)."""
    spec, tool = inputs.spec, inputs.roughing_tool_set
    if inputs.roughing.strategy != "flank" or spec.kind.helical or roughing.flank is None:
        return None
    widest_mm = 2.0 * space_half_width_mm(flank_polyline(spec), spec.reference_radius_mm)
    diameter = float(np.floor(widest_mm / TOP_TOOL_STEP_MM + 1e-9) * TOP_TOOL_STEP_MM)
    if diameter <= tool.diameter_mm + 1e-9:
        return None
    flutes = max(tool.flute_length_mm, 3.0 * diameter) if tool.flute_length_mm > 0.0 else 0.0
    top = dataclasses.replace(tool, diameter_mm=diameter, kind="flat", corner_radius_mm=0.0, flute_length_mm=flutes,
                              tool_number=tool.tool_number + 1)
    staged = dataclasses.replace(inputs, roughing_tool=top, bottom_tool=tool, top_tool=None)
    limit_s = TWO_STAGE_PAYS_FRACTION * _seconds(roughing)
    try:  # the upper program first: when it alone takes too long, the lower one is not planned
        upper = _plan_roughing(staged, lowest_roughing_level(spec, top, inputs.roughing, blank), blank)
        if upper.flank is None or upper.flank.uncut_mm2 > UNCUT_MM2 or _seconds(upper) > limit_s:
            return None
        flank = flank_plan_for(spec, tool, inputs.roughing, blank, roughing.levels, tips=False,
                               first=(upper.flank, top))
        if not flank.passes or flank.uncut_mm2 > UNCUT_MM2:
            return None
        lower = _plan_roughing(staged, roughing.levels, blank, tool, tips=False, flank=flank)
    except SpurCadError:  # the larger tool fits no level, or its plan is refused: nothing to suggest
        return None
    staged_s = _seconds(upper) + _seconds(lower)
    if staged_s > limit_s:
        return None
    return TwoStage(upper.lowest_level_above_root_mm, "reach", staged_s, _seconds(roughing), top)


def _levels_where(levels: RoughingLevels, keep: np.ndarray) -> RoughingLevels:
    return RoughingLevels(levels.heights_mm[keep], levels.half_widths_mm[keep], levels.junction_height_mm)


def _plan_tool_pair(inputs: CamInputs, levels: RoughingLevels, blank: float):
    """Roughing with two tools given: two-stage roughing or the smaller tool alone, whichever is quicker (with the
    machine's accelerations). [tools.bottom] names the smaller tool (`levels` are the larger roughing tool's);
    [tools.roughing_top] the larger (`levels` are the roughing tool's), and where two-stage roughing cannot be
    planned with it the roughing tool roughs alone, with a warning saying why. Returns (roughing, bottom or None,
    the two-stage roughing used or None, the one declined or None, warnings)."""
    notes: tuple[str, ...] = ()
    if inputs.top_tool is None:
        upper, lower, stage, alone = _plan_two_stage(inputs, levels, blank)
    else:
        spec, top = inputs.spec, inputs.top_tool
        staged = dataclasses.replace(inputs, roughing_tool=top, bottom_tool=inputs.roughing_tool, top_tool=None)
        try:
            moves, driver = estimated_roughing_moves(spec, top, inputs.roughing, blank)
            check_moves("roughing with [tools.roughing_top]", moves, "roughing", driver)
            upper, lower, stage, alone = _plan_two_stage(staged, roughing_levels(spec, top, inputs.roughing, blank),
                                                         blank)
        except SpurCadError as exc:
            return (_plan_roughing(inputs, levels, blank), None, None, None,
                    (f"[tools.roughing_top] is not used: two-stage roughing with it cannot be planned ({exc}); "
                     "roughing uses [tools.roughing] alone",))
    if stage.two_stage_time_s < stage.bottom_tool_alone_time_s:
        return upper, lower, stage, None, notes
    return alone, None, None, stage, notes


def _plan_two_stage(inputs: CamInputs, levels: RoughingLevels,
                    blank: float) -> tuple[RoughingPlan, RoughingPlan, TwoStage, RoughingPlan]:
    """Two-stage roughing by the job's strategy: the upper (roughing tool's) and lower (bottom tool's) programs,
    their comparison with the bottom tool alone, and that tool's plan alone.

    By levels: the roughing tool's levels down to a split, the bottom tool's levels below it. The split is one of
    the roughing tool's levels: the one [roughing] bottom_tool_above_root_mm names (the lowest at or above that
    height), or the one with the shortest feed-bound time of both programs. Below the split the bottom tool's own
    levels keep the staircase and depth limits (its next level above is at or above the split). By flanks
    (_plan_flank_two_stage): the roughing tool takes all it reaches, the bottom tool what it leaves."""
    if inputs.roughing.strategy == "flank":
        return _plan_flank_two_stage(inputs, levels, blank)
    spec, bottom = inputs.spec, inputs.bottom_tool_set
    bottom_levels = roughing_levels(spec, bottom, inputs.roughing, blank)
    alone = _plan_roughing(inputs, bottom_levels, blank, bottom)
    _, j, below = _two_stage_split(inputs, levels, blank, bottom_levels, alone)
    upper = _plan_roughing(inputs, _levels_where(levels, np.arange(len(levels.heights_mm)) <= j), blank)
    lower = _plan_roughing(inputs, _levels_where(bottom_levels, below), blank, bottom, tips=False)
    chosen = "set" if inputs.roughing.bottom_tool_above_root_mm > 0.0 else "shortest time"
    return upper, lower, TwoStage(float(levels.heights_mm[j] - spec.root_radius_mm), chosen,
                                  _seconds(upper) + _seconds(lower), _seconds(alone), upper.tool), alone


def _seconds(planned: RoughingPlan) -> float:
    return planned.estimate.time_with_acceleration_s


def _plan_flank_two_stage(inputs: CamInputs, levels: RoughingLevels,
                          blank: float) -> tuple[RoughingPlan, RoughingPlan, TwoStage, RoughingPlan]:
    """Two-stage roughing by flanks: the roughing tool's flank plan (with the tip lands) down to its own lowest
    level, then the bottom tool's from the section the first leaves in every space (its stock model starts there:
    flank_roughing.stock_after_all_spaces), whose completeness check covers the whole space."""
    spec, bottom, params = inputs.spec, inputs.bottom_tool_set, inputs.roughing
    upper = _plan_roughing(inputs, levels, blank)
    bottom_levels = roughing_levels(spec, bottom, params, blank)
    flank = flank_plan_for(spec, bottom, params, blank, bottom_levels, tips=False, first=(upper.flank, upper.tool))
    if not flank.passes:
        raise MachineError("two-stage roughing: the roughing tool "
                           f"(D {inputs.roughing_tool_set.diameter_mm:g} mm) leaves "
                           f"nothing for the bottom tool (D {bottom.diameter_mm:g} mm) to cut; leave out "
                           "[tools.bottom]", field="diameter_mm", section="tools.bottom")
    lower = _plan_roughing(inputs, bottom_levels, blank, bottom, tips=False, flank=flank)
    alone = _plan_roughing(inputs, bottom_levels, blank, bottom)
    return upper, lower, TwoStage(upper.lowest_level_above_root_mm, "reach", _seconds(upper) + _seconds(lower),
                                  _seconds(alone), upper.tool), alone


def by_levels(inputs: CamInputs) -> CamInputs:
    """The inputs with [roughing] strategy = "levels": two-stage roughing splits the space between the tools by
    levels (the flank strategy cuts a whole space with one tool)."""
    return dataclasses.replace(inputs, roughing=dataclasses.replace(inputs.roughing, strategy="levels"))


def _two_stage_split(inputs: CamInputs, levels: RoughingLevels, blank: float, bottom_levels: RoughingLevels,
                     alone: RoughingPlan) -> tuple[float, int, np.ndarray]:
    """(feed-bound seconds of both tools' levels, index of the roughing tool's lowest level, the bottom tool's
    levels below it) of the split `_plan_two_stage` describes; `alone`: the bottom tool's plan of all its levels."""
    spec, bottom = inputs.spec, inputs.bottom_tool_set
    root, set_height = spec.root_radius_mm, inputs.roughing.bottom_tool_above_root_mm
    splits: Sequence[int] = range(len(levels.heights_mm))
    if set_height > 0.0:
        at_or_above = np.flatnonzero(levels.heights_mm >= root + set_height - 1e-9)
        if len(at_or_above) == 0:
            raise MachineError(f"[roughing] bottom_tool_above_root_mm = {set_height:g} is above the roughing tool's "
                               f"highest level ({levels.heights_mm[0] - root:.3f} mm above the root)",
                               field="bottom_tool_above_root_mm", section="roughing")
        splits = [int(at_or_above[-1])]
    # each level's time from the two full toolpaths (a level's moves carry its index in `station`)
    full = _plan_roughing(inputs, levels, blank)
    upper_cost = _level_seconds(full.toolpath, inputs.machine, len(levels.heights_mm))
    lower_cost = _level_seconds(alone.toolpath, inputs.machine, len(bottom_levels.heights_mm))
    best = None
    for j in splits:
        below = bottom_levels.heights_mm < levels.heights_mm[j] - 1e-9
        total = upper_cost[:j + 1].sum() + lower_cost[below].sum()
        if below.any() and (best is None or total < best[0]):
            best = (total, j, below)
    if best is None:
        raise MachineError("two-stage roughing: the roughing tool "
                           f"(D {inputs.roughing_tool_set.diameter_mm:g} mm) reaches "
                           f"as deep as the bottom tool (D {bottom.diameter_mm:g} mm); leave out [tools.bottom]",
                           field="diameter_mm", section="tools.bottom")
    return best


TWO_STAGE_PAYS_FRACTION = 0.9
"""Two-stage roughing is suggested when it takes at most this fraction of the bottom tool's time alone: below a
tenth saved, a second tool change, tool and set-up are not worth it."""
TOP_TOOL_STEP_MM = 1.0  # suggested upper-level roughing tools: whole millimetres (the common catalogue sizes)
TOP_TOOL_CANDIDATES = 6  # at most this many sizes are planned (each plans the roughing of all spaces)


@dataclass(frozen=True)
class TwoStageSuggestion:
    """A larger roughing tool for the upper levels above `inputs.roughing_tool` (then the bottom tool)."""

    top_diameter_mm: float
    two_stage_time_s: float
    bottom_tool_alone_time_s: float


def suggested_two_stage(inputs: CamInputs) -> TwoStageSuggestion | None:
    """Two-stage roughing when it pays: with the job's roughing tool as the bottom tool, the larger flat end mill
    (whole millimetres, up to the space width at the reference circle) whose upper levels make the shortest
    roughing; None when none saves at least 1 - TWO_STAGE_PAYS_FRACTION of the bottom tool's time alone (by the job's
    strategy; the two stages run by levels)."""
    spec, bottom = inputs.spec, inputs.roughing_tool
    if bottom is None or spec.kind.helical:  # not suggested for helical gears (each of their roughing plans takes
        return None                        # seconds); a job file may still name a [tools.bottom] for one
    blank = inputs.stock.blank_radius_mm(spec)
    job_strategy = _plan_roughing(inputs, roughing_levels(spec, bottom, inputs.roughing, blank), blank, bottom)
    inputs = by_levels(inputs)
    bottom_levels = roughing_levels(spec, bottom, inputs.roughing, blank)
    alone = _plan_roughing(dataclasses.replace(inputs, bottom_tool=bottom), bottom_levels, blank, bottom)
    widest_mm = 2.0 * space_half_width_mm(flank_polyline(spec), spec.reference_radius_mm)
    first_mm = (np.floor(bottom.diameter_mm / TOP_TOOL_STEP_MM) + 1.0) * TOP_TOOL_STEP_MM
    sizes = np.arange(first_mm, widest_mm + 1e-9, TOP_TOOL_STEP_MM)
    if len(sizes) > TOP_TOOL_CANDIDATES:  # the largest sizes: a small step above the bottom tool gains little
        sizes = sizes[-TOP_TOOL_CANDIDATES:]
    best = None
    for diameter in sizes:
        top = dataclasses.replace(bottom, diameter_mm=float(diameter), kind="flat", corner_radius_mm=0.0)
        trial = dataclasses.replace(inputs, roughing_tool=top, bottom_tool=bottom, finishing_tool=None)
        try:  # the split's feed-bound time: the two programs less their linking moves
            seconds, _, _ = _two_stage_split(trial, roughing_levels(spec, top, inputs.roughing, blank), blank,
                                             bottom_levels, alone)
        except SpurCadError:  # the larger tool reaches no higher than the bottom tool, or no level fits
            continue
        if best is None or seconds < best.two_stage_time_s:
            best = TwoStageSuggestion(float(diameter), seconds, job_strategy.estimate.time_s)
    if best is None or best.two_stage_time_s > TWO_STAGE_PAYS_FRACTION * best.bottom_tool_alone_time_s:
        return None
    return best


def _level_seconds(path: Toolpath, machine: Machine, levels: int) -> np.ndarray:
    """Feed-bound seconds of each roughing level's moves over all spaces."""
    seconds = move_seconds(path, machine)
    on_level = path.station >= 0
    return np.bincount(path.station[on_level], weights=seconds[on_level], minlength=levels)


def _plan_roughing(inputs: CamInputs, levels: RoughingLevels, blank: float, tool: Tool | None = None,
                   tips: bool = True, flank: FlankPlan | None = None) -> RoughingPlan:
    """One roughing program: the spaces' levels, and the tip lands' passes when `tips`; `flank`: the flank
    strategy's plan when the caller has made it."""
    spec, stock = inputs.spec, inputs.stock
    tool = tool or inputs.roughing_tool_set
    lowest_above_root = levels.lowest_height_mm - spec.root_radius_mm
    if flank is None and inputs.roughing.strategy == "flank":
        flank = flank_plan_for(spec, tool, inputs.roughing, blank, levels, tips)
    path = roughing_toolpath(spec, tool, inputs.machine, inputs.roughing, blank, stock.back_margin_mm,
                             stock.stub_diameter_mm / 2.0, stock.front_margin_mm, levels=levels, tips=tips,
                             flank_plan=flank, stub_length_mm=stock.stub_length_mm)
    check_travel(inputs.machine, path.x, path.y, path.z, path.a, "roughing")
    heights = tip_heights_mm(spec, tool, inputs.roughing, blank) if tips else np.zeros(0)
    return RoughingPlan(tool, levels, lowest_above_root, path, estimate(path, inputs.machine), heights, flank)


def check_finishing_work(spec: GearSpec, tool: Tool, machine: Machine, section: FinishingSection,
                         strategies: Strategies = REGISTRY, **overrides) -> None:
    """The strategy's tool check, then refuse finishing whose contacts per flank or moves exceed the limits,
    before generating it (what generate_finishing trusts)."""
    strategy = get_strategy(section.strategy, strategies)
    params = params_from_section(strategy, section, **overrides)
    strategy.check_tool(spec, tool)
    if strategy.simultaneous_rotary and not machine.rotary_simultaneous:
        raise MachineError(f"finishing strategy '{strategy.name}' turns A while cutting, but [machine] "
                           "rotary_simultaneous = false (the table only indexes); choose a strategy that keeps A "
                           "fixed while cutting", field="strategy", section="finishing")
    try:  # a flat end mill has no corner contacts (only generating takes one: its passes are bounded below)
        counts = (contact_counts(spec, tool, params.target_scallop_mm, overrides.get("contact_spacing_mm"))
                  if tool.effective_corner_radius_mm > 0.0 else ContactCounts(0, 0, 0))
    except WorkLimitError:
        counts = ContactCounts(MAX_CONTACTS_PER_FLANK + 1, 0, 0)
    if counts.flank > MAX_CONTACTS_PER_FLANK:
        raise WorkLimitError(f"finishing would need more than {MAX_CONTACTS_PER_FLANK:,} contact points per flank "
                             f"for target_scallop_mm = {params.target_scallop_mm:.3g}; raise [finishing] "
                             "target_scallop_mm", field="target_scallop_mm", section="finishing")
    driver = "step_over_mm" if getattr(params, "step_over_mm", 0.0) > 0.0 else "target_scallop_mm"  # stations
    check_moves("finishing", strategy.estimate_moves(spec, tool, params), "finishing", driver)


def _plan_finishing(inputs: CamInputs, blank: float, check: Callable[[], None]) -> FinishingPlan:
    spec, tool, machine = inputs.finishing_spec, inputs.finishing_tool_set, inputs.machine
    path, result = generate_finishing(spec, tool, machine, inputs.finishing, blank, inputs.strategies,
                                      inputs.modifications, inputs.profile_tolerance_mm)  # checked: check_cam_inputs
    check_travel(machine, path.x, path.y, path.z, path.a, "finishing")
    own = estimate(path, machine)
    check()
    target = inputs.finishing.target_scallop_mm
    reference = _comparison_estimate(spec, tool, machine, blank,
                                     FinishingParams(strategy=COMPARISON_STRATEGY, target_scallop_mm=target,
                                                     step_over_mm=REFERENCE_STATION_STEP_MM),
                                     contact_spacing_mm=REFERENCE_CONTACT_SPACING_MM)
    check()
    perimeter = own if inputs.finishing.strategy == COMPARISON_STRATEGY else _comparison_estimate(
        spec, tool, machine, blank, FinishingParams(strategy=COMPARISON_STRATEGY, target_scallop_mm=target))
    return FinishingPlan(tool, result, path, own, reference, perimeter)


def _comparison_estimate(spec: GearSpec, tool: Tool, machine: Machine, blank: float, section: FinishingParams,
                         **overrides) -> Estimate | None:
    """The estimate of another finishing with the same tool, for comparison; None when it would exceed
    MAX_COMPARISON_MOVES (or cannot be planned with this tool). A table that only indexes is taken as
    simultaneous here: the figure says what that strategy would take."""
    strategy = get_strategy(section.strategy)
    if not spec.kind.accepts_strategy(strategy):  # perimeter is for spur gears only
        return None
    simultaneous = dataclasses.replace(machine, rotary_simultaneous=True)
    params = params_from_section(strategy, section, **overrides)
    try:
        check_finishing_work(spec, tool, simultaneous, section, **overrides)  # the tool check with the others
        if strategy.estimate_moves(spec, tool, params) > MAX_COMPARISON_MOVES:
            return None
        return strategy.estimate(spec, tool, simultaneous, params, blank)  # without building its toolpath
    except (WorkLimitError, MachineError, ToolError):
        return None


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
    if spec.kind.teeth_inward:  # the rotary-table strategies' recommendations do not apply to a ring
        from spur_cad.cam.three_axis_ring import ring_tool_recommendations

        return ring_tool_recommendations(spec, inputs.machine.clearance_mm), root
    from spur_cad.cam.three_axis import flat_tool_recommendations

    rotary = recommend_tools(spec, inputs.stock.blank_radius_mm(spec), inputs.machine.clearance_mm)
    return flat_tool_recommendations(spec, inputs.machine.clearance_mm, rotary.roughing_max_diameter_mm), root


def _plan_three_axis(inputs: CamInputs, tolerance_mm: float) -> CamPlan:
    """The CAM plan of a 3-axis job ([machine] axes = 3): the checks of three_axis.check_three_axis, roughing and
    finishing as spur_cad.cam.three_axis says; no tool recommendations for the rotary-table strategies
    (empty; the cut is simulated by spur_cad.sim.flat, its error budget is the 3-axis machine's:
    pipeline.error_budget)."""
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
    rec, root = check_three_axis_inputs(inputs)
    if spec.kind.teeth_inward:
        return _plan_three_axis_ring(inputs, tolerance_mm, root)
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


def _plan_three_axis_ring(inputs: CamInputs, tolerance_mm: float, root) -> CamPlan:
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
        ring_tool_recommendations,
    )
    from spur_cad.cam.three_axis_root import root_thickness

    spec, machine = inputs.spec, inputs.machine
    if inputs.three_axis.tabs or inputs.three_axis.onion_skin_mm:
        raise MachineError("[three_axis] tabs and onion_skin_mm hold a through-cut external gear; a ring is clamped "
                           "on its rim and its hole is milled away whole: leave them out",
                           field="tabs" if inputs.three_axis.tabs else "onion_skin_mm", section="three_axis")
    rec = ring_tool_recommendations(spec, machine.clearance_mm)
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
