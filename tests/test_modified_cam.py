"""Generating finishing of modified flanks (issue 31.3) and the simulation against the modified design (31.5):
programs rs274 reads with A clamped in every feed move, the simulated cut within the target of the MODIFIED design
(so a correctly cut relief is no leftover; helical gears, lead modifications too, gouge it nowhere by more than 1 um),
and the same cut read against the unmodified design shows the relief."""

from __future__ import annotations

import numpy as np
import pytest

from spur_cad.job import parse_job
from spur_cad.pipeline import job_stock, plan_cam
from spur_cad.sim import Cut, SimSettings, simulate, subset
from tests.tiers import sweep

GEAR = "[gear]\nteeth = 23\nmodule_mm = 4.0\nface_width_mm = 20\nrack_tip_radius_mm = 1.52\n"
TOOLS = "[tools.finishing]\ndiameter_mm = 'auto'\ncorner_radius_mm = 'auto'\n[tools.roughing]\ndiameter_mm = 'auto'\n"
SPUR = GEAR + TOOLS + ("[gear.modifications]\ntip_relief_um = 15\ntip_relief_start_diameter_mm = 98\n"
                       "lead_crowning_um = 10\n")
HELICAL = GEAR + "helix_angle_deg = 15\n" + TOOLS + ("[gear.modifications]\ntip_relief_um = 12\n"
                                                   "tip_relief_start_diameter_mm = 97.5\n")
HELICAL_PROFILE = GEAR + "helix_angle_deg = 15\n" + TOOLS + (
    "[gear.modifications]\nprofile_crowning_um = 6\nprofile_slope_um = 5\nroot_relief_um = 8\n"
    "root_relief_start_diameter_mm = 93\ntip_relief_um = 12\ntip_relief_start_diameter_mm = 97.5\n")
"""Moves the form point (by 16.5 um): the helical tip passes follow the faded fillet (not moved: 12.8 um left)."""
SPUR_SIDES = GEAR + TOOLS + ("[gear.modifications]\ntip_relief_um = 15\ntip_relief_start_diameter_mm = 98\n"
                             "[gear.modifications.left]\ntip_relief_um = 20\ntip_relief_shape = \"parabolic\"\n")
"""Sides modified differently: their turned passes differ, and each flank's raised tool ends must follow its own
neighbours (taken from both sides' passes together they left 13.7 um on the left flank of the modified example)."""
HELICAL_LEAD = GEAR + "helix_angle_deg = 15\n" + TOOLS + "[gear.modifications]\nlead_crowning_um = 10\n"
"""Lead crowning on a helical gear: the flank passes' ends are raised per section X (unraised, their corners moved
sideways with the flank gouged the fillet by 5.5 um)."""
HELICAL_END = GEAR + "helix_angle_deg = 15\n" + TOOLS + ("[gear.modifications]\nend_relief_um = 10\n"
                                                        "end_relief_length_mm = 3\n")
LEVELS_ROUGHING = '[roughing]\nstrategy = "levels"\n'
RES = 0.002
GOUGE_MM = 0.001
"""Helical lead modifications: the cut reaches at most this far into the modified design anywhere (fillet too)."""


@pytest.fixture(scope="module", params=sweep(["spur", "spur sides", "helical", "helical profile", "helical lead",
                                              "helical end relief"], fast=["spur", "spur sides"]))
def planned(request):
    jobs = {"spur": SPUR, "spur sides": SPUR_SIDES, "helical": HELICAL, "helical profile": HELICAL_PROFILE,
            "helical lead": HELICAL_LEAD, "helical end relief": HELICAL_END}
    text = jobs[request.param]
    if request.param.startswith("helical"):  # what is asked of finishing, not of roughing: the quick roughing plan
        text += LEVELS_ROUGHING                # (a helical plan by flanks takes about 15 s of CPU, by levels 1 s)
    job = parse_job(text, "f.toml")
    return request.param, job, plan_cam(job)


def _simulated(job, plan, modifications):
    def of(path):
        return subset(path, np.isin(path.space, [0, 1, 2]))

    result = simulate(job.gear, job_stock(job), [Cut(of(plan.roughing.toolpath), job.tools.roughing),
                                                 Cut(of(plan.finishing.toolpath), job.tools.finishing)],
                      SimSettings(resolution_mm=RES), modifications=modifications)
    return result, result.deviation[1][:, result.gear_rows], np.array(result.grid.feature_names())


def test_an_unmodified_job_plans_straight_passes():
    plan = plan_cam(parse_job(GEAR + TOOLS, "f.toml"))
    assert all(p.path == () for p in plan.finishing.result.passes)


def test_the_cut_lies_on_the_modified_design_and_shows_the_relief_against_the_unmodified(planned):
    name, job, plan = planned
    result, middle, names = _simulated(job, plan, job.modifications)
    target = job.finishing.target_scallop_mm
    assert -middle.min() <= RES
    # within the target and the simulation's own error (cusps between clipped poses, at most half its resolution);
    # the spur relief's start kink and the contacts behind it are cut by their own passes (7 um at 5 um without)
    assert middle.max() <= target + RES / 2, f"{name}: leftover {1000 * middle.max():.2f} um"
    if name.startswith("helical"):  # the raised ends keep the flank passes' corners off the fillet
        for feature in ("right fillet", "left fillet", "right involute", "left involute"):
            deepest = -middle[names == feature].min()
            assert deepest <= GOUGE_MM, f"{name}: {feature} gouged {1000 * deepest:.2f} um"
    # against the unmodified design the tip relief reads as a gouge of about its amount near the tip
    if name == "helical profile":
        return
    from spur_cad.sim.design import modification_removal_mm

    removal = modification_removal_mm(job.gear, result.grid, job.modifications)[:, result.gear_rows]
    plain = middle - removal
    flank = names == "right involute"
    tip_relief_um = 1000 * job.modifications.right.tip_relief_mm
    at_faces_um = 1000 * job.modifications.right.lead_offset_mm([0.0, job.gear.face_width_mm]).max()
    assert -1000 * plain[flank].min() == pytest.approx(tip_relief_um + at_faces_um, abs=3.0)


@pytest.mark.linuxcnc
def test_rs274_reads_the_modified_finishing_program_with_a_clamped(planned, tmp_path):
    from spur_cad.post import PostSettings, ProgramInfo, post_program
    from tests.rs274_helper import run_rs274
    from tests.test_post import assert_same_moves, canonical_moves

    name, job, plan = planned
    path = plan.finishing.toolpath
    program = post_program(path, PostSettings(), ProgramInfo("modified finishing test", ()))
    target = tmp_path / "finishing.ngc"
    target.write_text(program.text)
    ok, canon, messages = run_rs274(target)
    assert ok, messages
    moves = canonical_moves(canon)
    assert_same_moves(moves, path, 4, 4)
    for (_, before), (rapid, after) in zip(moves, moves[1:]):
        if not rapid:
            assert after[3] == before[3]
    # lead crowning: some feed moves change Y along X within a pass
    assert name not in ("spur", "helical lead") or sum(1 for p in plan.finishing.result.passes if len(p.path) > 2) > 10
