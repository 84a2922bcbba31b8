"""correction.json (docs/correction.md): each error `spur-cad correct` identified, with its standard uncertainty, what
the programs change for it (spur_cad.correct.apply.AppliedCorrection), the flanks before and as predicted after on
the machine that cut the measured gear, what could not be told apart and what was not corrected, and why."""

from __future__ import annotations

import math

import numpy as np

from spur_cad.correct.apply import AppliedCorrection
from spur_cad.correct.identify import Identified
from spur_cad.correct.table import MIN_FLANK_MOTION_UM, SIGNIFICANCE, TableError
from spur_cad.grade.simulated import helix_range_mm, profile_range_mm
from spur_cad.result import CorrectionFacts, HarmonicFacts, PitchFacts, SlopeFacts

NOT_CORRECTED = {
    "slopes_off_the_involute": "the fillet, root and land passes keep their place: a slope is measured on the "
                               "involute only, and the generating flank passes move alone",
    "form": "form ripple (scallops, vibration, the table's error of orders above z / 2) is not a position the "
            "program can move: it is left as cut",
    "side_size_difference": "the left and right flanks' size difference: a scan's fitted rotation takes half of it, "
                            "and a tool offset moves both flanks alike; only the mean size is corrected",
    "mean_table_error": "the table's mean error (order 0 of e(A)) is a turn of the whole gear, which a scan's fitted "
                        "rotation takes: the corrections are relative to it",
}

BEST_FIT_HIDES_ONCE_PER_TURN = (
    "a once-per-turn error of the table (order 1 of e(A)) or a blank off the A axis makes an eccentric gear, which a "
    "best-fit scan's fitted centre takes whole: it is not seen and not corrected; scan about the gear's datum axis "
    "(the bore) and correct with --datum axis to see it")

PROBE_SEES_NO_TABLE = (
    "the table's error e(A) is not corrected: a probe log is measured on the table that cut the gear, each space at "
    "its one index angle, so it sees only e at the A that cut a point less e at the A that probed it (a slope that "
    "varies from space to space), never e itself; nor a blank off the A axis, which the probe turns about as the "
    "cutter did (docs/probing.md). e(A) needs a scan about the gear's datum axis (spur-cad correct JOB scan.csv "
    "--datum axis) or the table's calibration")

PROBE_NOT_CORRECTED = {
    **{name: why for name, why in NOT_CORRECTED.items() if name not in ("side_size_difference", "mean_table_error")},
    "side_size_difference": "the left and right flanks' size difference (the probe log measures each side, with no "
                            "fit): a tool offset moves both flanks alike; only the mean size is corrected",
}
"""What a probe log's correction leaves, and why: a scan's notes on its fitted rotation do not apply (no fit)."""

HOW_ORDERS_CHOSEN = (
    f"orders 1 (on a datum-axis scan; 2 on a best-fit scan) to z // 2 are fitted together with each side's size and "
    f"slopes; an order is kept when its amplitude exceeds {SIGNIFICANCE:g} standard uncertainties (cluster-robust "
    f"over the flanks) and moves a flank by {MIN_FLANK_MOTION_UM:g} um or more (r_b x amplitude); z // 2 is the "
    "highest order the spaces sample without aliasing (n // 2 for a scan of n spaces), order z repeats in every space "
    "(a profile form, not a position)")

SAME_GEAR = (
    "a once-per-turn table error and a blank clamped off the A axis leave the same gear (every flank moved by c . n, "
    "an eccentric gear about the datum axis): the scan cannot tell them apart")


def _rounded(value: float, digits: int = 3) -> float | None:
    return round(value, digits) + 0.0 if math.isfinite(value) else None  # + 0.0: never -0.0


