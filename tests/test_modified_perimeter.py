"""Perimeter finishing of modified flanks (issue 31.3): each station's contacts on the flanks modified at its X.
A small spur gear (4 mm face) with a parabolic tip relief (the left flank's larger), a root relief and lead
crowning: the simulated cut lies on the MODIFIED design within the target and without gouge, the grading reads
every relief as designed within 1 um, and rs274 reads the program. Strategies that do not follow modifications
still refuse them."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from spur_cad.cam.tools import ToolError
from spur_cad.grade.design_trace import modifications_cut
from spur_cad.grade.simulated import grade_simulation
from spur_cad.job import parse_job
from spur_cad.pipeline import job_stock, plan_cam
from spur_cad.sim import Cut, SimSettings, simulate, subset
from tests.test_modified_cam import RES, TOOLS

GEAR = "[gear]\nteeth = 23\nmodule_mm = 4.0\nface_width_mm = 4\nrack_tip_radius_mm = 1.52\n"
MODS = ("[gear.modifications]\ntip_relief_um = 15\ntip_relief_start_diameter_mm = 98\ntip_relief_shape = 'parabolic'\n"
        "root_relief_um = 8\nroot_relief_start_diameter_mm = 93\nlead_crowning_um = 10\n"
        "[gear.modifications.left]\ntip_relief_um = 20\n")
"""The left flank's own tip relief: a side swapped between the contacts and the design reads 5 um off."""
PERIMETER = "[finishing]\nstrategy = 'perimeter'\n"
SPACES = [0, 1, 2]
GOUGE_MM = 0.001


@pytest.fixture(scope="module")
def cut():
    """(job, plan, simulation of spaces 0-2 against the modified design, its grading on the three spaces)."""
    job = parse_job(GEAR + TOOLS + PERIMETER + MODS, "perimeter.toml")
    plan = plan_cam(job)

    def of(path):
        return subset(path, np.isin(path.space, SPACES))

    result = simulate(job.gear, job_stock(job), [Cut(of(plan.roughing.toolpath), job.tools.roughing),
                                                 Cut(of(plan.finishing.toolpath), job.tools.finishing)],
                      SimSettings(resolution_mm=RES), modifications=job.modifications)
    three = dataclasses.replace(result, grid=dataclasses.replace(result.grid, teeth=len(SPACES)),
                                deviation=result.deviation[SPACES])
    return job, plan, result, grade_simulation(job.gear, three, None, job.modifications)


def test_the_perimeter_cut_lies_on_the_modified_design(cut):
    job, plan, result, _ = cut
    assert plan.finishing.result.strategy == "perimeter" and plan.finishing.result.stations > 10
    middle = result.deviation[1][:, result.gear_rows]
    target = job.finishing.target_scallop_mm
    assert -middle.min() <= GOUGE_MM, f"gouge {-1000 * middle.min():.2f} um"
    # within the target and the simulation's own error (cusps between clipped poses, at most half its resolution)
    assert middle.max() <= target + RES / 2, f"leftover {1000 * middle.max():.2f} um"


def test_the_grading_reads_each_relief_as_designed(cut):
    job, _, _, grading = cut
    cuts = modifications_cut([t for t in grading.traces if t.space == 1], job.modifications)
    read = {(c.side, c.symbol): c for c in cuts}
    for side, tip_um in (("right", 15.0), ("left", 20.0)):
        assert read[side, "C_a"].designed_um == tip_um
        assert read[side, "C_f"].designed_um == 8.0 and read[side, "C_beta"].designed_um == 10.0
    for c in cuts:
        assert c.cut_um == pytest.approx(c.designed_um, abs=1.0), f"{c.side} {c.sentence}"


@pytest.mark.linuxcnc
def test_rs274_reads_the_modified_perimeter_program(cut, tmp_path):
    from spur_cad.post import PostSettings, ProgramInfo, post_program
    from tests.rs274_helper import run_rs274
    from tests.test_post import assert_same_moves, canonical_moves

    _, plan, _, _ = cut
    path = subset(plan.finishing.toolpath, plan.finishing.toolpath.space == 0)  # one space at every station
    program = post_program(path, PostSettings(), ProgramInfo("modified perimeter test", ()))
    target = tmp_path / "perimeter.ngc"
    target.write_text(program.text)
    ok, canon, messages = run_rs274(target)
    assert ok, messages
    assert_same_moves(canonical_moves(canon), path, 4, 4)


def test_along_x_still_refuses_modifications():
    with pytest.raises(ToolError, match="along_x' does not cut flank modifications"):
        plan_cam(parse_job(GEAR + TOOLS + "[finishing]\nstrategy = 'along_x'\n" + MODS, "along_x.toml"))


def test_the_work_limit_counts_the_modified_contacts_before_building_them():
    """Reliefs split and curve the flanks, so a modified perimeter finish takes more contacts than the design the
    work check estimated (1.26 times on this gear): a 220 mm face is 8.8 million moves by the design's count, under
    the limit, and 11.1 million on the modified flanks, over it. It is refused before its toolpath is built."""
    from spur_cad.cam.ir import MAX_TOOLPATH_MOVES
    from spur_cad.cam.plan import params_from_section
    from spur_cad.cam.strategies.perimeter import PerimeterStrategy
    from spur_cad.errors import WorkLimitError

    reliefs = MODS.split("lead_crowning_um")[0]  # no lead modification: every station shares its contacts
    job = parse_job(GEAR.replace("face_width_mm = 4", "face_width_mm = 220") + TOOLS + PERIMETER + reliefs, "w.toml")
    strategy = PerimeterStrategy()
    params = params_from_section(strategy, job.finishing)
    assert strategy.estimate_moves(job.gear, job.tools.finishing, params) < MAX_TOOLPATH_MOVES
    with pytest.raises(WorkLimitError, match=r"finishing would need about 1\.1e\+07 moves") as refused:
        strategy.generate(job.gear, job.tools.finishing, job.machine, params, job.stock.blank_radius_mm(job.gear),
                          job.modifications)
    assert refused.value.field == "target_scallop_mm"
