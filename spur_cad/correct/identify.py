"""Identify a machine's systematic errors from a measured gear (docs/correction.md): the tool's size error, each
tooth space's index error and each flank side's profile and helix slope, with their uncertainties. Pure functions
of the design and the points.

Model. Every involute point of space k and side s deviates along its design normal (mm, + material) by

    d = size_s - e_k (p x n) + ideal(roll) + noise

where size_s is the flank's shift by the tool (+: the tool cut too little, a smaller tool or wear), e_k the
space's index error (rad: the table stood e_k further in A than commanded, which turns the space's cut by -e_k
in the part frame, spur_cad.sim.budget), p x n the point's lever (+r_b on one side, -r_b on the other: the same
along the whole involute) and ideal(roll) what the program leaves on an ideal machine (its scallops, the same
in every space). Per flank, the mean of d - ideal separates the terms: the two flanks of a space move the same
way by the size and opposite ways by a turn.

What a scan cannot tell apart: its best-fit rotation absorbs the mean index error and, with it, half the
difference between the left and right flanks' sizes (a turn moves the sides oppositely). So the index errors
are relative to their mean and the two sides' sizes are reported as measured, but only their mean is the tool's.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from spur_cad.grade.iso1328 import evaluate_trace
from spur_cad.grade.measured import (  # _design: the grader's design points
    MeasuredPoints,
    _design,
    fit,
    flank_traces,
)
from spur_cad.grade.simulated import SIDES, profile_range_mm

ARCSEC_RAD = math.pi / (180.0 * 3600.0)
MIN_FLANK_POINTS = 5


@dataclass(frozen=True)
class IdealFlanks:
    """What the program leaves on an ideal machine, per side: deviation (mm, + material) against roll length (mm),
    roll increasing; e.g. the scallops of generating passes (spur_cad.correct.ideal)."""

    roll_mm: dict[str, np.ndarray]
    deviation_mm: dict[str, np.ndarray]

    def at(self, side: str, roll_mm: np.ndarray) -> np.ndarray:
        return np.interp(roll_mm, self.roll_mm[side], self.deviation_mm[side])


@dataclass(frozen=True)
class Identified:
    """The errors a measurement shows (um and arcsec) with their standard uncertainties.

    size_um: the flanks' shift by the tool, mean of both sides (+: material left, the tool cut too little);
    side_size_um: per side as measured (their difference is a scan's rotation: not the tool's);
    index_arcsec: per space (machine numbering), relative to the mean over the measured spaces; NaN where a
    space has not both flanks measured; flank_position_um: per side and space, the flank's mean deviation about the
    gear's axis (the fit's centre remainder taken off) less the side's size; flank_residual_um: that less the
    index error's share, what the corrections leave; profile_slope_um / helix_slope_um: per side, f_Halpha /
    f_Hbeta of the deviations less the ideal cut's (side_slopes), missing for a side without such traces."""

    size_um: float
    size_uncertainty_um: float
    side_size_um: dict[str, float]
    index_arcsec: np.ndarray
    index_uncertainty_arcsec: float
    flank_mean_um: dict[str, np.ndarray]
    points_used: int
    centre_shift_um: tuple[float, float]
    scan_turn_deg: float
    profile_slope_um: dict[str, float] = dataclasses.field(default_factory=dict)
    profile_slope_uncertainty_um: dict[str, float] = dataclasses.field(default_factory=dict)
    helix_slope_um: dict[str, float] = dataclasses.field(default_factory=dict)
    helix_slope_uncertainty_um: dict[str, float] = dataclasses.field(default_factory=dict)
    flank_position_um: dict[str, np.ndarray] = dataclasses.field(default_factory=dict)
    flank_residual_um: dict[str, np.ndarray] = dataclasses.field(default_factory=dict)
    index_visible: bool = True  # False from an on-machine probe log: the probe shares the table's index errors


@dataclass(frozen=True)
class Slopes:
    """One side's slope (um over its ISO 1328 evaluation range, + material rising along the trace: toward the tip
    for a profile, toward the back face (+X) for a helix): the mean over the side's traces, and its standard
    uncertainty (the traces' spread over sqrt(n); NaN from a single trace)."""

    value_um: float
    uncertainty_um: float
    traces: int


def side_slopes(traces, kind: str) -> dict[str, Slopes]:
    """Per side, the mean slope deviation (f_Halpha or f_Hbeta, ISO 1328-1: the rise of the trace's least-squares
    line over the evaluation range) of the `kind` traces ("profile" or "helix") that have three points in range."""
    found: dict[str, Slopes] = {}
    for name in SIDES:
        slopes = []
        for trace in traces:
            if trace.kind == kind and trace.side == name:
                try:
                    slopes.append(evaluate_trace(trace.position_mm, trace.deviation_um, *trace.evaluation).slope_um)
                except ValueError:
                    continue
        if slopes:
            spread = float(np.std(slopes, ddof=1) / math.sqrt(len(slopes))) if len(slopes) > 1 else math.nan
            found[name] = Slopes(float(np.mean(slopes)), spread, len(slopes))
    return found