def pressure_angle_change_deg(spec, profile_slope_um: float) -> float:
    """The pressure angle as cut minus the design's (deg) that a profile slope f_Halpha over the evaluation length
    L_alpha means (docs/correction.md): a base radius changed by eps r_b, the tooth thickness on the reference circle
    held, moves the flank at roll length L by eps (L - L_ref) along its normal, so f_Halpha = eps L_alpha; with r_b =
    r cos(alpha), eps = -tan(alpha) d_alpha: d_alpha = -f_Halpha / (L_alpha tan alpha)."""
    start, end = profile_range_mm(spec)
    return -math.degrees(profile_slope_um / 1000.0 / ((end - start) * math.tan(spec.pressure_angle_rad)))


def slope_summary(spec, identified: Identified, corrected: bool) -> dict:
    """correction.json's `profile_slope_um` and `helix_slope_um`: per side the slope (f_Halpha, f_Hbeta, um over
    the evaluation range), its uncertainty, and for the profile the pressure angle change as cut it means."""
    start, end = profile_range_mm(spec)
    front, back = helix_range_mm(spec.face_width_mm, spec.module_mm)
    profile = {side: {"value": _rounded(value), "uncertainty": _rounded(identified.profile_slope_uncertainty_um[side]),
                      "pressure_angle_change_deg": round(pressure_angle_change_deg(spec, value), 6)}
               for side, value in identified.profile_slope_um.items()}
    helix = {side: {"value": _rounded(value), "uncertainty": _rounded(identified.helix_slope_uncertainty_um[side])}
             for side, value in identified.helix_slope_um.items()}
    return {
        "profile_slope_um": {"by_side": profile, "evaluation_range_roll_mm": [round(start, 4), round(end, 4)],
                             "corrected": corrected,
                             "meaning": "f_Halpha (ISO 1328-1) less the ideal cut's and the table's, mean over the "
                                        "side's profile traces: + material rising toward the tip; "
                                        "pressure_angle_change_deg = -f_Halpha / (L_alpha tan alpha), the pressure "
                                        "angle as cut less the design's"},
        "helix_slope_um": {"by_side": helix, "evaluation_range_x_mm": [round(front, 4), round(back, 4)],
                           "corrected": corrected,
                           "meaning": "f_Hbeta (ISO 1328-1), mean over the side's helix traces (three transverse "
                                      "planes or more): + material rising toward +X (the back face)"},
    }


def pitch_totals_um(flank_um: dict[str, np.ndarray]) -> dict[str, float | None]:
    """F_p per side (um of arc on the reference circle) of the flanks' positions (already arcs): their spread; None
    where a space was not measured (F_p needs every flank of a side)."""
    return {side: round(float(np.ptp(values)), 3) if np.all(np.isfinite(values)) else None
            for side, values in flank_um.items()}


def slopes_as_measured(identified: Identified) -> dict[str, dict[str, float]]:
    """The identified slopes per side (um), as correction.json's before holds them."""
    return {"profile_slope_um": {side: round(v, 3) + 0.0 for side, v in identified.profile_slope_um.items()},
            "helix_slope_um": {side: round(v, 3) + 0.0 for side, v in identified.helix_slope_um.items()}}


def table_summary(table: TableError) -> dict:
    """correction.json's `table_error_arcsec`: every order tested, its coefficients, amplitude and phase
    (amplitude x sin(h A + phase)), uncertainty and whether it was kept, and how the orders were chosen."""
    orders = [h.order for h in table.harmonics]
    return {
        "harmonics": [{"order": h.order, "cos": _rounded(h.cos_arcsec), "sin": _rounded(h.sin_arcsec),
                       "amplitude": _rounded(h.amplitude_arcsec),
                       "phase_deg": _rounded(math.degrees(math.atan2(h.cos_arcsec, h.sin_arcsec)), 2),
                       "uncertainty": _rounded(h.uncertainty_arcsec), "kept": h.kept} for h in table.harmonics],
        "orders_tested": [min(orders), max(orders)] if orders else [],
        "kept": [h.order for h in table.kept],
        "how_chosen": HOW_ORDERS_CHOSEN,
        "a_range_deg": [round(v, 4) for v in table.a_range_deg],
        "meaning": "e(A) = sum over the kept orders of cos x cos(h A) + sin x sin(h A) arcsec: the table stood this "
                   "much further in A than commanded at A; fitted from each flank point at the A that cut it "
                   "(space 0's flanks over a_range_deg, the other spaces the same turned by -k 360 / z)",
    }


