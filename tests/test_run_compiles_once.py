"""A second run in the same process (the workbench's next Generate, a script looping over gears) compiles
no numba function: the simulator's kernels are compiled once per process (and kept on disk by numba's cache for
the next one; the estimator's planner is numpy since issue 27, so a run without simulation imports no numba).
Checked in a fresh process with an empty cache folder: the first run compiles, the later ones neither compile
nor make new numba functions (which would load the first run's disk cache again, or compile where the cache
cannot be written). A run does not import CadQuery either (its import costs more than the CAD work)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

SCRIPT = """
import gc, json, sys, warnings
from numba.core.dispatcher import Dispatcher
from numba.core.event import install_recorder
from spur_cad.job import parse_job
from spur_cad.pipeline import run_job
from tests.workbench_helper import small_job_text

warnings.simplefilter("ignore")  # numba's warnings about the cache folder it cannot write
SIMULATION = "\\n[simulation]\\nresolution_mm = 0.02\\n"
compiled, dispatchers = [], []
for teeth in (12, 12, 13):
    with install_recorder("numba:compile") as recorder:
        run_job(parse_job(small_job_text(teeth=teeth) + SIMULATION, "small.toml"))
    compiled.append(len(recorder.buffer))
    gc.collect()
    dispatchers.append(sum(1 for item in gc.get_objects() if issubclass(type(item), Dispatcher)))
json.dump([compiled, dispatchers, "cadquery" in sys.modules], sys.stdout)
"""


@pytest.mark.slow  # three simulated runs with an empty numba cache (17 s of CPU)
def test_a_second_run_in_the_same_process_compiles_nothing(tmp_path):
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path), "PYTHONPATH": str(ROOT)}
    done = subprocess.run([sys.executable, "-c", SCRIPT], cwd=ROOT, env=env, capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    (first, second, other_gear), dispatchers, cadquery_imported = json.loads(done.stdout)
    assert not cadquery_imported  # a run works on OCP shapes: CadQuery's import costs a second
    assert first > 0  # the check sees compilation where there is some (an empty cache folder)
    assert second == 0 and other_gear == 0
    assert dispatchers[0] == dispatchers[1] == dispatchers[2], dispatchers


def test_a_run_without_simulation_imports_no_numba(tmp_path):
    """Without a simulation a run has nothing for numba to do: the estimator plans speeds with numpy, so numba's
    import and its first load (0.4 s and 110 MB of a 3 s run) are not paid."""
    script = ("import sys\nfrom spur_cad.job import parse_job\nfrom spur_cad.pipeline import run_job\n"
              "from tests.workbench_helper import small_job_text\n"
              "run_job(parse_job(small_job_text(teeth=12) + '\\n[simulation]\\nenabled = false\\n', 'small.toml'))\n"
              "print('numba' in sys.modules, 'llvmlite' in sys.modules)\n")
    done = subprocess.run([sys.executable, "-c", script], cwd=ROOT, env={**os.environ, "PYTHONPATH": str(ROOT)},
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split() == ["False", "False"]
