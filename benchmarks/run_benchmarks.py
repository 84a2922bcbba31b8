"""Benchmarks run on demand (`make bench`); results go into docs/benchmarks.md by hand.

Each benchmark reports the median of several runs and describes the machine.
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import platform
from pathlib import Path

from benchmarks.common import median_seconds
from spur_cad.geometry import GearSpec, gear_outline, sample_profile


def reference_spec() -> GearSpec:
    return GearSpec(teeth=23, module_mm=4.0, rack_tip_radius_mm=0.8, thickness_allowance_fraction=0.05,
                    face_width_mm=20.0)


def machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as handle:
            for line in handle:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}, {platform.system()}"


def bench_profile(runs: int) -> dict:
    """Exact profile construction (validation included) + sampling at 1 um, reference gear."""
    def build_and_sample():
        spec = reference_spec()
        return sample_profile(spec.tooth_space_profile(), 0.001)

    samples = build_and_sample()
    spec = reference_spec()
    outline_points = len(gear_outline(spec, 0.001))
    return {
        "profile_build_and_sample_1um_s": median_seconds(build_and_sample, runs),
        "profile_points_half_space": len(samples),
        "outline_1um_s": median_seconds(lambda: gear_outline(spec, 0.001), runs),
        "outline_points": outline_points,
    }


def bench_cad(runs: int) -> dict:
    """Gear solid + STEP: ours (reference gear) beside bd_warehouse's SpurGear (same m, z, alpha, b)."""
    from benchmarks import bench_cad as cad

    spec = reference_spec()
    nominal = GearSpec(teeth=23, module_mm=4.0, rack_tip_radius_mm=0.8, face_width_mm=20.0)
    ours_s = median_seconds(lambda: cad.ours(spec), runs)
    theirs_s = median_seconds(lambda: cad.bd_warehouse_gear(nominal), runs)
    our_shape, our_step = cad.ours(spec)
    their_shape, their_step = cad.bd_warehouse_gear(nominal)
    our_dev, our_form, our_phase = cad.deviation_of_ours(spec, our_shape)
    their_dev, their_form, their_phase = cad.deviation_of_bd_warehouse(nominal, their_shape)
    return {
        "spur_cad_solid_plus_step_s": ours_s,
        "bd_warehouse_solid_plus_step_s": theirs_s,
        "time_ratio_bd_warehouse_over_spur_cad": theirs_s / ours_s,
        "spur_cad_max_involute_deviation_mm": our_dev,
        "spur_cad_involute_form_error_mm": our_form,
        "spur_cad_fitted_phase_rad": our_phase,
        "bd_warehouse_max_involute_deviation_mm": their_dev,
        "bd_warehouse_involute_form_error_mm": their_form,
        "bd_warehouse_fitted_phase_rad": their_phase,
        "spur_cad_step_bytes": len(our_step),
        "bd_warehouse_step_bytes": len(their_step),
    }


def bench_cam(runs: int) -> dict:
    """Roughing + finishing generation for the reference job, with moves and estimated times
    beside the reference process's finishing strategy (0.08 mm contact spacing, 0.14 mm X step)."""
    from spur_cad.cam.estimate import estimate
    from spur_cad.cam.finishing import finishing_toolpath
    from spur_cad.cam.roughing import roughing_toolpath
    from spur_cad.cam.strategies import FinishingParams
    from spur_cad.job import load_job

    job = load_job(Path(__file__).resolve().parents[1] / "resources" / "examples" / "reference_gear.toml")
    spec, machine, blank = job.gear, job.machine, job.stock.blank_radius_mm(job.gear)
    rough = lambda: roughing_toolpath(spec, job.tools.roughing, machine, job.roughing, blank,  # noqa: E731
                                      job.stock.back_margin_mm, job.stock.stub_diameter_mm / 2,
                                      job.stock.front_margin_mm)
    finish = lambda: finishing_toolpath(spec, job.tools.finishing, machine, job.finishing, blank)  # noqa: E731
    reference = finishing_toolpath(spec, job.tools.finishing, machine, FinishingParams(step_over_mm=0.14), blank,
                                   contact_spacing_mm=0.08)
    r, f, ref = estimate(rough(), machine), estimate(finish(), machine), estimate(reference, machine)
    return {"roughing_generation_s": median_seconds(rough, runs),
            "finishing_generation_s": median_seconds(finish, runs),
            "roughing_moves": r.moves, "roughing_time_s": r.time_s, "finishing_moves": f.moves,
            "finishing_time_s": f.time_s, "reference_strategy_moves": ref.moves,
            "reference_strategy_time_s": ref.time_s}


