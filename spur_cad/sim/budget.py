"""The machine's error budget applied to the simulated cut (docs/simulation.md, "Error budget").

The simulation cuts with an ideal machine; a real one indexes each space with an error, runs its tool out,
positions its axes within an accuracy and bends its tool under the cutting force. Rather than cut again, the
budget acts on the simulated deviations of the flanks (the involute points ISO 1328 grades), exactly enough
for deviations of micrometres:

- the table's error e(A) (arcsec) turns a point's cut by -e(A) in the part frame, at the A that cut the point: a
  point p with normal n moves by -e(A) (p x n) along n, which is -e(A) r_b on an involute flank (the arc r e on the
  reference circle, as the grader reads it). With the finishing's contact angles (spur_cad.sim.contact: generating
  and perimeter finishing cut each flank point at its own A: 24 and 3 deg per flank of the reference gear) e is
  taken at each point's A, so a once-per-turn error makes the eccentric gear a real table makes; without them (a
  helical gear) at each space's index angle, a rigid turn of the space;
- runout (half the total indicated runout of spindle and tool: the longest edge cuts), a tool larger than
  the program assumes and the linear positioning accuracy (half of it, worst case into the material) move
  every flank into the material by their size;
- the finishing tool's deflection F / k (a cantilever of its stick-out) moves every flank out of the material.

A 3-axis machine (the blank lying flat, [machine] axes = 3) has no table indexing the spaces: its budget is the
flank shifts alone (runout, tool size, linear axes), no index error (ErrorBudget.rotary_table false).

Index errors: the calibration table when the job names one (the machine's measured error at each A), else a
once-per-turn sine of the positioning accuracy's amplitude (the worm wheel's eccentricity, the usual largest
term); plus the repeatability as a pseudo-random draw per space, uniform in +-repeatability / 2, from the
fixed seed RANDOM_SEED: the same job gives the same figures on every computer (a non-repeatable error, drawn once per
space: the space's index).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from spur_cad.cam.calibration import CalibrationTable

ARCSEC_RAD = math.pi / (180.0 * 3600.0)
CARBIDE_E_N_MM2 = 600_000.0
"""Young's modulus of cemented carbide (about 600 GPa)."""
FLUTED_CORE_FRACTION = 0.8
"""The fluted part of an end mill bends as a round bar of about 0.8 times its diameter."""
RANDOM_SEED = 1328
"""Seed of the repeatability's draw per space (stated in summary.json)."""
NO_TABLE_SOURCE = "no rotary table (3 axes): no index error"
"""The index errors' source on a 3-axis machine."""
@dataclass(frozen=True)
class Deflection:
    """The finishing tool bent by the cutting force: Kienzle's force on the finishing cut's chip (thickness h,
    width b), the cantilever's stiffness 3 E I / L^3 (I = pi d^4 / 64, d = 0.8 D, L the stick-out) and the
    deflection F / k."""

    material: str
    kc11_n_mm2: float
    mc: float
    layer_mm: float
    chip_thickness_mm: float
    chip_width_mm: float
    force_n: float
    stiffness_n_mm: float
    deflection_um: float


def finishing_deflection(diameter_mm: float, corner_radius_mm: float, stick_out_mm: float,
                         feed_per_tooth_mm: float, layer_mm: float, material) -> Deflection | None:
    """The deflection of the finishing tool (None without a stick-out). The finishing cut takes a layer
    `layer_mm` (the finish stock roughing leaves) off the flank: the mean chip thickness is f_z sqrt(a / D)
    and the chip's width the corner's arc in the layer, sqrt(2 r a) (r: the corner radius, D/2 for a flat
    tool). `material` is a spur_cad.cam.materials.Material."""
    if stick_out_mm <= 0.0 or layer_mm <= 0.0:
        return None
    radius = corner_radius_mm if corner_radius_mm > 0.0 else diameter_mm / 2.0
    thickness = feed_per_tooth_mm * math.sqrt(layer_mm / diameter_mm)
    width = math.sqrt(2.0 * radius * layer_mm)
    force = material.cutting_force_n(thickness, width)
    inertia = math.pi * (FLUTED_CORE_FRACTION * diameter_mm) ** 4 / 64.0
    stiffness = 3.0 * CARBIDE_E_N_MM2 * inertia / stick_out_mm ** 3
    return Deflection(material.name, material.kc11_n_mm2, material.mc, layer_mm, thickness, width, force, stiffness,
                      1000.0 * force / stiffness)


@dataclass(frozen=True)
class ErrorBudget:
    """What the machine adds to the ideal cut ([machine] accuracy keys, the calibration table, the deflection)."""

    rotary_accuracy_arcsec: float = 0.0
    rotary_repeatability_arcsec: float = 0.0
    calibration: CalibrationTable | None = None
    runout_tir_um: float = 0.0
    tool_radius_error_um: float = 0.0
    linear_accuracy_um: float = 0.0
    deflection: Deflection | None = None
    rotary_table: bool = True  # False: 3 axes, no table indexes the spaces (no index error)


