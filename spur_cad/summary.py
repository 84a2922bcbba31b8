"""summary.json: the typed `JobResult`'s parts built from the job's stages (`build_result`), and their one
serialisation (`summary_json`). Its keys are a public interface (users' scripts read them): add keys, never
rename or remove one. A golden test (tests/test_summary_golden.py) keeps them for the examples.
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING, Any, overload

import numpy as np

from spur_cad.cam.estimate import Estimate
from spur_cad.cam.machine import Machine, RoughingParams
from spur_cad.cam.plan import CamPlan, FinishingPlan, RoughingPlan, TwoStage
from spur_cad.cam.recommend import ToolRecommendations
from spur_cad.cam.tools import Tool
from spur_cad.dialects import dialect
from spur_cad.geometry.inspection import inspection_sheet, modification_inspection
from spur_cad.geometry.mate import GearPair, PairFacts, pair_facts
from spur_cad.geometry.sampling import ProfileSamples
from spur_cad.keys import Scalar, SectionValues
from spur_cad.post.program import PostedProgram
from spur_cad.post.settings import PostSettings
from spur_cad.result import (
    CadResult,
    DeclinedTwoStageFacts,
    ErrorBudgetFacts,
    FeatureDeviation,
    FinishingFacts,
    FlankSuggestionFacts,
    JobFacts,
    JobResult,
    LatheFacts,
    LevelsSuggestionFacts,
    PostFacts,
    ProfileFacts,
    ProgramFacts,
    RoughingFacts,
    SegmentCounts,
    SetupFacts,
    SimulationFacts,
    SuggestedTopToolFacts,
    ToolFacts,
    ToolsFacts,
    TwoStageFacts,
)
from spur_cad.version import __version__

if TYPE_CHECKING:  # the simulator loads only when a job uses it
    from _typeshed import DataclassInstance  # any dataclass instance (typeshed only: no module at run time)

    from spur_cad.grade.grading import Grading
    from spur_cad.sim.simulate import SimResult

SEGMENT_NAMES = ("root", "fillet", "involute", "tip")
FEATURES = ("right involute", "right fillet", "root", "left fillet", "left involute", "tip")

__all__ = ["CadResult", "build_result", "simulation_facts", "summary_json"]


# --- the typed parts, from the stages -----------------------------------------------------------------------


def build_result(job, samples: ProfileSamples, cad: CadResult | None, plan: CamPlan, post: PostSettings,
                 programs: dict[str, PostedProgram], simulation: SimResult | None, grading: Grading | None,
                 seconds: dict[str, float], error_budget: ErrorBudgetFacts | None = None) -> JobResult:
    """The run's typed result (`job` is a spur_cad.job.Job); `files` are added by the pipeline. `cad` None: the
    CAD stage still building in its worker (the pipeline draws the report's figures meanwhile and adds it before
    anything reads it)."""
    labels = np.array(samples.label_names())
    counts = SegmentCounts(*(int(np.count_nonzero(labels == name)) for name in SEGMENT_NAMES))
    inspection = inspection_sheet(job.gear)
    modifications = (None if job.modifications is None
                     else modification_inspection(job.gear, job.modifications, inspection))
    return JobResult(
        version=__version__, job=JobFacts(job.job.name, job.source), gear=job.gear.facts(), kind=job.gear.kind,
        inspection=inspection, modifications=modifications,
        profile=ProfileFacts(job.job.profile_tolerance_mm, len(samples), counts), cad=cad,
        tools=tools_facts(plan, job.machine, plan.roughing.tool if plan.roughing is not None else job.tools.roughing,
                          job.tools.finishing),
        roughing=roughing_facts(plan, job.machine, simulation), finishing=finishing_facts(plan.finishing),
        warnings=tuple(plan.warnings) + engagement_warnings(simulation, job.roughing, plan),
        post=PostFacts(post.dialect, post.folded, tuple(ProgramFacts(name, p.lines, p.bytes, p.subprograms)
                                                        for name, p in programs.items()),
                       dialect(post.dialect, job.dialects).extension),
        simulation=simulation_facts(simulation, job.simulation.resolution_mm), grading=grading,
        lathe=lathe_facts(job), timings_s=seconds, setup=setup_facts(job, plan, post), error_budget=error_budget,
        pair=job.pair, mate=pair_facts(job.pair) if job.pair is not None else None,
        job_file=job.section_values())


def error_budget_facts(job, terms, deflection, ideal: Grading, expected: Grading) -> ErrorBudgetFacts:
    """The budget's part of the result (`job` is a spur_cad.job.Job): its [machine] and [job] inputs, the terms
    as applied, the expected grade and each deviation's share from the budget."""
    inputs = job.machine.setup.budget_inputs(job.machine, job.job.material)  # the keys its budget reads
    share = {name: round(value - ideal.deviations_um.get(name, 0.0), 3)
             for name, value in expected.deviations_um.items()}
    percent = {name: (round(100.0 * share[name] / value, 1) if value else None)
               for name, value in expected.deviations_um.items()}
    cos_alpha = job.gear.base_radius_mm / job.gear.reference_radius_mm  # a normal shift is shift / cos on the arc
    thickness = round(2.0 * terms.flank_shift_um["total"] / cos_alpha, 3)
    return ErrorBudgetFacts(inputs, terms, deflection, expected, share, percent, thickness)


