"""The shop-floor pieces of issue 18 (docs/benchmarks.md): the tool recommendations (now with the generating
and flat end mill limits), a restart program, the blank's lathe program, and two-stage roughing against the
bottom tool alone (planning time and estimated machine time).

    python -m benchmarks.bench_shop_floor [--runs 3]
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

from benchmarks.common import median_seconds
from spur_cad.cam.recommend import recommend_tools
from spur_cad.cam.restart import parse_restart
from spur_cad.cam.turning import LatheSection
from spur_cad.job import load_job, parse_job
from spur_cad.pipeline import lathe_program, plan_cam, restart_program

ROOT = Path(__file__).resolve().parents[1]
REFERENCE_JOB = ROOT / "resources" / "examples" / "reference_gear.toml"

TWO_STAGE_JOB = """
[job]
name = "two-stage m6"
[gear]
teeth = 20
module_mm = 6.0
rack_tip_radius_mm = 1.5
face_width_mm = 20.0
[tools.roughing]
kind = "flat"
diameter_mm = 8.0
flutes = 3
cutting_speed_m_min = 80.0
feed_per_tooth_mm = 0.03
[tools.bottom]
kind = "flat"
diameter_mm = 4.0
flutes = 3
cutting_speed_m_min = 80.0
feed_per_tooth_mm = 0.015
[tools.finishing]
kind = "bull_nose"
diameter_mm = 3.5
corner_radius_mm = 1.0
[simulation]
enabled = false
"""


def figures(runs: int) -> dict:
    job = load_job(REFERENCE_JOB)
    spec, blank = job.gear, job.stock.blank_radius_mm(job.gear)
    plan = plan_cam(job)
    restart = parse_restart("roughing:space=11")
    lathe_job = dataclasses.replace(job, lathe=LatheSection())
    out = {
        "recommend_tools_s": median_seconds(lambda: recommend_tools(spec, blank, job.machine.clearance_mm,
                                                                    job.tools.finishing), runs),
        "restart_program_s": median_seconds(lambda: restart_program(job, plan, restart), runs),
        "restart_program_lines": restart_program(job, plan, restart)[1].count(b"\n"),
        "lathe_program_s": median_seconds(lambda: lathe_program(lathe_job), runs),
        "lathe_program_lines": lathe_program(lathe_job)[1].count(b"\n"),
    }
    two = parse_job(TWO_STAGE_JOB, "two-stage.toml")
    out["two_stage_plan_s"] = median_seconds(lambda: plan_cam(two), runs)
    # one stage: the bottom tool alone (the large tool alone cannot reach the bottom of the space)
    single = dataclasses.replace(two, tools=dataclasses.replace(two.tools, roughing=two.tools.bottom, bottom=None))
    out["one_stage_plan_s"] = median_seconds(lambda: plan_cam(single), runs)
    stage = plan_cam(two).two_stage
    out.update(two_stage_h=stage.two_stage_time_s / 3600.0, bottom_tool_alone_h=stage.bottom_tool_alone_time_s / 3600.0,
               one_stage_plan_roughing_h=plan_cam(single).roughing.estimate.time_s / 3600.0,
               split_above_root_mm=stage.split_height_above_root_mm)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="median of N runs for the timings")
    args = parser.parse_args()
    for name, value in figures(args.runs).items():
        print(f"{name}: {value:.3f}" if isinstance(value, float) else f"{name}: {value}")


if __name__ == "__main__":
    main()
