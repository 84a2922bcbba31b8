"""The CAM plan of a job, typed: tool recommendations, roughing (levels, toolpath, estimate),
finishing (strategy result, toolpath, estimate, and for comparison the estimates of the
perimeter strategy and of the reference process's strategy) and warnings. Computed once per
job; summary, posts, simulation, report and the workbench read it (docs/architecture.md).

Here: the checks that need no toolpath, the orchestration (plan_cam) and finishing. The plan's types are in
cam/plan_types.py, the roughing programs, two-stage roughing and the suggestions in cam/plan_roughing.py, the 3-axis
(lying-flat) plan in cam/plan_flat.py; the names callers know from here are re-exported."""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Callable

from spur_cad.cad.specs import StockSpec
from spur_cad.cam.common import check_moves
from spur_cad.cam.contacts import ContactCounts, contact_counts
from spur_cad.cam.estimate import Estimate, estimate
from spur_cad.cam.finishing import generate_finishing
from spur_cad.cam.flank_roughing import UNCUT_MM2
from spur_cad.cam.machine import Machine, MachineError, RoughingParams, check_travel
from spur_cad.cam.machine_limits import check_machine_limits
from spur_cad.cam.plan_flat import (  # noqa: F401  (check_three_axis_inputs re-exported)
    check_three_axis_inputs,
    plan_three_axis,
)
from spur_cad.cam.plan_roughing import (  # noqa: F401  (re-exported: the names callers know from here)
    TOP_TOOL_CANDIDATES,
    TOP_TOOL_STEP_MM,
    TWO_STAGE_PAYS_FRACTION,
    TwoStageSuggestion,
    by_levels,
    plan_roughing,
    plan_tool_pair,
    suggested_flank_roughing,
    suggested_levels_roughing,
    suggested_top_tool,
    suggested_two_stage,
)
from spur_cad.cam.plan_types import (  # noqa: F401  (re-exported: the names callers know from here)
    CamInputs,
    CamPlan,
    FinishingPlan,
    FlankSuggestion,
    LevelsSuggestion,
    RoughingPlan,
    TwoStage,
)
from spur_cad.cam.recommend import (
    LAND_PASS_DEPTH_FRACTION,
    ToolRecommendations,
    check_roughing_reach,
    check_tools,
    recommend_tools,
    small_tool_warnings,
)
from spur_cad.cam.roughing import (
    RoughingLevels,
    check_helical_roughing_machine,
    estimated_roughing_moves,
    roughing_levels,
)
from spur_cad.cam.setups import LYING_FLAT, ROTARY_TABLE, MachineSetup
from spur_cad.cam.strategies import (
    COMPARISON_STRATEGY,
    REGISTRY,
    FinishingParams,
    FinishingSection,
    Strategies,
    get_strategy,
    params_from_section,
)
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.errors import SpurCadError, StockError, WorkLimitError, shown
from spur_cad.geometry.mate import GearPair
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


def check_cam_inputs(inputs: CamInputs) -> tuple[ToolRecommendations, RoughingLevels | None]:
    """Every check that needs no toolpath (cheap enough for a GUI to run while the user types): tool
    recommendations, tool limits, the finishing strategy's fit to the machine and its work bound, the
    roughing work bound and the roughing reach. Returns the
    recommendations and the roughing levels (None without a roughing tool)."""
    spec, machine, stock = inputs.spec, inputs.machine, inputs.stock
    strategy = get_strategy(inputs.finishing.strategy, inputs.strategies)
    if inputs.finishing_tool is not None and not spec.kind.accepts_strategy(strategy):
        helical = " or ".join(f'"{name}"' for name, other in inputs.strategies.items()
                            if spec.kind.accepts_strategy(other))
        raise MachineError(f"[finishing] strategy = {shown(inputs.finishing.strategy)} is for spur gears; a "
                           f"helical gear (helix_angle_deg = {spec.helix_angle_deg:g}) is finished by "
                           f"strategy = {helical}",
                           field="strategy", section="finishing")
    if not machine.setup.accepts_strategy(strategy):  # a strategy declared `lying_flat` (the 3-axis plan has its own)
        fitting = " or ".join(f'"{name}"' for name, other in inputs.strategies.items()
                              if machine.setup.accepts_strategy(other))
        raise MachineError(f"[finishing] strategy = {shown(inputs.finishing.strategy)} cuts the gear lying flat; on "
                           f"the {machine.setup.name} ([machine] axes = {machine.setup.axes}) finish by strategy = "
                           f"{fitting}", field="strategy", section="finishing")
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
        # the strategy's rule for the tool, once: one-stage roughing ran it in tool_conflicts, two-stage's checks do not
        if inputs.bottom_tool is not None:
            strategy.check_tool(inputs.finishing_spec, inputs.finishing_tool)
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
    refused too), and CamPlan.flank_fallback says why. Each set-up plans its own way (SETUP_PLANS)."""
    return SETUP_PLANS[inputs.machine.setup](inputs, checkpoint)


def _plan_lying_flat(inputs: CamInputs, checkpoint: Callable[[], None] | None = None) -> CamPlan:
    """The blank lying flat (spur_cad.cam.three_axis)."""
    return plan_three_axis(inputs, inputs.profile_tolerance_mm)


def _plan_on_table(inputs: CamInputs, checkpoint: Callable[[], None] | None = None) -> CamPlan:
    """The part on the rotary table, roughing by flanks falling back to levels (plan_cam)."""
    if not (inputs.levels_fallback and inputs.roughing.strategy == "flank" and inputs.roughing_tool is not None):
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
    """The rotary table's plan by the strategy `inputs` name."""
    check = checkpoint if checkpoint is not None else (lambda: None)
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
        roughing, bottom, two_stage, declined, notes = plan_tool_pair(inputs, levels, blank)
        warnings.extend(notes + roughing.toolpath.warnings + (bottom.toolpath.warnings if bottom else ()))
    elif levels is not None:
        check()
        roughing = plan_roughing(inputs, levels, blank)
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


SETUP_PLANS: dict[MachineSetup, Callable[[CamInputs, Callable[[], None] | None], CamPlan]] = {
    ROTARY_TABLE: _plan_on_table, LYING_FLAT: _plan_lying_flat}
"""Each set-up's plan (plan_cam)."""
SETUP_CHECKS: dict[MachineSetup, Callable[[CamInputs], tuple[ToolRecommendations, object]]] = {
    ROTARY_TABLE: check_cam_inputs, LYING_FLAT: check_three_axis_inputs}
"""Each set-up's checks that need no toolpath (a front end runs them while the user types): (the tool
recommendations, the set-up's own analysis)."""


def check_finishing_work(spec: GearSpec, tool: Tool, machine: Machine, section: FinishingSection,
                         strategies: Strategies = REGISTRY, **overrides) -> None:
    """Refuse finishing whose contacts per flank or moves exceed the limits, before generating it (what
    generate_finishing trusts), for a tool that passed the strategy's `check_tool` (its callers run it, once)."""
    strategy = get_strategy(section.strategy, strategies)
    params = params_from_section(strategy, section, **overrides)
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
        strategy.check_tool(spec, tool)  # the comparison strategy's own rule for the tool
        check_finishing_work(spec, tool, simultaneous, section, **overrides)
        if strategy.estimate_moves(spec, tool, params) > MAX_COMPARISON_MOVES:
            return None
        return strategy.estimate(spec, tool, simultaneous, params, blank)  # without building its toolpath
    except (WorkLimitError, MachineError, ToolError):
        return None
