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

from benchmarks.peak_memory import run_measured

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "resources" / "examples"


def _cli() -> list[str]:
    exe = Path(sys.executable).with_name("spur-cad")
    return [str(exe)] if exe.exists() else [sys.executable, "-m", "spur_cad.cli"]


def _median_run(command: list[str], runs: int) -> dict:
    walls, peaks = [], []
    for _ in range(runs):
        result, peak, wall = run_measured(command, 600)
        if result.returncode != 0:
            raise RuntimeError(f"{command} failed: {result.stderr[-500:]}")
        walls.append(wall)
        peaks.append(peak)
    return {"wall_s": statistics.median(walls), "peak_mb": statistics.median(peaks) / 1e6,
            "walls_s": [round(w, 2) for w in walls]}


def _without_simulation(text: str) -> str:
    """A job file's text with `[simulation] enabled = false`."""
    if "[simulation]" in text:
        return text.replace("[simulation]", "[simulation]\nenabled = false", 1)
    return text + "\n[simulation]\nenabled = false\n"


def figures(runs: int) -> dict:
    """Medians of `runs` fresh runs: the bare import floor, the reference job (simulation on and off) and the
    helical example."""
    with tempfile.TemporaryDirectory(prefix="spur_cad_bench_run_") as tmp:
        folder = Path(tmp)
        no_simulation = folder / "reference_no_simulation.toml"
        no_simulation.write_text(_without_simulation((EXAMPLES / "reference_gear.toml").read_text()))
        jobs = {"reference": EXAMPLES / "reference_gear.toml", "reference_no_simulation": no_simulation,
                "helical": EXAMPLES / "helical_gear.toml"}
        out = {"import_ocp_numpy": _median_run([sys.executable, "-c", "import OCP, numpy"], runs)}
        for name, job in jobs.items():
            target = folder / f"out_{name}"
            out[name] = _median_run([*_cli(), "run", str(job), "--out", str(target), "--quiet"], runs)
            shutil.rmtree(target, ignore_errors=True)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, default=5)
    print(json.dumps(figures(parser.parse_args().runs), indent=2))


if __name__ == "__main__":
    main()
