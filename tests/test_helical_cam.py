"""Helical gears cut: roughing along the lead against the textbook lead (dA = -hand 360 dX / p_z), the
simulator's helical design against the B-rep, the simulated roughing against its promise (the design is
never touched, the finish stock kept), a wrong hand caught, and LinuxCNC's interpreter on the program."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from spur_cad.cam.ir import Feature, MoveKind
from spur_cad.geometry.frames import turn_points
from spur_cad.job import load_job
from spur_cad.pipeline import job_stock, plan_cam
from spur_cad.sim import Cut, SimSettings, simulate, subset
from tests.textbook import HelicalTextbook

HELICAL_EXAMPLE = Path(__file__).resolve().parents[1] / "resources" / "examples" / "helical_gear.toml"
RES = 0.005


def _job(hand: str = "right"):
    job = load_job(HELICAL_EXAMPLE)
    if hand != job.gear.hand:
        job = dataclasses.replace(job, gear=dataclasses.replace(job.gear, hand=hand))
    return job


def _book(spec) -> HelicalTextbook:
    return HelicalTextbook(spec.teeth, spec.module_mm, spec.pressure_angle_deg, spec.helix_angle_deg,
                           x=spec.profile_shift_coefficient, rho=spec.rack_tip_radius_mm,
                           allowance_fraction=spec.thickness_allowance_fraction)


@pytest.fixture(scope="module", params=["right", "left"])
def roughed(request):
    job = _job(request.param)
    plan = plan_cam(job)
    return job, plan


def test_every_cutting_pass_follows_the_textbook_lead(roughed):
    job, plan = roughed
    path = plan.roughing.toolpath
    lead = _book(job.gear).lead
    hand = 1.0 if job.gear.hand == "right" else -1.0
    start = path.start_poses()
    passes = (path.feature == Feature.LEVEL) & (path.kind == MoveKind.LINEAR) & (path.x != start[:, 0])
    assert passes.sum() > 1000
    dx, da = path.x[passes] - start[passes, 0], path.a[passes] - start[passes, 3]
    np.testing.assert_allclose(da, -hand * 360.0 * dx / lead, rtol=1e-12, atol=1e-12)
    assert path.inverse_time[passes].all()
    # Every move of a space keeps the space under the tool: A + turn(X) is the space's index angle.
    k = path.space[passes]
    np.testing.assert_allclose(path.a[passes] + hand * 360.0 * path.x[passes] / lead, -k * 360.0 / job.gear.teeth,
                               atol=1e-9)


def test_simulated_roughing_keeps_the_finish_stock_and_a_wrong_hand_gouges(roughed):
    job, plan = roughed
    stock = job_stock(job)
    settings = SimSettings(resolution_mm=RES)
    tool = job.tools.roughing
    result = simulate(job.gear, stock, [Cut(plan.roughing.toolpath, tool)], settings)
    dev = result.deviation[:, :, result.gear_rows]
    finish_stock = job.roughing.finish_stock_mm
    assert dev.min() >= finish_stock - RES / 2, dev.min()  # the design is never touched, the finish stock kept
    flanks = np.isin(result.grid.feature_names(), ["right involute", "left involute"])
    # Flanks: the planned staircase (flank allowance) plus what the helix costs the passes' reach (docs/cam.md).
    assert dev[:, flanks].max() <= 1.25 * job.roughing.flank_allowance_mm
    assert result.uncut_points == 0
    # Planted fault: the lowest level of one space programmed for the other hand cuts into the flanks by far
    # more than the stock (the same moves for the right hand do not). A wrong hand does not follow this
    # design's lead, so the simulator samples its poses: one level keeps that quick.
    other = "left" if job.gear.hand == "right" else "right"
    wrong = plan_cam(dataclasses.replace(job, gear=dataclasses.replace(job.gear, hand=other))).roughing.toolpath
    for path, gouges in ((plan.roughing.toolpath, False), (wrong, True)):
        lowest = (path.space == 3) & (path.station == path.station[path.space == 3].max())
        lowest[np.nonzero(lowest)[0][0] - 1] = True  # the move to the level's start
        result = simulate(job.gear, stock, [Cut(subset(path, lowest), tool)], settings)
        assert result.max_gouge_mm > 0.3 if gouges else result.max_gouge_mm == 0.0, result.max_gouge_mm


@pytest.mark.slow
def test_the_simulated_design_lies_on_the_brep_at_every_row():
    """The simulator's helical rows (the transverse points turned by its twist) against the B-rep's surface."""
    import cadquery as cq
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape
    from OCP.gp import gp_Pnt

    from spur_cad.cad.solid import build_gear_shape
    from spur_cad.sim.design import design_grid

    for hand in ("right", "left"):
        spec = dataclasses.replace(_job().gear, hand=hand)
        shape, _ = build_gear_shape(spec)
        grid = design_grid(spec, 0.3, 0.0, spec.face_width_mm)
        compound = cq.Compound.makeCompound([f for f in cq.Shape.cast(shape).Faces()
                                             if abs(f.normalAt().x) < 0.99]).wrapped
        worst = 0.0
        for x in (0.0, 7.0, spec.face_width_mm):
            points = turn_points(grid.points, grid.twist_rad_per_mm * x)
            for y, z in points[::7]:
                extrema = BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeVertex(gp_Pnt(x, y, z)).Vertex(), compound)
                extrema.Perform()
                worst = max(worst, extrema.Value())
        assert worst < 1e-3, (hand, worst)


def _canonical(canon):
    from tests.rs274_helper import canon_args

    moves = []
    for line in canon:
        if line.startswith(("STRAIGHT_FEED", "STRAIGHT_TRAVERSE")):
            x, y, z, a = canon_args(line)[:4]
            moves.append((line.split("(")[0], (x, y, z, a)))
    return moves


@pytest.mark.linuxcnc
def test_rs274_reads_the_helical_roughing_program_with_the_lead_in_inverse_time(tmp_path):
    from spur_cad.post import PostSettings, ProgramInfo, post_program
    from tests.rs274_helper import canon_args, run_rs274
    from tests.test_post import relative_path_length

    job = _job()
    path = plan_cam(job).roughing.toolpath
    lead = _book(job.gear).lead
    feed = job.tools.roughing.feed_mm_min(job.machine)
    info = ProgramInfo("spur_cad helical roughing test", ("gear: helical",))
    canon_by_mode = {}
    for folded in (False, True):
        program = post_program(path, PostSettings(folded=folded), info)
        assert "G93" in program.text
        target = tmp_path / f"helical_roughing_{folded}.ngc"
        target.write_text(program.text)
        ok, canon, messages = run_rs274(target)
        assert ok, messages
        rounded = np.round(path.poses()[path.motion_mask], 4)
        moving = 1 + int(np.any(rounded[1:] != rounded[:-1], axis=1).sum())  # the post leaves out null moves
        assert len(_canonical(canon)) == moving
        inverse, rate, pose, along = False, None, None, 0
        for line in canon:
            if "feed mode set to inverse time" in line:
                inverse = True
            elif "feed mode set to units per minute" in line:
                inverse = False
            elif line.startswith("SET_FEED_RATE"):
                rate = canon_args(line)[0]
            elif line.startswith(("STRAIGHT_FEED", "STRAIGHT_TRAVERSE")):
                end = np.array(canon_args(line)[:4])
                dx, da = (end - pose)[[0, 3]] if pose is not None else (0.0, 0.0)
                if line.startswith("STRAIGHT_FEED") and abs(dx) > 1.0 and np.all(end[1:3] == pose[1:3]):
                    assert da == pytest.approx(-360.0 * dx / lead, abs=2e-4)  # 4 decimals of A
                    assert inverse  # X and A together: inverse time, taking the relative path at the tool's feed
                    minutes = float(np.linalg.norm(end[:3] - pose[:3])) / rate  # rs274 reports a cartesian rate
                    assert minutes == pytest.approx(relative_path_length(pose, end) / feed, rel=2e-3)
                    along += 1
                pose = end
        assert along > 1000
        canon_by_mode[folded] = [line for line in canon if line.startswith("STRAIGHT")]
    assert canon_by_mode[True] == canon_by_mode[False]
