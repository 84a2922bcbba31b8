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


NOT_CORRECTED = {
    "profile_slope": "not identified yet: a profile slope per side would change the passes' positions along the "
                     "profile; the programs keep the design's",
    "helix_slope": "not identified yet: a helix slope per side would turn the passes along X; the programs keep "
                   "the design's",
    "form": "form ripple (scallops, vibration, the table's error within one space's roll) is not a position the "
            "program can move: it is left as cut",
    "side_size_difference": "the left and right flanks' size difference: a scan's fitted rotation takes half of it, "
                            "and a tool offset moves both flanks alike; only the mean size is corrected",
    "mean_index": "the mean index error is a turn of the whole gear, which a scan's fitted rotation takes: the "
                  "corrections are relative to it",
}


def correction_summary(spec, identified: Identified, finishing_tool_before, finishing_tool_after,
                       a_correction_deg: np.ndarray, measured_source: str) -> dict:
    """correction.json: each error identified with its standard uncertainty, what the programs change, the flank
    positions before and as predicted after, and what was not corrected and why."""
    reference_arc_um = spec.reference_radius_mm * ARCSEC_RAD * 1000.0  # um of arc per arcsec on the reference circle
    index = identified.index_arcsec
    measured = np.isfinite(index)
    spread_um = float(np.nanmax(index) - np.nanmin(index)) * reference_arc_um
    return {
        "measured": measured_source,
        "model": "deviation = size - index error x (p x n) + the ideal cut's (docs/correction.md)",
        "scan_turn_deg": round(identified.scan_turn_deg, 6),
        "centre_shift_um": [round(v, 3) for v in identified.centre_shift_um],
        "points_used": identified.points_used,
        "size_error_um": {"value": round(identified.size_um, 3),
                          "uncertainty": round(identified.size_uncertainty_um, 3),
                          "by_side": {side: round(v, 3) for side, v in identified.side_size_um.items()},
                          "meaning": "+: material left (the tool cut too little); -: the tool cut too much"},
        "index_error_arcsec": {"values": [None if not ok else round(float(v), 3) for v, ok in zip(index, measured)],
                               "uncertainty": round(identified.index_uncertainty_arcsec, 3),
                               "meaning": "per space (machine numbering), relative to their mean: the table stood "
                                          "this much further in A than commanded"},
        "corrections": {
            "finishing_tool_diameter_mm": {"before": finishing_tool_before.diameter_mm,
                                           "programmed": round(finishing_tool_after.diameter_mm, 6),
                                           "why": "the finishing toolpath is regenerated for the tool as it cuts: "
                                                  "its tip centre is programmed without cutter compensation, so "
                                                  "a controller's wear offset would not move it"},
            "a_correction_deg": [round(float(v), 7) for v in a_correction_deg],
            "unmeasured_spaces": [int(k) for k in np.nonzero(~measured)[0]],
        },
        "before": {"flank_position_um": round(identified.size_um, 3),
                   "index_spread_on_reference_circle_um": round(spread_um, 3)},
        "predicted_after": {"flank_position_um": 0.0, "flank_position_uncertainty_um":
                            round(identified.size_uncertainty_um, 3), "index_spread_on_reference_circle_um": 0.0,
                            "index_uncertainty_on_reference_circle_um":
                                round(identified.index_uncertainty_arcsec * reference_arc_um, 3)},
        "not_corrected": NOT_CORRECTED,
    }


def correct_job(job, measured, measured_source: str):
    """Identify the errors in `measured` (spur_cad.grade.measured.MeasuredPoints) and build the corrected output set:
    every program re-planned with the finishing tool as it cuts, each space's A words turned by its correction
    (all operations: the table errs alike for each), and correction.json. Returns (Identified, {name: bytes})."""
    import json

    from spur_cad.correct.identify import identify
    from spur_cad.errors import SpurCadError
    from spur_cad.pipeline import build_programs, plan_cam

    spec = job.gear
    if spec.is_helical:
        raise SpurCadError("correcting from measured points of a helical gear is not supported yet (spur gears only)")
    if job.tools.finishing is None:
        raise SpurCadError("the job has no [tools.finishing]: there is no finishing program to correct")
    plan = plan_cam(job)
    try:
        identified = identify(spec, measured, ideal_flanks(job, plan))
    except ValueError as exc:
        raise SpurCadError(f"{measured_source}: {exc}") from None
    fixed = corrected_job(job, identified)
    fixed_plan = plan_cam(fixed)
    correction = index_correction_deg(identified)
    turned = {name: dataclasses.replace(planned, toolpath=turned_by_space(planned.toolpath, correction))
              for name in ("roughing", "roughing_bottom", "finishing")
              if (planned := getattr(fixed_plan, name)) is not None}
    notes = (f"corrected from {measured_source}: finishing tool programmed as D "
             f"{fixed.tools.finishing.diameter_mm:.4f} mm (size error {identified.size_um:+.2f} um), A of each space "
             "turned by its index correction (correction.json)",)
    _, files = build_programs(fixed, dataclasses.replace(fixed_plan, **turned), notes)
    summary = correction_summary(spec, identified, job.tools.finishing, fixed.tools.finishing, correction,
                                 measured_source)
    files["correction.json"] = (json.dumps(summary, indent=2) + "\n").encode()
    return identified, files
