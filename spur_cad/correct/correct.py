"""Corrected programs from a measured gear (`spur-cad correct`, docs/correction.md): identify the machine's
errors (spur_cad.correct.identify), re-plan the job with the tool offset, turn each space's A words by its index
correction and post the corrected finishing program with correction.json."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from spur_cad.cam.ir import Feature
from spur_cad.correct.identify import ARCSEC_RAD, IdealFlanks, Identified
from spur_cad.grade.measured import MeasuredPoints
from spur_cad.grade.simulated import SIDES, helix_range_mm, profile_range_mm

IDEAL_RESOLUTION_MM = 0.002
"""The ideal cut is simulated this finely: its scallops' mean (1.6 um for the reference gear's 5 um target) must
be known to a fraction of a micrometre, since the measured mean less it is the tool's size error."""


def finishing_cut(spec, path, tool, stock, x_range_mm: tuple[float, float], stations=None,
                  resolution_mm: float = IDEAL_RESOLUTION_MM, modifications=None):
    """The finishing toolpath alone cut into the stock cylinder over `x_range_mm` (spur_cad.sim.simulate): the
    flanks are the finishing's, whatever roughing left; deviations from the modified design with `modifications`."""
    from spur_cad.sim.simulate import Cut, SimSettings, simulate

    return simulate(spec, stock, [Cut(path, tool)], SimSettings(resolution_mm=resolution_mm),
                    station_x=stations, rows_x_range=x_range_mm, modifications=modifications)


def ideal_flanks(job, plan) -> IdealFlanks:
    """What the job's finishing leaves on an ideal machine over the face, per side against roll length (the mean
    over spaces and rows at each design point), from the modified design when the job has modifications: the
    scallops alone, as identify reads the measured points."""
    from spur_cad.pipeline import job_stock

    spec = job.gear
    result = finishing_cut(spec, plan.finishing.toolpath, plan.finishing.tool, job_stock(job),
                           (0.0, spec.face_width_mm), plan.finishing.result.station_x_mm,
                           modifications=job.modifications)
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


SLOPE_STRATEGY = "generating"
"""The finishing strategy whose passes can follow a slope: each generating flank pass is one straight line along X,
tangent to the involute at one roll, its normal along the machine's Y (spur_cad.cam.strategies.generating_geometry)."""

FLANK_SIDES = {Feature.RIGHT_FLANK: "right", Feature.LEFT_FLANK: "left"}


def pressure_angle_change_deg(spec, profile_slope_um: float) -> float:
    """The pressure angle as cut minus the design's (deg) that a profile slope f_Halpha over the evaluation length
    L_alpha means (docs/correction.md): a base radius changed by eps r_b, the tooth thickness on the reference circle
    held, moves the flank at roll length L by eps (L - L_ref) along its normal, so f_Halpha = eps L_alpha; with r_b =
    r cos(alpha), eps = -tan(alpha) d_alpha: d_alpha = -f_Halpha / (L_alpha tan alpha)."""
    start, end = profile_range_mm(spec)
    return -math.degrees(profile_slope_um / 1000.0 / ((end - start) * math.tan(spec.pressure_angle_rad)))


def slope_corrected_passes(spec, passes, identified: Identified) -> tuple:
    """The generating passes with each flank pass moved along its normal (the machine's Y, toward the material it
    cuts: `side`) by what the identified slopes left at its line: the profile slope at the pass's contact roll
    length r_b t (0 at the middle of the evaluation range, so the flank's mean position is the size correction's)
    and the helix slope along X (0 at the middle of the helix range): a Y offset and a Y rate along X. Fillet, root
    and land passes keep their place."""
    start, end = profile_range_mm(spec)
    front, back = helix_range_mm(spec.face_width_mm, spec.module_mm)
    moved = []
    for p in passes:
        side = FLANK_SIDES.get(p.feature)
        if p.mode != "flank" or side is None:
            moved.append(p)
            continue
        profile_mm = identified.profile_slope_um.get(side, 0.0) / 1000.0
        helix_per_x = identified.helix_slope_um.get(side, 0.0) / 1000.0 / (back - front)
        roll_mm = spec.base_radius_mm * p.roll_rad
        remove_mm = profile_mm * (roll_mm - 0.5 * (start + end)) / (end - start) - helix_per_x * 0.5 * (front + back)
        moved.append(dataclasses.replace(p, y_mm=p.y_mm + p.side * remove_mm,
                                         dy_per_x=p.dy_per_x + p.side * helix_per_x))
    return tuple(moved)


