"""The fast simulation against OCP booleans (tool swept solids cut from a B-rep stock) on subsets of moves."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from spur_cad.cam.ir import Feature
from spur_cad.job import parse_job
from spur_cad.pipeline import job_stock, plan_cam
from spur_cad.sim import SimSettings, finishing_stations, subset
from spur_cad.sim.occ_check import cross_check
from tests.gears import reference_job_text

pytestmark = pytest.mark.slow  # make test-all

ROOT = Path(__file__).resolve().parents[1]
RES = 0.005


@pytest.fixture(scope="module")
def reference():
    """The reference job with perimeter finishing (the window below is one of its stations)."""
    job = parse_job(reference_job_text("perimeter"))
    return job, plan_cam(job)


def test_finishing_flank_moves_agree_with_ocp_booleans(reference):
    job, plan = reference
    fin = plan.finishing.toolpath
    moves = np.nonzero((fin.station == 70) & (fin.space == 3) & (fin.feature == Feature.RIGHT_FLANK))[0][40:46]
    mask = np.zeros(len(fin), bool)
    mask[moves] = True
    x = finishing_stations(fin)
    check = cross_check(job.gear, job_stock(job), subset(fin, mask), job.tools.finishing,
                        SimSettings(resolution_mm=RES), (x[64], x[76]), x)
    assert check.cut_blades > 100
    assert check.max_difference_mm <= RES  # (the speed ratio is a benchmark figure: docs/benchmarks.md)


def test_roughing_passes_agree_with_ocp_booleans(reference):
    job, plan = reference
    rough = plan.roughing.toolpath
    first_space = np.nonzero(rough.space == 0)[0]
    mask = np.zeros(len(rough), bool)
    mask[first_space[:5]] = True  # approach, plunge, passes along X and a step across the first level
    # Rows inside the stock's length (blades lying in its end faces are ambiguous for the B-rep probe).
    check = cross_check(job.gear, job_stock(job), subset(rough, mask), job.tools.roughing,
                        SimSettings(resolution_mm=RES), (0.0, 20.0))
    assert check.cut_blades > 100
    assert check.max_difference_mm <= RES
