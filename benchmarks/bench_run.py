"""Whole runs as a user starts them (issue 27): `spur-cad run` as a fresh process, wall seconds and peak
resident memory, the median of several runs, beside a bare `python -c "import OCP, numpy"` measured in the
same session (the floor any run stands on). `python -m benchmarks.bench_run [--runs N]` prints JSON.
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import sys
import tempfile
from pathlib import Path

from benchmarks.peak_memory import run_measured, run_measured_tree

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "resources" / "examples"


def _cli() -> list[str]:
    exe = Path(sys.executable).with_name("spur-cad")
    return [str(exe)] if exe.exists() else [sys.executable, "-m", "spur_cad.cli"]


def _median_run(command: list[str], runs: int, summary: Path | None = None) -> dict:
    """Medians of `runs` runs: wall seconds, the peak of the largest process and of its processes together
    (`spur-cad run` builds its CAD in a worker process; peak_memory.run_measured_tree), and with the run's
    `summary` (its summary.json) the stages' own seconds: the main process's stages summed (its critical path,
    waiting for the CAD included) and the CAD worker's."""
    walls, peaks, together, main_stages, cad = [], [], [], [], []
    for _ in range(runs):
        result, peak, peak_together, wall = run_measured_tree(command, 600)
        if result.returncode != 0:
            raise RuntimeError(f"{command} failed: {result.stderr[-500:]}")
        walls.append(wall)
        peaks.append(peak)
        together.append(peak_together)
        if summary is not None:
            timings = json.loads(summary.read_text())["timings_s"]
            in_worker = "cad_wait" in timings  # cad_and_step is then the worker's, beside the main stages
            main_stages.append(sum(v for k, v in timings.items() if not (in_worker and k == "cad_and_step")))
            cad.append(timings["cad_and_step"])
    figures = {"wall_s": statistics.median(walls), "peak_mb": statistics.median(peaks) / 1e6,
               "peak_together_mb": statistics.median(together) / 1e6, "walls_s": [round(w, 2) for w in walls]}
    if summary is not None:
        figures.update(main_stages_s=round(statistics.median(main_stages), 3), cad_and_step_s=round(
            statistics.median(cad), 3))
    return figures


def _without_simulation(text: str) -> str:
    """A job file's text with `[simulation] enabled = false`."""
    if "[simulation]" in text:
        return text.replace("[simulation]", "[simulation]\nenabled = false", 1)
    return text + "\n[simulation]\nenabled = false\n"


def big_gear_job(teeth: int, module_mm: float, face_width_mm: float, rack_tip_radius_mm: float,
                 radial_allowance_mm: float) -> str:
    """A job file for a big gear with tools the recommendations choose (95 % of the largest roughing tool in
    0.1 mm, the generating tool with corner radius rho in 0.05 mm)."""
    import math

    from spur_cad.cam.recommend import recommend_tools
    from spur_cad.geometry import GearSpec

    spec = GearSpec(teeth=teeth, module_mm=module_mm, rack_tip_radius_mm=rack_tip_radius_mm,
                    face_width_mm=face_width_mm, thickness_allowance_fraction=0.05)
    rec = recommend_tools(spec, spec.tip_radius_mm + radial_allowance_mm, 1.0)
    roughing = math.floor(rec.roughing_max_diameter_mm * 0.95 * 10) / 10
    finishing = math.floor(rec.finishing_generating_max_diameter_mm * 0.95 * 20) / 20
    return (f'[job]\nname = "big z{teeth} m{module_mm:g}"\n[gear]\nteeth = {teeth}\nmodule_mm = {module_mm}\n'
            f"rack_tip_radius_mm = {rack_tip_radius_mm}\nthickness_allowance_percent = 5.0\n"
            f"face_width_mm = {face_width_mm}\n[stock]\nradial_allowance_mm = {radial_allowance_mm}\n"
            f'[tools.roughing]\nkind = "flat"\ndiameter_mm = {roughing}\nflutes = 3\n'
            f'[tools.finishing]\nkind = "bull_nose"\ndiameter_mm = {finishing}\n'
            f"corner_radius_mm = {rack_tip_radius_mm}\nflutes = 2\n")


BIG_GEARS = {"z120_m1_b10": (120, 1.0, 10.0, 0.25, 0.3), "z200_m3_b30": (200, 3.0, 30.0, 0.6, 0.5)}


def compile_bytecode() -> None:
    """spur_cad's modules compiled to bytecode (__pycache__), as pip does when it installs a wheel: a machine
    that sets PYTHONDONTWRITEBYTECODE (as this one's CI does) would otherwise compile every module in every
    measured run (0.1 s)."""
    import compileall

    compileall.compile_dir(str(ROOT / "spur_cad"), quiet=1)


def figures(runs: int, only: set[str] | None = None) -> dict:
    """Medians of `runs` fresh runs: the bare import floor, the reference job (simulation on and off), the
    helical example and the two big gears of issue 27."""
    compile_bytecode()
    with tempfile.TemporaryDirectory(prefix="spur_cad_bench_run_") as tmp:
        folder = Path(tmp)
        no_simulation = folder / "reference_no_simulation.toml"
        no_simulation.write_text(_without_simulation((EXAMPLES / "reference_gear.toml").read_text()))
        jobs = {"reference": EXAMPLES / "reference_gear.toml", "reference_no_simulation": no_simulation,
                "helical": EXAMPLES / "helical_gear.toml"}
        for name, values in BIG_GEARS.items():
            jobs[name] = folder / f"{name}.toml"
            jobs[name].write_text(big_gear_job(*values))
        out = {"import_ocp_numpy": _median_run([sys.executable, "-c", "import OCP, numpy"], runs)}
        for name, job in jobs.items():
            if only is not None and name not in only:
                continue
            target = folder / f"out_{name}"
            out[name] = _median_run([*_cli(), "run", str(job), "--out", str(target), "--quiet"], runs,
                                    target / "summary.json")
            shutil.rmtree(target, ignore_errors=True)
    if only is None or "reference_in_one_process" in only:
        out["reference_in_one_process"] = second_run_figures(runs)
    return out


SECOND_RUN = """
import json, sys, time
from spur_cad.job import load_job
from spur_cad.pipeline import run_job
job = load_job(sys.argv[1])
seconds = []
for _ in range(2):
    started = time.perf_counter()
    run_job(job)
    seconds.append(time.perf_counter() - started)
print(json.dumps(seconds))
"""


def second_run_figures(runs: int) -> dict:
    """The reference job run twice by `run_job` in one process (as the workbench or a script does): the first
    run pays for the imports it defers and numba's loading of its cache, the second for nothing but the work."""
    firsts, seconds = [], []
    for _ in range(runs):
        result, _peak, _wall = run_measured([sys.executable, "-c", SECOND_RUN,
                                             str(EXAMPLES / "reference_gear.toml")], 600)
        if result.returncode != 0:
            raise RuntimeError(f"second run failed: {result.stderr[-500:]}")
        first, second = json.loads(result.stdout)
        firsts.append(first)
        seconds.append(second)
    return {"first_run_s": statistics.median(firsts), "second_run_s": statistics.median(seconds)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--only", help="comma-separated figures to measure (e.g. reference,reference_no_simulation; "
                                       "the floor is always measured)")
    args = parser.parse_args()
    print(json.dumps(figures(args.runs, set(args.only.split(",")) if args.only else None), indent=2))


if __name__ == "__main__":
    main()