def slope_corrected_finishing(job, finishing, identified: Identified):
    """The finishing plan with its passes moved for the slopes (slope_corrected_passes), or unchanged (with the
    reason) when its strategy has no straight passes to move."""
    from spur_cad.cam.strategies.generating import passes_toolpath

    if finishing.result.strategy != SLOPE_STRATEGY:
        return finishing, (f"the {finishing.result.strategy} finishing strategy's moves are not straight passes "
                           "tangent at one roll: the slopes are not corrected (generating finishing can follow them)")
    spec = job.gear
    passes = slope_corrected_passes(spec, finishing.result.passes, identified)
    toolpath = passes_toolpath(spec, finishing.tool, job.machine, finishing.result.params, passes,
                               job.stock.blank_radius_mm(spec))
    return dataclasses.replace(finishing, toolpath=toolpath,
                               result=dataclasses.replace(finishing.result, passes=passes)), None


NOT_CORRECTED = {
    "slopes_off_the_involute": "the fillet, root and land passes keep their place: a slope is measured on the "
                               "involute only, and the generating flank passes move alone",
    "form": "form ripple (scallops, vibration, the table's error within one space's roll) is not a position the "
            "program can move: it is left as cut",
    "side_size_difference": "the left and right flanks' size difference: a scan's fitted rotation takes half of it, "
                            "and a tool offset moves both flanks alike; only the mean size is corrected",
    "mean_index": "the mean index error is a turn of the whole gear, which a scan's fitted rotation takes: the "
                  "corrections are relative to it",
}


def slope_summary(spec, identified: Identified, corrected: bool) -> dict:
    """correction.json's `profile_slope_um` and `helix_slope_um`: per side the slope (f_Halpha, f_Hbeta, um over
    the evaluation range), its uncertainty, and for the profile the pressure angle change as cut it means."""
    start, end = profile_range_mm(spec)
    front, back = helix_range_mm(spec.face_width_mm, spec.module_mm)

    def rounded(value: float) -> float | None:
        return round(value, 3) + 0.0 if math.isfinite(value) else None  # + 0.0: never -0.0

    profile = {side: {"value": rounded(value), "uncertainty": rounded(identified.profile_slope_uncertainty_um[side]),
                      "pressure_angle_change_deg": round(pressure_angle_change_deg(spec, value), 6)}
               for side, value in identified.profile_slope_um.items()}
    helix = {side: {"value": rounded(value), "uncertainty": rounded(identified.helix_slope_uncertainty_um[side])}
             for side, value in identified.helix_slope_um.items()}
    return {
        "profile_slope_um": {"by_side": profile, "evaluation_range_roll_mm": [round(start, 4), round(end, 4)],
                             "corrected": corrected,
                             "meaning": "f_Halpha (ISO 1328-1) less the ideal cut's, mean over the side's profile "
                                        "traces: + material rising toward the tip; pressure_angle_change_deg = "
                                        "-f_Halpha / (L_alpha tan alpha), the pressure angle as cut less the design's"},
        "helix_slope_um": {"by_side": helix, "evaluation_range_x_mm": [round(front, 4), round(back, 4)],
                           "corrected": corrected,
                           "meaning": "f_Hbeta (ISO 1328-1), mean over the side's helix traces (three transverse "
                                      "planes or more): + material rising toward +X (the back face)"},
    }


def pitch_totals_um(spec, flank_um: dict[str, np.ndarray]) -> dict[str, float | None]:
    """F_p per side (um of arc on the reference circle) of the flanks' normal positions: their spread / cos alpha;
    None where a space was not measured (F_p needs every flank of a side)."""
    cos_alpha = spec.base_radius_mm / spec.reference_radius_mm
    return {side: round(float(np.ptp(values)) / cos_alpha, 3) if np.all(np.isfinite(values)) else None
            for side, values in flank_um.items()}


def slopes_as_measured(identified: Identified) -> dict[str, dict[str, float]]:
    """The identified slopes per side (um), as correction.json's before holds them."""
    return {"profile_slope_um": {side: round(v, 3) + 0.0 for side, v in identified.profile_slope_um.items()},
            "helix_slope_um": {side: round(v, 3) + 0.0 for side, v in identified.helix_slope_um.items()}}