def space_numbering_offset(angle_rad: float, teeth: int) -> int:
    """Whole pitches in the fitted rotation beyond the turn nearest zero: the fit labels a point of the scan's space
    k as space k + offset (mod z); the scan's frame is taken as the machine's within half a pitch."""
    pitch = 2.0 * math.pi / teeth
    return int(round((angle_rad - ((angle_rad + 0.5 * pitch) % pitch - 0.5 * pitch)) / pitch))


def identify(spec, measured: MeasuredPoints, ideal: IdealFlanks | None = None, modifications=None) -> Identified:
    """Fit the scan (spur_cad.grade.measured.fit), take each involute point's deviation minus the ideal cut's in the
    profile evaluation range, and separate size and index per space (see the module docstring). Uncertainties:
    the flank means' noise is read from the scatter over the spaces of each space's size (the sum of its two
    flanks, constant in the model); an index error's is that over the lever's 2 r_b, the size's over sqrt(z).
    `modifications` (the job's FlankModifications): the points are read from the modified design, as the grader reads
    them (spur_cad.grade.measured.fit), so that a designed relief, crowning or slope is no machine error; `ideal`
    must then be read from it too (spur_cad.correct.correct.ideal_flanks)."""
    design = _design(spec)
    points, normals, space, side, roll, _ = design
    params, deviation, nearest = fit(spec, measured, design, modifications=modifications)
    offset = space_numbering_offset(float(params[0]), spec.teeth)
    machine_space = (space[nearest] - offset) % spec.teeth
    lever = points[nearest, 0] * normals[nearest, 1] - points[nearest, 1] * normals[nearest, 0]
    start, end = profile_range_mm(spec)
    point_roll = roll[nearest]
    used = np.isin(side[nearest], SIDES) & (point_roll >= start) & (point_roll <= end)
    corrected = deviation.copy()
    if ideal is not None:
        for name in SIDES:
            on = used & (side[nearest] == name)
            corrected[on] -= ideal.at(name, point_roll[on])
    flank_mean = {name: np.full(spec.teeth, np.nan) for name in SIDES}
    flank_lever = {name: np.full(spec.teeth, np.nan) for name in SIDES}
    flank_normal = {name: np.full((spec.teeth, 2), np.nan) for name in SIDES}
    for name in SIDES:
        for k in range(spec.teeth):
            on = used & (side[nearest] == name) & (machine_space == k)
            if np.count_nonzero(on) >= MIN_FLANK_POINTS:
                flank_mean[name][k] = corrected[on].mean()
                flank_lever[name][k] = lever[on].mean()
                flank_normal[name][k] = normals[nearest[on]].mean(axis=0)
    right, left = flank_mean["right"], flank_mean["left"]
    both = np.isfinite(right) & np.isfinite(left)
    if np.count_nonzero(both) < 4:
        raise ValueError("fewer than four tooth spaces have both flanks measured in the profile evaluation range")
    # The fit's centre takes a once-per-turn index error for eccentricity. A centre moved by c moves a flank by
    # c . n: the sum of a space's flanks by c . (n_r + n_l), which a turn leaves alone (the sizes are the same in
    # every space), so the sums give the size and the centre, and the differences then the turns.
    normal_sum = flank_normal["right"][both] + flank_normal["left"][both]
    design_matrix = np.column_stack([np.full(len(normal_sum), 2.0), normal_sum])
    (size, cx, cy), *_ = np.linalg.lstsq(design_matrix, (right + left)[both], rcond=None)
    residual = (right + left)[both] - design_matrix @ np.array([size, cx, cy])
    sum_noise = float(np.sqrt(np.sum(residual ** 2) / max(len(residual) - 3, 1)))
    centre = np.array([cx, cy])
    difference = (right - left) - (flank_normal["right"] - flank_normal["left"]) @ centre
    # d_right - d_left = size_r - size_l - e (lever_r - lever_l): the size difference is a constant, like the mean e
    turn = -difference / (flank_lever["right"] - flank_lever["left"])
    index = np.where(both, turn - np.nanmean(turn[both]), np.nan) / ARCSEC_RAD
    lever_span = float(np.nanmean(np.abs(flank_lever["right"] - flank_lever["left"])))
    side_size = {name: float(np.nanmean(flank_mean[name] - flank_normal[name] @ centre)) for name in SIDES}
    position = {name: flank_mean[name] - flank_normal[name] @ centre - side_size[name] for name in SIDES}
    relative_turn = turn - np.nanmean(turn[both])
    traces, _ = flank_traces(spec, measured.axial, corrected, space[nearest], side[nearest], roll[nearest])
    profile, helix = side_slopes(traces, "profile"), side_slopes(traces, "helix")
    return Identified(
        size_um=float(size) * 1000.0,
        size_uncertainty_um=sum_noise / (2.0 * math.sqrt(len(residual))) * 1000.0,
        side_size_um={name: value * 1000.0 for name, value in side_size.items()},
        index_arcsec=index,
        index_uncertainty_arcsec=sum_noise / lever_span / ARCSEC_RAD,  # a difference's noise is a sum's
        flank_mean_um={name: flank_mean[name] * 1000.0 for name in SIDES},
        points_used=int(np.count_nonzero(used)),
        centre_shift_um=(float(cx) * 1000.0, float(cy) * 1000.0),
        scan_turn_deg=-math.degrees((params[0] + math.pi / spec.teeth) % (2 * math.pi / spec.teeth)
                                    - math.pi / spec.teeth),
        profile_slope_um={name: found.value_um for name, found in profile.items()},
        profile_slope_uncertainty_um={name: found.uncertainty_um for name, found in profile.items()},
        helix_slope_um={name: found.value_um for name, found in helix.items()},
        helix_slope_uncertainty_um={name: found.uncertainty_um for name, found in helix.items()},
        flank_position_um={name: np.where(both, value, np.nan) * 1000.0 for name, value in position.items()},
        flank_residual_um={name: np.where(both, position[name] + relative_turn * flank_lever[name], np.nan) * 1000.0
                           for name in SIDES})


