"""Grade a real gear from measured points (`spur-cad grade JOB MEASURED.csv`): best-fit the gear's rotation
and centre (or, with the datum "axis", the rotation only), take each point's deviation from the design along
the design normal, and evaluate profile, helix and pitch traces by ISO 1328-1:2013 as for a simulated gear
(spur_cad.grade.simulated). A probe log of the job's probing program is read here too and graded by
spur_cad.grade.probe_log.

CSV: one point per line, `x_mm,y_mm` in a transverse plane (any rotation and a centre near the gear's
axis), optionally a third column `X_mm`, the axial position (several transverse planes give helix
traces). A header line of names is allowed; `#` starts a comment. Points of several flanks and tooth
spaces may be mixed: each point belongs to the flank of the design point nearest to it (after the fit).
A helical gear's section at X is the section at X = 0 turned by spec.section_turn_rad(X); the points are turned
back by it before they meet the design. A modified gear's points are graded against the modified design (a flank
point's deviation plus the design's removal at its roll length and X; spur_cad.grade.design_trace).
"""

from __future__ import annotations

import contextlib
import math
import os
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from spur_cad.errors import SpurCadError
from spur_cad.grade.design_trace import against_design, design_removal_mm
from spur_cad.grade.grading import Grading, MeasuredFit, Trace, add_pitch, classes_of, validity, worst_deviations
from spur_cad.grade.simulated import helix_range_mm, profile_range_mm, profile_roll_mm

if TYPE_CHECKING:
    from spur_cad.geometry.spec import GearSpec

MAX_POINTS = 2_000_000
MAX_MEASURED_BYTES = 128 * 1024 * 1024  # a scan of MAX_POINTS points (about 70 MB of text) fits
MAX_LINE_CHARS = 1024
FIT_POINTS = 4000  # points used for the best fit (an even subset of the file)
DESIGN_SPACING_MM = 0.005


class MeasuredPointsError(SpurCadError):
    """A measured-points file that cannot be read: the message names the file and line."""


@dataclass(frozen=True)
class MeasuredPoints:
    """The file's points: coordinates in their transverse plane (mm, the file's x and y) and the axial
    position X of the plane (mm, 0 at the gear's front face as in the job; 0 when the file has none)."""

    plane_x: np.ndarray
    plane_y: np.ndarray
    axial: np.ndarray


def read_points_csv(text: str, source: str) -> MeasuredPoints:
    """The points of a measured-points CSV text (see the module docstring); one line naming the line on error."""
    return points_from_lines(enumerate(text.splitlines(), start=1), source)


def read_points_file(path: str | os.PathLike, source: str | None = None) -> MeasuredPoints:
    """The points of a measured-points CSV file, read as a stream (measured_lines; never taken for a probe log:
    spur_cad.grade.probe_log.read_measured_file tells them apart)."""
    with measured_lines(path, source) as (lines, shown_source):
        return points_from_lines(lines, shown_source)


@contextlib.contextmanager
def measured_lines(path: str | os.PathLike, source: str | None = None):
    """(the (line number, text) pairs of a measured file, the name its messages use) of a regular file (a FIFO or
    a device is refused before reading) of at most MAX_MEASURED_BYTES, read a line at a time."""
    from spur_cad.errors import shown_path
    from spur_cad.inputs import open_regular_file

    source = source if source is not None else shown_path(path)
    with open_regular_file(path, "measured points file", MeasuredPointsError) as handle:
        size = os.fstat(handle.fileno()).st_size
        if size > MAX_MEASURED_BYTES:
            raise MeasuredPointsError(f"{source}: the measured points file has {size:,} bytes; grade reads at most "
                                      f"{MAX_MEASURED_BYTES:,} ({MAX_MEASURED_BYTES // 2**20} MiB)")
        yield _file_lines(handle, source), source


def looks_like_probe_log(line: str) -> bool:
    """True for a line of nine numbers separated by blanks (LinuxCNC's probe log), never for a CSV line."""
    parts = line.split()
    if "," in line or ";" in line or len(parts) != 9:
        return False
    try:
        [float(part) for part in parts]
    except ValueError:
        return False
    return True