@dataclass(frozen=True)
class BudgetTerms:
    """The budget as applied: each space's A, systematic and random index error (arcsec) and their sum, and the
    flanks' shift along their normal by each term (um, + out of the material)."""

    index_source: str
    random_seed: int
    space_a_deg: tuple[float, ...]
    systematic_index_arcsec: tuple[float, ...]
    random_index_arcsec: tuple[float, ...]
    index_error_arcsec: tuple[float, ...]
    flank_shift_um: dict[str, float]
    eccentricity_um: float = 0.0  # r_b x the systematic error's once-per-turn amplitude, when applied per point
    rotary_table: bool = True  # False: the 3-axis machine's budget (no index error; index_source says so)

    def to_json(self) -> dict:
        return {"index_source": self.index_source, "random_seed": self.random_seed,
                "space_a_deg": list(self.space_a_deg),
                "systematic_index_arcsec": list(self.systematic_index_arcsec),
                "random_index_arcsec": list(self.random_index_arcsec),
                "index_error_arcsec": list(self.index_error_arcsec), "flank_shift_um": dict(self.flank_shift_um)}


def index_errors(budget: ErrorBudget, teeth: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, str]:
    """Each space's A (space k is cut at A = -k 360 / z, taken in [0, 360)), its systematic and random index
    error (arcsec), and where the systematic one comes from."""
    a_deg = np.mod(-360.0 * np.arange(teeth) / teeth, 360.0)
    if not budget.rotary_table:
        return a_deg, np.zeros(teeth), np.zeros(teeth), NO_TABLE_SOURCE
    if budget.calibration is not None:
        systematic = budget.calibration.error_at(a_deg)
        source = f"calibration table {budget.calibration.source}"
    else:
        systematic = budget.rotary_accuracy_arcsec * np.sin(np.radians(a_deg))
        source = f"positioning accuracy: once-per-turn sine of {budget.rotary_accuracy_arcsec:g} arcsec amplitude"
    half = budget.rotary_repeatability_arcsec / 2.0
    random = np.random.default_rng(RANDOM_SEED).uniform(-half, half, teeth) if half > 0.0 else np.zeros(teeth)
    return a_deg, systematic, random, source


def systematic_at(budget: ErrorBudget, a_deg: np.ndarray) -> np.ndarray:
    """The table's systematic error (arcsec) at the commanded A (deg): the calibration table's, else the accuracy's
    once-per-turn sine."""
    if budget.calibration is not None:
        return budget.calibration.error_at(a_deg)
    return budget.rotary_accuracy_arcsec * np.sin(np.radians(a_deg))


def once_per_turn_arcsec(budget: ErrorBudget) -> float:
    """The amplitude (arcsec) of the systematic error's first harmonic over the turn (1 deg samples)."""
    a = np.radians(np.arange(360.0))
    error = systematic_at(budget, np.degrees(a))
    return float(np.hypot(2.0 * np.mean(error * np.cos(a)), 2.0 * np.mean(error * np.sin(a))))


def flank_shifts_um(budget: ErrorBudget) -> dict[str, float]:
    """Every flank's shift along its normal by each term and their total (um, + out of the material)."""
    shifts = {"runout": 0.0 - budget.runout_tir_um / 2.0, "tool_radius": 0.0 - budget.tool_radius_error_um,
              "linear": 0.0 - budget.linear_accuracy_um / 2.0,
              "deflection": budget.deflection.deflection_um if budget.deflection is not None else 0.0}
    return {**shifts, "total": sum(shifts.values())}


def flank_mask(grid) -> np.ndarray:
    """The involute points of a design grid (both flanks)."""
    return np.array([name.endswith("involute") for name in grid.feature_names()])


def apply_budget(grid, deviation: np.ndarray, budget: ErrorBudget,
                 point_a_deg: np.ndarray | None = None) -> tuple[np.ndarray, BudgetTerms]:
    """The deviations (space, point, row; mm, + material) of the flanks cut on the budget's machine (a new
    array; fillets, root and tip keep theirs) and the terms as applied. point_a_deg (space, involute point): the
    commanded A that cut each involute point (spur_cad.sim.contact.flank_point_angles); the systematic error is
    then taken there, else at each space's index angle."""
    a_deg, systematic, random, source = index_errors(budget, grid.teeth)
    total = systematic + random
    shifts = flank_shifts_um(budget)
    mask = flank_mask(grid)
    p, n = grid.points[mask], grid.normals[mask]
    lever_mm = p[:, 0] * n[:, 1] - p[:, 1] * n[:, 0]  # p x n: the normal motion per radian of turn (r_b on flanks)
    eccentricity_um = 0.0
    if not budget.rotary_table:
        per_point = np.zeros((grid.teeth, len(lever_mm)))
    elif point_a_deg is None:
        per_point = np.repeat(total[:, None], len(lever_mm), axis=1)
        source += ", at each space's index angle (a rigid turn of the space)"
    else:
        per_point = systematic_at(budget, point_a_deg) + random[:, None]
        source += ", at the A that cut each flank point"
        eccentricity_um = round(float(np.mean(np.abs(lever_mm))) * once_per_turn_arcsec(budget) * ARCSEC_RAD
                                * 1000.0, 3)
    change = -(per_point * ARCSEC_RAD) * lever_mm[None, :] + shifts["total"] / 1000.0
    moved = np.array(deviation, dtype=float, copy=True)
    flank = np.flatnonzero(mask)
    for space in range(len(moved)):  # a space at a time: no temporary the size of the whole gear's deviations
        moved[space, flank, :] += change[space, :, None]
    terms = BudgetTerms(source, RANDOM_SEED, tuple(round(float(a), 6) for a in a_deg),
                        tuple(round(float(e), 3) for e in systematic), tuple(round(float(e), 3) for e in random),
                        tuple(round(float(e), 3) for e in total), {k: round(v, 3) for k, v in shifts.items()},
                        eccentricity_um, budget.rotary_table)
    return moved, terms
