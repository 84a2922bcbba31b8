"""The flank roughing strategy (issue 29): the reference gear's roughing time against the levels' with the same tool
and cutting data, the engagement the simulation's section model measures against the job's limits (and a
hand-made overload flagged), the chip-thinning feed against the measured engagement, complete plans, and the
helical example's simulated roughing keeping the finish stock. The 2-D silhouette checks of both strategies are in
test_cam_silhouette.py, LinuxCNC's reading of the programs in test_estimate_rs274.py."""

from __future__ import annotations

import math

import numpy as np
import pytest

from spur_cad.cam.flank_roughing import UNCUT_MM2, FlankLimits, chip_thinning_factor
from spur_cad.cam.ir import Feature, MoveKind
from spur_cad.cam.machine import Machine, RoughingParams
from spur_cad.cam.roughing import flank_plan_for, roughing_levels
from spur_cad.cam.tools import Tool
from spur_cad.job import parse_job
from spur_cad.pipeline import job_stock, plan_cam, roughing_engagement
from spur_cad.sim import Cut, SimSettings, simulate
from spur_cad.sim.engagement import MeasuredCut, engagement_warnings
from spur_cad.sim.section_engagement import measure_section_engagement
from spur_cad.sim.simulate import shifted
from spur_cad.summary import engagement_limits, roughing_facts, roughing_json
from tests.gears import CAM_GEARS, REFERENCE_JOB, spec_of, tools_for, with_roughing_strategy


def flank_job_text(path=REFERENCE_JOB, strategy: str = "flank") -> str:
    """A shipped example with [roughing] strategy given: "flank" (their default, given) or "levels"."""
    return with_roughing_strategy(path.read_text(), strategy)


@pytest.fixture(scope="module")
def reference():
    job = parse_job(flank_job_text(), "reference_flank.toml")
    return job, plan_cam(job)


def test_the_reference_gear_roughs_in_at_most_50_minutes_with_its_own_tool_and_cutting_data(reference):
    job, plan = reference
    levels = plan_cam(parse_job(flank_job_text(strategy="levels"), "reference.toml"))
    assert plan.roughing.tool == levels.roughing.tool == job.tools.roughing
    flank_min = plan.roughing.estimate.time_with_acceleration_s / 60.0
    levels_min = levels.roughing.estimate.time_with_acceleration_s / 60.0
    assert flank_min <= 50.0, flank_min
    assert levels_min / flank_min >= 2.8, (levels_min, flank_min)
    # the job by levels is told what roughing by flanks would take: the time of the job planned so
    assert levels.flank_suggested is not None and plan.flank_suggested is None
    assert levels.flank_suggested.flank_time_s == plan.roughing.estimate.time_with_acceleration_s
    assert levels.flank_suggested.levels_time_s == levels.roughing.estimate.time_with_acceleration_s
    assert levels.flank_suggested.passes_per_space == len(plan.roughing.flank.passes)
    facts = roughing_json(roughing_facts(levels, Machine()), measured=False)["flank_suggested"]
    assert facts["time_saved_s"] == pytest.approx(60.0 * (levels_min - flank_min))


def test_the_measured_engagement_is_within_the_job_s_limits_and_the_feed_keeps_the_chip(reference):
    job, plan = reference
    e = roughing_engagement(job, plan)
    limits = engagement_limits(job.roughing, plan)
    assert limits.max_axial_depth_mm == pytest.approx(10.5)  # the 12 mm flutes, at most 3 D
    assert engagement_warnings(e, limits) == []
    d = job.tools.roughing.diameter_mm
    cutting = e.cutting & e.measured
    slot_mm = job.roughing.max_level_depth_fraction * d
    deep = cutting & (e.axial_depth_mm > slot_mm + 1.5 * e.axial_step_mm)
    assert deep.sum() >= job.gear.teeth * 4  # side passes deeper than a slot in every space
    assert np.all(e.radial_fraction[deep] <= job.roughing.max_radial_engagement_fraction + 1.5 * e.radial_step[deep])
    assert e.max_axial_depth_mm > 2.0 * slot_mm  # full-depth passes, not levels
    # the chip: the programmed feed over the measured a_e (less its sampling: the true a_e is no smaller) never
    # makes a chip thicker than f_z; the thinnest cuts run faster than the tool's base feed
    tool, path = job.tools.roughing, plan.roughing.toolpath
    per_tooth = path.feed[e.index] / (tool.spindle_rpm(job.machine) * tool.flutes)
    a_e = np.maximum(e.radial_fraction - 1.5 * e.radial_step, 1e-6) * d
    thinning = np.where(a_e < d / 2, 2.0 * np.sqrt(a_e * np.maximum(d - a_e, 0.0)) / d, 1.0)
    chip = per_tooth * thinning
    assert np.all(chip[cutting] <= tool.feed_per_tooth_mm * (1.0 + 1e-9)), chip[cutting].max()
    assert (path.feed[e.index][cutting] > 1.2 * tool.feed_mm_min(job.machine)).any()
    assert e.mean_removal_rate_mm3_min > 3.0 * roughing_engagement(
        parse_job(flank_job_text(strategy="levels"), "r.toml"),
        plan_cam(parse_job(flank_job_text(strategy="levels"), "r.toml"))
    ).mean_removal_rate_mm3_min


