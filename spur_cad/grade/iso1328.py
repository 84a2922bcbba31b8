"""ISO 1328-1:2013 flank tolerances and the evaluation of profile, helix and pitch traces (plain numbers).

Tolerances: each is its class-5 value times sqrt(2)^(A - 5) for flank tolerance class A (1 finest to
11), rounded (above 10 um to 1 um, 5 to 10 um to 0.5 um, below 5 um to 0.1 um). Class-5 values, with
d the reference diameter, b the face width, m_n the normal module, all in mm, results in um:

    single pitch           f_pT = 0.001 d + 0.4 m_n + 5
    total cumulative pitch F_pT = 0.002 d + 0.55 sqrt(d) + 0.7 m_n + 12
    profile slope          f_HaT = 0.4 m_n + 0.001 d + 4
    profile form           f_faT = 0.55 m_n + 5
    total profile          F_aT = sqrt(f_HaT^2 + f_faT^2)
    helix slope            f_HbT = 0.05 sqrt(d) + 0.35 sqrt(b) + 4
    helix form             f_fbT = 0.07 sqrt(d) + 0.45 sqrt(b) + 4
    total helix            F_bT = sqrt(f_HbT^2 + f_fbT^2)

valid for 5 <= z <= 1000, 5 <= d <= 15000 mm, 0.5 <= m_n <= 70 mm, 4 <= b <= 1200 mm, beta <= 45 deg
(the standard forbids extrapolating; `validity_problems` names what is outside).

Trace evaluation (deviation in um, + is material above the design, along a roll length or the face
width): slope = the least-squares line's rise over the evaluation range; form = the width of the band
around that line holding the trace; total = the band between two copies of the design holding the trace
(max - min).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

CLASSES = tuple(range(1, 12))
KINDS = ("f_pT", "F_pT", "f_HaT", "f_faT", "F_aT", "f_HbT", "f_fbT", "F_bT")
# The deviation each tolerance bounds (ISO 1328-1 symbols without the T).
DEVIATIONS = {"f_pT": "f_pt", "F_pT": "F_p", "f_HaT": "f_Ha", "f_faT": "f_fa", "F_aT": "F_a", "f_HbT": "f_Hb",
              "f_fbT": "f_fb", "F_bT": "F_b"}


def class5_um(d_mm: float, b_mm: float, m_n_mm: float) -> dict[str, float]:
    """The class-5 tolerances (um, unrounded) of a gear with reference diameter d, face width b, module m_n."""
    f_ha = 0.4 * m_n_mm + 0.001 * d_mm + 4.0
    f_fa = 0.55 * m_n_mm + 5.0
    f_hb = 0.05 * math.sqrt(d_mm) + 0.35 * math.sqrt(b_mm) + 4.0
    f_fb = 0.07 * math.sqrt(d_mm) + 0.45 * math.sqrt(b_mm) + 4.0
    return {"f_pT": 0.001 * d_mm + 0.4 * m_n_mm + 5.0,
            "F_pT": 0.002 * d_mm + 0.55 * math.sqrt(d_mm) + 0.7 * m_n_mm + 12.0,
            "f_HaT": f_ha, "f_faT": f_fa, "F_aT": math.hypot(f_ha, f_fa),
            "f_HbT": f_hb, "f_fbT": f_fb, "F_bT": math.hypot(f_hb, f_fb)}


def rounded_um(value_um: float) -> float:
    """ISO 1328-1's rounding of a tolerance: above 10 um to 1 um, 5 to 10 um to 0.5 um, below 5 um to 0.1 um."""
    step = 1.0 if value_um > 10.0 else 0.5 if value_um >= 5.0 else 0.1
    return round(math.floor(value_um / step + 0.5) * step, 1)


def tolerance_um(kind: str, grade: int, d_mm: float, b_mm: float, m_n_mm: float) -> float:
    """Tolerance `kind` (one of KINDS) for flank tolerance class `grade` (1..11), rounded, in um."""
    if grade not in CLASSES:
        raise ValueError(f"flank tolerance class must be 1..11, got {grade}")
    return rounded_um(class5_um(d_mm, b_mm, m_n_mm)[kind] * math.sqrt(2.0) ** (grade - 5))


def class_of(kind: str, deviation_um: float, d_mm: float, b_mm: float, m_n_mm: float) -> int | None:
    """The finest class whose tolerance `kind` holds |deviation|; None when even class 11 does not."""
    for grade in CLASSES:
        if abs(deviation_um) <= tolerance_um(kind, grade, d_mm, b_mm, m_n_mm):
            return grade
    return None


def validity_problems(teeth: int, d_mm: float, m_n_mm: float, b_mm: float, helix_deg: float) -> list[str]:
    """Where the gear is outside the standard's range for these formulas (empty: within)."""
    checks = (("teeth z", teeth, 5, 1000), ("reference diameter d", d_mm, 5.0, 15000.0),
              ("normal module m_n", m_n_mm, 0.5, 70.0), ("face width b", b_mm, 4.0, 1200.0),
              ("helix angle beta", helix_deg, 0.0, 45.0))
    return [f"{name} = {value:g} is outside [{low:g}, {high:g}]" for name, value, low, high in checks
            if not low <= value <= high]


@dataclass(frozen=True)
class TraceDeviations:
    """A trace's slope, form and total deviation (um); slope is signed (+: the trace rises along it)."""

    slope_um: float
    form_um: float
    total_um: float
    mean_line: tuple[float, float]  # (intercept at the range's start, rise per mm) of the least-squares line


def evaluate_trace(position_mm: np.ndarray, deviation_um: np.ndarray, start_mm: float,
                   end_mm: float) -> TraceDeviations:
    """Slope, form and total deviation of a trace over its evaluation range [start, end] (see the module
    docstring); at least three points must lie in the range."""
    position, deviation = np.asarray(position_mm, float), np.asarray(deviation_um, float)
    inside = (position >= start_mm - 1e-12) & (position <= end_mm + 1e-12)
    if np.count_nonzero(inside) < 3 or not end_mm > start_mm:
        raise ValueError("an evaluation needs at least three trace points in a range of positive length")
    s, e = position[inside] - start_mm, deviation[inside]
    rise, intercept = np.polyfit(s, e, 1)
    residual = e - (intercept + rise * s)
    return TraceDeviations(float(rise * (end_mm - start_mm)), float(residual.max() - residual.min()),
                           float(e.max() - e.min()), (float(intercept), float(rise)))


def pitch_deviations(positions_um: np.ndarray) -> tuple[np.ndarray, float, float]:
    """From the position deviation of each flank of one side, around the gear (um, arc on the measuring
    circle; + is the flank ahead of its design place): the single pitch deviations (flank i minus flank
    i - 1), the largest |single| f_pt and the total cumulative pitch deviation F_p (max - min position)."""
    positions = np.asarray(positions_um, float)
    single = positions - np.roll(positions, 1)
    return single, float(np.abs(single).max()), float(positions.max() - positions.min())
