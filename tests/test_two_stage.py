"""Two-stage roughing (issue 18): a large flat end mill roughs the upper levels, a smaller one ([tools.bottom])
the bottom of the spaces; the split is the one with the shortest estimated time, or set.

Independent checks: the 2-D silhouette checker (tests/silhouette.py) on both tools' toolpaths together
(never inside the finish stock, at most the flank allowance left above the bottom tool's lowest pass), the
cycle time of the bottom tool alone (a plan without the large tool), LinuxCNC's rs274 on the second program."""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest
from shapely.geometry import Polygon

from spur_cad.cam.ir import Feature
from spur_cad.cam.roughing import roughing_levels
from spur_cad.errors import JobFileError, SpurCadError
from spur_cad.geometry import gear_outline
from spur_cad.job import parse_job
from spur_cad.pipeline import build_programs, plan_cam
from tests import silhouette
from tests.rs274_helper import run_rs274

JOB = """
[job]
name = "two-stage m3"
[gear]
teeth = 14
module_mm = 3.0
rack_tip_radius_mm = 0.9
face_width_mm = 4.0
[tools.roughing]
kind = "flat"
diameter_mm = 3.0
flutes = 3
[tools.bottom]
kind = "flat"
diameter_mm = 1.5
flutes = 3
[tools.finishing]
kind = "bull_nose"
diameter_mm = 1.5
corner_radius_mm = 0.5
[roughing]
strategy = "levels"
flank_allowance_mm = 0.15
finish_stock_mm = 0.02
[finishing]
target_scallop_mm = 0.05
step_over_mm = 1.5
[simulation]
enabled = false
"""
HALF_MICRON = 0.5e-3


@pytest.fixture(scope="module")
def two_stage():
    job = parse_job(JOB, "two.toml")
    return job, plan_cam(job)


def test_the_large_tool_roughs_down_to_the_split_and_the_bottom_tool_below_it(two_stage):
    job, plan = two_stage
    spec, root = job.gear, job.gear.root_radius_mm
    split = root + plan.two_stage.split_height_above_root_mm
    large = plan.roughing.toolpath
    small = plan.roughing_bottom.toolpath
    assert large.tool_number == 1 and small.tool_number == 3  # T3: the bottom tool's default number
    large_levels = large.z[large.feature == Feature.LEVEL]
    small_levels = small.z[small.feature == Feature.LEVEL]
    assert large_levels.min() == pytest.approx(split) and np.all(small_levels < split - 1e-9)
    # the bottom tool goes as deep as it would alone; the large one never below its own lowest level
    assert small_levels.min() == pytest.approx(roughing_levels(spec, job.tools.bottom, job.roughing,
                                                               job.stock.blank_radius_mm(spec)).lowest_height_mm)
    assert large_levels.min() >= roughing_levels(spec, job.tools.roughing, job.roughing,
                                                 job.stock.blank_radius_mm(spec)).lowest_height_mm - 1e-9


def test_together_they_keep_the_finish_stock_and_leave_at_most_the_flank_allowance(two_stage):
    job, plan = two_stage
    spec = job.gear
    design = Polygon(gear_outline(spec, 1e-5))
    sils = []
    for planned in (plan.roughing, plan.roughing_bottom):
        path = planned.toolpath
        rows = path.motion_mask & (path.space == 0)
        sils += silhouette.silhouettes_in_part_frame(path, planned.tool.diameter_mm, 0.0, 30.0, mask=rows)
    grown = design.buffer(job.roughing.finish_stock_mm - 1e-6, quad_segs=256)
    assert silhouette.max_penetration_mm(grown, sils) <= HALF_MICRON
    small = plan.roughing_bottom.toolpath
    lowest = float(small.z[(small.space == 0) & (small.feature == Feature.LEVEL)].min())
    points, _ = silhouette.design_boundary(spec, [0], labels=("fillet", "involute"))
    leftover = silhouette.leftover_mm(points[points[:, 1] >= lowest], sils)
    assert leftover.max() <= job.roughing.flank_allowance_mm + HALF_MICRON
    # the large tool alone leaves far more at the bottom: the bottom tool is needed there
    large_only = silhouette.silhouettes_in_part_frame(plan.roughing.toolpath, job.tools.roughing.diameter_mm, 0.0,
                                                      30.0, mask=plan.roughing.toolpath.motion_mask
                                                      & (plan.roughing.toolpath.space == 0))
    assert silhouette.leftover_mm(points[points[:, 1] >= lowest], large_only).max() > \
        2 * job.roughing.flank_allowance_mm


