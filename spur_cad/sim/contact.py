"""The commanded A at which the finishing cut each flank point (docs/correction.md, issue 46).

A rotary table's error is a function e(A) of the commanded A, and every block of the finishing carries its own A:
generating finishing turns each flank point's normal onto the tool's side (A clamped per pass), perimeter finishing
onto the corner, so a flank of one space is cut over a range of A (generating: 24 deg per flank of the reference
gear). A table error moves a flank point by r_b e(A) along its normal at the A that cut it, not at the space's index
angle. This module finds that A from the finishing toolpath itself, for any strategy: for each cutting pose of
space 0, the involute point the tool touches (the nearest to the tool's section in the transverse plane, inside
the involute), tabulated per side against roll length. Space k is the same cut turned by A = -k 360 / z.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from spur_cad.cam.ir import MoveKind
from spur_cad.geometry.frames import turn_points

CONTACT_SPACING_MM = 0.02
"""Involute points are taken this far apart along the flank when finding each pose's contact: a pose's roll length is
known to about this (0.03 deg of A on the reference gear's 24 deg per 18 mm of roll length)."""
TOOL_LENGTH_DIAMETERS = 10.0
"""The tool's section is taken this many diameters long at least (its flute length or stick-out when longer; a job
may give neither): generating finishing touches the flank with the tool's side, several millimetres above its tip."""
CONTACT_TOLERANCE_MM = 0.05
"""A pose touches the flank when its tool comes this close to an involute point (the finishing's passes touch the
design within their scallop; roughing and positioning moves are far off)."""


@dataclass(frozen=True)
class ContactAngles:
    """Per flank side ('right', 'left'): roll lengths (mm, increasing) of space 0's flank and the commanded A (deg)
    of the finishing pose that touched it there; space k is cut at that A - k 360 / z."""

    roll_mm: dict[str, np.ndarray]
    a_deg: dict[str, np.ndarray]
    teeth: int

    def __post_init__(self) -> None:
        for side, roll in self.roll_mm.items():
            if len(roll) < 2 or len(roll) != len(self.a_deg[side]) or np.any(np.diff(roll) <= 0.0):
                raise ValueError(f"contact angles of the {side} flank need two or more increasing roll lengths")

    def at(self, side: np.ndarray, roll_mm: np.ndarray, space: np.ndarray) -> np.ndarray:
        """The commanded A (deg) that cut the points labelled by side, roll length and space (machine numbering);
        NaN for a side with no contacts. Between poses: linear in roll; beyond the first and last, the nearest."""
        found = np.full(len(roll_mm), np.nan)
        for name, roll in self.roll_mm.items():
            on = side == name
            found[on] = np.interp(roll_mm[on], roll, self.a_deg[name])
        return found - 360.0 * np.asarray(space, dtype=float) / self.teeth

    def span_deg(self) -> tuple[float, float]:
        """The range of A over a turn that the flanks were cut at: the space-0 angles' extremes (the other spaces
        repeat them turned)."""
        values = np.concatenate(list(self.a_deg.values()))
        return float(values.min()), float(values.max())


def _tool_distance_mm(local_y: np.ndarray, local_z: np.ndarray, diameter_mm: float, corner_radius_mm: float,
                      length_mm: float) -> np.ndarray:
    """Distance (mm) of points (tool tip centre at the origin, axis +Z) to the tool's axial section: the rectangle
    [-d/2, d/2] x [r, L] grown by the corner radius r (d = D - 2r), which is the bull nose's section (a flat tool:
    r = 0, a ball: d = 0); negative inside."""
    half_core = diameter_mm / 2.0 - corner_radius_mm
    dy = np.abs(local_y) - half_core
    below, above = corner_radius_mm - local_z, local_z - length_mm
    dz = np.maximum(below, above)
    outside = np.hypot(np.maximum(dy, 0.0), np.maximum(dz, 0.0))
    inside = np.minimum(np.maximum(dy, dz), 0.0)
    return outside + inside - corner_radius_mm


def contact_angles(spec, toolpath, tool) -> ContactAngles:
    """The finishing's contact A per side against roll length (ContactAngles) from its cutting poses of space 0.
    ValueError when a side has fewer than two poses touching its involute inside its ends."""
    from spur_cad.sim.design import design_grid

    grid = design_grid(spec, CONTACT_SPACING_MM, 0.0, 0.0, np.zeros(0))
    names = np.array(grid.feature_names())
    flank = np.array([name.endswith("involute") for name in names])
    points = grid.points[flank]
    side = np.array([name.split()[0] for name in names[flank]])
    roll = np.sqrt(np.maximum(np.hypot(points[:, 0], points[:, 1]) ** 2 - spec.base_radius_mm ** 2, 0.0))
    cutting = (toolpath.kind == MoveKind.LINEAR) & (toolpath.space == 0)
    # A taken within (-180, 180]: an unwound program (perimeter finishing goes round the gear at every station) cuts
    # space 0 at A - 360 n too, the same pose for the table's periodic error
    wrapped = np.mod(toolpath.a[cutting] + 180.0, 360.0) - 180.0
    poses = np.unique(np.round(np.column_stack([toolpath.y[cutting], toolpath.z[cutting], wrapped]), 7), axis=0)
    length = max(tool.flute_length_mm, tool.stick_out_mm, TOOL_LENGTH_DIAMETERS * tool.diameter_mm)
    found: dict[str, list[tuple[float, float]]] = {"right": [], "left": []}
    for name in found:
        on = side == name
        flank_points, flank_roll = points[on], roll[on]
        ends = (float(flank_roll.min()), float(flank_roll.max()))
        for y, z, a in poses:
            turned = turn_points(flank_points, math.radians(a))  # the points at R(A) p in the machine, taken
            my, mz = turned[:, 0] - y, turned[:, 1] - z  # about the tool's tip centre
            distance = _tool_distance_mm(my, mz, tool.diameter_mm, tool.corner_radius_mm, length)
            nearest = int(np.argmin(distance))
            touched = float(flank_roll[nearest])
            if abs(distance[nearest]) <= CONTACT_TOLERANCE_MM and ends[0] < touched < ends[1]:
                found[name].append((touched, float(a)))
    rolls: dict[str, np.ndarray] = {}
    angles: dict[str, np.ndarray] = {}
    for name, pairs in found.items():
        if len(pairs) < 2:
            raise ValueError(f"the finishing toolpath touches the {name} involute of space 0 at {len(pairs)} poses; "
                             "the A that cut each flank point cannot be found")
        table = np.array(sorted(pairs))
        unique_roll = np.unique(table[:, 0])
        rolls[name] = unique_roll
        angles[name] = np.array([table[table[:, 0] == r, 1].mean() for r in unique_roll])
    return ContactAngles(rolls, angles, spec.teeth)



def flank_point_angles(spec, grid, contacts: ContactAngles) -> np.ndarray:
    """The commanded A (deg) that cut each involute point of a design grid (spur_cad.sim.design.DesignGrid), per tooth
    space: (teeth, involute points) in the grid's order of its involute points."""
    names = np.array(grid.feature_names())
    flank = np.array([name.endswith("involute") for name in names])
    side = np.array([name.split()[0] for name in names[flank]])
    roll = np.sqrt(np.maximum(np.hypot(grid.points[flank, 0], grid.points[flank, 1]) ** 2
                              - spec.base_radius_mm ** 2, 0.0))
    return np.stack([contacts.at(side, roll, np.full(len(roll), k)) for k in range(grid.teeth)])