def test_the_passes_turn_just_beyond_the_stock_and_cut_only_along_x(reference):
    """Every pass runs between the stock's ends plus the tool radius and ENTRY_GAP_MM (the tool's edge that far from
    the stock, not the machine's clearance: no air legs to accelerate through), and everything but the passes (the
    links, the returns along a cleared column beside the holding stub) is at the largest feed and removes nothing
    in the section model (tip lands included)."""
    from spur_cad.cam.roughing import ENTRY_GAP_MM

    job, plan = reference
    path = plan.roughing.toolpath
    e = roughing_engagement(job, plan)
    radius = job.tools.roughing.diameter_mm / 2.0
    front = -(job.stock.front_margin_mm + radius + ENTRY_GAP_MM)
    start = path.start_poses()
    cutting = path.feature != Feature.NONE
    along_x = (path.kind == MoveKind.LINEAR) & (path.x != start[:, 0]) & (path.y == start[:, 1])
    assert np.all(along_x[cutting])
    assert np.isclose(np.minimum(path.x, start[:, 0])[cutting].min(), front)  # the pass's end at the front
    links = (path.kind == MoveKind.LINEAR) & ~cutting
    assert np.all(path.x[links] >= front - 1e-9)  # no leg in the air beyond that
    assert np.all(path.feed[links] == job.machine.max_feed_mm_min)
    assert e.removed_mm3[np.isin(e.index, np.flatnonzero(links))].max() == 0.0
    assert np.all(path.feed[cutting] < job.machine.max_feed_mm_min)


def test_a_hand_made_overload_is_flagged(reference):
    """Planted fault: one side pass of space 5 moved back onto the column before it, so that the next pass meets
    twice the radial engagement at full depth: the section model measures it and the warning names that move."""
    job, plan = reference
    path = plan.roughing.toolpath
    side = plan.roughing.flank.limits.radial_engagement_mm
    passes = np.nonzero((path.space == 5) & (path.feature == Feature.LEVEL))[0]
    ys = path.y[passes]
    # two consecutive passes one radial step apart, both deeper than a slot, in one run
    k = next(i for i in range(1, len(passes) - 1)
             if path.station[passes[i]] == path.station[passes[i + 1]] == path.station[passes[i - 1]]
             and abs(abs(ys[i + 1] - ys[i]) - side) < 1e-6 and abs(abs(ys[i] - ys[i - 1]) - side) < 1e-6)
    moved, following = passes[k], passes[k + 1]
    mask = np.zeros(len(path), bool)
    mask[moved - 1:moved + 1] = True  # the pass and the link to its start
    bad = shifted(path, mask, dy=ys[k - 1] - ys[k])
    stock = job_stock(job)
    e = measure_section_engagement(job.gear.teeth, stock.radius_mm, (stock.x_min, stock.x_max),
                                   [MeasuredCut("roughing", bad, job.tools.roughing)])
    row = int(np.nonzero(e.index == following)[0][0])
    assert e.radial_fraction[row] == pytest.approx(2.0 * job.roughing.max_radial_engagement_fraction,
                                                   abs=2.0 * e.radial_step[row])
    (warning,) = engagement_warnings(e, engagement_limits(job.roughing, plan))
    assert warning.startswith(f"measured roughing engagement: roughing move {following} (tooth space 5, ")
    assert "max_radial_engagement_fraction" in warning


