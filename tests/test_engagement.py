"""Roughing engagement measured on the simulated stock (spur_cad.sim.engagement): a_e, a_p and removal rate of
known cuts, the planner's roughing within the job's limits, and an overloading move named in a warning."""

from __future__ import annotations

import re

import numpy as np
import pytest

from spur_cad.cam.ir import Feature, MoveKind, Operation, ToolpathBuilder
from spur_cad.cam.machine import Machine, RoughingParams
from spur_cad.cam.roughing import roughing_toolpath
from spur_cad.cam.tools import Tool
from spur_cad.geometry import GearSpec
from spur_cad.job import load_job, parse_job
from spur_cad.pipeline import job_stock, plan_cam, roughing_engagement
from spur_cad.sim.engagement import (
    COLUMNS_PER_DIAMETER,
    EngagementLimits,
    MeasuredCut,
    engagement_warnings,
    measure_engagement,
)
from spur_cad.sim.simulate import shifted
from tests.gears import REFERENCE_JOB, spec_of, tools_for, with_roughing_strategy

FEED = 600.0
LIMITS = EngagementLimits(max_level_depth_fraction=0.5, step_over_fraction=0.5)


def _passes(tool_number: int, passes: list[tuple[float, float]], x_from: float, x_to: float) -> object:
    """Passes along X at (Y, Z) each, from x_from to x_to, with plunges and retracts outside the stock."""
    b = ToolpathBuilder(Operation.ROUGHING, tool_number, 1000.0)
    b.move(MoveKind.RAPID, x_from, passes[0][0], 80.0, 0.0)
    for y, z in passes:
        b.move(MoveKind.RAPID, x_from, y, 80.0, 0.0, space=0)
        b.move(MoveKind.LINEAR, x_from, y, z, 0.0, FEED / 3, space=0, station=0)
        b.move(MoveKind.LINEAR, x_to, y, z, 0.0, FEED, space=0, station=0, feature=Feature.LEVEL)
        b.move(MoveKind.LINEAR, x_to, y, 80.0, 0.0, FEED, space=0, station=0)
    return b.build()


def _cut_moves(engagement) -> np.ndarray:
    return np.nonzero(engagement.cutting)[0]


def test_a_slot_in_a_flat_top_is_one_diameter_wide_and_as_deep_as_cut_and_a_side_step_its_width():
    """A facing pass (D 40) flattens the top of the blank at Z 29; a D 4 slot 1.5 mm below it meets a_e = 1 D and
    a_p = 1.5 mm; a pass 1.3 mm to the side meets 1.3 / 4 of its diameter; volumes and rates from the cross
    sections (width x depth x length, length / feed)."""
    blank, length, face, depth, side = 30.0, 20.0, 29.0, 1.5, 1.3
    facing = Tool(diameter_mm=40.0, tool_number=1)
    slot = Tool(diameter_mm=4.0, tool_number=2)
    cuts = [MeasuredCut("face", _passes(1, [(0.0, face)], -25.0, 45.0), facing),
            MeasuredCut("slot", _passes(2, [(0.0, face - depth), (side, face - depth)], -5.0, 25.0), slot)]
    e = measure_engagement(6, blank, (0.0, length), cuts)
    facing_pass, slot_pass, side_pass = _cut_moves(e)
    assert e.operation[facing_pass] == "face" and e.operation[slot_pass] == e.operation[side_pass] == "slot"
    column = e.column_mm
    assert column == pytest.approx(slot.diameter_mm / COLUMNS_PER_DIAMETER, rel=0.05)
    assert e.radial_fraction[slot_pass] == pytest.approx(1.0, abs=column / 4.0)
    assert e.axial_depth_mm[slot_pass] == pytest.approx(depth, abs=1e-9)
    assert e.radial_fraction[side_pass] == pytest.approx(side / 4.0, abs=column / 4.0)
    assert e.axial_depth_mm[side_pass] == pytest.approx(depth, abs=1e-9)
    assert e.removed_mm3[slot_pass] == pytest.approx(4.0 * depth * length, rel=column / 4.0)
    assert e.removed_mm3[side_pass] == pytest.approx(side * depth * length, abs=column * depth * length)
    pass_minutes = 30.0 / FEED
    assert e.minutes[slot_pass] == pytest.approx(pass_minutes)
    rate = (e.removed_mm3[slot_pass] + e.removed_mm3[side_pass]) / (2 * pass_minutes)
    assert e.removed_mm3[facing_pass] > 0.0
    assert engagement_warnings(e, LIMITS) == []  # the slot is 1.5 mm <= 0.5 x 4 mm deep; the side step 0.33 D
    only_slot = measure_engagement(6, blank, (0.0, length), cuts[1:])
    assert only_slot.mean_removal_rate_mm3_min > rate  # the slot also meets the round top: more material
    two = measure_engagement(6, blank, (0.0, length), [cuts[0], MeasuredCut("slot", cuts[1].path, slot)])
    assert two.mean_removal_rate_mm3_min == pytest.approx(
        (two.removed_mm3.sum()) / (two.minutes[two.cutting].sum()))


