"""The involute function and its inverse (plain math: the lowest module of the geometry layer)."""

from __future__ import annotations

import math


def involute_function(angle_rad: float) -> float:
    """inv(a) = tan(a) - a, the polar angle of an involute point with pressure angle a."""
    return math.tan(angle_rad) - angle_rad


def inverse_involute_function(value: float) -> float:
    """The pressure angle a in [0, pi/2) with inv(a) = value (Newton on a monotone function)."""
    if value < 0.0:
        raise ValueError(f"inv(a) is never negative, got {value}")
    if value == 0.0:
        return 0.0
    # Cube-root start (inv(a) ~ a^3/3 for small a), then Newton; converges in a few steps.
    angle = min((3.0 * value) ** (1.0 / 3.0), 1.5)
    for _ in range(100):
        step = (involute_function(angle) - value) / math.tan(angle) ** 2
        angle = min(max(angle - step, 1e-12), math.pi / 2 - 1e-12)
        if abs(step) < 1e-16:
            break
    return angle


__all__ = ["involute_function", "inverse_involute_function"]
