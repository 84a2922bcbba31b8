"""Toolpaths drawn in the part's frame (plain numpy; the FreeCAD objects are made in features.py).

The IR is in the machine frame where A turns the part, so a move is drawn where the tool tip
goes relative to the part: each pose is turned by -A (spur_cad.geometry.frames.machine_to_part), and
a move that turns A by more than MAX_A_STEP_DEG is drawn through intermediate poses (the
machine interpolates X, Y, Z, A linearly), so an index move is an arc around the gear, not a
chord through it. A 3-axis program ([machine] axes = 3: gear axis = machine Z, Z0 on the top face, no A) is
drawn with part x = face width + Z (the top face is the part's back face x = b; a spur gear is the same either
way up) and (y, z) = machine (X, Y), its arcs through points at most MAX_ARC_STEP_DEG apart. Programs with
more than MAX_DISPLAY_MOVES moves are drawn with a subset of their finishing stations (first and last
included); the object says how many moves it shows.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from spur_cad.cam.ir import MoveKind, Toolpath, arc_sweeps_rad
from spur_cad.geometry.frames import machine_to_part

MAX_DISPLAY_MOVES = 60_000
MAX_A_STEP_DEG = 2.0
MAX_ARC_STEP_DEG = 5.0


@dataclass(frozen=True)
class DisplayPath:
    """Points of the drawn path in the part frame; `rapid[i]` says the segment ending at point i is a rapid."""

    points: np.ndarray  # (N, 3) x, y, z
    rapid: np.ndarray  # (N,) bool; point 0 is the start (rapid)
    moves_shown: int
    moves_total: int


def shown_moves(path: Toolpath, limit: int = MAX_DISPLAY_MOVES) -> np.ndarray:
    """Indices of the motion moves to draw: all of them, or whole stations spread over the program."""
    motion = np.nonzero(path.motion_mask)[0]
    if len(motion) <= limit:
        return motion
    stations = path.station[motion]
    labels, counts = np.unique(stations[stations >= 0], return_counts=True)
    if len(labels) > 1 and counts.max() <= limit:
        keep_count = max(1, min(len(labels), int(limit // counts.mean())))
        while keep_count > 1:
            chosen = labels[np.unique(np.round(np.linspace(0, len(labels) - 1, keep_count)).astype(int))]
            if counts[np.isin(labels, chosen)].sum() <= limit:
                break
            keep_count -= 1
        chosen = labels[np.unique(np.round(np.linspace(0, len(labels) - 1, keep_count)).astype(int))]
        return motion[np.isin(stations, chosen)]
    stride = math.ceil(len(motion) / limit)
    return motion[::stride]


def _drawn_moves(path: Toolpath, limit: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(the moves drawn, every motion move, each drawn move's start move (0 for the first), joined): a move is drawn
    from its start pose when that pose was drawn too; otherwise it is a jump."""
    moves = shown_moves(path, limit)
    motion = np.nonzero(path.motion_mask)[0]
    previous_motion = np.full(len(path), -1)
    previous_motion[motion[1:]] = motion[:-1]
    start = previous_motion[moves]
    drawn = np.zeros(len(path), bool)
    drawn[moves] = True
    joined = (start >= 0) & drawn[np.maximum(start, 0)]
    return moves, motion, np.maximum(start, 0), joined


def display_path(path: Toolpath, limit: int = MAX_DISPLAY_MOVES, max_a_step_deg: float = MAX_A_STEP_DEG) -> DisplayPath:
    """The drawn path of `path` in the part frame (see the module docstring)."""
    moves, motion, start, joined = _drawn_moves(path, limit)
    if len(moves) == 0:
        return DisplayPath(np.zeros((0, 3)), np.zeros(0, bool), 0, len(motion))
    x0, y0, z0, a0 = (np.where(joined, c[start], c[moves]) for c in (path.x, path.y, path.z, path.a))
    x1, y1, z1, a1 = path.x[moves], path.y[moves], path.z[moves], path.a[moves]
    steps = np.maximum(1, np.ceil(np.abs(a1 - a0) / max_a_step_deg - 1e-9)).astype(int)
    owner = np.repeat(np.arange(len(moves)), steps)
    first = np.cumsum(steps) - steps
    t = (np.arange(len(owner)) - first[owner] + 1) / steps[owner]
    xs = x0[owner] + (x1 - x0)[owner] * t
    ys = y0[owner] + (y1 - y0)[owner] * t
    zs = z0[owner] + (z1 - z0)[owner] * t
    as_ = a0[owner] + (a1 - a0)[owner] * t
    transverse = machine_to_part(ys, zs, as_)
    points = np.column_stack([xs, transverse[:, 0], transverse[:, 1]])
    rapid = (path.kind[moves] == MoveKind.RAPID)[owner] | ~joined[owner]
    start_point = machine_to_part(np.array([y0[0]]), np.array([z0[0]]), np.array([a0[0]]))[0]
    points = np.vstack([[x0[0], start_point[0], start_point[1]], points])
    rapid = np.concatenate([[True], rapid])
    return DisplayPath(points, rapid, len(moves), len(motion))