def test_a_slot_twice_the_allowed_depth_and_a_side_cut_wider_than_the_step_over_are_named():
    blank, face = 30.0, 29.0
    facing, slot = Tool(diameter_mm=40.0, tool_number=1), Tool(diameter_mm=4.0, tool_number=2)
    too_deep = face - 2 * LIMITS.max_level_depth_fraction * slot.diameter_mm
    cuts = [MeasuredCut("face", _passes(1, [(0.0, face)], -25.0, 45.0), facing),
            MeasuredCut("roughing", _passes(2, [(0.0, too_deep), (3.0, too_deep)], -5.0, 25.0), slot)]
    e = measure_engagement(6, blank, (0.0, 20.0), cuts)
    _, deep_pass, wide_pass = _cut_moves(e)
    assert e.axial_depth_mm[deep_pass] == pytest.approx(4.0)
    assert e.radial_fraction[wide_pass] == pytest.approx(0.75, abs=0.01)
    deep, wide = engagement_warnings(e, LIMITS)
    assert f"roughing move {e.index[deep_pass]} (tooth space 0, level 0): axial depth 4.000 mm" in deep
    assert "max_level_depth_fraction" in deep and str(e.index[wide_pass]) in deep  # the side cut is as deep
    assert f"roughing move {e.index[wide_pass]} (tooth space 0, level 0): radial engagement 0.75 D" in wide
    assert "step_over_fraction" in wide


def _planned(spec: GearSpec, tool: Tool, params: RoughingParams, blank: float):
    machine = Machine()
    path = roughing_toolpath(spec, tool, machine, params, blank, back_margin_mm=1.0, front_margin_mm=1.0)
    return path, measure_engagement(spec.teeth, blank, (-1.0, spec.face_width_mm + 1.0),
                                    [MeasuredCut("roughing", path, tool)])


@pytest.mark.parametrize("name", ["many_teeth_z120", "shifted_z12", "pa25_sharp_rack_z17"])
def test_the_planned_roughing_of_gears_of_module_1_to_5_stays_within_its_limits(name):
    """Every level starts with a full slot (a_e = 1 D) no deeper than the depth limit; the other passes step
    over at most the step-over; no warning."""
    spec = spec_of(name)
    tool, _ = tools_for(name)
    params = RoughingParams(flank_allowance_mm=0.1 * spec.module_mm, finish_stock_mm=0.02, strategy="levels")
    blank = spec.tip_radius_mm + 0.5
    path, e = _planned(spec, tool, params, blank)
    assert engagement_warnings(e, EngagementLimits(params.max_level_depth_fraction, params.step_over_fraction)) == []
    cutting = e.cutting & e.measured  # the tip lands' passes straddle two spaces' fields: not measured
    assert e.max_radial_fraction == pytest.approx(1.0, abs=1e-9)
    assert e.max_axial_depth_mm <= params.max_level_depth_fraction * tool.diameter_mm + 1e-9
    first = np.array([np.nonzero(cutting & (e.space == k))[0][0] for k in range(spec.teeth)])
    assert np.allclose(e.radial_fraction[first], 1.0, atol=e.column_mm / tool.diameter_mm)
    # the first slot meets the blank from its top (at the column nearest the space's axis) down to level 0
    y = path.y[e.index[first]]
    nearest = np.maximum(np.abs(y) - tool.diameter_mm / 2.0, 0.0)
    blank_top = np.sqrt(blank**2 - nearest**2)
    assert np.allclose(e.axial_depth_mm[first], blank_top - path.z[e.index[first]], atol=e.column_mm * 0.2)
    # the later passes of a level meet its step-over at most (they are measured, not taken for slots)
    along_x = path.x[e.index] != path.x[np.maximum(e.index - 1, 0)]
    for k, level in {(int(k), int(v)) for k, v in zip(e.space[cutting], e.level[cutting])}:
        passes = np.nonzero(cutting & along_x & (e.space == k) & (e.level == level))[0]
        assert np.all(e.radial_fraction[passes[1:]] <= params.step_over_fraction + 1.5 * e.radial_step[passes[1:]])
    assert e.removed_mm3.sum() > 0.0 and e.mean_removal_rate_mm3_min > 0.0


