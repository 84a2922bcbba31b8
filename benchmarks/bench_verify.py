"""`spur-cad verify` and the ISO 1328-1 grading on the reference job (docs/benchmarks.md): reading the
LinuxCNC programs (spur_cad's reader and rs274's canonical output), the verification's simulation
against the run's own simulation stage, and grading the simulated gear.

    python -m benchmarks.bench_verify [--runs 3] [--large-runs 3]

`large_program_figures` times `spur-cad verify` as a fresh process on a 50 MB program (the reference job's
finishing program unfolded into plain moves and repeated), with its peak resident memory (issue 33's
target: within 60 s and 500 MB).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
from pathlib import Path

from benchmarks.common import median_seconds
from benchmarks.peak_memory import fresh_python_floor_bytes, run_measured
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
    out["grading"] = {"class": grading.overall_class, "deviations_um": grading.deviations_um,
                      "classes": grading.classes}
    return out


def flat_program(path: Path, target_bytes: int, job_path: Path = REFERENCE_JOB) -> int:
    """The job's finishing program unfolded into plain G0/G1 moves, repeated to `target_bytes`; returns the
    number of moves."""
    job = load_job(job_path)
    _, files = build_programs(job, plan_cam(job))
    moves = read_program(files["finishing.ngc"].decode(), "linuxcnc", "finishing.ngc")
    body = "".join(f"G0 X{x:.4f} Y{y:.4f} Z{z:.4f} A{a:.4f}\n" if rapid else
                   f"G1 X{x:.4f} Y{y:.4f} Z{z:.4f} A{a:.4f} F{f:.1f}\n"
                   for rapid, x, y, z, a, f in zip(moves.rapid, moves.x, moves.y, moves.z, moves.a, moves.feed))
    copies = max(1, target_bytes // len(body))
    with open(path, "w") as handle:
        handle.write(f"G21 G90 G94 G17\nT{int(moves.tool[0])} M6\nS5000 M3\n")
        for _ in range(copies):
            handle.write(body)
        handle.write("M30\n")
    return copies * len(moves)


def large_program_figures(runs: int) -> dict:
    """`spur-cad verify` (spur_cad's reader, rs274's verdict too where installed) of a 50 MB program, each run a
    fresh process; the floor of a bare Python started the same way for comparison."""
    with tempfile.TemporaryDirectory() as folder:
        program = Path(folder) / "flat.ngc"
        moves = flat_program(program, 50 * 1024 * 1024)
        results = [run_measured([sys.executable, "-m", "spur_cad.cli", "verify", str(REFERENCE_JOB), str(program),
                                 "--quiet"], 600) for _ in range(runs)]
        size = program.stat().st_size
    assert all(result.returncode == 0 for result, _, _ in results), [r.stderr for r, _, _ in results]
    return {"bytes": size, "moves": moves, "wall_s": statistics.median(r[2] for r in results),
            "peak_mb": statistics.median(r[1] for r in results) / 1e6,
            "python_floor_mb": fresh_python_floor_bytes() / 1e6}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="median of N runs for the timings")
    parser.add_argument("--large-runs", type=int, default=3, help="median of N runs of the 50 MB program")
    args = parser.parse_args()
    large = large_program_figures(args.large_runs)
    print(f"50 MB program ({large['bytes']:,} bytes, {large['moves']:,} moves): spur-cad verify "
          f"{large['wall_s']:.1f} s, peak {large['peak_mb']:.0f} MB (median of {args.large_runs} fresh processes)")
    f = figures(args.runs)
    print(f"reference job, {f['moves']:,} moves: read {f['read_s']:.2f} s (rs274 canonical "
          f"{f.get('read_rs274_s', float('nan')):.2f} s); verify (simulation and verdict) {f['verify_s']:.1f} s "
          f"against the run's simulation stage {f['run_simulation_s']:.1f} s; grading {f['grade_s']:.3f} s")
    print(f"grading of the simulated reference gear: class {f['grading']['class']}, {f['grading']['deviations_um']}, "
          f"classes {f['grading']['classes']}")


if __name__ == "__main__":
    main()
