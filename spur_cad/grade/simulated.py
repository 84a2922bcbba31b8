"""Grade a simulated gear by ISO 1328-1:2013: profile, helix and pitch deviations of every flank and the
flank tolerance class each meets (spur_cad.grade.iso1328 for the tolerances and trace evaluation).

The simulation's deviations are along the design normals of a transverse section (as a gear
measuring machine's profile probe reads them), + for material above the design. For each tooth
space and both flanks:

- profile traces at three face positions (the ends and the middle of the helix evaluation range):
  deviation against the roll length sqrt(r^2 - r_b^2) of the involute points (a ring's negative: its traces
  run root to tip too), evaluated from the form circle to 95 % of the roll length to the tip circle (the
  standard leaves the tip's last 5 % out);
- a helix trace on the reference circle's point of the flank, along the face width without, at each
  end, the smaller of 5 % of b and one module;
- the flank's position on the reference circle at mid face: a normal deviation e moves the flank by
  the arc e / cos(alpha_t) there; single pitch deviations are differences of neighbouring flanks of
  one side, the total cumulative pitch deviation their spread.

The gear's grade is the worst class over every deviation of every flank. A modified gear is graded against its
modified design (ISO 1328-1 with a design profile and helix: the simulation's deviations read from the modified
flanks), and the modifications as cut are read from the same traces (spur_cad.grade.design_trace).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from spur_cad.geometry.modifications import FlankModifications
from spur_cad.geometry.spec import GearSpec
from spur_cad.grade.design_trace import against_design
from spur_cad.grade.grading import (
    Grading,
    Trace,
    add_pitch,
    class5,
    classes_of,
    validity,
    worst_deviations,
)

if TYPE_CHECKING:  # the simulator loads only when a job simulates
    from spur_cad.sim.design import DesignGrid
    from spur_cad.sim.simulate import SimResult

SIDES = ("right", "left")
TIP_EXCLUDED_FRACTION = 0.05


def helix_range_mm(face_width_mm: float, module_mm: float) -> tuple[float, float]:
    """The helix evaluation range: the face width less, at each end, the smaller of 5 % of b and one module."""
    cut = min(0.05 * face_width_mm, module_mm)
    return cut, face_width_mm - cut


def profile_roll_mm(spec: GearSpec, radius_mm: float | np.ndarray) -> np.ndarray:
    """The profile trace's position of an involute point at `radius_mm`: its roll length sqrt(r^2 - r_b^2), a
    ring's negative (ISO 21771 signs an internal gear's radii so), so that every profile trace runs from the root
    to the tip in increasing position and a slope + means material rising toward the tip, external or internal."""
    roll = np.sqrt(np.maximum(np.asarray(radius_mm, float) ** 2 - spec.base_radius_mm ** 2, 0.0))
    return spec.kind.roll_sign * roll


def profile_range_mm(spec: GearSpec, start_radius_mm: float | None = None) -> tuple[float, float]:
    """The profile evaluation range in profile_roll_mm: form circle (or `start_radius_mm`: where a 3-axis tool
    leaves the involute, above the rack's form circle; a ring's: inside its cutter-generated form circle), or the
    start of the active profile in mesh with the mate ([mate]: spec.active_profile_start_diameter_mm) when that is
    nearer the tip (ISO 1328-1 evaluates from the SAP), to 95 % of the way to the tip circle (ISO 1328-1 leaves the
    tip's last 5 % out, an internal gear's as well: its tip is the circle toward the axis)."""
    start_radius = spec.form_radius_mm if start_radius_mm is None else start_radius_mm
    start, tip = float(profile_roll_mm(spec, start_radius)), float(profile_roll_mm(spec, spec.tip_radius_mm))
    if spec.active_profile_start_diameter_mm > 0.0:  # roll positions grow toward the tip, a ring's too
        start = max(start, float(profile_roll_mm(spec, spec.active_profile_start_diameter_mm / 2.0)))
    return start, start + (1.0 - TIP_EXCLUDED_FRACTION) * (tip - start)


def _flank_points(grid: DesignGrid, side: str) -> np.ndarray:
    names = grid.feature_names()
    return np.array([name == f"{side} involute" for name in names])


def traces(spec: GearSpec, result: SimResult, profile_start_radius_mm: float | None = None) -> list[Trace]:
    """Profile traces (three face positions) and a helix trace for both flanks of every tooth space (profiles from
    `profile_start_radius_mm`, default the form circle)."""
    grid = result.grid
    rows = np.nonzero(result.gear_rows)[0]
    x = grid.rows_x[rows]
    helix_lo, helix_hi = helix_range_mm(spec.face_width_mm, spec.module_mm)
    face_rows = [rows[np.argmin(np.abs(x - target))] for target in (helix_lo, 0.5 * (helix_lo + helix_hi), helix_hi)]
    profile_range = profile_range_mm(spec, profile_start_radius_mm)
    found = []
    for side in SIDES:
        mask = _flank_points(grid, side)
        radius = np.hypot(grid.points[mask, 0], grid.points[mask, 1])
        roll = profile_roll_mm(spec, radius)
        order = np.argsort(roll)
        reference = int(np.argmin(np.abs(radius - spec.reference_radius_mm)))
        for k in range(grid.teeth):
            deviation = result.deviation[k][mask] * 1000.0
            for row in face_rows:
                found.append(Trace("profile", k, side, float(grid.rows_x[row]), roll[order],
                                   deviation[order, row], profile_range))
            found.append(Trace("helix", k, side, None, x, deviation[reference, rows], (helix_lo, helix_hi)))
    return found


def flank_positions_um(spec: GearSpec, result: SimResult, side: str) -> np.ndarray:
    """Arc deviation of each tooth space's `side` flank on the reference circle at mid face (um)."""
    grid = result.grid
    mask = _flank_points(grid, side)
    radius = np.hypot(grid.points[mask, 0], grid.points[mask, 1])
    reference = int(np.argmin(np.abs(radius - spec.reference_radius_mm)))
    rows = np.nonzero(result.gear_rows)[0]
    middle = rows[np.argmin(np.abs(grid.rows_x[rows] - 0.5 * spec.face_width_mm))]
    cos_alpha = spec.base_radius_mm / spec.reference_radius_mm
    return np.array([result.deviation[k][mask][reference, middle] * 1000.0 / cos_alpha for k in range(grid.teeth)])


def grade_simulation(spec: GearSpec, result: SimResult, profile_start_radius_mm: float | None = None,
                     modifications: FlankModifications | None = None) -> Grading:
    """The gear's ISO 1328-1 grade from the simulated cut: worst deviations over all flanks, their classes, the
    gear's class, the class-5 tolerances, every space's pitch, the validity of the formulas and the traces
    (profiles evaluated from `profile_start_radius_mm`, default the form circle). A modified gear's `result` reads
    its deviations from the modified design (simulate's `modifications`); give the same `modifications` here for
    the design traces and the modifications as cut (spur_cad.grade.design_trace)."""
    measured = traces(spec, result, profile_start_radius_mm)
    worst, where = worst_deviations(measured)
    pitch = {side: add_pitch(worst, where, side, flank_positions_um(spec, result, side)) for side in SIDES}
    classes, overall = classes_of(spec, worst, set(worst))
    tolerances, unrounded = class5(spec)
    grading = Grading(deviations_um={name: round(value, 3) for name, value in worst.items()}, where=where,
                      classes=classes, overall_class=overall, validity=validity(spec), traces=tuple(measured),
                      class5_tolerances_um=tolerances, class5_unrounded_um=unrounded, pitch=pitch)
    return against_design(grading, modifications)
