"""The helical example's programs against the same gear and tools as a spur gear (docs/benchmarks.md):
passes per space, moves and estimated cycle times (feed-bound and with acceleration), program lines,
and the median time of planning and of the simulation.

    python -m benchmarks.bench_helical [--runs 3]
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

from benchmarks.common import median_seconds
from spur_cad.job import Job, load_job
from spur_cad.pipeline import build_programs, plan_cam, simulate_stage
from spur_cad.post import PostSettings

ROOT = Path(__file__).resolve().parents[1]
HELICAL_JOB = ROOT / "resources" / "examples" / "helical_gear.toml"


def figures(job: Job, runs: int) -> dict:
    plan = plan_cam(job)
    out = {"plan_s": median_seconds(lambda: plan_cam(job), runs)}
    for name, op in (("roughing", plan.roughing), ("finishing", plan.finishing)):
        lines = {}
        for folded in (True, False):
            posted = dataclasses.replace(job, post=PostSettings(dialect="linuxcnc", folded=folded))
            lines[folded] = build_programs(posted, plan)[0][name].lines
        out[name] = {"moves": op.estimate.moves, "feed_bound_h": op.estimate.time_s / 3600.0,
                     "with_acceleration_h": op.estimate.time_with_acceleration_s / 3600.0,
                     "folded_lines": lines[True], "flat_lines": lines[False]}
    out["finishing"]["passes_per_space"] = plan.finishing.result.passes_per_space
    out["finishing"]["facts"] = dataclasses.asdict(plan.finishing.result.facts)
    result = simulate_stage(job, plan)
    out["sim_s"] = median_seconds(lambda: simulate_stage(job, plan), runs)
    out["sim"] = {"max_gouge_um": 1000 * result.max_gouge_mm, "max_leftover_um": 1000 * result.max_leftover_mm,
                  "poses": result.poses_clipped}
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="median of N runs for the timings")
    args = parser.parse_args()
    helical = load_job(HELICAL_JOB)
    spur = dataclasses.replace(helical, gear=dataclasses.replace(helical.gear, helix_angle_deg=0.0))
    for label, job in (("helical 15 deg", helical), ("same gear, spur", spur)):
        f = figures(job, args.runs)
        print(f"## {label}: plan {f['plan_s']:.2f} s, simulation {f['sim_s']:.1f} s ({f['sim']['poses']:,} poses; "
              f"gouge {f['sim']['max_gouge_um']:.2f} um, leftover {f['sim']['max_leftover_um']:.2f} um)")
        print(f"finishing facts: passes per space {f['finishing']['passes_per_space']}, {f['finishing']['facts']}")
        for name in ("roughing", "finishing"):
            r = f[name]
            print(f"| {name} | {r['moves']:,} | {r['feed_bound_h']:.2f} h | {r['with_acceleration_h']:.2f} h | "
                  f"{r['folded_lines']:,} / {r['flat_lines']:,} |")


if __name__ == "__main__":
    main()
