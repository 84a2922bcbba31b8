"""Toolpath IR: a neutral, typed sequence of moves in numpy arrays (docs/architecture.md).

Each row is one move to the pose (x, y, z, a) from the previous row's pose (the first row
starts from wherever the machine is). Machine frame: gear axis = X = rotary axis A, Y = 0 and
Z = 0 on the rotary axis, X = 0 on the front face; the tool axis is Z and the pose is the
centre of the tool tip. `a` is in degrees, right-hand about +X.

`feed` is mm/min for linear moves where A does not move, inverse time (1/min: the move takes
1/feed minutes) where A moves together with X/Y/Z (`inverse_time` True), and NaN for rapids
and markers. Markers (clamp/unclamp of the rotary axis) carry the current pose unchanged.

Arcs (ARC_CW / ARC_CCW, only in 3-axis toolpaths: [machine] axes = 3) turn in the machine's XY plane
(G17) about the centre (`center_x`, `center_y`, absolute mm) from the previous pose to their own, seen
from +Z; Z stays and A is 0. A toolpath without arcs has `center_x` and `center_y` None.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from enum import IntEnum
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from spur_cad.geometry.frames import machine_to_part

NAN = float("nan")

MAX_TOOLPATH_MOVES = 10_000_000
"""Largest toolpath a plan builds (about 13 x the reference job's perimeter finishing: some 0.6 GB of
IR and 0.4 GB of flat G-code); larger work is refused before it is generated (cam/plan.py)."""


class MoveKind(IntEnum):
    RAPID = 0
    LINEAR = 1
    CLAMP_ROTARY = 2
    UNCLAMP_ROTARY = 3
    ARC_CW = 4  # G2 in the XY plane
    ARC_CCW = 5  # G3 in the XY plane


class Operation(IntEnum):
    ROUGHING = 0
    FINISHING = 1


class Feature(IntEnum):
    """What a move is doing, for reports, checks and subprogram folding."""

    NONE = 0  # positioning: rapids, retracts, plunges, index moves
    RIGHT_FLANK = 1
    LEFT_FLANK = 2
    ROOT = 3
    TIP = 4
    LEVEL = 5  # a roughing level pass (or the step between passes)


@dataclass(frozen=True)
class Toolpath:
    """Moves of one operation with one tool (arrays of equal length)."""

    kind: np.ndarray  # int8, MoveKind
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    a: np.ndarray  # degrees
    feed: np.ndarray
    inverse_time: np.ndarray  # bool
    space: np.ndarray  # int32 tooth space index k (space k is turned by k * 360/z from space 0), -1 none
    station: np.ndarray  # int32 finishing station (X step) index, or roughing level index; -1 none
    feature: np.ndarray  # int8, Feature
    operation: Operation
    tool_number: int
    spindle_rpm: float
    warnings: tuple[str, ...] = ()
    center_x: np.ndarray | None = None  # arcs' centres (absolute mm), NaN on other moves; None without arcs
    center_y: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.kind)

    def poses(self) -> np.ndarray:
        """(N, 4) array of x, y, z, a."""
        return np.stack([self.x, self.y, self.z, self.a], axis=-1)

    def start_poses(self) -> np.ndarray:
        """(N, 4) pose each move starts from: the previous row's pose (the first row from its own pose,
        since where the machine is before the program is unknown)."""
        poses = self.poses()
        return np.concatenate([poses[:1], poses[:-1]])

    @property
    def motion_mask(self) -> np.ndarray:
        return (self.kind == MoveKind.RAPID) | self.feed_mask

    @property
    def feed_mask(self) -> np.ndarray:
        """Moves at feed: lines and arcs."""
        return (self.kind == MoveKind.LINEAR) | self.arc_mask

    @property
    def arc_mask(self) -> np.ndarray:
        return (self.kind == MoveKind.ARC_CW) | (self.kind == MoveKind.ARC_CCW)

    def replace(self, **arrays: Any) -> "Toolpath":
        """A copy with some arrays replaced (same length), e.g. feeds converted to inverse time."""
        return dataclasses.replace(self, **arrays)


@dataclass
class ToolpathBuilder:
    """Accumulates moves; generators keep one locally and call build() once (no shared state)."""

    operation: Operation
    tool_number: int
    spindle_rpm: float
    _rows: list[tuple] = field(default_factory=list)
    _chunks: list[dict] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)

    def _flush_rows(self) -> None:
        if not self._rows:
            return
        cols = list(zip(*self._rows))
        self._chunks.append({
            "kind": np.array(cols[0], dtype=np.int8), "x": np.array(cols[1], float), "y": np.array(cols[2], float),
            "z": np.array(cols[3], float), "a": np.array(cols[4], float), "feed": np.array(cols[5], float),
            "inverse_time": np.array(cols[6], bool), "space": np.array(cols[7], np.int32),
            "station": np.array(cols[8], np.int32), "feature": np.array(cols[9], np.int8),
            "center_x": np.array(cols[10], float), "center_y": np.array(cols[11], float)})
        self._rows = []

    def move(self, kind: MoveKind, x: float, y: float, z: float, a: float, feed: float = float("nan"), *,
             inverse_time: bool = False, space: int = -1, station: int = -1,
             feature: Feature = Feature.NONE) -> None:
        self._rows.append((int(kind), x, y, z, a, feed, inverse_time, space, station, int(feature), NAN, NAN))

    def arc(self, clockwise: bool, x: float, y: float, z: float, center_x: float, center_y: float, feed: float, *,
            station: int = -1, feature: Feature = Feature.NONE) -> None:
        """An arc in the XY plane from the last pose to (x, y, z) about (center_x, center_y), A = 0 (3-axis paths)."""
        kind = MoveKind.ARC_CW if clockwise else MoveKind.ARC_CCW
        self._rows.append((int(kind), x, y, z, 0.0, feed, False, -1, station, int(feature), center_x, center_y))

    def extend(self, kind: ArrayLike, x: ArrayLike, y: ArrayLike, z: ArrayLike, a: ArrayLike,
               feed: ArrayLike, inverse_time: ArrayLike, space: ArrayLike, station: ArrayLike,
               feature: ArrayLike) -> None:
        """Append many moves at once (arrays broadcast to a common length)."""
        self._flush_rows()
        n = max(np.size(v) for v in (kind, x, y, z, a, feed, inverse_time, space, station, feature))

        def full(v, dtype):
            return np.broadcast_to(np.asarray(v, dtype=dtype), (n,)).copy()

        self._chunks.append({"kind": full(kind, np.int8), "x": full(x, float), "y": full(y, float),
                             "z": full(z, float), "a": full(a, float), "feed": full(feed, float),
                             "inverse_time": full(inverse_time, bool), "space": full(space, np.int32),
                             "station": full(station, np.int32), "feature": full(feature, np.int8),
                             "center_x": np.full(n, NAN), "center_y": np.full(n, NAN)})

    def last_pose(self) -> tuple[float, float, float, float]:
        """(x, y, z, a) of the last move added; a path's first move has no pose before it (ValueError)."""
        if self._rows:
            row = self._rows[-1]
            return row[1], row[2], row[3], row[4]
        if self._chunks:
            c = self._chunks[-1]
            return float(c["x"][-1]), float(c["y"][-1]), float(c["z"][-1]), float(c["a"][-1])
        raise ValueError("the toolpath has no move yet, so no last pose")

    def build(self) -> Toolpath:
        self._flush_rows()
        keys = ("kind", "x", "y", "z", "a", "feed", "inverse_time", "space", "station", "feature")
        if self._chunks:
            arrays = {k: np.concatenate([c[k] for c in self._chunks]) for k in keys}
        else:
            arrays = {k: np.zeros(0) for k in keys}
        centers = {}
        if self._chunks and any(np.isin(c["kind"], (MoveKind.ARC_CW, MoveKind.ARC_CCW)).any() for c in self._chunks):
            centers = {k: np.concatenate([c[k] for c in self._chunks]) for k in ("center_x", "center_y")}
        return Toolpath(operation=self.operation, tool_number=self.tool_number, spindle_rpm=self.spindle_rpm,
                        warnings=tuple(self.warnings), **arrays, **centers)


