"""The simulator verifies finishing by generation on the reference job (which ships with it): the
whole job cut to the design within the target, and planted faults reported where they were planted.
The simulator sweeps each straight pass exactly along X; nothing here repeats the strategy's maths."""

from __future__ import annotations

import numpy as np
import pytest

from spur_cad.cam.ir import Feature, MoveKind
from spur_cad.job import load_job
from spur_cad.pipeline import job_stock, plan_cam
from spur_cad.sim import Cut, SimSettings, simulate, subset
from spur_cad.summary import simulation_section
from tests.gears import REFERENCE_JOB

RES = 0.005
SPACE = 5


@pytest.fixture(scope="module")
def reference():
    job = load_job(REFERENCE_JOB)
    assert job.finishing.strategy == "generating"
    return job, plan_cam(job)


def _simulate(job, plan, finishing_path):
    cuts = [Cut(plan.roughing.toolpath, job.tools.roughing), Cut(finishing_path, job.tools.finishing)]
    return simulate(job.gear, job_stock(job), cuts, SimSettings(resolution_mm=RES))


def _cut_rows(path, feature, space):
    """Indices of the cutting moves (along X) of `feature` in `space`, in program order."""
    return np.nonzero((path.feature == feature) & (path.space == space) & (path.kind == MoveKind.LINEAR))[0]


def test_reference_job_is_cut_to_the_design_within_target_and_resolution(reference):
    job, plan = reference
    result = _simulate(job, plan, plan.finishing.toolpath)
    facts = simulation_section(result, RES)
    target = job.finishing.target_scallop_mm
    assert facts["max_gouge_mm"] <= RES
    assert facts["uncut_points"] == 0
    for name, feature in facts["per_feature"].items():  # tip lands included: the land passes finish them
        assert feature["max_leftover_mm"] <= target + RES, name
        assert feature["max_gouge_mm"] <= RES, name


def test_one_flank_pass_left_out_leaves_material_on_that_flank_only(reference):
    job, plan = reference
    path = plan.finishing.toolpath
    rows = _cut_rows(path, Feature.RIGHT_FLANK, SPACE)  # flank passes (tip -> root), then the fillet's
    dropped = int(rows[plan.finishing.result.facts.flank_passes_per_flank // 2])
    keep = np.ones(len(path), bool)
    keep[dropped] = False
    result = _simulate(job, plan, subset(path, keep))
    target = job.finishing.target_scallop_mm
    dev = result.deviation[:, :, result.gear_rows]
    assert dev.max() > target + RES
    worst = result.worst(gouge=False)
    assert worst.space == SPACE and worst.feature.endswith(("involute", "fillet")), worst
    others = [k for k in range(job.gear.teeth) if k != SPACE]
    assert dev[others].max() <= target + RES
    assert -dev.min() <= RES


def test_a_root_pass_20um_too_low_is_a_20um_gouge_in_that_root(reference):
    job, plan = reference
    path = plan.finishing.toolpath
    rows = _cut_rows(path, Feature.ROOT, SPACE)
    middle = int(rows[len(rows) // 2])
    z = path.z.copy()
    z[[middle - 1, middle]] -= 0.020  # the plunge's end and the pass along X
    result = _simulate(job, plan, subset(path, np.ones(len(path), bool), z=z))
    dev = result.deviation[:, :, result.gear_rows]
    assert -dev.min() == pytest.approx(0.020, abs=RES)
    worst = result.worst(gouge=True)
    assert worst.space == SPACE and worst.feature in ("root", "right fillet", "left fillet"), worst
    others = [k for k in range(job.gear.teeth) if k != SPACE]
    assert -dev[others].min() <= RES


# (gear, tool diameter, corner radius): the other gears of the acceptance (tests/test_generating.py's CASES)
OTHER_GEARS = [("undercut_z8", 1.45, 0.6), ("many_teeth_z120", 0.77, 0.25), ("shifted_z12_x04", 2.1, 0.5),
               ("pa25_z31_negative_shift", 1.13, 0.5)]


@pytest.mark.parametrize("name, diameter, corner", OTHER_GEARS)
def test_finishing_by_generation_alone_cuts_other_gears_from_the_blank_within_target(name, diameter, corner):
    """No roughing: the blank (tip radius + 0.5 mm) cut by the generating passes alone must come out as the
    design, every feature within the target + resolution, no gouge beyond the resolution."""
    from spur_cad.cam.finishing import plan_finishing
    from spur_cad.cam.machine import Machine
    from spur_cad.cam.strategies import FinishingParams
    from spur_cad.cam.tools import Tool
    from spur_cad.sim import StockCylinder
    from tests.test_generating import _gear

    spec = _gear(name)
    tool = Tool(diameter_mm=diameter, kind="bull_nose", corner_radius_mm=corner, flutes=2)
    blank = spec.tip_radius_mm + 0.5
    path, _ = plan_finishing(spec, tool, Machine(), FinishingParams(strategy="generating"), blank)
    result = simulate(spec, StockCylinder(blank, 0.0, spec.face_width_mm), [Cut(path, tool)],
                      SimSettings(resolution_mm=RES))
    facts = simulation_section(result, RES)
    assert facts["uncut_points"] == 0
    for feature, values in facts["per_feature"].items():
        assert values["max_gouge_mm"] <= RES, (feature, values)
        assert values["max_leftover_mm"] <= 0.005 + RES, (feature, values)