@pytest.mark.slow
def test_the_time_saved_is_against_the_bottom_tool_alone_and_the_split_is_the_quickest(two_stage):
    job, plan = two_stage
    text = JOB.replace("[tools.roughing]\nkind = \"flat\"\ndiameter_mm = 3.0\nflutes = 3\n", "").replace(
        "[tools.bottom]", "[tools.roughing]")
    alone = plan_cam(parse_job(text, "alone.toml"))
    assert alone.roughing_bottom is None and alone.roughing.tool.diameter_mm == 1.5
    stage = plan.two_stage
    assert stage.bottom_tool_alone_time_s == pytest.approx(alone.roughing.estimate.time_with_acceleration_s, rel=1e-9)
    assert stage.two_stage_time_s == pytest.approx(plan.roughing.estimate.time_with_acceleration_s
                                                   + plan.roughing_bottom.estimate.time_with_acceleration_s, rel=1e-9)
    assert stage.gain_s > 0.0 and stage.chosen == "shortest time"
    # no other split among the large tool's levels is quicker by more than the per-level model's slack (1 %)
    levels = plan.roughing.levels.heights_mm
    full = roughing_levels(job.gear, job.tools.roughing, job.roughing, job.stock.blank_radius_mm(job.gear))
    root = job.gear.root_radius_mm
    for height in full.heights_mm:
        if height - root < 1e-6 or height == levels[-1]:
            continue
        other = parse_job(JOB.replace("finish_stock_mm = 0.02", "finish_stock_mm = 0.02\nbottom_tool_above_root_mm = "
                                                                f"{height - root:.9f}"), "set.toml")
        try:
            planned = plan_cam(other)
        except SpurCadError:
            continue
        if planned.two_stage is not None:
            assert planned.two_stage.two_stage_time_s >= stage.two_stage_time_s * 0.99


def test_a_set_split_is_the_lowest_large_level_at_or_above_it(two_stage):
    job, _ = two_stage
    root = job.gear.root_radius_mm
    wanted = 3.0
    set_job = parse_job(JOB.replace("finish_stock_mm = 0.02", f"finish_stock_mm = 0.02\nbottom_tool_above_root_mm = "
                                                              f"{wanted}"), "set.toml")
    planned = plan_cam(set_job)
    assert planned.two_stage.chosen == "set"
    split = planned.two_stage.split_height_above_root_mm
    assert split >= wanted - 1e-9 and split < wanted + 1.5  # a level spacing at most the depth limit 0.5 x D
    assert np.all(planned.roughing_bottom.levels.heights_mm < root + split)
    assert np.all(planned.roughing.levels.heights_mm >= root + split - 1e-9)


def test_a_bottom_tool_not_smaller_than_the_roughing_tool_is_refused():
    text = JOB.replace("diameter_mm = 3.0", "diameter_mm = 2.0").replace(
        "[tools.bottom]\nkind = \"flat\"\ndiameter_mm = 1.5", "[tools.bottom]\nkind = \"flat\"\ndiameter_mm = 2.0")
    with pytest.raises(SpurCadError, match=r"\[tools.bottom\] diameter_mm = 2 must be smaller than the roughing"):
        plan_cam(parse_job(text, "big.toml"))


def test_two_tools_under_one_number_are_refused_naming_the_bottom_tools_line():
    text = JOB.replace("[tools.bottom]\n", "[tools.bottom]\ntool_number = 1\n")
    with pytest.raises(JobFileError, match=r"two.toml:\d+: \[tools.bottom\] tool_number = 1 is also the roughing"):
        parse_job(text, "two.toml")


@pytest.mark.linuxcnc
def test_the_bottom_program_runs_in_rs274_with_its_own_tool(two_stage, tmp_path):
    job, plan = two_stage
    files = build_programs(job, plan)[1]
    assert set(files) == {"roughing.ngc", "roughing_bottom.ngc", "finishing.ngc"}
    path = tmp_path / "roughing_bottom.ngc"
    path.write_bytes(files["roughing_bottom.ngc"])
    ok, canon, messages = run_rs274(path)
    assert ok, messages
    assert any(line.startswith("CHANGE_TOOL(") for line in canon)
    assert "two-stage" in files["roughing_bottom.ngc"].decode().splitlines()[4]


