"""Grade a gear from the probe log of its probing program (`spur-cad grade JOB probe.log`; docs/probing.md).

LinuxCNC's `(PROBEOPEN probe.log)` writes one line per G38.2 trip: the ball centre's X Y Z A B C U V W in the
program's coordinates (`%f` each, blanks between). The log carries no labels, so the job's probing plan
(spur_cad.cam.probing, recomputed from its [probe] section) names each trip: the n-th line is the plan's n-th
point. Each centre is turned into the part frame with the logged A (as programmed: [post] rotary_sign undone),
checked to lie on its planned probe line, and its deviation is read directly along the design normal:
(centre - R n - p) . n, + material. No fit: the probe moved about the A axis, the gear's datum axis in the
cutting setup, so an eccentricity of the teeth shows in F_p.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from spur_cad.errors import shown
from spur_cad.geometry.frames import machine_to_part
from spur_cad.grade.design_trace import against_design, design_removal_mm
from spur_cad.grade.grading import Grading, MeasuredFit
from spur_cad.grade.measured import (
    MAX_POINTS,
    MeasuredPointsError,
    flank_traces,
    graded,
    looks_like_probe_log,
    measured_lines,
    points_from_lines,
)

LINE_TOLERANCE_MM = 0.005
"""A logged centre farther than this from its planned probe line is not that move's trip (another program, an
edited or shifted one): refused. The ball stops on its programmed line; the program's numbers are rounded to
0.1 um."""
X_TOLERANCE_MM = 0.005
"""The logged X must be the planned point's X within this (X does not move during a probe move)."""
A_TOLERANCE_DEG = 0.01
"""The logged A must be the planned space's A within this (modulo 360 deg)."""


@dataclass(frozen=True)
class ProbeLog:
    """The trips of a probe log in file order: (N, 9) X Y Z A B C U V W as logged, and each one's line."""

    values: np.ndarray
    line_numbers: tuple[int, ...]
    source: str


def read_probe_log_lines(lines, source: str) -> ProbeLog:
    """A probe log from (line number, text) pairs: lines of nine numbers; blank lines are skipped, anything else
    is refused with one line naming the file and line."""
    rows: list[list[float]] = []
    numbers: list[int] = []
    for number, raw in lines:
        line = raw.strip()
        if not line:
            continue
        parts = line.split()
        try:
            values = [float(part) for part in parts]
        except ValueError:
            raise MeasuredPointsError(f"{source}:{number}: a probe log line is nine numbers (X Y Z A B C U V W), "
                                      f"got {shown(line)}") from None
        if len(values) != 9:
            raise MeasuredPointsError(f"{source}:{number}: a probe log line is nine numbers (X Y Z A B C U V W), "
                                      f"got {len(values)}")
        if not all(math.isfinite(v) and abs(v) < 1e5 for v in values):
            raise MeasuredPointsError(f"{source}:{number}: a value is not a finite coordinate below 1e5")
        rows.append(values)
        numbers.append(number)
        if len(rows) > MAX_POINTS:
            raise MeasuredPointsError(f"{source}: more than {MAX_POINTS:,} trips")
    if not rows:
        raise MeasuredPointsError(f"{source}: the probe log holds no trip")
    return ProbeLog(np.array(rows, dtype=np.float64), tuple(numbers), source)


def _part(points_yz: np.ndarray, a_deg: np.ndarray) -> np.ndarray:
    return machine_to_part(points_yz[:, 0], points_yz[:, 1], a_deg)


