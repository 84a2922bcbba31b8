"""The three frames of the project and the one rotation convention that links them.

- Gap frame of tooth space k: origin at the gear centre, +y along the space's symmetry axis,
  x to the right as seen from +X (the chuck side; seen from the front face, x points left).
  Profiles are computed here for space 0.
- Part frame: fixed to the part, machine (Y, Z) when A = 0. Space 0's gap frame *is* the
  part frame (gap x = machine Y, gap y = machine Z); space k's is turned by k * 360/z in the
  positive A direction.
- Machine frame: gear axis = X = rotary axis A, Y = Z = 0 on the axis, X = 0 on the front
  face, tool along Z above the part. A turns the part right-handed about +X: a point fixed to
  the part at (y, z) is at (y cos A - z sin A, y sin A + z cos A) when A is commanded.

Every module (CAM, simulation, report, workbench display, CAD) turns points with these
functions; see docs/architecture.md.
"""

from __future__ import annotations

import math

import numpy as np


def turn_points(points: np.ndarray, angle_rad: float) -> np.ndarray:
    """(N, 2) points (y, z) turned counter-clockwise by `angle_rad` (as a positive A turns the part)."""
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return np.stack([points[:, 0] * c - points[:, 1] * s, points[:, 0] * s + points[:, 1] * c], axis=-1)


def turn_points_by(points: np.ndarray, angle_rad: float | np.ndarray) -> np.ndarray:
    """Points (..., 2) (y, z) turned counter-clockwise by `angle_rad`; an array of angles (m,) turns (n, 2) points
    by each, giving (m, n, 2) (numpy's cos and sin, for arrays of angles)."""
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    y, z = points[..., 0], points[..., 1]
    if np.ndim(angle_rad) == 0:
        return np.stack([c * y - s * z, s * y + c * z], axis=-1)
    c, s = c[:, None], s[:, None]
    return np.stack([c * y - s * z, s * y + c * z], axis=-1)


def turned_clockwise(angle_rad: np.ndarray | float, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Vectors (x, y) turned clockwise by `angle_rad` (R(-angle)), as an (N, 2) array (the profile's curves are
    built in their own frame and turned into the gap frame with it)."""
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    return np.stack([x * c + y * s, -x * s + y * c], axis=-1)


def turn_point(y: float, z: float, angle_rad: float) -> tuple[float, float]:
    """One point (y, z) turned counter-clockwise by `angle_rad`."""
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return y * c - z * s, y * s + z * c


def machine_to_part(y: np.ndarray, z: np.ndarray, a_deg: np.ndarray) -> np.ndarray:
    """Machine (Y, Z) at rotary angle A -> (N, 2) part-frame coordinates (as at A = 0).

    A point fixed to the part at p is at R(A) p when A is commanded, so p = R(-A) (Y, Z).
    """
    a = np.radians(a_deg)
    c, s = np.cos(a), np.sin(a)
    return np.stack([y * c + z * s, -y * s + z * c], axis=-1)


def part_to_machine(points: np.ndarray, a_deg: float) -> np.ndarray:
    """(N, 2) part-frame points -> machine (Y, Z) when A = `a_deg` is commanded."""
    return turn_points(points, math.radians(a_deg))


def space_angle_rad(space: int, teeth: int) -> float:
    """Angle by which tooth space `space`'s gap frame is turned from space 0's (positive A direction)."""
    return space * 2.0 * math.pi / teeth


def gap_to_part(points: np.ndarray, space: int, teeth: int) -> np.ndarray:
    """(N, 2) gap-frame points of tooth space `space` -> part frame."""
    return turn_points(points, space_angle_rad(space, teeth))
