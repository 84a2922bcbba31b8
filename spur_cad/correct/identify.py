"""Identify a machine's systematic errors from a measured gear (docs/correction.md): the tool's size error, the
rotary table's error e(A) as a function of the commanded A, and each flank side's profile and helix slope, with their
uncertainties. Pure functions of the design, the points and the A at which the finishing cut each flank point.

Model. Every involute point of side s deviates along its design normal (mm, + material) by

    d = size_s - e(A) (p x n) + slope_s,profile t_profile + slope_s,helix t_helix + ideal(roll) + noise

where size_s is the flank's shift by the tool (+: the tool cut too little, a smaller tool or wear), e(A) the table's
error (rad: the table stood e(A) further in A than commanded) at the A that cut the point (spur_cad.sim.contact),
which turns the point's cut by -e(A) in the part frame, p x n the point's lever (+-r_b on an involute), and ideal(roll)
what the program leaves on an ideal machine (its scallops, the same in every space). e(A) is a Fourier series whose
orders are chosen from the data (spur_cad.correct.table).

What a scan cannot tell apart: its fitted rotation takes the mean of e(A) and, with it, half the difference between
the left and right flanks' sizes (a turn moves the sides oppositely), so only the mean size is the tool's. A
once-per-turn e(A) moves every flank by c . n, exactly as a blank off the A axis (or the gear measured about another
centre) does: on a datum-axis scan it is seen but not told from an off-centre blank; on a best-fit scan the fitted
centre takes it whole and it is not seen at all.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from spur_cad.correct.table import TableError, blank_offset_mm, fit_flank_model
from spur_cad.geometry.frames import turn_points
from spur_cad.grade.iso1328 import evaluate_trace
from spur_cad.grade.measured import (  # _design: the grader's design points
    MeasuredPoints,
    _design,
    fit,
    flank_traces,
)
from spur_cad.grade.simulated import SIDES, helix_range_mm, profile_range_mm
from spur_cad.sim.contact import ContactAngles

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
    table: the rotary table's error e(A) (spur_cad.correct.table.TableError), None from a probe log (which cannot see
    it); blank_offset_um: the once-per-turn order of e(A) read as a blank off the A axis instead (the gear's centre as
    cut about the datum axis, part frame), None without a kept order 1; datum: 'axis', 'best-fit' or 'probe log';
    flank_position_um: per side and space, the flank's position at the reference circle (um of arc, mean over the
    planes) about the datum (or the fitted centre) less the side's size; flank_residual_um: that less the table's
    share, what the corrections leave; profile_slope_um / helix_slope_um: per side, f_Halpha / f_Hbeta of the
    deviations less the ideal cut's and the table's share (side_slopes), missing for a side without such traces."""

    size_um: float
    size_uncertainty_um: float
    side_size_um: dict[str, float]
    table: TableError | None
    blank_offset_um: tuple[float, float] | None
    datum: str
    flank_mean_um: dict[str, np.ndarray]
    points_used: int
    scan_turn_deg: float
    profile_slope_um: dict[str, float] = dataclasses.field(default_factory=dict)
    profile_slope_uncertainty_um: dict[str, float] = dataclasses.field(default_factory=dict)
    helix_slope_um: dict[str, float] = dataclasses.field(default_factory=dict)
    helix_slope_uncertainty_um: dict[str, float] = dataclasses.field(default_factory=dict)
    flank_position_um: dict[str, np.ndarray] = dataclasses.field(default_factory=dict)
    flank_residual_um: dict[str, np.ndarray] = dataclasses.field(default_factory=dict)

    @property
    def table_visible(self) -> bool:
        """False from an on-machine probe log: the probe is carried by the table that cut the gear."""
        return self.table is not None


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


def _positions_um(spec, axial, deviation, space, side, roll) -> dict[str, np.ndarray]:
    """Per side and space (machine numbering) the flank's position at the reference circle (um of arc, the grader's
    flank_traces), NaN where not measured."""
    _, positions = flank_traces(spec, axial, deviation, space, side, roll)
    found = {name: np.full(spec.teeth, np.nan) for name in SIDES}
    for name in SIDES:
        for k, value in positions[name].items():
            found[name][k] = value
    return found