def relative_path_lengths(x0, y0, z0, a0, x1, y1, z1, a1, substeps: int = 16) -> np.ndarray:
    """Length of the tool tip's path relative to the part for moves interpolated linearly in X, Y, Z, A."""
    t = np.linspace(0.0, 1.0, substeps + 1)[:, None]
    ys, zs, as_ = y0 + (y1 - y0) * t, z0 + (z1 - z0) * t, a0 + (a1 - a0) * t
    xs = x0 + (x1 - x0) * t
    p = machine_to_part(ys, zs, as_)
    d = np.diff(p, axis=0)
    dx = np.diff(xs, axis=0)
    return np.sqrt(d[..., 0] ** 2 + d[..., 1] ** 2 + dx**2).sum(axis=0)


def arc_sweeps_rad(path: Toolpath) -> tuple[np.ndarray, np.ndarray]:
    """(radius mm, signed sweep rad: + counterclockwise seen from +Z) of every move; 0 for moves that are not arcs.
    An arc whose end is its start is a full turn."""
    radius, sweep = np.zeros(len(path)), np.zeros(len(path))
    arcs = path.arc_mask
    if not arcs.any() or path.center_x is None or path.center_y is None:
        return radius, sweep
    x0, y0 = path.start_poses()[:, 0][arcs], path.start_poses()[:, 1][arcs]
    cx, cy = path.center_x[arcs], path.center_y[arcs]
    start = np.arctan2(y0 - cy, x0 - cx)
    end = np.arctan2(path.y[arcs] - cy, path.x[arcs] - cx)
    ccw = path.kind[arcs] == MoveKind.ARC_CCW
    turn = np.where(ccw, np.mod(end - start, 2.0 * np.pi), -np.mod(start - end, 2.0 * np.pi))
    turn = np.where(np.abs(turn) < 1e-12, np.where(ccw, 2.0 * np.pi, -2.0 * np.pi), turn)
    radius[arcs] = np.hypot(x0 - cx, y0 - cy)
    sweep[arcs] = turn
    return radius, sweep


def arc_points(path: Toolpath, index: int, max_chord_error_mm: float) -> np.ndarray:
    """(n, 2) XY points along arc move `index`, its start and end included, chords within `max_chord_error_mm`."""
    radius, sweep = arc_sweeps_rad(path)
    r, s = float(radius[index]), float(sweep[index])
    x0, y0 = path.start_poses()[index, :2]
    if path.center_x is None or path.center_y is None:
        raise ValueError(f"move {index} is not an arc: the toolpath has no arcs")
    cx, cy = float(path.center_x[index]), float(path.center_y[index])
    step = 2.0 * np.arccos(max(0.0, 1.0 - max_chord_error_mm / max(r, 1e-12))) if r > max_chord_error_mm else np.pi
    n = max(1, int(np.ceil(abs(s) / max(step, 1e-6))))
    angles = np.arctan2(y0 - cy, x0 - cx) + s * np.linspace(0.0, 1.0, n + 1)
    points = np.stack([cx + r * np.cos(angles), cy + r * np.sin(angles)], axis=-1)
    points[-1] = path.x[index], path.y[index]
    return points