def _file_lines(handle, source: str):
    """(line number, text) of a binary file handle, a line of at most MAX_LINE_CHARS at a time; one line naming
    the file and line for a longer line or one that is not UTF-8."""
    for number, raw in enumerate(iter(lambda: handle.readline(MAX_LINE_CHARS + 3), b""), start=1):
        if len(raw) > MAX_LINE_CHARS + 2:
            raise MeasuredPointsError(f"{source}:{number}: a line of more than {MAX_LINE_CHARS:,} "
                                      "characters; a point is a line of two or three numbers")
        try:
            yield number, raw.decode("utf-8")
        except UnicodeDecodeError:
            raise MeasuredPointsError(f"{source}:{number}: not a text file (not UTF-8)") from None


def points_from_lines(lines, source: str) -> MeasuredPoints:
    """Points from (line number, text) pairs; compact columns (24 bytes a point), at most MAX_POINTS."""
    from array import array

    from spur_cad.errors import shown

    columns = (array("d"), array("d"), array("d"))
    for number, raw in lines:
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        parts = [part.strip() for part in line.replace(";", ",").split(",")]
        try:
            values = [float(part) for part in parts]
        except ValueError:
            if not columns[0] and not any(ch.isdigit() for ch in line):
                continue  # a header of column names
            raise MeasuredPointsError(f"{source}:{number}: not numbers: {shown(line)}") from None
        if len(values) not in (2, 3):
            raise MeasuredPointsError(f"{source}:{number}: expected x_mm,y_mm[,X_mm], got {len(values)} values")
        if not all(math.isfinite(v) and abs(v) < 1e5 for v in values):
            raise MeasuredPointsError(f"{source}:{number}: a value is not a finite coordinate below 1e5 mm")
        for column, value in zip(columns, values + [0.0] * (3 - len(values))):
            column.append(value)
        if len(columns[0]) > MAX_POINTS:
            raise MeasuredPointsError(f"{source}: more than {MAX_POINTS:,} points")
    if len(columns[0]) < 10:
        raise MeasuredPointsError(f"{source}: {len(columns[0])} points; at least 10 are needed")
    return MeasuredPoints(*(np.frombuffer(column, np.float64).copy() for column in columns))


def _design(spec):
    """Every tooth space's design points, normals, roll lengths and flank labels (space, side) for the gear. The
    involute's end on the form circle is sampled as the fillet's first point; it is labelled a flank point too,
    since the profile's evaluation range starts there (a probe's first profile point sits on it)."""
    from spur_cad.sim.design import design_grid

    grid = design_grid(spec, DESIGN_SPACING_MM, 0.0, 0.0, np.zeros(0))
    names = grid.feature_names()
    radius = np.hypot(grid.points[:, 0], grid.points[:, 1])
    on_flank = [name.endswith("involute") or (name.endswith("fillet") and abs(r - spec.form_radius_mm) <= 1e-6)
                for name, r in zip(names, radius)]
    side = np.array([name.split()[0] if flank else "" for name, flank in zip(names, on_flank)])
    points = np.concatenate([grid.space_points(k) for k in range(grid.teeth)])
    normals = np.concatenate([grid.space_normals(k) for k in range(grid.teeth)])
    space = np.repeat(np.arange(grid.teeth), len(grid.points))
    roll = np.tile(profile_roll_mm(spec, radius), grid.teeth)  # a ring's negative, as the simulated grading's
    return points, normals, space, np.tile(side, grid.teeth), roll, np.tile(radius, grid.teeth)


def _deviations(tree, points, normals, y, z, axial, params, turn_rad_per_mm):
    """Normal deviation (mm) of each point from its nearest design point and that point's index: the points
    taken about the centre, turned by the angle and, for a helical gear, back by their section's turn at their X
    (`turn_rad_per_mm`), so that every section meets the design section of X = 0."""
    angle, cy, cz = params
    angle = angle - turn_rad_per_mm * axial
    c, s = np.cos(angle), np.sin(angle)
    py, pz = c * (y - cy) - s * (z - cz), s * (y - cy) + c * (z - cz)
    _, nearest = tree.query(np.column_stack([py, pz]))
    deviation = (py - points[nearest, 0]) * normals[nearest, 0] + (pz - points[nearest, 1]) * normals[nearest, 1]
    return deviation, nearest