def correction_summary(spec, identified: Identified, finishing_tool_before, finishing_tool_after,
                       a_correction_deg: np.ndarray, measured_source: str, slopes_not_corrected: str | None = None
                       ) -> dict:
    """correction.json: each error identified with its standard uncertainty, what the programs change, the flank
    positions before and as predicted after, and what was not corrected and why."""
    reference_arc_um = spec.reference_radius_mm * ARCSEC_RAD * 1000.0  # um of arc per arcsec on the reference circle
    index = identified.index_arcsec
    measured = np.isfinite(index)
    spread_um = float(np.nanmax(index) - np.nanmin(index)) * reference_arc_um if measured.any() else None
    unseen = {} if identified.index_visible else {"index": PROBE_SEES_NO_INDEX}
    index_uncertainty = identified.index_uncertainty_arcsec
    index_uncertainty = round(index_uncertainty, 3) if math.isfinite(index_uncertainty) else None
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
                               "uncertainty": index_uncertainty,
                               "meaning": "per space (machine numbering), relative to their mean: the table stood "
                                          "this much further in A than commanded" + (
                                              "" if identified.index_visible else "; " + PROBE_SEES_NO_INDEX)},
        "corrections": {
            "finishing_tool_diameter_mm": {"before": finishing_tool_before.diameter_mm,
                                           "programmed": round(finishing_tool_after.diameter_mm, 6),
                                           "why": "the finishing toolpath is regenerated for the tool as it cuts: "
                                                  "its tip centre is programmed without cutter compensation, so "
                                                  "a controller's wear offset would not move it"},
            "a_correction_deg": [round(float(v), 7) for v in a_correction_deg],
            "unmeasured_spaces": [int(k) for k in np.nonzero(~measured)[0]],
            **({} if slopes_not_corrected else {"flank_passes": (
                "each generating flank pass moved along its normal (Y) by the side's profile slope at its contact "
                "roll (0 at the middle of the evaluation range) and turned along X by the side's helix slope (0 at "
                "the middle of the helix range): the slopes as measured are cut off")}),
        },
        **slope_summary(spec, identified, slopes_not_corrected is None),
        "before": {"flank_position_um": round(identified.size_um, 3),
                   "index_spread_on_reference_circle_um": None if spread_um is None else round(spread_um, 3),
                   "F_p_um": pitch_totals_um(spec, identified.flank_position_um),
                   **slopes_as_measured(identified)},
        "predicted_after": {"flank_position_um": 0.0, "flank_position_uncertainty_um":
                            round(identified.size_uncertainty_um, 3),
                            "index_spread_on_reference_circle_um": None if spread_um is None else 0.0,
                            "index_uncertainty_on_reference_circle_um":
                                None if index_uncertainty is None else round(index_uncertainty * reference_arc_um, 3),
                            "F_p_um": pitch_totals_um(spec, identified.flank_residual_um),
                            **({name: {side: 0.0 for side in by_side} for name, by_side in
                                slopes_as_measured(identified).items()} if slopes_not_corrected is None
                               else slopes_as_measured(identified))},
        "predicted_after_meaning": "the measured deviations less what the corrections remove: the size and the "
                                   "index errors (F_p from the flanks' scatter the model leaves), the slopes when "
                                   "corrected; on the machine that cut the measured gear",
        "not_corrected": {**unseen, **({"slopes": slopes_not_corrected} if slopes_not_corrected else {}),
                          **(NOT_CORRECTED if identified.index_visible else PROBE_NOT_CORRECTED)},
    }


PROBE_NOT_CORRECTED = {
    **{name: why for name, why in NOT_CORRECTED.items() if name not in ("side_size_difference", "mean_index")},
    "side_size_difference": "the left and right flanks' size difference (the probe log measures each side, with no "
                            "fit): a tool offset moves both flanks alike; only the mean size is corrected",
}
"""What a probe log's correction leaves, and why: a scan's notes on its fitted rotation do not apply (no fit)."""

PROBE_SEES_NO_INDEX = ("the index errors are not corrected: a probe log is measured in the cutting set-up, on the "
                       "table that cut the gear, so its repeatable index error is in both and invisible to it "
                       "(docs/probing.md); pitch needs an external measurement (a scan, spur-cad correct JOB scan.csv) "
                       "or the table's calibration")


