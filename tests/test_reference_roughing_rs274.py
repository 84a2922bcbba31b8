"""Acceptance of the reference example's roughing as shipped (issue 48: roughing by flanks, the job files'
default): LinuxCNC's interpreter (rs274) reads the roughing program, and from its canonical moves alone, not from
spur_cad's toolpath, the time at the programmed feeds is at most 50 min (issue 29's target), and the tool's
silhouettes at the interpreted poses (tests/silhouette.py, the 2-D check: each pose's silhouette turned into the
part frame by its A) never come closer to the designed gear than the finish stock and leave nothing beyond the
flank allowance in any tooth space above its lowest pass (below it the finishing tool takes what is left: the
plunge allowance, checked by the plan)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from shapely.geometry import Polygon

from spur_cad.geometry import gear_outline
from spur_cad.job import load_job
from spur_cad.pipeline import build_programs, plan_cam
from tests import silhouette
from tests.gears import REFERENCE_JOB
from tests.rs274_helper import run_rs274
from tests.test_estimate_rs274 import interpreted_seconds
from tests.test_post import canonical_straight_moves

pytestmark = pytest.mark.linuxcnc
ROUGHING_LIMIT_MIN = 50.0  # issue 29's target for the reference job's roughing, at its programmed feeds
HALF_MICRON = 0.5e-3
TOOL_LENGTH_MM = 30.0
SUBSTEPS = 4  # poses along each interpreted move (A turns only on the links between passes)


@pytest.fixture(scope="module")
def interpreted(tmp_path_factory):
    """The shipped job, its plan and rs274's straight moves of its roughing program as (feed move, start, end)."""
    job = load_job(REFERENCE_JOB)
    plan = plan_cam(job)
    programs, _ = build_programs(job, plan)
    path = tmp_path_factory.mktemp("rs274") / "roughing.ngc"
    path.write_text(programs["roughing"].text)
    ok, canon, messages = run_rs274(path, timeout_s=300)
    assert ok, messages
    return job, plan, canon


def _poses(canon: list[str]) -> np.ndarray:
    """(X, Y, Z, A) along every straight move rs274 reads, SUBSTEPS per move, linear in each axis as the control
    moves."""
    t = np.arange(1, SUBSTEPS + 1)[:, None] / SUBSTEPS
    return np.concatenate([start + (end - start) * t for _, _, _, start, end in canonical_straight_moves(canon)
                           if start is not None])


def _passes(canon: list[str]) -> np.ndarray:
    """(X, Y, Z, A) at the end of every fed move along X alone (Y, Z and A held): the cutting passes, whose
    silhouette seen along X is what they remove (the links between them move Y, Z or A outside the blank)."""
    return np.array([end for feed, _, _, start, end in canonical_straight_moves(canon)
                     if feed and start is not None and np.allclose(start[1:], end[1:], atol=1e-9)
                     and start[0] != end[0]])


def test_the_shipped_reference_job_roughs_by_flanks_in_at_most_50_minutes(interpreted):
    job, plan, canon = interpreted
    assert job.roughing.strategy == "flank" and plan.flank_fallback is None
    assert plan.roughing.flank is not None
    minutes = interpreted_seconds(canon, job.machine) / 60.0
    assert minutes <= ROUGHING_LIMIT_MIN, minutes
    assert minutes == pytest.approx(plan.roughing.estimate.time_s / 60.0, rel=0.01)  # the report's figure


def test_the_interpreted_roughing_never_gouges_and_leaves_nothing_beyond_the_flank_allowance(interpreted):
    job, plan, canon = interpreted
    spec, tool, params = job.gear, job.tools.roughing, job.roughing
    design = Polygon(gear_outline(spec, 1e-5))
    # every pose (rapids and links too) where the tool's side can reach the gear's faces: nothing may reach into the
    # design grown by the finish stock (links turn A beyond the faces, in the air)
    every = _poses(canon)
    radius = tool.diameter_mm / 2.0
    every = every[(every[:, 0] > -radius) & (every[:, 0] < spec.face_width_mm + radius)]
    sils = silhouette.place_silhouettes(every[:, 1], every[:, 2], every[:, 3], tool.diameter_mm, 0.0, TOOL_LENGTH_MM)
    grown = design.buffer(params.finish_stock_mm - 1e-6, quad_segs=256)
    assert silhouette.max_penetration_mm(grown, list(sils)) <= HALF_MICRON
    cutting = _passes(canon)
    union = shapely.union_all(silhouette.place_silhouettes(cutting[:, 1], cutting[:, 2], cutting[:, 3],
                                                           tool.diameter_mm, 0.0, TOOL_LENGTH_MM))
    # each space k is cut at A = -k 360 / z; its middle slot's passes (A exactly that) reach its lowest level
    pitch_deg = 360.0 / spec.teeth
    blank = job.stock.blank_radius_mm(spec)
    disk = shapely.Point(0.0, 0.0).buffer(blank, quad_segs=1024)
    allowed = design.buffer(params.flank_allowance_mm + 1e-3, quad_segs=64)
    half = math.pi / spec.teeth
    left_mm2 = []
    for k in range(spec.teeth):
        a_deg = -k * pitch_deg
        at_space = np.abs(cutting[:, 3] - a_deg) < 1e-3  # rs274 prints A to 4 decimals
        lowest = float(cutting[at_space, 2].min())
        axis = silhouette.to_part_frame(0.0, 1.0, a_deg)
        centre = math.atan2(axis[0], axis[1])
        angles = centre + np.linspace(-half, half, 129)
        sector = Polygon(np.concatenate([[[0.0, 0.0]],
                                         2.0 * blank * np.stack([np.sin(angles), np.cos(angles)], axis=1)]))
        # above the lowest pass: the half-plane of points whose height on the space's axis is at least `lowest`
        normal = np.array([axis[0], axis[1]])
        across, up = 2.0 * blank * np.array([normal[1], -normal[0]]), 2.0 * blank * normal
        base = lowest * normal
        above = Polygon([base - across, base + across, base + across + up, base - across + up])
        stock = disk.intersection(sector).intersection(above)
        left_mm2.append(stock.difference(union).difference(allowed).area)
    assert max(left_mm2) <= 1e-4, left_mm2
