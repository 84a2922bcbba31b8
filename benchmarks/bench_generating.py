"""Finishing by generation against perimeter finishing on the reference job (docs/benchmarks.md).

Cycle times come from the estimator (feed-bound, and with acceleration); they are deterministic.
Program lines are the LinuxCNC post's, folded and flat. `--runs N` also times `spur-cad run` of the
reference job end to end (median of N) with strategy "generating" (the job as shipped) and
"perimeter" (the job as it was before generating became the default).

    python -m benchmarks.bench_generating [--runs 3]
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from spur_cad.job import Job, load_job
from spur_cad.pipeline import build_programs, plan_cam
from spur_cad.post import PostSettings

ROOT = Path(__file__).resolve().parents[1]
REFERENCE_JOB = ROOT / "resources" / "examples" / "reference_gear.toml"


def _variant(job: Job, strategy: str, target_mm: float, tool=None) -> Job:
    finishing = dataclasses.replace(job.finishing, strategy=strategy, target_scallop_mm=target_mm)
    tools = dataclasses.replace(job.tools, finishing=tool) if tool is not None else job.tools
    return dataclasses.replace(job, finishing=finishing, tools=tools)


def recommended_tool(job: Job):
    """The generating advice's largest tool with the advised corner radius, rounded down to 0.1 mm, four
    flutes, the job's cutting data (a catalogue-like choice)."""
    advice = plan_cam(job).finishing.result.tool_advice
    diameter = math.floor(10.0 * advice.recommended_diameter_mm) / 10.0
    return dataclasses.replace(job.tools.finishing, diameter_mm=diameter,
                               corner_radius_mm=advice.advised_corner_radius_mm, flutes=4)


def figures(job: Job) -> list[dict]:
    rows = []
    rec = recommended_tool(job)
    perimeter_5um_s = None
    cases = [("perimeter", 0.005, None), ("generating", 0.005, None), ("generating", 0.001, None),
             ("generating", 0.005, rec), ("generating", 0.001, rec)]
    for strategy, target, tool in cases:
        variant = _variant(job, strategy, target, tool)
        plan = plan_cam(variant)
        fin = plan.finishing
        lines = {}
        for folded in (True, False):
            posted = dataclasses.replace(variant, post=PostSettings(dialect="linuxcnc", folded=folded))
            lines[folded] = build_programs(posted, plan)[0]["finishing"].lines
        if strategy == "perimeter":
            perimeter_5um_s = fin.estimate.time_s
        used = variant.tools.finishing
        rows.append({
            "strategy": strategy, "target_um": 1000 * target,
            "tool": f"D{used.diameter_mm:g} r{used.effective_corner_radius_mm:g} z{used.flutes}, "
                    f"{used.feed_mm_min(variant.machine):.0f} mm/min",
            "passes_per_space": fin.result.passes_per_space or None,
            "moves": fin.estimate.moves,
            "feed_bound_h": fin.estimate.time_s / 3600.0,
            "with_acceleration_h": fin.estimate.time_with_acceleration_s / 3600.0,
            "ratio_to_perimeter_5um": fin.estimate.time_s / perimeter_5um_s,
            "linuxcnc_folded_lines": lines[True], "linuxcnc_flat_lines": lines[False],
        })
    reference = plan_cam(job).finishing.reference_estimate
    rows.append({"strategy": "reference process's strategy", "target_um": 5.0, "tool": "job's",
                 "passes_per_space": None, "moves": reference.moves, "feed_bound_h": reference.time_s / 3600.0,
                 "with_acceleration_h": reference.time_with_acceleration_s / 3600.0,
                 "ratio_to_perimeter_5um": reference.time_s / perimeter_5um_s,
                 "linuxcnc_folded_lines": None, "linuxcnc_flat_lines": None})
    return rows


def end_to_end_seconds(strategy: str, runs: int) -> float:
    """Median wall time of `spur-cad run` (a fresh process each time) of the reference job with `strategy`."""
    text = REFERENCE_JOB.read_text()
    line = next(line for line in text.splitlines() if line.startswith("strategy = "))
    times = []
    with tempfile.TemporaryDirectory() as folder:
        job = Path(folder) / "job.toml"
        job.write_text(text.replace(line, f'strategy = "{strategy}"'))
        for _ in range(runs):
            start = time.perf_counter()
            subprocess.run([sys.executable, "-m", "spur_cad.cli", "run", str(job), "--out", f"{folder}/out",
                            "--quiet"], check=True)
            times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=0, help="also time spur-cad run end to end (median of N)")
    args = parser.parse_args()
    job = load_job(REFERENCE_JOB)
    print("| strategy | target | tool | passes per space | moves | feed-bound | with acceleration | "
          "vs perimeter 5 um | LinuxCNC folded / flat lines |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for r in figures(job):
        lines = (f"{r['linuxcnc_folded_lines']:,} / {r['linuxcnc_flat_lines']:,}"
                 if r["linuxcnc_folded_lines"] else "-")
        print(f"| {r['strategy']} | {r['target_um']:g} um | {r['tool']} | {r['passes_per_space'] or '-'} | "
              f"{r['moves']:,} | {r['feed_bound_h']:.2f} h | {r['with_acceleration_h']:.2f} h | "
              f"{r['ratio_to_perimeter_5um']:.3f} | {lines} |")
    if args.runs:
        for strategy in ("generating", "perimeter"):
            print(f"spur-cad run, reference job, strategy {strategy}: median of {args.runs}: "
                  f"{end_to_end_seconds(strategy, args.runs):.1f} s")


if __name__ == "__main__":
    main()