def _identify_probe_log(job, log, ideal: IdealFlanks) -> Identified:
    """identify_probed on a probe log's deviations from the job's probing plan (its [probe] section), read from the
    modified design when the job has modifications."""
    from spur_cad.cam.probing import plan_probe
    from spur_cad.correct.identify import identify_probed
    from spur_cad.errors import SpurCadError
    from spur_cad.grade.probe_log import labelled_deviations

    spec = job.gear
    if job.probe is None:
        raise SpurCadError(f"{log.source}: a probe log, but the job has no [probe] section to name its trips "
                           "(correct with the job that wrote the probing program)")
    plan = plan_probe(spec, job.stock, job.machine, job.probe)
    trips = labelled_deviations(spec, plan, log, job.post.rotary_sign, job.modifications)
    return identify_probed(spec, trips.space, trips.side, trips.roll_mm, trips.x_mm, trips.deviation_mm, ideal)


def corrected_plan_of(job, identified: Identified):
    """(the corrected job, its plan with the corrections, why the slopes are not corrected or None): the job re-planned
    with the finishing tool as it cuts (its modifications kept: the finishing still cuts the modified flanks), the
    generating flank passes moved for the slopes, and each space's A words of every operation turned by its index
    correction."""
    from spur_cad.pipeline import plan_cam

    fixed = corrected_job(job, identified)
    fixed_plan = plan_cam(fixed)
    finishing, slopes_not_corrected = slope_corrected_finishing(fixed, fixed_plan.finishing, identified)
    fixed_plan = dataclasses.replace(fixed_plan, finishing=finishing)
    correction = index_correction_deg(identified)
    turned = {name: dataclasses.replace(planned, toolpath=turned_by_space(planned.toolpath, correction))
              for name in ("roughing", "roughing_bottom", "finishing")
              if (planned := getattr(fixed_plan, name)) is not None}
    return fixed, dataclasses.replace(fixed_plan, **turned), slopes_not_corrected


def correct_job(job, measured, measured_source: str):
    """Identify the errors in `measured` (spur_cad.grade.measured.MeasuredPoints, or a ProbeLog of the job's
    probing program: then the size and slopes only, identify_probed) and build the corrected output set:
    every program re-planned with the finishing tool as it cuts, each space's A words turned by its correction
    (all operations: the table errs alike for each), correction.json, and report.html (the corrected job's run on its
    corrected plan, with the Correction section). Returns (Identified, {name: bytes})."""
    import json

    from spur_cad.correct.identify import identify
    from spur_cad.errors import SpurCadError
    from spur_cad.pipeline import build_programs, plan_cam, run_job

    spec = job.gear
    if spec.kind.helical:
        raise SpurCadError("correcting from measured points of a helical gear is not supported yet (spur gears only)")
    if job.tools.finishing is None:
        raise SpurCadError("the job has no [tools.finishing]: there is no finishing program to correct")
    plan = plan_cam(job)
    try:
        identified = identify(spec, measured, ideal_flanks(job, plan), job.modifications) \
            if isinstance(measured, MeasuredPoints) \
            else _identify_probe_log(job, measured, ideal_flanks(job, plan))
    except ValueError as exc:
        raise SpurCadError(f"{measured_source}: {exc}") from None
    fixed, corrected_plan, slopes_not_corrected = corrected_plan_of(job, identified)
    correction = index_correction_deg(identified)
    notes = (f"corrected from {measured_source}: finishing tool programmed as D "
             f"{fixed.tools.finishing.diameter_mm:.4f} mm (size error {identified.size_um:+.2f} um), A of each space "
             "turned by its index correction" + ("" if slopes_not_corrected else ", flank passes moved for the "
                                                  "profile and helix slopes") + " (correction.json)",)
    _, files = build_programs(fixed, corrected_plan, notes)
    summary = correction_summary(spec, identified, job.tools.finishing, fixed.tools.finishing, correction,
                                 measured_source, slopes_not_corrected)
    files["correction.json"] = (json.dumps(summary, indent=2) + "\n").encode()
    # the report's own simulation would cut the corrected programs on an ideal machine, where the corrections show
    # as deviations (a warned "gouge" of the size error): it is left out; the Correction section predicts the gear
    # on the measured machine instead
    unsimulated = dataclasses.replace(fixed, simulation=dataclasses.replace(fixed.simulation, enabled=False))
    files["report.html"] = run_job(unsimulated, plan=corrected_plan, correction=summary).files["report.html"]
    return identified, files
