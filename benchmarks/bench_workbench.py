"""The workbench's Generate (issue 27): the reference job imported into a FreeCAD document and exported
as `spur-cad run` writes it (`commands.export_job`, the same pipeline), twice in one FreeCAD process, timed
inside freecadcmd. `python -m benchmarks.bench_workbench` prints JSON (needs FreeCAD; uses the test helpers
that install the workbench into a private HOME)."""

from __future__ import annotations

import argparse
import json
import statistics
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

BODY = """
import time
import FreeCAD
from spur_cad_workbench import commands
doc = FreeCAD.newDocument("Bench")
started = time.perf_counter()
job = commands.import_job_file(doc, JOB_FILE)[2]
RESULT["import_s"] = time.perf_counter() - started
for run in ("first", "second"):
    started = time.perf_counter()
    commands.export_job(job, OUT + "_" + run)
    RESULT[run + "_generate_s"] = time.perf_counter() - started
"""


def _one_process(freecadcmd: str) -> dict:
    from tests.workbench_helper import run_workbench_code

    with tempfile.TemporaryDirectory(prefix="spur_cad_bench_workbench_") as tmp:
        work = Path(tmp)
        body = (f"JOB_FILE = {str(ROOT / 'resources' / 'examples' / 'reference_gear.toml')!r}\n"
                f"OUT = {str(work / 'out')!r}\n" + BODY)
        result, proc = run_workbench_code(body, work / "fc", freecadcmd=freecadcmd, timeout_s=600)
    if not result or not result.get("ok"):
        raise RuntimeError(f"the workbench run failed: {proc.stderr[-800:]}")
    return {key: value for key, value in result.items() if key.endswith("_s")}


def figures(runs: int = 3) -> dict:
    """Medians over `runs` fresh freecadcmd processes of the import, the first and the second Generate."""
    from tests.conftest import freecadcmd_path

    freecadcmd = freecadcmd_path()
    if freecadcmd is None:
        return {"skipped": "FreeCAD's freecadcmd is not installed"}
    each = [_one_process(freecadcmd) for _ in range(runs)]
    return {key: round(statistics.median(run[key] for run in each), 2) for key in each[0]}


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, default=3)
    print(json.dumps(figures(parser.parse_args().runs), indent=2))