@pytest.mark.parametrize("name", CAM_GEARS)
def test_every_plan_leaves_nothing_beyond_the_flank_allowance_in_its_model(name):
    spec = spec_of(name)
    tool, _ = tools_for(name)
    params = RoughingParams(flank_allowance_mm=0.1 * spec.module_mm, finish_stock_mm=0.005 * spec.module_mm,
                            strategy="flank")
    blank = spec.tip_radius_mm + 0.5
    plan = flank_plan_for(spec, tool, params, blank, roughing_levels(spec, tool, params, blank))
    assert plan.uncut_mm2 <= UNCUT_MM2
    limits = FlankLimits.of(tool, params)
    for p in plan.passes:  # the planner's own engagement keeps the rules it states
        assert p.axial_depth_mm <= limits.axial_depth_mm + 1e-9
        assert (p.axial_depth_mm <= limits.slot_depth_mm + 1e-9
                or p.radial_engagement_mm <= limits.radial_engagement_mm + 1e-6)
        assert p.feed_factor == pytest.approx(chip_thinning_factor(p.radial_engagement_mm, tool.diameter_mm, 2.0))


def test_chip_thinning_follows_the_catalogue_formula():
    d = 10.0
    assert chip_thinning_factor(5.0, d, 2.0) == 1.0 and chip_thinning_factor(8.0, d, 2.0) == 1.0
    assert chip_thinning_factor(1.0, d, 2.0) == pytest.approx(d / (2.0 * math.sqrt(1.0 * 9.0)))  # 1.667
    assert chip_thinning_factor(0.2, d, 2.0) == 2.0  # capped


# simulates the helical example's roughing (8 s); tests/test_helical_cam.py simulates helical roughing in the fast tier
@pytest.mark.slow
def test_the_helical_example_s_flank_roughing_keeps_the_finish_stock():
    job = parse_job(flank_job_text(REFERENCE_JOB.with_name("helical_gear.toml")), "helical_flank.toml")
    plan = plan_cam(job)
    assert plan.roughing.flank is not None and not plan.roughing.toolpath.warnings
    stock = job_stock(job)
    res = 0.01
    result = simulate(job.gear, stock, [Cut(plan.roughing.toolpath, job.tools.roughing)],
                      SimSettings(resolution_mm=res))
    dev = result.deviation[:, :, result.gear_rows]
    assert dev.min() >= job.roughing.finish_stock_mm - res / 2, dev.min()
    flanks = np.isin(result.grid.feature_names(), ["right involute", "left involute"])
    assert dev[:, flanks].max() <= 1.25 * job.roughing.flank_allowance_mm
    assert result.uncut_points == 0
    e = roughing_engagement(job, plan)
    assert engagement_warnings(e, engagement_limits(job.roughing, plan)) == []
    # every pass over the stock turns A along the lead (inverse time)
    passes = (plan.roughing.toolpath.feature == Feature.LEVEL) & (plan.roughing.toolpath.kind == MoveKind.LINEAR)
    assert plan.roughing.toolpath.inverse_time[passes].all()


def test_a_machine_s_largest_feed_caps_the_raised_feed():
    spec = spec_of("reference_z23_m4")
    tool, _ = tools_for("reference_z23_m4")
    params = RoughingParams(flank_allowance_mm=0.3, finish_stock_mm=0.02, strategy="flank")
    from spur_cad.cam.roughing import roughing_toolpath

    slow = Machine(max_feed_mm_min=1.1 * tool.feed_mm_min(Machine()))
    path = roughing_toolpath(spec, tool, slow, params, spec.tip_radius_mm + 0.5)
    cutting = (path.feature == Feature.LEVEL) & (path.kind == MoveKind.LINEAR)
    assert path.feed[cutting].max() <= slow.max_feed_mm_min + 1e-9


