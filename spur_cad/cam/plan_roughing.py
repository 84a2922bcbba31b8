"""Roughing programs of the CAM plan: one roughing program (plan_roughing), two-stage roughing with two tools
(plan_tool_pair: the split between the roughing and the bottom tool, or the bottom tool alone when quicker), and the
suggestions the plan makes beside the job's roughing (a larger top tool, roughing by flanks or by levels instead,
the workbench's two-stage sizes). Split from cam/plan.py, which calls these and re-exports the public names."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from spur_cad.cam.common import check_moves
from spur_cad.cam.estimate import estimate, move_seconds
from spur_cad.cam.flank_roughing import UNCUT_MM2, FlankPlan
from spur_cad.cam.ir import Toolpath
from spur_cad.cam.machine import Machine, MachineError, check_travel
from spur_cad.cam.plan_types import (
    CamInputs,
    FlankSuggestion,
    LevelsSuggestion,
    RoughingPlan,
    TwoStage,
)
from spur_cad.cam.recommend import flank_polyline, space_half_width_mm
from spur_cad.cam.roughing import (
    RoughingLevels,
    estimated_roughing_moves,
    flank_plan_for,
    lowest_roughing_level,
    roughing_levels,
    roughing_toolpath,
    tip_heights_mm,
)
from spur_cad.cam.tools import Tool
from spur_cad.errors import SpurCadError
from spur_cad.geometry.kinds import EXTERNAL_SPUR, INTERNAL_SPUR

SUGGESTED_FOR = frozenset({EXTERNAL_SPUR, INTERNAL_SPUR})
"""Gear kinds another roughing (by flanks, by levels, two-stage) is planned for to be suggested: not helical gears,
each of whose roughing plans takes seconds."""


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
        levels = plan_roughing(levels_inputs, roughing.levels, blank)
    except SpurCadError:  # levels cannot rough this space with this tool (a work bound, the travel): no suggestion
        return None
    if _seconds(levels) > TWO_STAGE_PAYS_FRACTION * _seconds(roughing):
        return None
    return LevelsSuggestion(_seconds(levels), _seconds(roughing), len(levels.levels.heights_mm))


def suggested_flank_roughing(inputs: CamInputs, roughing: RoughingPlan, blank: float) -> FlankSuggestion | None:
    """Roughing by levels with one tool (a job file's default strategy): roughing by flanks with the same tool,
    cutting data and allowances, when it takes at most TWO_STAGE_PAYS_FRACTION of `roughing`'s time and leaves
    nothing uncut; else None. Not for helical gears (a flank plan of theirs takes seconds)."""
    if inputs.roughing.strategy != "levels" or inputs.spec.kind not in SUGGESTED_FOR:
        return None
    flank_inputs = dataclasses.replace(inputs, roughing=dataclasses.replace(inputs.roughing, strategy="flank"))
    try:  # bounded as the job's own roughing would be
        moves, driver = estimated_roughing_moves(inputs.spec, roughing.tool, flank_inputs.roughing, blank)
        check_moves("roughing by flanks", moves, "roughing", driver)
        flank = plan_roughing(flank_inputs, roughing.levels, blank)
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
    if inputs.roughing.strategy != "flank" or spec.kind not in SUGGESTED_FOR or roughing.flank is None:
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
        upper = plan_roughing(staged, lowest_roughing_level(spec, top, inputs.roughing, blank), blank)
        if upper.flank is None or upper.flank.uncut_mm2 > UNCUT_MM2 or _seconds(upper) > limit_s:
            return None
        flank = flank_plan_for(spec, tool, inputs.roughing, blank, roughing.levels, tips=False,
                               first=(upper.flank, top))
        if not flank.passes or flank.uncut_mm2 > UNCUT_MM2:
            return None
        lower = plan_roughing(staged, roughing.levels, blank, tool, tips=False, flank=flank)
    except SpurCadError:  # the larger tool fits no level, or its plan is refused: nothing to suggest
        return None
    staged_s = _seconds(upper) + _seconds(lower)
    if staged_s > limit_s:
        return None
    return TwoStage(upper.lowest_level_above_root_mm, "reach", staged_s, _seconds(roughing), top)


def _levels_where(levels: RoughingLevels, keep: np.ndarray) -> RoughingLevels:
    return RoughingLevels(levels.heights_mm[keep], levels.half_widths_mm[keep], levels.junction_height_mm)


def plan_tool_pair(inputs: CamInputs, levels: RoughingLevels, blank: float):
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
            return (plan_roughing(inputs, levels, blank), None, None, None,
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
    alone = plan_roughing(inputs, bottom_levels, blank, bottom)
    _, j, below = _two_stage_split(inputs, levels, blank, bottom_levels, alone)
    upper = plan_roughing(inputs, _levels_where(levels, np.arange(len(levels.heights_mm)) <= j), blank)
    lower = plan_roughing(inputs, _levels_where(bottom_levels, below), blank, bottom, tips=False)
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
    upper = plan_roughing(inputs, levels, blank)
    bottom_levels = roughing_levels(spec, bottom, params, blank)
    flank = flank_plan_for(spec, bottom, params, blank, bottom_levels, tips=False, first=(upper.flank, upper.tool))
    if not flank.passes:
        raise MachineError("two-stage roughing: the roughing tool "
                           f"(D {inputs.roughing_tool_set.diameter_mm:g} mm) leaves "
                           f"nothing for the bottom tool (D {bottom.diameter_mm:g} mm) to cut; leave out "
                           "[tools.bottom]", field="diameter_mm", section="tools.bottom")
    lower = plan_roughing(inputs, bottom_levels, blank, bottom, tips=False, flank=flank)
    alone = plan_roughing(inputs, bottom_levels, blank, bottom)
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
    full = plan_roughing(inputs, levels, blank)
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
    if bottom is None or spec.kind not in SUGGESTED_FOR:  # a job file may still name a [tools.bottom] for one
        return None
    blank = inputs.stock.blank_radius_mm(spec)
    job_strategy = plan_roughing(inputs, roughing_levels(spec, bottom, inputs.roughing, blank), blank, bottom)
    inputs = by_levels(inputs)
    bottom_levels = roughing_levels(spec, bottom, inputs.roughing, blank)
    alone = plan_roughing(dataclasses.replace(inputs, bottom_tool=bottom), bottom_levels, blank, bottom)
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


def plan_roughing(inputs: CamInputs, levels: RoughingLevels, blank: float, tool: Tool | None = None,
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