def probe_deviations(spec, plan, log: ProbeLog, rotary_sign: int = 1) -> np.ndarray:
    """Each trip's normal deviation (mm, + material) from its planned point (the log's n-th line is the plan's
    n-th point). MeasuredPointsError naming the line for a trip beyond the plan, at another X or A than its
    point's, off its probe line or beyond the move's ends."""
    points, probe = plan.points[:len(log.values)], plan.section
    if len(log.values) > len(plan.points):
        line = log.line_numbers[len(plan.points)]
        raise MeasuredPointsError(f"{log.source}:{line}: trip {len(plan.points) + 1}, but the job's probing program "
                                  f"has {len(plan.points)} points (a log of another program, or of two runs?)")
    x, y, z, a = log.values[:, :4].T
    a_job = rotary_sign * a  # the programmed A word is rotary_sign * A
    plan_a = np.array([pt.a_deg for pt in points])
    design = _part(np.array([pt.point for pt in points]), plan_a)
    normal = _part(np.array([pt.normal for pt in points]), plan_a)
    centre = machine_to_part(y, z, a_job)
    along = np.sum((centre - design) * normal, axis=1)
    off_line = np.hypot(*(centre - design - along[:, None] * normal).T)
    ball = probe.ball_radius_mm
    checks = (
        (np.abs((a_job - plan_a + 180.0) % 360.0 - 180.0) > A_TOLERANCE_DEG,
         lambda i: f"A = {a[i]:g}, but its point (P{i + 1}, space {points[i].space}) is probed at "
                   f"A = {rotary_sign * plan_a[i]:g}"),
        (np.abs(x - np.array([pt.x_mm for pt in points])) > X_TOLERANCE_MM,
         lambda i: f"X = {x[i]:g}, but its point (P{i + 1}) is at X = {points[i].x_mm:g}"),
        (off_line > LINE_TOLERANCE_MM,
         lambda i: f"the ball centre is {off_line[i] * 1000.0:.1f} um off the probe line of its point (P{i + 1}, "
                   f"space {points[i].space}, {points[i].side} {points[i].kind}); at most "
                   f"{LINE_TOLERANCE_MM * 1000.0:g} um"),
        ((along < ball - probe.overtravel_mm - LINE_TOLERANCE_MM)
         | (along > ball + probe.approach_mm + LINE_TOLERANCE_MM),
         lambda i: f"the ball centre lies {along[i] - ball:+.4f} mm from the design contact of its point "
                   f"(P{i + 1}), beyond the probe move (+{probe.approach_mm:g} to -{probe.overtravel_mm:g} mm)"),
    )
    for bad, message in checks:
        if np.any(bad):
            i = int(np.argmax(bad))
            raise MeasuredPointsError(f"{log.source}:{log.line_numbers[i]}: trip {i + 1}: {message(i)}")
    return along - ball


@dataclass(frozen=True)
class LabelledDeviations:
    """A probe log's trips as points of the plan: each one's space, flank side, roll length (mm) and X (mm), and its
    normal deviation (mm, + material) from the design, the modified design when the job has modifications."""

    space: np.ndarray
    side: np.ndarray
    roll_mm: np.ndarray
    x_mm: np.ndarray
    deviation_mm: np.ndarray


def labelled_deviations(spec, plan, log: ProbeLog, rotary_sign: int = 1, modifications=None) -> LabelledDeviations:
    """probe_deviations labelled by the plan's points; with `modifications`, each trip's deviation plus the design's
    removal at its point (read from the modified flank: a designed relief is no deviation)."""
    deviation = probe_deviations(spec, plan, log, rotary_sign)
    points = plan.points[:len(deviation)]
    roll = np.sqrt(np.maximum(np.array([pt.radius_mm for pt in points]) ** 2 - spec.base_radius_mm ** 2, 0.0))
    axial = np.array([pt.x_mm for pt in points])
    sides = np.array([pt.side for pt in points])
    if modifications is not None:
        deviation = deviation + design_removal_mm(modifications, sides, roll, axial)
    return LabelledDeviations(np.array([pt.space for pt in points]), sides, roll, axial, deviation)


def grade_probe_log(spec, plan, log: ProbeLog, rotary_sign: int = 1, modifications=None) -> Grading:
    """ISO 1328-1 deviations and classes from a probe log (the module docstring): traces as the measured-points
    grading builds them, from the plan's labels (space, side, roll length, X), with no fit. A log shorter than the
    plan (the program stopped) is graded on its trips, with a note. `modifications`: graded against the modified
    design (labelled_deviations), with the modifications as cut."""
    trips = labelled_deviations(spec, plan, log, rotary_sign, modifications)
    found, positions = flank_traces(spec, trips.x_mm, trips.deviation_mm, trips.space, trips.side, trips.roll_mm)
    notes = () if len(trips.space) == len(plan.points) else (
        f"the probe log holds {len(trips.space)} of the probing program's {len(plan.points)} trips (the program "
        f"stopped early?): graded on those",)
    fitted = MeasuredFit(0.0, (0.0, 0.0), float(np.sqrt(np.mean(trips.deviation_mm ** 2)) * 1000.0), "probe log")
    return against_design(graded(spec, found, positions, trips.x_mm, fitted, notes), modifications)


def read_measured_file(path, source: str | None = None):
    """A measured file (spur_cad.grade.measured.measured_lines): a ProbeLog when its first non-blank line is nine
    numbers separated by blanks, as LinuxCNC's PROBEOPEN log writes them, else the MeasuredPoints of a CSV."""
    from itertools import chain

    with measured_lines(path, source) as (lines, shown_source):
        first = next(((number, text) for number, text in lines if text.strip()), None)
        rest = chain([first], lines) if first is not None else iter(())
        if first is not None and looks_like_probe_log(first[1]):
            return read_probe_log_lines(rest, shown_source)
        return points_from_lines(rest, shown_source)