def fit(spec, measured: MeasuredPoints, design=None, datum: str = "best-fit", modifications=None):
    """Rotation (rad) and centre (mm) that bring the points nearest the design (least squares of the normal
    deviations), and each point's deviation (mm, + material) and nearest design point after the fit. With
    `modifications` the design is the modified one: a flank point's deviation is read from the modified flank.
    `datum` "axis": the file's origin is the gear's datum axis, the centre stays (0, 0) and only the rotation is
    fitted (a turn changes no pitch deviation; a centre fit would take the eccentricity out of F_p).
    `design`: `_design(spec)` when the caller has it already."""
    from scipy.optimize import least_squares
    from scipy.spatial import cKDTree

    points, normals, _, sides, rolls, _ = design if design is not None else _design(spec)
    tree = cKDTree(points)

    def modified(deviation, nearest, axial):  # the deviation from the modified design (+ the design's removal)
        if modifications is None:
            return deviation
        return deviation + design_removal_mm(modifications, sides[nearest], rolls[nearest], axial)

    turn = spec.section_turn_rad(1.0)  # rad per mm of X (0 for a spur gear)
    pitch = 2.0 * math.pi / spec.teeth
    step = max(1, len(measured.plane_x) // FIT_POINTS)  # the fit on an even subset; deviations of every point after
    y, z, x = measured.plane_x[::step], measured.plane_y[::step], measured.axial[::step]

    def residuals(p):
        params = p if datum != "axis" else [p[0], 0.0, 0.0]
        deviation, nearest = _deviations(tree, points, normals, y, z, x, params, turn)
        return modified(deviation, nearest, x)

    starts = np.linspace(0.0, pitch, 48, endpoint=False)  # the rotation's basin is narrower than a pitch
    costs = [np.sum(residuals([a, 0.0, 0.0]) ** 2) for a in starts]
    start = [float(starts[int(np.argmin(costs))]), 0.0, 0.0][:1 if datum == "axis" else 3]
    best = least_squares(residuals, x0=start, x_scale=[0.01] * len(start))
    params = list(best.x) + [0.0, 0.0] if datum == "axis" else list(best.x)
    deviation, nearest = _deviations(tree, points, normals, measured.plane_x, measured.plane_y, measured.axial,
                                     params, turn)
    return params, modified(deviation, nearest, measured.axial), nearest


REFERENCE_ROLL_TOLERANCE_MM = 0.1
"""A flank's point in one plane counts as its point on the reference circle (a pitch or helix point, as a probe
or a CMM takes them) when its roll length is this close to the reference circle's; traces that span the
reference circle are interpolated. A fitted centre tens of um off slides a point along the flank by as much,
which is about three times that in roll length near the reference circle of a 20 deg gear; a profile slope of
10 um over the trace changes the deviation by well under 0.1 um over 0.1 mm."""


def flank_traces(spec: GearSpec, axial: np.ndarray, deviation: np.ndarray, space: np.ndarray, side: np.ndarray,
                 roll: np.ndarray) -> tuple[list[Trace], dict[str, dict[int, float]]]:
    """Profile traces per flank and plane of points labelled by space, side ('right', 'left', '' off the
    involutes) and roll length (mm); per flank and plane the deviation at the reference circle's roll length
    (interpolated along the profile trace, or a single point within REFERENCE_ROLL_TOLERANCE_MM of it), which
    gives helix traces (three planes or more) and the flank's position on the reference circle (um of arc, mean
    over the planes) by side and space."""
    profile_range = profile_range_mm(spec)
    helix_range = helix_range_mm(spec.face_width_mm, spec.module_mm)
    cos_alpha = spec.base_radius_mm / spec.reference_radius_mm
    reference_roll = float(profile_roll_mm(spec, spec.reference_radius_mm))
    found: list[Trace] = []
    positions: dict[str, dict[int, float]] = {"right": {}, "left": {}}
    for flank_side in ("right", "left"):
        for k in range(spec.teeth):
            on_flank = (side == flank_side) & (space == k)
            if not np.any(on_flank):
                continue
            dev_um, flank_roll = deviation[on_flank] * 1000.0, roll[on_flank]
            planes = np.round(axial[on_flank], 3)
            at_reference = []
            for plane in np.unique(planes):
                order = np.argsort(flank_roll[planes == plane])
                trace_roll, trace_dev = flank_roll[planes == plane][order], dev_um[planes == plane][order]
                if len(trace_roll) >= 3:
                    found.append(Trace("profile", k, flank_side, float(plane), trace_roll, trace_dev, profile_range))
                nearest = int(np.argmin(np.abs(trace_roll - reference_roll)))
                if len(trace_roll) >= 2 and trace_roll[0] <= reference_roll <= trace_roll[-1]:
                    at_reference.append((float(plane), float(np.interp(reference_roll, trace_roll, trace_dev))))
                elif abs(trace_roll[nearest] - reference_roll) <= REFERENCE_ROLL_TOLERANCE_MM:
                    at_reference.append((float(plane), float(trace_dev[nearest])))
            if at_reference:
                positions[flank_side][k] = float(np.mean([dev for _, dev in at_reference])) / cos_alpha
            if len(at_reference) >= 3:
                x, dev = np.array(at_reference).T
                found.append(Trace("helix", k, flank_side, None, x, dev, helix_range))
    return found, positions


def graded(spec, found_traces: list[Trace], positions, axial: np.ndarray, fitted: MeasuredFit,
           notes: tuple[str, ...] = ()) -> Grading:
    """The Grading of measured traces and flank positions: pitch when every flank of a side has its position;
    a note for planes outside the face width."""
    worst, where = worst_deviations(found_traces)
    complete = [(flank_side, p) for flank_side, p in positions.items() if len(p) == spec.teeth]
    for flank_side, flank_positions in complete:  # pitch needs every flank of one side
        add_pitch(worst, where, flank_side, np.array([flank_positions[k] for k in range(spec.teeth)]))
    graded_names = ({name for name in worst if name not in ("f_pt", "F_p")}
                    | ({"f_pt", "F_p"} if complete else set()))
    outside = sorted({float(x) for x in np.unique(np.round(axial, 3))
                      if not -1e-9 <= x <= spec.face_width_mm + 1e-9})
    classes, overall = classes_of(spec, worst, graded_names)
    if outside:
        notes += (f"planes at X = {', '.join(f'{x:g}' for x in outside)} mm lie outside the face width "
                  f"[0, {spec.face_width_mm:g}] mm (X is measured from the gear's front face)",)
    return Grading(deviations_um={name: round(value, 3) for name, value in worst.items() if name in graded_names},
                   where=where, classes=classes, overall_class=overall, validity=validity(spec),
                   traces=tuple(found_traces), points=int(len(axial)), notes=notes, fit=fitted)


def grade_measured(spec, measured: MeasuredPoints, datum: str = "best-fit", modifications=None) -> Grading:
    """ISO 1328-1 deviations and classes of the measured flanks (worst over the flanks measured). `datum`:
    "best-fit" fits the centre and rotation (the eccentricity leaves F_p), "axis" takes the file's origin as the
    gear's datum axis and fits the rotation only. A helical gear's sections are turned back by their X first.
    `modifications` (the job's FlankModifications): graded against the modified design, with the modifications as
    cut (spur_cad.grade.design_trace)."""
    if datum not in ("best-fit", "axis"):
        raise SpurCadError(f"datum must be 'best-fit' or 'axis', got {datum!r}")
    design = _design(spec)
    params, deviation, nearest = fit(spec, measured, design, datum, modifications)
    _, _, space, side, roll, _ = design
    found_traces, positions = flank_traces(spec, measured.axial, deviation, space[nearest], side[nearest],
                                           roll[nearest])
    pitch = 2.0 * math.pi / spec.teeth
    turn = -((params[0] + 0.5 * pitch) % pitch - 0.5 * pitch)  # the scan's turn from the design, within a pitch
    fitted = MeasuredFit(math.degrees(turn), (float(params[1]), float(params[2])),
                         float(np.sqrt(np.mean(deviation ** 2)) * 1000.0), datum)
    return against_design(graded(spec, found_traces, positions, measured.axial, fitted), modifications)