def lathe_facts(job) -> LatheFacts | None:
    """The lathe program's control, bar and part (with [lathe])."""
    if job.lathe is None:
        return None
    from spur_cad.cam.turning import lathe_geometry

    g = lathe_geometry(job.gear, job.stock, job.lathe)
    return LatheFacts(job.lathe.dialect, g.bar_diameter, g.blank_diameter, g.blank_length, g.stub_diameter,
                      g.stub_length, job.lathe.part_off, job.lathe.work_offset)


@overload
def tool_facts(tool: Tool, machine: Machine) -> ToolFacts: ...
@overload
def tool_facts(tool: None, machine: Machine) -> None: ...
@overload
def tool_facts(tool: Tool | None, machine: Machine) -> ToolFacts | None: ...
def tool_facts(tool: Tool | None, machine: Machine) -> ToolFacts | None:
    if tool is None:
        return None
    return ToolFacts(tool.kind, tool.diameter_mm, tool.effective_corner_radius_mm, tool.flat_width_mm,
                     tool.spindle_rpm(machine), tool.feed_mm_min(machine), tool.tool_number, tool.flutes,
                     tool.flute_length_mm, tool.stick_out_mm)


def setup_facts(job, plan: CamPlan, post: PostSettings) -> SetupFacts:
    """The set-up sheet's facts of a job (`job` is a spur_cad.job.Job) and its plan."""
    spec, stock, rough = job.gear, job.stock, job.roughing
    paths = [p.toolpath for p in (plan.roughing, plan.roughing_bottom, plan.finishing) if p is not None]
    z = np.concatenate([path.z[path.motion_mask] for path in paths]) if paths else np.zeros(0)
    x_min, x_max = stock.blank_x_range_mm(spec)
    tool = job.tools.roughing
    flank = plan.roughing.flank if plan.roughing is not None else None
    steps: tuple[float | None, float | None] = (
        (flank.limits.axial_depth_mm, flank.limits.radial_engagement_mm) if flank is not None else
        (rough.max_level_depth_fraction * tool.diameter_mm, rough.step_over_fraction * tool.diameter_mm)
        if tool is not None else (None, None))
    return SetupFacts(
        job.machine.name, 2.0 * stock.blank_radius_mm(spec), x_min, x_max, stock.stub_diameter_mm,
        stock.stub_length_mm, post.work_offset, post.rotary_sign, post.coolant, job.machine.clearance_mm,
        float(z.min()) if z.size else None, float(z.max()) if z.size else None, rough.finish_stock_mm,
        rough.flank_allowance_mm, steps[0], steps[1], machine_setup=job.machine.setup)


def tools_facts(plan: CamPlan, machine: Machine, roughing_tool: Tool | None,
                finishing_tool: Tool | None) -> ToolsFacts:
    result = plan.finishing.result if plan.finishing is not None else None
    advice = result.tool_advice if result is not None else None
    return ToolsFacts(plan.recommendations, tool_facts(roughing_tool, machine), tool_facts(finishing_tool, machine),
                      result.strategy if result is not None and advice is not None else None, advice)


def _roughing(roughing: RoughingPlan) -> RoughingFacts:
    flank = roughing.flank
    return RoughingFacts(len(roughing.levels.heights_mm), roughing.lowest_level_above_root_mm,
                         tuple(float(h) for h in roughing.levels.heights_mm), roughing.estimate,
                         tip_heights_mm=tuple(float(h) for h in roughing.tip_heights_mm),
                         passes_per_space=len(flank.passes) if flank is not None else None,
                         flank_turns_deg=tuple(float(s.turn_deg) for s in flank.segments) if flank is not None else ())