def test_a_module_6_gear_with_deep_levels_stays_within_its_limits_and_its_depth_limit_binds():
    spec = GearSpec(teeth=18, module_mm=6.0, pressure_angle_deg=20.0, rack_tip_radius_mm=1.5, face_width_mm=12.0)
    tool = Tool(diameter_mm=5.0, flutes=3)
    params = RoughingParams(flank_allowance_mm=1.0, finish_stock_mm=0.05, max_level_depth_fraction=0.3,
                            strategy="levels")
    _, e = _planned(spec, tool, params, spec.tip_radius_mm + 1.0)
    assert engagement_warnings(e, EngagementLimits(0.3, params.step_over_fraction)) == []
    assert e.max_axial_depth_mm == pytest.approx(0.3 * tool.diameter_mm, abs=1e-6)  # levels as deep as allowed


def test_the_reference_job_s_roughing_is_within_its_limits_and_a_deepened_pass_is_named():
    job = parse_job(with_roughing_strategy(REFERENCE_JOB.read_text(), "levels"), "reference_levels.toml")
    plan = plan_cam(job)
    e = roughing_engagement(job, plan)
    params, tool = job.roughing, plan.roughing.tool
    limits = EngagementLimits(params.max_level_depth_fraction, params.step_over_fraction)
    assert engagement_warnings(e, limits) == []
    assert e.max_radial_fraction == pytest.approx(1.0)
    assert e.max_axial_depth_mm <= params.max_level_depth_fraction * tool.diameter_mm
    path = plan.roughing.toolpath
    levels = plan.roughing.levels.heights_mm
    max_depth = params.max_level_depth_fraction * tool.diameter_mm
    # space 5, level 3: its first pass and the plunge before it (outside the stock) lowered by 2 x the depth limit
    level_moves = np.nonzero((path.space == 5) & (path.station == 3) & (path.feature == Feature.LEVEL))[0]
    deepened = level_moves[0]
    mask = np.zeros(len(path), bool)
    mask[[deepened - 1, deepened]] = True
    bad = shifted(path, mask, dz=-2.0 * max_depth)
    stock = job_stock(job)
    e_bad = measure_engagement(job.gear.teeth, stock.radius_mm, (stock.x_min, stock.x_max),
                               [MeasuredCut("roughing", bad, tool)])
    row = int(np.nonzero(e_bad.index == deepened)[0][0])
    expected = levels[2] - levels[3] + 2.0 * max_depth  # from level 2's floor down to the lowered pass
    assert e_bad.axial_depth_mm[row] == pytest.approx(expected, abs=1e-6)
    (warning,) = engagement_warnings(e_bad, limits)
    assert warning.startswith(f"measured roughing engagement: roughing move {deepened} (tooth space 5, level 3): "
                              f"axial depth {expected:.3f} mm beyond the slotting depth limit 1.750 mm")
    named_spaces = {int(s) for s in re.findall(r"tooth space (\d+)", warning)}
    assert named_spaces == {5}