def bench_post(runs: int) -> dict:
    """G-code for the reference job: lines and bytes flat vs folded per dialect, and posting time."""
    from spur_cad.job import load_job
    from spur_cad.pipeline import plan_cam
    from spur_cad.post import DIALECT_NAMES, PostSettings, ProgramInfo, post_program

    job = load_job(Path(__file__).resolve().parents[1] / "resources" / "examples" / "reference_gear.toml")
    plan = plan_cam(job)
    info = ProgramInfo("benchmark", ("reference job",))
    result: dict = {}
    for dialect in DIALECT_NAMES:
        for folded in (False, True):
            label = f"{dialect}_{'folded' if folded else 'flat'}"
            settings = PostSettings(dialect=dialect, folded=folded)
            finishing = post_program(plan.finishing.toolpath, settings, info)
            roughing = post_program(plan.roughing.toolpath, settings, info)
            result[label] = {"finishing_lines": finishing.lines, "finishing_bytes": finishing.bytes,
                             "roughing_lines": roughing.lines, "roughing_bytes": roughing.bytes}
        for folded in (False, True):
            settings = PostSettings(dialect=dialect, folded=folded)
            seconds = median_seconds(functools.partial(post_program, plan.finishing.toolpath, settings, info), runs)
            result[f"{dialect}_{'folded' if folded else 'flat'}"]["finishing_post_s"] = seconds
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, default=21)
    parser.add_argument("--cad-runs", type=int, default=5)
    parser.add_argument("--sim-runs", type=int, default=5)
    parser.add_argument("--run-runs", type=int, default=3, help="spur-cad run end to end, generating and perimeter")
    args = parser.parse_args()
    from benchmarks.bench_flat import figures as flat_figures
    from benchmarks.bench_generating import REFERENCE_JOB, end_to_end_seconds, figures
    from benchmarks.bench_helical import HELICAL_JOB
    from benchmarks.bench_helical import figures as helical_figures
    from benchmarks.bench_roughing import figures as roughing_figures
    from benchmarks.bench_roughing import two_stage_figures
    from benchmarks.bench_run import figures as run_figures
    from benchmarks.bench_shop_floor import figures as shop_floor_figures
    from benchmarks.bench_sim import bench_sim
    from benchmarks.bench_verify import figures as verify_figures
    from benchmarks.bench_verify import large_program_figures
    from benchmarks.bench_workbench import figures as workbench_figures
    from spur_cad.job import load_job

    results = {"machine": machine(), "runs": args.runs, "profile": bench_profile(args.runs),
               "cad_runs": args.cad_runs, "cad": bench_cad(args.cad_runs), "cam": bench_cam(args.cad_runs),
               "post": bench_post(args.cad_runs), "sim_runs": args.sim_runs, "sim": bench_sim(args.sim_runs),
               "generating": figures(load_job(REFERENCE_JOB)),
               "helical": helical_figures(load_job(HELICAL_JOB), args.run_runs),
               "verify": verify_figures(args.run_runs), "verify_large": large_program_figures(args.run_runs),
               "shop_floor": shop_floor_figures(args.run_runs), "roughing": roughing_figures(args.run_runs),
               "roughing_two_stage": two_stage_figures(),
               "modified_ring_flat": flat_figures(args.cad_runs),
               "fresh_runs": run_figures(args.cad_runs), "workbench_generate": workbench_figures(),
               "run_s": {strategy: end_to_end_seconds(strategy, args.run_runs)
                         for strategy in ("generating", "perimeter")}}
    print(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