def display_flat_path(path: Toolpath, face_width_mm: float, limit: int = MAX_DISPLAY_MOVES,
                      max_arc_step_deg: float = MAX_ARC_STEP_DEG) -> DisplayPath:
    """The drawn path of a 3-axis program in the part frame (see the module docstring)."""
    moves, motion, start, joined = _drawn_moves(path, limit)
    if len(moves) == 0:
        return DisplayPath(np.zeros((0, 3)), np.zeros(0, bool), 0, len(motion))
    x0, y0, z0 = (np.where(joined, c[start], c[moves]) for c in (path.x, path.y, path.z))
    x1, y1, z1 = path.x[moves], path.y[moves], path.z[moves]
    radius, sweep = (values[moves] for values in arc_sweeps_rad(path))
    arc = joined & (sweep != 0.0)
    steps = np.where(arc, np.ceil(np.abs(sweep) / math.radians(max_arc_step_deg) - 1e-9), 1).astype(int)
    steps = np.maximum(steps, 1)
    owner = np.repeat(np.arange(len(moves)), steps)
    first = np.cumsum(steps) - steps
    t = (np.arange(len(owner)) - first[owner] + 1) / steps[owner]
    xs = x0[owner] + (x1 - x0)[owner] * t
    ys = y0[owner] + (y1 - y0)[owner] * t
    zs = z0[owner] + (z1 - z0)[owner] * t
    on_arc = arc[owner]
    if on_arc.any() and path.center_x is not None and path.center_y is not None:
        cx = np.nan_to_num(path.center_x[moves])[owner][on_arc]
        cy = np.nan_to_num(path.center_y[moves])[owner][on_arc]
        begin = np.arctan2(y0[owner][on_arc] - cy, x0[owner][on_arc] - cx)
        angle = begin + sweep[owner][on_arc] * t[on_arc]
        xs[on_arc] = cx + radius[owner][on_arc] * np.cos(angle)
        ys[on_arc] = cy + radius[owner][on_arc] * np.sin(angle)
    points = np.column_stack([face_width_mm + zs, xs, ys])
    rapid = (path.kind[moves] == MoveKind.RAPID)[owner] | ~joined[owner]
    points = np.vstack([[face_width_mm + z0[0], x0[0], y0[0]], points])
    rapid = np.concatenate([[True], rapid])
    return DisplayPath(points, rapid, len(moves), len(motion))


def gcode_text(display: DisplayPath) -> str:
    """The drawn path as G0/G1 blocks in the part frame (for a FreeCAD Path object: no A word)."""
    words = np.where(display.rapid, "G0", "G1")
    return "\n".join(f"{word} X{x:.4f} Y{y:.4f} Z{z:.4f}" for word, (x, y, z) in zip(words, display.points)) + "\n"


def polylines(display: DisplayPath) -> list[tuple[bool, np.ndarray]]:
    """The drawn path split into runs of rapid or feed segments: (is_rapid, points incl. the run's start)."""
    runs: list[tuple[bool, np.ndarray]] = []
    points, rapid = display.points, display.rapid
    if len(points) < 2:
        return runs
    change = np.nonzero(np.diff(rapid[1:].astype(np.int8)))[0] + 2
    bounds = np.concatenate([[1], change, [len(points)]])
    for begin, end in itertools.pairwise(bounds):
        run = points[begin - 1:end]
        keep = np.concatenate([[True], np.any(np.abs(np.diff(run, axis=0)) > 1e-9, axis=1)])
        if keep.sum() >= 2:
            runs.append((bool(rapid[begin]), run[keep]))
    return runs