def test_the_helical_example_s_roughing_slots_once_per_level_and_steps_over_within_its_limit():
    """Passes following the lead: each level's first pass a slot (a_e = 1 D measured across the lead), the others
    within the step-over; no warning."""
    job = parse_job(with_roughing_strategy(REFERENCE_JOB.with_name("helical_gear.toml").read_text(), "levels"),
                    "helical_levels.toml")
    plan = plan_cam(job)
    e = roughing_engagement(job, plan)
    params = job.roughing
    assert engagement_warnings(e, EngagementLimits(params.max_level_depth_fraction, params.step_over_fraction)) == []
    slots = e.cutting & e.measured & (e.radial_fraction > 0.99)
    assert slots.sum() == job.gear.teeth * len(plan.roughing.levels.heights_mm)
    assert e.max_radial_fraction <= 1.0
    assert e.max_axial_depth_mm <= params.max_level_depth_fraction * plan.roughing.tool.diameter_mm
    others = e.cutting & e.measured & ~slots
    assert np.all(e.radial_fraction[others] <= params.step_over_fraction + 1.5 * e.radial_step[others])


def test_two_stage_roughing_measures_the_bottom_tool_on_what_the_large_one_left():
    """Both operations measured, in order, on one stock: the bottom tool meets what the large one left (much less
    deep than the blank it would meet alone), within its own limits (fractions of its own diameter)."""
    from tests.test_two_stage import JOB

    job = parse_job(JOB, "two.toml")
    plan = plan_cam(job)
    e = roughing_engagement(job, plan)
    params = job.roughing
    assert engagement_warnings(e, EngagementLimits(params.max_level_depth_fraction, params.step_over_fraction)) == []
    bottom = np.array(e.operation) == "roughing_bottom"
    assert bottom.any() and (~bottom).any()
    assert np.all(e.diameter_mm[bottom] == job.tools.bottom.diameter_mm)
    assert np.any(e.cutting & bottom)
    assert e.axial_depth_mm[bottom].max() <= params.max_level_depth_fraction * job.tools.bottom.diameter_mm + 1e-9
    # without the large tool's moves the bottom tool's first level would meet the blank from its top: deeper
    alone = measure_engagement(job.gear.teeth, *_stock(job), [MeasuredCut("roughing_bottom",
                                                                          plan.roughing_bottom.toolpath,
                                                                          plan.roughing_bottom.tool)])
    assert alone.max_axial_depth_mm > e.axial_depth_mm[bottom].max() + 1.0


def _stock(job):
    stock = job_stock(job)
    return stock.radius_mm, (stock.x_min, stock.x_max)


def test_a_height_field_beyond_the_cell_limit_is_sampled_coarser_and_still_measures_a_slot(monkeypatch):
    from spur_cad.sim import engagement

    monkeypatch.setattr(engagement, "MAX_CELLS", 30_000)
    blank, face = 30.0, 29.0
    cuts = [MeasuredCut("face", _passes(1, [(0.0, face)], -25.0, 45.0), Tool(diameter_mm=40.0, tool_number=1)),
            MeasuredCut("slot", _passes(2, [(0.0, face - 1.0)], -5.0, 25.0), Tool(diameter_mm=4.0, tool_number=2))]
    e = measure_engagement(6, blank, (0.0, 20.0), cuts)
    fine = 4.0 / COLUMNS_PER_DIAMETER
    assert e.column_mm > 1.5 * fine  # 6 spaces x 25 rows x 750 columns at full sampling
    slot = _cut_moves(e)[1]
    assert e.radial_fraction[slot] == pytest.approx(1.0, abs=e.column_mm / 4.0)
    assert e.axial_depth_mm[slot] == pytest.approx(1.0)


def test_tip_land_moves_are_cut_in_the_model_but_not_measured():
    """The reference roughing's tip-land moves (level -1) remove material (the volume counts) but give no a_e or
    a_p to the maxima or the warnings: the per-space fields cannot hold a pass centred on a tooth."""
    job = load_job(REFERENCE_JOB)
    plan = plan_cam(job)
    e = roughing_engagement(job, plan)
    tips = e.level < 0
    assert (e.cutting & tips).any() and not e.measured[tips].any() and e.measured[~tips].all()
    assert e.max_radial_fraction == pytest.approx(float(e.radial_fraction[e.measured].max()))

