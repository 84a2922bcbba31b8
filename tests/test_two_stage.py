"""Two-stage roughing (issue 18): a large flat end mill roughs the upper levels, a smaller one ([tools.bottom])
the bottom of the spaces; the split is the one with the shortest estimated time, or set.

Independent checks: the 2-D silhouette checker (tests/silhouette.py) on both tools' toolpaths together
(never inside the finish stock, at most the flank allowance left above the bottom tool's lowest pass), the
cycle time of the bottom tool alone (a plan without the large tool), LinuxCNC's rs274 on the second program."""

from __future__ import annotations

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
    assert stage.bottom_tool_alone_time_s == pytest.approx(alone.roughing.estimate.time_s, rel=1e-9)
    assert stage.two_stage_time_s == pytest.approx(plan.roughing.estimate.time_s
                                                   + plan.roughing_bottom.estimate.time_s, rel=1e-9)
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
