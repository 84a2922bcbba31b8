"""The generating flat (docs/method.md): how far the involute departs from the tangent line a straight tool
side leaves at one roll, and the leftover between two neighbouring flats. Plain math shared by the spur
and helical generating passes."""

from __future__ import annotations

import numpy as np

from spur_cad.geometry.roots import brentq


def flat_deviation_mm(base_radius_mm: float, t_i: float, t: np.ndarray | float) -> np.ndarray | float:
    """D_i(t) = r_b [t_i (1 - cos d) + sin d - d cos d], d = t - t_i: distance of the involute point
    at roll t from the tangent line (generating flat) at roll t_i (docs/method.md)."""
    d = np.asarray(t, dtype=float) - t_i
    return base_radius_mm * (t_i * (1.0 - np.cos(d)) + np.sin(d) - d * np.cos(d))


def flat_leftover_mm(rb: float, t_i: float, t_j: float) -> float:
    """Largest min(D_i(t), D_j(t)) over t in [t_i, t_j]: at the crossing D_i = D_j."""
    if t_j <= t_i:
        return 0.0
    def difference(t: float) -> float:
        return float(flat_deviation_mm(rb, t_i, t) - flat_deviation_mm(rb, t_j, t))

    t_star = brentq(difference, t_i, t_j, xtol=1e-14, rtol=1e-14)
    return float(flat_deviation_mm(rb, t_i, t_star))
