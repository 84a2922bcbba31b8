"""Grading a modified gear against its design (issue 31.5): the simulated cut of tests/test_modified_cam.py's jobs
(spur: tip relief, lead crowning and a profile slope; helical: tip relief and lead crowning) graded by ISO 1328-1
with the design profile and helix is in the class of the same gear unmodified, and the modifications read from the
cut flanks (ISO 21771 amounts) are the designed ones within 1 um. Graded on the middle of three simulated spaces."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from spur_cad.grade.design_trace import modifications_cut
from spur_cad.grade.grading import HELIX_DEVIATIONS, PROFILE_DEVIATIONS, classes_of, worst_deviations
from spur_cad.grade.simulated import grade_simulation
from spur_cad.job import parse_job
from spur_cad.pipeline import job_stock, plan_cam
from spur_cad.sim import Cut, SimSettings, simulate, subset
from tests.test_modified_cam import GEAR, RES, TOOLS
from tests.tiers import sweep

SPUR_MODS = ("[gear.modifications]\ntip_relief_um = 15\ntip_relief_start_diameter_mm = 98\nlead_crowning_um = 10\n"
             "profile_slope_um = 8\n")
HELICAL = GEAR + "helix_angle_deg = 15\n" + TOOLS
HELICAL_MODS = "[gear.modifications]\ntip_relief_um = 12\ntip_relief_start_diameter_mm = 97.5\nlead_crowning_um = 10\n"
SPACES = [0, 1, 2]
ROUGHING = {"spur": "", "helical": '[roughing]\nstrategy = "levels"\n'}
"""What is graded is the finishing: the helical gear is roughed by levels, the quick plan (by flanks, its default, a
helical plan takes about 15 s of CPU, by levels 1 s)."""
FINISHING = "[finishing]\ntarget_scallop_mm = 0.004\n"
"""A 5 um target leaves the profile form f_fa at the class-4 tolerance (5.0 um) itself, where the resolution's
hundredths of a micrometre would decide the class."""
FLANK_DEVIATIONS = PROFILE_DEVIATIONS + HELIX_DEVIATIONS


def _simulated(job):
    """The job's roughing and finishing of spaces 0-2, measured against its (modified) design."""
    plan = plan_cam(job)

    def of(path):
        return subset(path, np.isin(path.space, SPACES))

    return simulate(job.gear, job_stock(job), [Cut(of(plan.roughing.toolpath), job.tools.roughing),
                                               Cut(of(plan.finishing.toolpath), job.tools.finishing)],
                    SimSettings(resolution_mm=RES), modifications=job.modifications)


def _graded(job):
    """grade_simulation of the cut, on the three simulated spaces, and the middle space's traces."""
    result = _simulated(job)
    three = dataclasses.replace(result, grid=dataclasses.replace(result.grid, teeth=len(SPACES)),
                                deviation=result.deviation[SPACES])
    grading = grade_simulation(job.gear, three, None, job.modifications)
    return grading, [t for t in grading.traces if t.space == 1]


def _flank_grade(job, measured):
    """Profile and helix deviations of the traces and their classes (no pitch: three spaces were cut)."""
    worst, _ = worst_deviations(measured)
    worst = {name: worst[name] for name in FLANK_DEVIATIONS}
    classes, overall = classes_of(job.gear, worst, set(worst))
    return worst, classes, overall


@pytest.fixture(scope="module", params=sweep(["spur", "helical"], fast=["spur"]))
def graded(request):
    """(name, modified job, its grading, its space-1 traces, the unmodified job's flank grade of space 1)."""
    plain, mods = {"spur": (GEAR + TOOLS, SPUR_MODS), "helical": (HELICAL, HELICAL_MODS)}[request.param]
    plain += FINISHING + ROUGHING[request.param]
    modified_job, plain_job = parse_job(plain + mods, "m.toml"), parse_job(plain, "p.toml")
    grading, measured = _graded(modified_job)
    plain_grading, plain_traces = _graded(plain_job)
    assert plain_grading.modifications_cut is None and all(t.design_um is None for t in plain_traces)
    return request.param, modified_job, grading, measured, _flank_grade(plain_job, plain_traces)


def test_a_correctly_cut_modified_gear_grades_as_the_unmodified_one(graded):
    name, job, _, measured, (plain_worst, _, plain_class) = graded
    worst, classes, overall = _flank_grade(job, measured)
    # no worse than the unmodified gear (a relief's own contacts may make the profile finer: class 3 against 4)
    assert overall <= plain_class, f"{name}: {worst} in {classes}, unmodified {plain_worst} in class {plain_class}"


def test_the_modifications_read_from_the_cut_flanks_are_the_designed_ones(graded):
    name, job, grading, measured, _ = graded
    cuts = modifications_cut(measured, job.modifications)
    read = {(c.side, c.symbol): c for c in cuts}
    assert {symbol for _, symbol in read} >= {"C_a", "f_Halpha", "f_Hbeta", "C_beta"}
    for cut in cuts:
        assert cut.cut_um == pytest.approx(cut.designed_um, abs=1.0), f"{name}: {cut.side} {cut.sentence}"
    assert read["left", "C_beta"].designed_um == 10.0 and read["right", "C_beta"].designed_um == 10.0
    if name == "spur":
        assert read["right", "f_Halpha"].designed_um == 8.0
    # the grading over the three spaces says the same, in summary.json's grading
    listed = grading.to_json()["modifications_cut"]
    tip = next(item for item in listed if item["symbol"] == "C_a" and item["side"] == "right")
    assert tip["designed_um"] == 1000 * job.modifications.right.tip_relief_mm
    assert tip["cut_um"] == pytest.approx(tip["designed_um"], abs=1.0) and tip["traces"] == 3 * len(SPACES)


def test_ignoring_the_design_trace_fails_the_grade(graded):
    """The planted fault: the same cut graded against the unmodified design (the design trace ignored)."""
    name, job, _, measured, (_, _, plain_class) = graded
    ignored = [dataclasses.replace(t, deviation_um=t.deviation_um + t.design_um, design_um=None) for t in measured]
    worst, classes, overall = _flank_grade(job, ignored)
    assert overall is None or overall > plain_class, f"{name}: {worst} in {classes}"
