"""`spur-cad verify` and the ISO 1328-1 grading on the reference job (docs/benchmarks.md): reading the
LinuxCNC programs (spur_cad's reader and rs274's canonical output), the verification's simulation
against the run's own simulation stage, and grading the simulated gear.

    python -m benchmarks.bench_verify [--runs 3]
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

from benchmarks.run_benchmarks import median_seconds
from spur_cad.job import load_job
from spur_cad.pipeline import build_programs, plan_cam, simulate_stage
from spur_cad.verify.reader import read_program
from spur_cad.verify.rs274 import read_canonical, rs274_executable
from spur_cad.verify.verify import verify_moves

ROOT = Path(__file__).resolve().parents[1]
REFERENCE_JOB = ROOT / "resources" / "examples" / "reference_gear.toml"


def _canonical(path: Path):
    """The moves of a program file through rs274 (spur-cad verify --reader rs274)."""
    with open(path, "rb") as handle:
        return read_canonical(handle, path.name)


def figures(runs: int) -> dict:
    from spur_cad.grade.simulated import grade_simulation

    job = load_job(REFERENCE_JOB)
    plan = plan_cam(job)
    _, files = build_programs(job, plan)
    texts = {name: data.decode() for name, data in files.items()}
    out = {"moves": sum(len(read_program(text, "linuxcnc", name)) for name, text in texts.items())}
    out["read_s"] = median_seconds(lambda: [read_program(text, "linuxcnc", name) for name, text in texts.items()],
                                   runs)
    if rs274_executable() is not None:
        with tempfile.TemporaryDirectory() as folder:
            paths = []
            for name, data in files.items():
                (Path(folder) / name).write_bytes(data)
                paths.append(Path(folder) / name)
            out["read_rs274_s"] = median_seconds(lambda: [_canonical(p) for p in paths], runs)
    programs = [read_program(texts[name], "linuxcnc", name) for name in ("roughing.ngc", "finishing.ngc")]
    out["verify_s"] = median_seconds(lambda: verify_moves(job, programs), runs)
    out["run_simulation_s"] = median_seconds(lambda: simulate_stage(job, plan), runs)
    result = simulate_stage(job, plan)
    out["grade_s"] = median_seconds(lambda: grade_simulation(job.gear, result), runs)
    grading = grade_simulation(job.gear, result)
    out["grading"] = {"class": grading["class"], "deviations_um": grading["deviations_um"],
                      "classes": grading["classes"]}
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="median of N runs for the timings")
    args = parser.parse_args()
    f = figures(args.runs)
    print(f"reference job, {f['moves']:,} moves: read {f['read_s']:.2f} s (rs274 canonical "
          f"{f.get('read_rs274_s', float('nan')):.2f} s); verify (simulation and verdict) {f['verify_s']:.1f} s "
          f"against the run's simulation stage {f['run_simulation_s']:.1f} s; grading {f['grade_s']:.3f} s")
    print(f"grading of the simulated reference gear: class {f['grading']['class']}, {f['grading']['deviations_um']}, "
          f"classes {f['grading']['classes']}")


if __name__ == "__main__":
    main()
