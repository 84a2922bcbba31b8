"""The rotary table's error e(A) as a Fourier series, identified from a measured gear (docs/correction.md, issue 46).

Every flank point was cut at its own commanded A (spur_cad.sim.contact); the table stood e(A) further, which
turns the point's cut by -e(A) in the part frame and moves it by -e(A) (p x n) along its normal (p x n = +-r_b on an
involute). Over the gear, the flanks' points sample e(A) over the whole turn (each flank over a range of A, the
spaces 360 / z apart), so e(A) is fitted as a series

    e(A) = sum over the orders h kept of  c_h cos(h A) + s_h sin(h A)

by least squares, together with each side's size and slopes (the columns of fit_flank_model). Which orders:

- tested are 1 to z // 2 (z // 2: the highest order the z spaces' flanks sample at least twice per period at each
  roll length: higher orders alias with lower ones in the pitch, and order z repeats in every space, which is a
  form error of the profile, not a position); a scan of fewer spaces, n, tests up to n // 2;
- the mean (order 0) is a turn of the whole gear, which the scan's fitted rotation takes;
- order 1 on a datum-axis scan only: a best fit of the centre takes a once-per-turn error whole (it is an eccentric
  gear), and so does a once-per-turn error look exactly like a blank off the A axis (FirstHarmonic);
- an order is kept when its amplitude exceeds SIGNIFICANCE times its standard uncertainty and moves a flank by
  MIN_FLANK_MOTION_UM or more;
  the uncertainties are cluster-robust over the flanks (each flank's residuals are one draw: its scallops and form
  repeat in every plane), so a flank's ripple does not count as many independent points.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

ARCSEC_RAD = math.pi / (180.0 * 3600.0)
SIGNIFICANCE = 3.0
"""An order's amplitude must exceed this many standard uncertainties to be kept (a false harmonic from noise alone
passes with a probability of about 1 %, Rayleigh-distributed amplitude)."""
MIN_FLANK_MOTION_UM = 0.1
"""Nor is an order kept that moves a flank by less than this (r_b times its amplitude; 0.48 arcsec on the reference
gear): below it the flanks' scallops and form, which repeat in every space, make harmonics of a few hundredths of
an arcsec that pass the significance test but are no table's."""


@dataclass(frozen=True)
class Harmonic:
    """One order of e(A): c cos(h A) + s sin(h A) (arcsec), the amplitude's standard uncertainty, and whether it
    was kept (significant) or only tested."""

    order: int
    cos_arcsec: float
    sin_arcsec: float
    uncertainty_arcsec: float
    kept: bool

    @property
    def amplitude_arcsec(self) -> float:
        return math.hypot(self.cos_arcsec, self.sin_arcsec)

    def __post_init__(self) -> None:
        if self.order < 1 or not all(map(math.isfinite, (self.cos_arcsec, self.sin_arcsec))):
            raise ValueError(f"a table harmonic needs an order >= 1 and finite coefficients, got {self}")


@dataclass(frozen=True)
class TableError:
    """The table's error identified: the orders tested (kept and not), the A range the finishing used (deg, space
    0's flanks; the other spaces repeat it turned, so the series holds over the turn), and whether order 1 could be
    seen (datum axis) at all."""

    harmonics: tuple[Harmonic, ...]
    a_range_deg: tuple[float, float]
    first_order_visible: bool

    @property
    def kept(self) -> tuple[Harmonic, ...]:
        return tuple(h for h in self.harmonics if h.kept)

    def at(self, a_deg: np.ndarray, orders: tuple[int, ...] | None = None) -> np.ndarray:
        """e(A) (arcsec) at the commanded A (deg) from the kept orders (or the kept ones among `orders`)."""
        a = np.radians(np.asarray(a_deg, dtype=float))
        total = np.zeros_like(a)
        for h in self.kept:
            if orders is None or h.order in orders:
                total += h.cos_arcsec * np.cos(h.order * a) + h.sin_arcsec * np.sin(h.order * a)
        return total


@dataclass(frozen=True)
class FlankModel:
    """The least-squares fit of the flank points (fit_flank_model): per side the size (mm), the profile and helix
    slopes (mm over their ranges), the table's error, and each point's residual (mm)."""

    size_mm: dict[str, float]
    size_uncertainty_mm: float
    table: TableError
    residual_mm: np.ndarray
    table_part_mm: np.ndarray


def _columns(lever_mm: np.ndarray, a_deg: np.ndarray, orders: list[int]) -> np.ndarray:
    """Per order the columns -lever cos(hA), -lever sin(hA) (mm of normal motion per radian of the coefficient)."""
    a = np.radians(a_deg)
    return np.column_stack([f(h * a) * -lever_mm for h in orders for f in (np.cos, np.sin)]) \
        if orders else np.zeros((len(a_deg), 0))