def engagement_limits(params: RoughingParams, plan: CamPlan):
    """The limits the job's roughing keeps (sim.engagement.EngagementLimits): the flank strategy's where the plan
    roughs by flanks (each tool's axial depth limit in two-stage roughing), or the levels' (also where a job file's
    default flank roughing fell back to levels)."""
    from spur_cad.cam.flank_roughing import FlankLimits
    from spur_cad.sim.engagement import EngagementLimits

    if plan.roughing is not None and plan.roughing.flank is not None:
        by_operation = {name: FlankLimits.of(planned.tool, params).axial_depth_mm for name, planned in
                        (("roughing", plan.roughing), ("roughing_bottom", plan.roughing_bottom)) if planned is not None}
        return EngagementLimits(params.max_level_depth_fraction, params.max_radial_engagement_fraction,
                                max(by_operation.values()), by_operation)
    return EngagementLimits(params.max_level_depth_fraction, params.step_over_fraction)


def engagement_warnings(simulation: SimResult | None, params: RoughingParams, plan: CamPlan) -> tuple[str, ...]:
    """Roughing moves the simulated stock shows beyond the job's depth or engagement limits."""
    if simulation is None or simulation.engagement is None:
        return ()
    from spur_cad.sim.engagement import engagement_warnings as warnings

    return tuple(warnings(simulation.engagement, engagement_limits(params, plan)))


def roughing_facts(plan: CamPlan, machine: Machine, simulation: SimResult | None = None) -> RoughingFacts | None:
    """The roughing operation, with two-stage roughing's bottom operation and the engagement measured on the
    simulated stock."""
    if plan.roughing is None:
        return None
    facts = _roughing(plan.roughing)
    engagement = simulation.engagement if simulation is not None else None
    if engagement is not None:
        facts = dataclasses.replace(facts, max_radial_engagement_fraction=engagement.max_radial_fraction,
                                    max_axial_depth_mm=engagement.max_axial_depth_mm,
                                    mean_removal_rate_mm3_min=engagement.mean_removal_rate_mm3_min)
    declined = plan.two_stage_declined
    if declined is not None:
        facts = dataclasses.replace(facts, two_stage_declined=DeclinedTwoStageFacts(
            tool_facts(_larger_tool(declined), machine), declined.two_stage_time_s, declined.bottom_tool_alone_time_s))
    suggested = plan.two_stage_suggested
    if suggested is not None:
        facts = dataclasses.replace(facts, two_stage_suggested=SuggestedTopToolFacts(
            _larger_tool(suggested).diameter_mm, suggested.two_stage_time_s, suggested.bottom_tool_alone_time_s))
    by_flanks = plan.flank_suggested
    if by_flanks is not None:
        facts = dataclasses.replace(facts, flank_suggested=FlankSuggestionFacts(
            by_flanks.flank_time_s, by_flanks.levels_time_s, by_flanks.passes_per_space))
    if plan.flank_fallback is not None:
        facts = dataclasses.replace(facts, flank_fallback=plan.flank_fallback)
    by_levels = plan.levels_suggested
    if by_levels is not None:
        facts = dataclasses.replace(facts, levels_suggested=LevelsSuggestionFacts(
            by_levels.levels_time_s, by_levels.flank_time_s, by_levels.levels_per_space))
    stage, bottom = plan.two_stage, plan.roughing_bottom
    if stage is None or bottom is None:  # two-stage roughing has both, one-tool roughing neither
        return facts
    two_stage = TwoStageFacts(tool_facts(bottom.tool, machine),
                              stage.split_height_above_root_mm, stage.chosen, _roughing(bottom),
                              stage.two_stage_time_s, stage.bottom_tool_alone_time_s, stage.gain_s)
    return dataclasses.replace(facts, two_stage=two_stage)


def _larger_tool(stage: TwoStage) -> Tool:
    """The larger (upper) tool of a declined or suggested two-stage roughing, which always names it."""
    if stage.roughing_tool is None:
        raise ValueError("a declined or suggested two-stage roughing names its larger tool")
    return stage.roughing_tool


def finishing_facts(finishing: FinishingPlan | None) -> FinishingFacts | None:
    if finishing is None:
        return None
    result = finishing.result
    return FinishingFacts(result.strategy, result.strategy_facts, result.report_text(), finishing.estimate,
                          finishing.perimeter_estimate, finishing.reference_estimate)