def identify(spec, measured: MeasuredPoints, contacts: ContactAngles, ideal: IdealFlanks | None = None,
             modifications=None, datum: str = "best-fit") -> Identified:
    """Fit the scan (spur_cad.grade.measured.fit: the rotation, and the centre unless `datum` is 'axis'), take each
    involute point's deviation less the ideal cut's in the profile evaluation range, and fit the model of the module
    docstring (spur_cad.correct.table.fit_flank_model): each side's size and slopes and the table's e(A) at the A that
    cut each point (`contacts`, from the job's finishing). `modifications` (the job's FlankModifications): the points
    are read from the modified design, as the grader reads them, so that a designed relief, crowning or slope is no
    machine error; `ideal` must then be read from it too (spur_cad.correct.correct.ideal_flanks)."""
    design = _design(spec)
    points, normals, space, side, roll, _ = design
    params, deviation, nearest = fit(spec, measured, design, datum, modifications)
    offset = space_numbering_offset(float(params[0]), spec.teeth)
    machine_space = (space[nearest] - offset) % spec.teeth
    lever = points[nearest, 0] * normals[nearest, 1] - points[nearest, 1] * normals[nearest, 0]
    start, end = profile_range_mm(spec)
    front, back = helix_range_mm(spec.face_width_mm, spec.module_mm)
    point_side, point_roll = side[nearest], roll[nearest]
    used = np.isin(point_side, SIDES) & (point_roll >= start) & (point_roll <= end)
    corrected = deviation.copy()
    if ideal is not None:
        for name in SIDES:
            on = used & (point_side == name)
            corrected[on] -= ideal.at(name, point_roll[on])
    flank_id = machine_space * 2 + (point_side == "left")
    flank_mean = {name: np.full(spec.teeth, np.nan) for name in SIDES}
    for name in SIDES:
        for k in range(spec.teeth):
            on = used & (point_side == name) & (machine_space == k)
            if np.count_nonzero(on) >= MIN_FLANK_POINTS:
                flank_mean[name][k] = corrected[on].mean()
    both = np.isfinite(flank_mean["right"]) & np.isfinite(flank_mean["left"])
    if np.count_nonzero(both) < 4:
        raise ValueError("fewer than four tooth spaces have both flanks measured in the profile evaluation range")
    a_deg = contacts.at(point_side[used], point_roll[used], machine_space[used])
    profile_t = (point_roll[used] - 0.5 * (start + end)) / (end - start)
    model = fit_flank_model(point_side[used], lever[used], a_deg, profile_t,
                            (measured.axial[used] - 0.5 * (front + back)) / (back - front), corrected[used],
                            flank_id[used], int(np.count_nonzero(both)), datum == "axis", contacts.span_deg())
    table_part = np.zeros(len(corrected))
    table_part[used] = model.table_part_mm
    size = 0.5 * (model.size_mm["right"] + model.size_mm["left"])
    blank = None
    if any(h.order == 1 for h in model.table.kept):
        turn = -offset * 2.0 * math.pi / spec.teeth  # the design's numbering to the machine's (its part frame at A 0)
        machine_normals = turn_points(normals[nearest[used]], turn)
        cy, cz = blank_offset_mm(model.table, lever[used], a_deg, machine_normals)
        blank = (cy * 1000.0, cz * 1000.0)
    labels = (machine_space[used], point_side[used], point_roll[used])
    axial = measured.axial[used]
    before = _positions_um(spec, axial, corrected[used], *labels)
    after = _positions_um(spec, axial, corrected[used] - table_part[used], *labels)
    cos_alpha = spec.base_radius_mm / spec.reference_radius_mm
    side_arc = {name: model.size_mm[name] * 1000.0 / cos_alpha for name in SIDES}
    traces, _ = flank_traces(spec, axial, corrected[used] - table_part[used], *labels)
    profile, helix = side_slopes(traces, "profile"), side_slopes(traces, "helix")
    return Identified(
        size_um=size * 1000.0, size_uncertainty_um=model.size_uncertainty_mm * 1000.0,
        side_size_um={name: value * 1000.0 for name, value in model.size_mm.items()},
        table=model.table, blank_offset_um=blank, datum=datum,
        flank_mean_um={name: flank_mean[name] * 1000.0 for name in SIDES},
        points_used=int(np.count_nonzero(used)),
        scan_turn_deg=-math.degrees((params[0] + math.pi / spec.teeth) % (2 * math.pi / spec.teeth)
                                    - math.pi / spec.teeth),
        profile_slope_um={name: found.value_um for name, found in profile.items()},
        profile_slope_uncertainty_um={name: found.uncertainty_um for name, found in profile.items()},
        helix_slope_um={name: found.value_um for name, found in helix.items()},
        helix_slope_uncertainty_um={name: found.uncertainty_um for name, found in helix.items()},
        flank_position_um={name: before[name] - side_arc[name] for name in SIDES},
        flank_residual_um={name: after[name] - side_arc[name] for name in SIDES})


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
        table=None, blank_offset_um=None, datum="probe log",
        flank_mean_um={name: flank_mean[name] * 1000.0 for name in SIDES}, points_used=int(np.count_nonzero(used)),
        scan_turn_deg=0.0,
        profile_slope_um={name: found.value_um for name, found in profile.items()},
        profile_slope_uncertainty_um={name: found.uncertainty_um for name, found in profile.items()},
        helix_slope_um={name: found.value_um for name, found in helix.items()},
        helix_slope_uncertainty_um={name: found.uncertainty_um for name, found in helix.items()},
        flank_position_um={name: unseen for name in SIDES}, flank_residual_um={name: unseen for name in SIDES})