def _solve(matrix: np.ndarray, values: np.ndarray, cluster: np.ndarray):
    """Least squares with cluster-robust covariance (the clusters' residual sums as the independent draws)."""
    coef, *_ = np.linalg.lstsq(matrix, values, rcond=None)
    residual = values - matrix @ coef
    bread = np.linalg.pinv(matrix.T @ matrix)
    groups = np.unique(cluster, return_inverse=True)[1]
    scores = np.zeros((groups.max() + 1, matrix.shape[1]))
    np.add.at(scores, groups, matrix * residual[:, None])
    count = len(scores)
    scale = count / max(count - 1, 1) * (len(values) - 1) / max(len(values) - matrix.shape[1], 1)
    covariance = bread @ (scores.T @ scores) @ bread * scale
    return coef, residual, covariance


def fit_flank_model(side: np.ndarray, lever_mm: np.ndarray, a_deg: np.ndarray, profile_t: np.ndarray,
                    helix_t: np.ndarray, deviation_mm: np.ndarray, flank: np.ndarray, teeth: int,
                    first_order_visible: bool, a_range_deg: tuple[float, float]) -> FlankModel:
    """Fit d = size_side + e(A) lever + slope_side,profile t_profile + slope_side,helix t_helix to the points
    (deviation less the ideal cut's, mm), t the position over the evaluation range (-1/2 to 1/2, 0 at its middle);
    the orders of e(A) chosen as the module docstring says, up to half of `teeth`, the number of spaces measured
    (z when all are). `flank`: a label per point naming its flank (the
    clusters of the uncertainty)."""
    sides = ("right", "left")
    base = [(side == name).astype(float) for name in sides]
    base += [(side == name) * profile_t for name in sides] + [(side == name) * helix_t for name in sides]
    fixed = np.column_stack(base)
    keep = np.abs(fixed).sum(axis=0) > 0.0  # a side without helix spread (one plane) has no helix column
    fixed = fixed[:, keep]
    tested = list(range(1 if first_order_visible else 2, teeth // 2 + 1))  # teeth: the spaces measured, at most z
    floor_arcsec = MIN_FLANK_MOTION_UM / 1000.0 / float(np.mean(np.abs(lever_mm))) / ARCSEC_RAD
    coef, _, covariance = _solve(np.column_stack([fixed, _columns(lever_mm, a_deg, tested)]), deviation_mm, flank)
    harmonics = []
    start = fixed.shape[1]
    for i, order in enumerate(tested):
        c, s = coef[start + 2 * i: start + 2 * i + 2] / ARCSEC_RAD
        spread = math.sqrt(max(covariance[start + 2 * i, start + 2 * i], covariance[start + 2 * i + 1,
                                                                                    start + 2 * i + 1]))
        amplitude = math.hypot(c, s)
        harmonics.append(Harmonic(order, float(c), float(s), spread / ARCSEC_RAD,
                                  amplitude > max(SIGNIFICANCE * spread / ARCSEC_RAD, floor_arcsec)))
    kept = [h.order for h in harmonics if h.kept]
    coef, residual, covariance = _solve(np.column_stack([fixed, _columns(lever_mm, a_deg, kept)]), deviation_mm, flank)
    refit = {order: (coef[start + 2 * i] / ARCSEC_RAD, coef[start + 2 * i + 1] / ARCSEC_RAD,
                     math.sqrt(max(covariance[start + 2 * i, start + 2 * i],
                                   covariance[start + 2 * i + 1, start + 2 * i + 1])) / ARCSEC_RAD)
             for i, order in enumerate(kept)}
    harmonics = [Harmonic(h.order, *refit[h.order], True) if h.kept else h for h in harmonics]
    table = TableError(tuple(harmonics), a_range_deg, first_order_visible)
    table_part = _columns(lever_mm, a_deg, kept) @ coef[start:] if kept else np.zeros(len(deviation_mm))
    size_spread = math.sqrt(0.25 * (covariance[0, 0] + covariance[1, 1] + 2.0 * covariance[0, 1]))
    return FlankModel({name: float(coef[i]) for i, name in enumerate(sides)}, size_spread, table, residual,
                      table_part)


def blank_offset_mm(table: TableError, lever_mm: np.ndarray, a_deg: np.ndarray, normals: np.ndarray
                    ) -> tuple[float, float]:
    """The blank offset that leaves the flanks where the table's first order leaves them: the least-squares c with
    c . n = -e_1(A) (p x n) over the points (exact on an involute cut where its normal is turned onto the same line
    in the machine, as generating and perimeter finishing cut: both are c . n for one c). c is the gear's centre as
    cut, about the datum axis (mm, part frame)."""
    motion = -table.at(a_deg, (1,)) * ARCSEC_RAD * lever_mm
    (cy, cz), *_ = np.linalg.lstsq(normals, motion, rcond=None)
    return float(cy), float(cz)