def simulation_facts(result: SimResult | None, resolution_mm: float) -> SimulationFacts:
    """The simulated cut's facts (only `enabled` and the resolution when nothing was simulated)."""
    if result is None:
        return SimulationFacts(enabled=False, resolution_mm=resolution_mm)
    from spur_cad.sim.statistics import feature_statistics, scallop_statistics

    dev = result.gear_deviation  # a view: a big gear has millions of design points x rows
    scallop = scallop_statistics(dev, result.settings.leftover_range_mm - 1e-9)  # the finished points
    names = np.array(result.grid.feature_names())
    per_feature = []
    for name in FEATURES:
        mask = np.array([n.endswith(name) if name in ("root", "tip") else n == name for n in names])
        if mask.any():
            feature = feature_statistics(dev, mask)
            per_feature.append(FeatureDeviation(name, feature.max_gouge_mm, feature.max_leftover_mm, feature.mean_mm))
    return SimulationFacts(
        enabled=True, resolution_mm=result.settings.resolution_mm, max_gouge_mm=result.max_gouge_mm,
        max_leftover_mm=result.max_leftover_mm, removed_volume_mm3=result.removed_volume_mm3,
        seconds=result.seconds, design_points=int(dev.size), points_per_space=int(result.grid.points.shape[0]),
        rows=int(result.gear_rows.sum()), point_spacing_mm=result.grid.spacing_mm,
        uncut_points=result.uncut_points,
        scallop_mean_mm=scallop.mean_mm, scallop_p95_mm=scallop.p95_mm, scallop_p99_mm=scallop.p99_mm,
        worst_gouge=result.worst(True), worst_leftover=result.worst(False), per_feature=tuple(per_feature),
        moves=result.moves, poses_clipped=result.poses_clipped, x_sweeps=result.x_sweeps,
        gouge_range_mm=result.settings.gouge_range_mm, leftover_range_mm=result.settings.leftover_range_mm)


# --- the one serialisation ------------------------------------------------------------------------------------


def _inspection_json(inspection) -> dict:
    """The inspection sheet's figures; `pins_between` only for an internal gear (an external gear's summary keeps
    the keys it had, so scripts and golden files that read it are unchanged)."""
    facts = dataclasses.asdict(inspection)
    if not facts.get("pins_between"):
        facts.pop("pins_between", None)
    return facts


def summary_json(result: JobResult) -> dict:
    """summary.json's content: every key as users' scripts read it."""
    tools = result.tools
    summary: dict[str, Any] = {
        "spur_cad_version": result.version,
        "job": {"name": result.job.name, "file": result.job.file},
        "job_file": job_file_json(result.job_file),
        "gear": dataclasses.asdict(result.gear),
        **({"mate": mate_json(result.pair, result.mate)} if result.pair is not None and result.mate is not None
           else {}),
        "inspection": _inspection_json(result.inspection),
        **({"modifications": modifications_json(result.modifications)} if result.modifications is not None else {}),
        "profile": {"tolerance_mm": result.profile.tolerance_mm, "points": result.profile.points,
                    "points_per_segment": dataclasses.asdict(result.profile.points_per_segment)},
        "cad": cad_json(result.cad),
        "tools": {**recommendations_json(tools.recommendations), "roughing": tool_json(tools.roughing),
                  "finishing": tool_json(tools.finishing)},
    }
    if tools.advice is not None:
        summary["tools"][f"{tools.advice_strategy}_advice"] = facts_json(tools.advice)
    if result.roughing is not None:
        summary["roughing"] = roughing_json(result.roughing)
    if result.finishing is not None:
        summary["finishing"] = finishing_json(result.finishing)
    summary["warnings"] = list(result.warnings)
    summary["post"] = post_json(result.post)
    summary["simulation"] = simulation_json(result.simulation)
    summary["grading"] = result.grading.to_json() if result.grading is not None else None
    summary["error_budget"] = error_budget_json(result.error_budget)
    if result.lathe is not None:
        summary["lathe"] = dataclasses.asdict(result.lathe)
    summary["timings_s"] = dict(result.timings_s)
    return summary


def job_file_json(sections: tuple[SectionValues, ...]) -> dict[str, dict[str, Scalar]]:
    """summary.json's `job_file`: {section: {key: value}} of every key of every section the job has, as the run
    used it (defaults included; spur_cad.job.Job.section_values). Values are JSON's own: numbers, strings as the
    file gives them, true / false."""
    return {section.section: {k.name: k.value for k in section.keys} for section in sections}


MATE_INTERNALS = ("internal", "start_of_active_profile_roll_mm", "mate_start_of_active_profile_roll_mm")
"""PairFacts fields summary.json's `mate` leaves out (the mate's own `internal` is there; the rolls are the
computation's)."""