def once_per_turn_summary(identified: Identified, applied: AppliedCorrection) -> dict:
    """correction.json's `once_per_turn`: whether order 1 could be seen, what it is as a table error and as a blank
    offset, which model the corrected programs assumed, and what the user checks before the next blank."""
    if identified.table is None:
        return {"visible": False, "why": PROBE_SEES_NO_TABLE}
    if not identified.table.first_order_visible:
        return {"visible": False, "why": BEST_FIT_HIDES_ONCE_PER_TURN}
    first = [h for h in identified.table.kept if h.order == 1]
    if not first or identified.blank_offset_um is None:
        return {"visible": True, "found": False,
                "why": "no once-per-turn error above the significance test: the gear is centred on its datum axis"}
    cy, cz = identified.blank_offset_um
    assumed = applied.once_per_turn
    return {
        "visible": True, "found": True, "amplitude_arcsec": _rounded(first[0].amplitude_arcsec),
        "as_gear_centre_um": [_rounded(cy), _rounded(cz)], "eccentricity_um": _rounded(math.hypot(cy, cz)),
        "assumed": assumed,
        "why": SAME_GEAR + ("; the corrected programs take it for the table's (the A words): right for every blank "
                            "clamped on the A axis" if assumed == "table" else
                            "; the corrected programs take it for the blank's offset (Y and Z): right for this blank "
                            "in this set-up only"),
        "check": "before the next blank, probe the bore's centre at set-up (or read the table's calibration): a bore "
                 f"off the A axis by about {math.hypot(cy, cz):.1f} um means it was the blank, not the table; then "
                 "correct with --once-per-turn blank for this set-up, and clamp the next blank centred instead",
    }


def correction_summary(spec, identified: Identified, applied: AppliedCorrection, measured_source: str) -> dict:
    """correction.json: each error identified with its standard uncertainty, what the programs change, the flank
    positions before and as predicted after, and what was not corrected and why."""
    table = identified.table
    unseen = {"table_error": PROBE_SEES_NO_TABLE} if table is None else {}
    if table is not None and not table.first_order_visible:
        unseen["once_per_turn"] = BEST_FIT_HIDES_ONCE_PER_TURN
    corrections: dict = {
        "finishing_tool_diameter_mm": {"before": applied.diameter_before_mm,
                                       "programmed": round(applied.diameter_programmed_mm, 6),
                                       "why": "the finishing toolpath is regenerated for the tool as it cuts: its tip "
                                              "centre is programmed without cutter compensation, so a controller's "
                                              "wear offset would not move it"}}
    if applied.table_orders:
        corrections["a_words"] = {"orders": list(applied.table_orders),
                                  "how": "every block's A (all programs) moved by -e(A) of these orders, e evaluated "
                                         "at the block's own commanded A"}
    if applied.blank_offset_um is not None:
        corrections["y_z_words"] = {"datum_offset_um": [_rounded(v) for v in applied.blank_offset_um],
                                    "how": "every block's Y and Z moved by the datum axis's offset from the A axis "
                                           "(the table's frame at A 0) turned to the block's A"}
    if applied.unfolded:
        corrections["unfolded"] = ("the programs are written unfolded: the correction differs from block to block, "
                                   "and a folded program shares one subprogram among the spaces")
    if applied.slopes_not_corrected is None:
        corrections["flank_passes"] = (
            "each generating flank pass moved along its normal (Y) by the side's profile slope at its contact roll "
            "(0 at the middle of the evaluation range) and turned along X by the side's helix slope (0 at the middle "
            "of the helix range): the slopes as measured are cut off")
    not_corrected = {**unseen, **({"slopes": applied.slopes_not_corrected} if applied.slopes_not_corrected else {}),
                     **(NOT_CORRECTED if table is not None else PROBE_NOT_CORRECTED)}
    slopes_after = ({name: {side: 0.0 for side in by_side} for name, by_side in slopes_as_measured(identified).items()}
                    if applied.slopes_not_corrected is None else slopes_as_measured(identified))
    return {
        "measured": measured_source,
        "datum": identified.datum,
        "model": "deviation = size - e(A) x (p x n) + slopes + the ideal cut's, e at the A that cut each point "
                 "(docs/correction.md)",
        "scan_turn_deg": round(identified.scan_turn_deg, 6),
        "points_used": identified.points_used,
        "size_error_um": {"value": round(identified.size_um, 3),
                          "uncertainty": round(identified.size_uncertainty_um, 3),
                          "by_side": {side: round(v, 3) for side, v in identified.side_size_um.items()},
                          "meaning": "+: material left (the tool cut too little); -: the tool cut too much"},
        "table_error_arcsec": table_summary(table) if table is not None else {"seen": False,
                                                                              "why": PROBE_SEES_NO_TABLE},
        "once_per_turn": once_per_turn_summary(identified, applied),
        "corrections": corrections,
        **slope_summary(spec, identified, applied.slopes_not_corrected is None),
        "before": {"flank_position_um": round(identified.size_um, 3),
                   "F_p_um": pitch_totals_um(identified.flank_position_um),
                   **slopes_as_measured(identified)},
        "predicted_after": {"flank_position_um": 0.0,
                            "flank_position_uncertainty_um": round(identified.size_uncertainty_um, 3),
                            "F_p_um": pitch_totals_um(identified.flank_residual_um), **slopes_after},
        "predicted_after_meaning": "the measured deviations less what the corrections remove: the size, the table's "
                                   "error (F_p from the flanks' scatter the model leaves), the slopes when corrected; "
                                   "on the machine that cut the measured gear",
        "not_corrected": not_corrected,
    }