def test_the_report_and_summary_show_both_programs_and_the_time_saved(two_stage, tmp_path):
    from spur_cad.cli import main

    job_file = tmp_path / "two.toml"
    job_file.write_text(JOB)
    assert main(["run", str(job_file), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    import json

    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    stage = summary["roughing"]["two_stage"]
    _, plan = two_stage
    assert stage["time_saved_s"] == pytest.approx(plan.two_stage.bottom_tool_alone_time_s
                                                  - plan.two_stage.two_stage_time_s)
    assert stage["bottom"]["moves"] == len(plan.roughing_bottom.toolpath)
    assert summary["post"]["roughing_bottom_lines"] > 0
    report = (tmp_path / "out" / "report.html").read_text()
    assert "Two-stage roughing: the bottom tool (T3, D 1.500 mm)" in report and "roughing_bottom.ngc" in report
    assert re.search(r"<th>T3</th><td class=\"text\">roughing, bottom of the spaces</td>", report)  # its tool row


# --------------------------------------------------------------------------- by flanks (issue 29)

FLANK_JOB = JOB.replace("strategy = \"levels\"", "strategy = \"flank\"")
TOP_JOB = FLANK_JOB.replace("[tools.roughing]\nkind = \"flat\"\ndiameter_mm = 3.0\nflutes = 3\n", "").replace(
    "[tools.bottom]", "[tools.roughing]") + "\n[tools.roughing_top]\nkind = \"flat\"\ndiameter_mm = 3.0\nflutes = 3\n"


@pytest.fixture(scope="module")
def flank_two_stage():
    job = parse_job(FLANK_JOB, "flank_two.toml")
    return job, plan_cam(job)


def test_by_flanks_the_smaller_tool_starts_from_what_the_larger_leaves_and_together_they_rough_the_space(
        flank_two_stage):
    """The 2-D silhouettes of both programs (space 0 and its neighbours, so the tip lands and the neighbours' cuts
    count): never inside the finish stock, at most the flank allowance left on the flanks and fillets above the
    smaller tool's lowest level; the larger tool alone leaves far more; the smaller tool's program is the shorter
    for the larger one's work (fewer passes than it needs alone)."""
    job, plan = flank_two_stage
    spec = job.gear
    assert plan.two_stage is not None and plan.two_stage.chosen == "reach"
    assert plan.roughing.flank is not None and plan.roughing_bottom.flank is not None
    spaces = [0, 1, spec.teeth - 1]
    design = Polygon(gear_outline(spec, 1e-5))
    sils = {}
    for name, planned in (("large", plan.roughing), ("small", plan.roughing_bottom)):
        path = planned.toolpath
        sils[name] = silhouette.silhouettes_in_part_frame(path, planned.tool.diameter_mm, 0.0, 30.0,
                                                          mask=path.motion_mask & np.isin(path.space, spaces))
    both = sils["large"] + sils["small"]
    grown = design.buffer(job.roughing.finish_stock_mm - 1e-6, quad_segs=256)
    assert silhouette.max_penetration_mm(grown, both) <= HALF_MICRON
    lowest = roughing_levels(spec, job.tools.bottom, job.roughing, job.stock.blank_radius_mm(spec)).lowest_height_mm
    points, _ = silhouette.design_boundary(spec, [0], labels=("fillet", "involute"))
    above = points[points[:, 1] >= lowest]
    assert silhouette.leftover_mm(above, both).max() <= job.roughing.flank_allowance_mm + HALF_MICRON
    assert silhouette.leftover_mm(above, sils["large"]).max() > 2 * job.roughing.flank_allowance_mm
    alone = plan_cam(parse_job(FLANK_JOB.replace("diameter_mm = 3.0", "diameter_mm = 1.5").replace(
        "[tools.bottom]\nkind = \"flat\"\ndiameter_mm = 1.5\nflutes = 3\n", ""), "alone.toml"))
    assert alone.roughing_bottom is None and alone.roughing.tool.diameter_mm == 1.5
    assert len(plan.roughing_bottom.flank.passes) < len(alone.roughing.flank.passes)
    assert plan.two_stage.bottom_tool_alone_time_s == pytest.approx(
        alone.roughing.estimate.time_with_acceleration_s, rel=1e-9)
    assert plan.two_stage.two_stage_time_s < plan.two_stage.bottom_tool_alone_time_s


def _nearest_axis_mm(path, radius: float, mask) -> float:
    """The flat tool bottom's least distance from the A axis over the selected moves (Y, Z interpolated along each
    move at 33 points; A does not change it)."""
    start, end = path.start_poses()[mask][:, 1:3], path.poses()[mask][:, 1:3]
    t = np.linspace(0.0, 1.0, 33)[:, None, None]
    y, z = np.moveaxis(start + t * (end - start), -1, 0)
    return float(np.where(np.abs(y) <= radius, z, np.hypot(np.abs(y) - radius, z)).min())


def test_by_flanks_the_links_between_runs_come_no_nearer_the_axis_than_the_passes(flank_two_stage):
    """The smaller tool's runs start low where the larger tool took the top: a link across the space at the height
    of two deep passes would pass below the root circle, beyond the face, where the reference job's holding stub
    (D 80 mm, the root circle D 82 mm) stands. Its D 3.5 mm below a D 8 mm, and the flank job's pair."""
    from spur_cad.cam.roughing import flank_plan_for, roughing_toolpath
    from tests.gears import REFERENCE_JOB

    job = parse_job(REFERENCE_JOB.read_text().replace("[roughing]\n", "[roughing]\nstrategy = \"flank\"\n", 1), "r")
    spec, params, stock, small = job.gear, job.roughing, job.stock, job.tools.roughing
    blank = stock.blank_radius_mm(spec)
    large = dataclasses.replace(small, diameter_mm=8.0, flute_length_mm=20.0)
    first = flank_plan_for(spec, large, params, blank, roughing_levels(spec, large, params, blank))
    levels = roughing_levels(spec, small, params, blank)
    second = flank_plan_for(spec, small, params, blank, levels, tips=False, first=(first, large))
    reference = roughing_toolpath(spec, small, job.machine, params, blank, stock.back_margin_mm,
                                  stock.stub_diameter_mm / 2.0, stock.front_margin_mm, levels=levels, tips=False,
                                  flank_plan=second, stub_length_mm=stock.stub_length_mm)
    _, plan = flank_two_stage
    for path, radius in [(reference, small.diameter_mm / 2.0)] + [
            (p.toolpath, p.tool.diameter_mm / 2.0) for p in (plan.roughing, plan.roughing_bottom)]:
        linear = path.kind == 1
        passes = _nearest_axis_mm(path, radius, linear & (path.feature == Feature.LEVEL))
        links = _nearest_axis_mm(path, radius, linear & (path.feature == Feature.NONE) & (path.space >= 0))
        assert links >= passes - 1e-9, (links, passes)


def test_by_flanks_each_tool_keeps_its_own_engagement_limits_measured_on_the_section(flank_two_stage):
    from spur_cad.pipeline import roughing_engagement
    from spur_cad.sim.engagement import engagement_warnings
    from spur_cad.summary import engagement_limits

    job, plan = flank_two_stage
    e = roughing_engagement(job, plan)
    limits = engagement_limits(job.roughing, plan)
    assert set(limits.axial_depth_by_operation) == {"roughing", "roughing_bottom"}
    assert engagement_warnings(e, limits) == []
    cut = e.cutting & e.measured
    for name, planned in (("roughing", plan.roughing), ("roughing_bottom", plan.roughing_bottom)):
        mine = cut & (np.array(e.operation) == name)
        assert mine.sum() > 0 and np.all(e.diameter_mm[mine] == planned.tool.diameter_mm)
    # planted fault: the smaller tool's axial limit applied to the larger tool's passes is overstepped
    tight = dataclasses.replace(limits, axial_depth_by_operation={
        "roughing": limits.axial_depth_by_operation["roughing_bottom"] * 0.5, "roughing_bottom": 1e9})
    (warning,) = engagement_warnings(e, tight)
    assert warning.startswith("measured roughing engagement: roughing move ")


def test_a_larger_tool_that_saves_nothing_is_declined_and_the_report_says_so(tmp_path):
    """The reference gear by flanks with [tools.roughing_top] D 8 mm above its D 3.5 mm: two-stage roughing would
    take longer than the D 3.5 alone, so roughing is that tool's one program, and the report gives both times."""
    import json

    from spur_cad.pipeline import run_job
    from tests.gears import REFERENCE_JOB

    text = REFERENCE_JOB.read_text().replace("[roughing]\n", "[roughing]\nstrategy = \"flank\"\n", 1)
    text += ("\n[tools.roughing_top]\nkind = \"flat\"\ndiameter_mm = 8.0\nflutes = 3\nflute_length_mm = 20.0\n"
             "cutting_speed_m_min = 80.0\nfeed_per_tooth_mm = 0.03\n")
    text = text.replace("[simulation]\n", "[simulation]\nenabled = false\n") if "[simulation]" in text else \
        text + "\n[simulation]\nenabled = false\n"
    job = parse_job(text, "top.toml")
    plan = plan_cam(job)
    declined = plan.two_stage_declined
    assert plan.two_stage is None and plan.roughing_bottom is None and declined is not None
    assert plan.roughing.tool == job.tools.roughing and declined.roughing_tool == job.tools.roughing_top
    assert declined.bottom_tool_alone_time_s == pytest.approx(plan.roughing.estimate.time_with_acceleration_s)
    assert declined.two_stage_time_s > declined.bottom_tool_alone_time_s
    result = run_job(job)
    assert "roughing_bottom.ngc" not in result.files
    summary = json.loads(result.files["summary.json"])["roughing"]
    assert summary["two_stage_declined"]["roughing_tool"]["diameter_mm"] == 8.0
    assert summary["two_stage_declined"]["two_stage_time_s"] == pytest.approx(declined.two_stage_time_s)
    report = result.files["report.html"].decode()
    assert "Two-stage roughing with the larger tool (T4, D 8.000 mm)" in report
    assert "roughing uses the smaller tool alone" in report


def test_roughing_top_is_the_bottom_tool_mechanism_in_reverse(flank_two_stage):
    """[tools.roughing_top] D 3 above [tools.roughing] D 1.5 plans the same two programs as [tools.roughing] D 3
    with [tools.bottom] D 1.5 (tool numbers aside)."""
    job, plan = flank_two_stage
    top = plan_cam(parse_job(TOP_JOB, "top.toml"))
    assert top.roughing.tool.tool_number == 4 and top.roughing_bottom.tool.tool_number == 1
    for mine, theirs in ((top.roughing, plan.roughing), (top.roughing_bottom, plan.roughing_bottom)):
        for name in ("x", "y", "z", "a", "feed"):
            np.testing.assert_array_equal(getattr(mine.toolpath, name), getattr(theirs.toolpath, name))


@pytest.mark.parametrize(("change", "message"), [
    (lambda t: t.replace("[tools.roughing]\nkind = \"flat\"\ndiameter_mm = 1.5\nflutes = 3\n", ""),
     r"top.toml:\d+: \[tools.roughing_top\] needs \[tools.roughing\]"),
    (lambda t: t + "\n[tools.bottom]\nkind = \"flat\"\ndiameter_mm = 1.0\n",
     r"top.toml:\d+: \[tools.roughing_top\] and \[tools.bottom\] both make two-stage roughing"),
    (lambda t: t.replace("[tools.roughing_top]\nkind = \"flat\"\ndiameter_mm = 3.0",
                         "[tools.roughing_top]\nkind = \"flat\"\ndiameter_mm = 1.2"),
     r"top.toml:\d+: \[tools.roughing_top\] diameter_mm = 1.2 must be larger than the roughing tool's 1.5 mm"),
])
def test_a_roughing_top_that_cannot_serve_is_one_line_at_its_key(change, message):
    text = change(TOP_JOB)
    with pytest.raises(JobFileError, match=message) as info:
        parse_job(text, "top.toml")
    line = int(re.search(r"top.toml:(\d+):", str(info.value)).group(1))
    assert "[tools.roughing_top]" in text.splitlines()[line - 1] or "diameter_mm" in text.splitlines()[line - 1]


@pytest.mark.linuxcnc
def test_the_flank_bottom_program_runs_in_rs274(flank_two_stage, tmp_path):
    job, plan = flank_two_stage
    files = build_programs(job, plan)[1]
    path = tmp_path / "roughing_bottom.ngc"
    path.write_bytes(files["roughing_bottom.ngc"])
    ok, canon, messages = run_rs274(path)
    assert ok, messages
    assert "two-stage" in files["roughing_bottom.ngc"].decode().splitlines()[4]