def mate_json(pair: GearPair, facts: PairFacts) -> dict:
    """summary.json's `mate` ([mate] jobs only): the mate as it meshes (its shift solved when a centre distance
    set it) and the pair's quantities (spur_cad.geometry.mate.PairFacts, mm and degrees)."""
    mate = pair.mate
    return {"teeth": mate.teeth, "internal": mate.internal, "profile_shift_coefficient": mate.profile_shift_coefficient,
            "addendum_coefficient": mate.addendum_coefficient, "dedendum_coefficient": mate.dedendum_coefficient,
            **{name: value for name, value in dataclasses.asdict(facts).items() if name not in MATE_INTERNALS}}


def modifications_json(facts) -> dict:
    """summary.json's `modifications` (modified gears only): amounts per side in um, the reliefs' start diameters,
    the removal at the span and pin contacts and the span the modified gear reads."""
    return {"amounts_um": {name: {"right": right, "left": left} for name, (right, left) in facts.amounts_um.items()},
            "tip_relief_start_diameters_mm": list(facts.tip_relief_start_diameters_mm),
            "root_relief_start_diameters_mm": list(facts.root_relief_start_diameters_mm),
            "span_removal_um": list(facts.span_removal_um), "pin_removal_um": list(facts.pin_removal_um),
            "measured_unmodified": facts.measured_unmodified, "span_modified_mm": facts.span_modified_mm}


def error_budget_json(budget: ErrorBudgetFacts | None) -> dict | None:
    """The expected grade with the machine's errors (`grading` is the ideal machine's), the budget's share of
    each deviation, and how the budget was applied."""
    if budget is None:
        return None
    return {"inputs": dict(budget.inputs), "grading": budget.grading.to_json(),
            "budget_share_um": dict(budget.share_um), "budget_share_percent": dict(budget.share_percent),
            "tooth_thickness_change_um": budget.tooth_thickness_change_um, **budget.terms.to_json(),
            "deflection": dataclasses.asdict(budget.deflection) if budget.deflection is not None else None}


def facts_json(facts: DataclassInstance) -> dict:
    """A strategy's typed facts or advice as JSON: its fields in order, None fields left out."""
    return {name: value for name, value in dataclasses.asdict(facts).items() if value is not None}


def cad_json(cad: CadResult | None) -> dict:
    if cad is None:  # the pipeline adds the CAD facts before it writes summary.json
        raise ValueError("summary.json needs the CAD stage's facts: the result has none yet")
    report = cad.report
    return {
        "fit_tolerance_mm": report.fit_tolerance_mm,
        "fillet_max_deviation_mm": report.fillet_max_deviation_mm,
        "involute_max_deviation_mm": report.involute_max_deviation_mm,
        "fillet_spline_poles": report.fillet_poles,
        "involute_spline_poles": report.involute_poles,
        "gear_volume_mm3": cad.gear_volume_mm3,
        "stock_volume_mm3": cad.stock_volume_mm3,
        "step_bytes": dict(cad.step_bytes),
    }


def recommendations_json(rec: ToolRecommendations) -> dict:
    return rec.as_dict()


def tool_json(tool: ToolFacts | None, with_number: bool = False) -> dict | None:
    if tool is None:
        return None
    facts = {"kind": tool.kind, "diameter_mm": tool.diameter_mm, "corner_radius_mm": tool.corner_radius_mm,
             "flat_width_mm": tool.flat_width_mm, "spindle_rpm": tool.spindle_rpm, "feed_mm_min": tool.feed_mm_min}
    return {**facts, "tool_number": tool.tool_number} if with_number else facts


def estimate_json(est: Estimate) -> dict:
    return {"moves": est.moves, "cutting_length_mm": est.cutting_length_mm, "rapid_length_mm": est.rapid_length_mm,
            "estimated_time_s": est.time_s, "estimated_time_with_acceleration_s": est.time_with_acceleration_s}