def identify_probed(spec, space: np.ndarray, side: np.ndarray, roll_mm: np.ndarray, axial_mm: np.ndarray,
                    deviation_mm: np.ndarray, ideal: IdealFlanks | None = None) -> Identified:
    """Size and slopes from an on-machine probe log's deviations (spur_cad.grade.probe_log: no fit, the A axis the
    datum), each point labelled by space, side, roll length and X. The probe is carried by the axes and the table
    that cut the gear, so the table's index errors, which it shares, are not seen: index errors and flank positions
    are NaN (docs/probing.md). The size is the mean of the two sides' means of the flanks' mean deviations less the
    ideal cut's; its uncertainty the flank means' spread about their side's mean over sqrt(n)."""
    start, end = profile_range_mm(spec)
    used = np.isin(side, SIDES) & (roll_mm >= start - 1e-9) & (roll_mm <= end + 1e-9)
    corrected = np.asarray(deviation_mm, dtype=float).copy()
    if ideal is not None:
        for name in SIDES:
            on = used & (side == name)
            corrected[on] -= ideal.at(name, roll_mm[on])
    flank_mean = {name: np.full(spec.teeth, np.nan) for name in SIDES}
    for name in SIDES:
        for k in range(spec.teeth):
            on = used & (side == name) & (space == k)
            if on.any():
                flank_mean[name][k] = corrected[on].mean()
    side_size = {name: float(np.nanmean(flank_mean[name])) for name in SIDES if np.isfinite(flank_mean[name]).any()}
    if len(side_size) < 2:
        raise ValueError("the probe log has no points of both flank sides in the profile evaluation range")
    spread = np.concatenate([flank_mean[name][np.isfinite(flank_mean[name])] - side_size[name] for name in SIDES])
    size = 0.5 * (side_size["right"] + side_size["left"])
    noise = float(np.std(spread, ddof=1)) if len(spread) > 1 else math.nan
    traces, _ = flank_traces(spec, axial_mm, corrected, space, side, roll_mm)
    profile, helix = side_slopes(traces, "profile"), side_slopes(traces, "helix")
    unseen = np.full(spec.teeth, np.nan)
    return Identified(
        size_um=size * 1000.0, size_uncertainty_um=noise / math.sqrt(len(spread)) * 1000.0,
        side_size_um={name: value * 1000.0 for name, value in side_size.items()},
        index_arcsec=unseen, index_uncertainty_arcsec=math.nan,
        flank_mean_um={name: flank_mean[name] * 1000.0 for name in SIDES}, points_used=int(np.count_nonzero(used)),
        centre_shift_um=(0.0, 0.0), scan_turn_deg=0.0,
        profile_slope_um={name: found.value_um for name, found in profile.items()},
        profile_slope_uncertainty_um={name: found.uncertainty_um for name, found in profile.items()},
        helix_slope_um={name: found.value_um for name, found in helix.items()},
        helix_slope_uncertainty_um={name: found.uncertainty_um for name, found in helix.items()},
        flank_position_um={name: unseen for name in SIDES}, flank_residual_um={name: unseen for name in SIDES},
        index_visible=False)