def correction_facts(summary: dict) -> CorrectionFacts:
    """The correction as the corrected set's report shows it, typed, from correction.json's data (`correction_summary`):
    the same rounded figures the file holds, read here, beside the writer of its keys."""
    before, after = summary["before"], summary["predicted_after"]
    size, table, changes = summary["size_error_um"], summary["table_error_arcsec"], summary["corrections"]
    tool = changes["finishing_tool_diameter_mm"]
    kept = (tuple(HarmonicFacts(h["order"], h["amplitude"], h["phase_deg"], h["uncertainty"])
                  for h in table["harmonics"] if h["kept"]) if "harmonics" in table else None)
    tested = table.get("orders_tested") or None

    def slopes(name: str) -> tuple[SlopeFacts, ...]:
        return tuple(SlopeFacts(side, found["value"], found["uncertainty"], before[name][side], after[name][side],
                                found.get("pressure_angle_change_deg"))
                     for side, found in summary[name]["by_side"].items())

    once = summary.get("once_per_turn", {})
    told = (once["why"], once["check"]) if once.get("found") else ()
    return CorrectionFacts(
        measured=summary["measured"], points_used=summary["points_used"], size_um=size["value"],
        size_uncertainty_um=size["uncertainty"], tool_before_mm=tool["before"], tool_programmed_mm=tool["programmed"],
        flank_position_before_um=before["flank_position_um"], flank_position_after_um=after["flank_position_um"],
        table_kept=kept, table_orders_tested=(tested[0], tested[-1]) if tested else None,
        a_words_moved="a_words" in changes, y_z_words_moved="y_z_words" in changes, unfolded="unfolded" in changes,
        pitch=tuple(PitchFacts(side, value, after["F_p_um"][side]) for side, value in before["F_p_um"].items()
                    if value is not None),
        profile_slopes=slopes("profile_slope_um"), helix_slopes=slopes("helix_slope_um"),
        slopes_corrected=summary["profile_slope_um"]["corrected"],
        notes=told + tuple(summary["not_corrected"].values()))
