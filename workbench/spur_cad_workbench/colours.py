"""The deviation colour scale, shared by the simulation's points and its colour bar (plain numpy, no FreeCAD)."""

from __future__ import annotations

import numpy as np


def deviation_colours(deviation: np.ndarray, scale_mm: float) -> np.ndarray:
    """(N, 3) RGB in [0, 1]: blue at -scale (gouge), green at 0, red at +scale (leftover) and beyond."""
    t = np.clip(np.asarray(deviation, float) / scale_mm, -1.0, 1.0)
    red = np.clip(t, 0.0, 1.0)
    blue = np.clip(-t, 0.0, 1.0)
    return np.column_stack([red, 1.0 - np.abs(t), blue])