def roughing_json(roughing: RoughingFacts, measured: bool = True) -> dict:
    """The operation's facts; `measured`: with the engagement keys (of both operations, on the first only)."""
    facts = {"levels_per_space": roughing.levels_per_space,
             "lowest_level_height_mm": roughing.lowest_level_height_mm,
             "level_heights_mm": list(roughing.level_heights_mm),
             "tip_pass_heights_mm": list(roughing.tip_heights_mm), **estimate_json(roughing.estimate)}
    if roughing.passes_per_space is not None:  # the flank strategy (the levels' keys above: its lowest level)
        facts.update(strategy="flank", passes_per_space=roughing.passes_per_space,
                     flank_segment_turns_deg=list(roughing.flank_turns_deg))
    if measured:
        facts.update(max_radial_engagement_fraction=roughing.max_radial_engagement_fraction,
                     max_axial_depth_mm=roughing.max_axial_depth_mm,
                     mean_removal_rate_mm3_min=roughing.mean_removal_rate_mm3_min)
    stage = roughing.two_stage
    if stage is not None:
        facts["two_stage"] = {
            "bottom_tool": tool_json(stage.bottom_tool, with_number=True),
            "split_height_above_root_mm": stage.split_height_above_root_mm, "split_chosen_by": stage.split_chosen_by,
            "bottom": roughing_json(stage.bottom, measured=False), "two_stage_time_s": stage.two_stage_time_s,
            "bottom_tool_alone_time_s": stage.bottom_tool_alone_time_s, "time_saved_s": stage.time_saved_s}
    declined = roughing.two_stage_declined
    if declined is not None:
        facts["two_stage_declined"] = {
            "roughing_tool": tool_json(declined.roughing_tool, with_number=True),
            "two_stage_time_s": declined.two_stage_time_s,
            "bottom_tool_alone_time_s": declined.bottom_tool_alone_time_s}
    suggested = roughing.two_stage_suggested
    if suggested is not None:
        facts["two_stage_suggested"] = {
            "top_tool_diameter_mm": suggested.top_tool_diameter_mm, "two_stage_time_s": suggested.two_stage_time_s,
            "roughing_tool_alone_time_s": suggested.roughing_tool_alone_time_s,
            "time_saved_s": suggested.roughing_tool_alone_time_s - suggested.two_stage_time_s}
    by_flanks = roughing.flank_suggested
    if by_flanks is not None:
        facts["flank_suggested"] = {
            "flank_time_s": by_flanks.flank_time_s, "levels_time_s": by_flanks.levels_time_s,
            "passes_per_space": by_flanks.passes_per_space,
            "time_saved_s": by_flanks.levels_time_s - by_flanks.flank_time_s}
    if roughing.flank_fallback is not None:
        facts["flank_fallback"] = roughing.flank_fallback
    by_levels = roughing.levels_suggested
    if by_levels is not None:
        facts["levels_suggested"] = {
            "levels_time_s": by_levels.levels_time_s, "flank_time_s": by_levels.flank_time_s,
            "levels_per_space": by_levels.levels_per_space,
            "time_saved_s": by_levels.flank_time_s - by_levels.levels_time_s}
    return facts


def finishing_json(finishing: FinishingFacts) -> dict:
    """The strategy and its own facts, its estimate, and the comparison estimates (null when left out)."""
    facts = {"strategy": finishing.strategy, **facts_json(finishing.strategy_facts),
             **estimate_json(finishing.estimate)}
    for prefix, other in (("perimeter", finishing.perimeter), ("reference_strategy", finishing.reference_strategy)):
        facts[f"{prefix}_moves"] = other.moves if other else None
        facts[f"{prefix}_time_s"] = other.time_s if other else None
        facts[f"{prefix}_time_with_acceleration_s"] = other.time_with_acceleration_s if other else None
    return facts


def post_json(post: PostFacts) -> dict:
    facts: dict = {"dialect": post.dialect, "folded": post.folded}
    for program in post.programs:
        facts[f"{program.operation}_lines"] = program.lines
        facts[f"{program.operation}_bytes"] = program.bytes
        facts[f"{program.operation}_subprograms"] = program.subprograms
    return facts


def simulation_json(sim: SimulationFacts) -> dict:
    if not sim.enabled:
        return {"enabled": False, "resolution_mm": sim.resolution_mm}
    facts = dataclasses.asdict(sim)
    facts["per_feature"] = {f.feature: {"max_gouge_mm": f.max_gouge_mm, "max_leftover_mm": f.max_leftover_mm,
                                        "mean_mm": f.mean_mm} for f in sim.per_feature}
    return facts


def simulation_section(result: SimResult | None, resolution_mm: float) -> dict:
    """summary.json's `simulation` section of a simulation result (for scripts and tests)."""
    return simulation_json(simulation_facts(result, resolution_mm))


def recommendations_section(rec: ToolRecommendations) -> dict:
    """summary.json's recommendation keys of `tools` (for scripts and tests)."""
    return recommendations_json(rec)