def test_clamp_rotary_holds_a_for_every_cut_and_releases_it_for_every_turn():
    """[roughing] clamp_rotary with the flank strategy: A turns between runs of one space, so the table is
    released before every move that turns A and clamped before every cutting move (read from the IR alone)."""
    from spur_cad.cam.roughing import roughing_toolpath

    spec = spec_of("reference_z23_m4")
    tool, _ = tools_for("reference_z23_m4")
    machine = Machine(rotary_clamp_code="M10", rotary_unclamp_code="M11")
    params = RoughingParams(flank_allowance_mm=0.3, finish_stock_mm=0.02, strategy="flank", clamp_rotary=True)
    path = roughing_toolpath(spec, tool, machine, params, spec.tip_radius_mm + 0.5)
    clamped, a, turns_while_clamped, cuts_unclamped = False, path.a[0], 0, 0
    for i in range(len(path)):
        if path.kind[i] in (MoveKind.CLAMP_ROTARY, MoveKind.UNCLAMP_ROTARY):
            clamped = path.kind[i] == MoveKind.CLAMP_ROTARY
            continue
        turns_while_clamped += int(clamped and path.a[i] != a)
        cuts_unclamped += int(path.feature[i] in (Feature.LEVEL, Feature.TIP) and not clamped)
        a = path.a[i]
    assert turns_while_clamped == 0 and cuts_unclamped == 0
    runs = len(np.unique(path.station[(path.space == 0) & (path.feature == Feature.LEVEL)]))
    assert np.count_nonzero((path.kind == MoveKind.CLAMP_ROTARY) & (path.space == 0)) >= runs + 1  # + the tip land


def test_the_summary_the_report_and_the_program_name_the_strategy(reference):
    import json

    from spur_cad.pipeline import run_job

    job, plan = reference
    result = run_job(job)
    summary = json.loads(result.files["summary.json"])["roughing"]
    flank = plan.roughing.flank
    assert summary["strategy"] == "flank" and summary["passes_per_space"] == len(flank.passes)
    assert summary["flank_segment_turns_deg"] == pytest.approx([s.turn_deg for s in flank.segments])
    assert summary["max_axial_depth_mm"] > 2.0 * job.roughing.max_level_depth_fraction * job.tools.roughing.diameter_mm
    report = result.files["report.html"].decode()
    assert f"roughing by flanks, {len(flank.passes)} passes per space" in report and "z-level roughing" not in report
    program = result.files["roughing.ngc"].decode()
    assert f"(strategy: by flanks, {len(flank.passes)} passes per space" in program


def test_one_small_tool_gets_a_larger_top_tool_suggested_when_it_pays_and_the_estimator_confirms_it(reference):
    """z120 m1 roughed by flanks with one D 0.569 mm tool: the plan suggests a larger top tool, and planning the job
    with that tool as [tools.roughing_top] gives two-stage roughing with the suggested time, quicker than the tool
    alone by the suggested saving; the reference job (its D 3.5 mm tool) gets no suggestion."""
    import dataclasses

    from spur_cad.cad.specs import StockSpec
    from spur_cad.cam.plan import TWO_STAGE_PAYS_FRACTION, CamInputs, plan_cam
    from spur_cad.cam.strategies import FinishingParams
    from spur_cad.geometry import GearSpec

    spec = GearSpec(teeth=120, module_mm=1.0, pressure_angle_deg=20.0, rack_tip_radius_mm=0.25, face_width_mm=6.0)
    tool = Tool(diameter_mm=0.569, kind="flat", flutes=3)
    params = RoughingParams(flank_allowance_mm=0.075, finish_stock_mm=0.005, strategy="flank")
    inputs = CamInputs(spec, StockSpec(radial_allowance_mm=0.5), tool, None, params, FinishingParams(), Machine())
    alone = plan_cam(inputs)
    suggested = alone.two_stage_suggested
    assert suggested is not None and suggested.roughing_tool.diameter_mm > tool.diameter_mm
    assert suggested.bottom_tool_alone_time_s == alone.roughing.estimate.time_with_acceleration_s
    assert suggested.two_stage_time_s <= TWO_STAGE_PAYS_FRACTION * suggested.bottom_tool_alone_time_s
    staged = plan_cam(dataclasses.replace(inputs, top_tool=suggested.roughing_tool))
    assert staged.two_stage is not None and staged.two_stage_suggested is None
    total = (staged.roughing.estimate.time_with_acceleration_s +
             staged.roughing_bottom.estimate.time_with_acceleration_s)
    assert math.isclose(total, suggested.two_stage_time_s, rel_tol=1e-9)
    # summary.json says it under roughing, the saving in seconds; nothing when there is nothing to suggest
    facts = roughing_json(roughing_facts(alone, Machine()), measured=False)["two_stage_suggested"]
    assert facts["top_tool_diameter_mm"] == suggested.roughing_tool.diameter_mm
    assert facts["time_saved_s"] == pytest.approx(alone.roughing.estimate.time_with_acceleration_s - total)
    assert reference[1].two_stage_suggested is None
    assert "two_stage_suggested" not in roughing_json(roughing_facts(reference[1], Machine()), measured=False)
