"""Corrected programs from a measured gear (`spur-cad correct`, docs/correction.md): identify the machine's
errors (spur_cad.correct.identify), re-plan the job with the tool offset, turn each space's A words by its index
correction and post the corrected finishing program with correction.json."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from spur_cad.correct.identify import ARCSEC_RAD, IdealFlanks, Identified
from spur_cad.grade.simulated import SIDES

IDEAL_RESOLUTION_MM = 0.002
"""The ideal cut is simulated this finely: its scallops' mean (1.6 um for the reference gear's 5 um target) must
be known to a fraction of a micrometre, since the measured mean less it is the tool's size error."""


def finishing_cut(spec, path, tool, stock, x_range_mm: tuple[float, float], stations=None,
                  resolution_mm: float = IDEAL_RESOLUTION_MM):
    """The finishing toolpath alone cut into the stock cylinder over `x_range_mm` (spur_cad.sim.simulate): the
    flanks are the finishing's, whatever roughing left."""
    from spur_cad.sim.simulate import Cut, SimSettings, simulate

    return simulate(spec, stock, [Cut(path, tool)], SimSettings(resolution_mm=resolution_mm),
                    station_x=stations, rows_x_range=x_range_mm)


def ideal_flanks(job, plan) -> IdealFlanks:
    """What the job's finishing leaves on an ideal machine over the face, per side against roll length (the mean
    over spaces and rows at each design point)."""
    from spur_cad.pipeline import job_stock

    spec = job.gear
    result = finishing_cut(spec, plan.finishing.toolpath, plan.finishing.tool, job_stock(job),
                           (0.0, spec.face_width_mm), plan.finishing.result.station_x_mm)
    grid = result.grid
    names = grid.feature_names()
    mean = result.gear_deviation.mean(axis=(0, 2))
    radius = np.hypot(grid.points[:, 0], grid.points[:, 1])
    roll = np.sqrt(np.maximum(radius ** 2 - spec.base_radius_mm ** 2, 0.0))
    rolls, deviations = {}, {}
    for side in SIDES:
        on = np.array([name == f"{side} involute" for name in names])
        order = np.argsort(roll[on])
        rolls[side], deviations[side] = roll[on][order], mean[on][order]
    return IdealFlanks(rolls, deviations)


def turned_by_space(path, turn_deg: np.ndarray):
    """A copy of the toolpath with every move of space k (path.space == k) turned by turn_deg[k] in A; moves of no
    space keep their A (what the machine's index table adds, or the correction that takes it off)."""
    a = path.a.copy()
    in_space = path.space >= 0
    a[in_space] += np.asarray(turn_deg)[path.space[in_space]]
    return path.replace(a=a)


def corrected_job(job, identified: Identified):
    """The job with the finishing tool's diameter changed by the size error (2 x: the radius cuts each flank):
    material left (+) asks for a smaller programmed tool, which cuts deeper."""
    tools = job.tools
    finishing = dataclasses.replace(tools.finishing,
                                    diameter_mm=tools.finishing.diameter_mm - 2.0 * identified.size_um / 1000.0)
    return dataclasses.replace(job, tools=dataclasses.replace(tools, finishing=finishing))


def index_correction_deg(identified: Identified) -> np.ndarray:
    """Each space's A correction (deg): minus its index error; 0 where the space was not measured."""
    return -np.nan_to_num(identified.index_arcsec) * ARCSEC_RAD * 180.0 / math.pi
