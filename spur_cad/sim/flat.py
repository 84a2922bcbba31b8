"""The 3-axis cut simulated ([machine] axes = 3): the blank lying flat, a flat end mill's side cutting in the XY
plane at constant depths (docs/simulation.md, "3 axes").

The design grid is the rotary table's (spur_cad.sim.design: design points with normals along each space; the 3-axis
machine's X, Y are the grid's transverse (y, z)), its rows standing for depths below the top face (row x at Z = -x).
Every cutting move is a line or an arc of the tool centre at one Z (a plunge is the tool at its lowest point; a move
that changes Z and XY together is taken at its lowest Z, which can only cut more). The tool removes the disk of its
radius all along the move: the swept area, arcs exact. A level cuts every row at or above its Z (the side reaches
up), so a row's section is the blank less the swept areas of every level at its depth or below.

Each design point's blade (along its normal, from gouge_range_mm inside the material) keeps the material up to
where it first enters a swept area, found by sphere tracing on the exact distance to the lines and arcs (steps of
the distance less the radius, never shorter than MIN_STEP_MM, then bisection to 1 nm): the same blades, deviations
and SimResult as spur_cad.sim.simulate, so the grading and the report read it unchanged.

A ring (internal gear) is the same grid: its design normals point out of the material into the spaces, toward the
axis, so a blade reads + leftover and - gouge as an external gear's. Its stock is the rim's disc with the stock's
bore (air: blades end where they enter it), and what is cut is the hole: the removed volume is the simulated hole's
area less the bore's, not the blank's disc less the section.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from spur_cad.cam.ir import Toolpath, arc_sweeps_rad
from spur_cad.geometry.kinds import INTERNAL_SPUR
from spur_cad.geometry.spec import GearSpec
from spur_cad.sim.design import DesignGrid, design_grid
from spur_cad.sim.simulate import (
    Cut,
    SimResult,
    SimSettings,
    StockCylinder,
    check_design_size,
    initial_blades,
    point_spacing_mm,
    section_areas,
)

MIN_STEP_MM = 0.0001
"""Shortest step along a blade: a swept area the blade crosses over less than 0.1 um is not seen."""
BISECTIONS = 40
"""Halvings of the last step once a blade is inside a swept area (0.1 um / 2^40: far below a nanometre)."""
MAX_STEPS = 20000
"""Steps along a blade before it is given up as never entering (MAX_STEPS x MIN_STEP_MM = 2 mm, the blade's
longest)."""


@dataclass(frozen=True)
class Pieces:
    """The tool-centre path of one level: lines (start, end) and arcs (centre, radius, start angle, signed sweep
    in rad, + counterclockwise); `radius_mm` the tool's."""

    line_start: np.ndarray  # (L, 2)
    line_end: np.ndarray  # (L, 2)
    arc_centre: np.ndarray  # (A, 2)
    arc_radius: np.ndarray  # (A,)
    arc_start_rad: np.ndarray  # (A,)
    arc_sweep_rad: np.ndarray  # (A,)
    radius_mm: float

    def boxes(self) -> np.ndarray:
        """(L + A, 4) bounding boxes (x_min, y_min, x_max, y_max) of every piece's swept area."""
        lines = np.concatenate([np.minimum(self.line_start, self.line_end),
                                np.maximum(self.line_start, self.line_end)], axis=1)
        arcs = np.zeros((len(self.arc_radius), 4))
        if len(self.arc_radius):  # the arc's ends and the axis extremes it passes
            angles = self.arc_start_rad[:, None] + self.arc_sweep_rad[:, None] * np.linspace(0.0, 1.0, 2)[None, :]
            xs = self.arc_centre[:, :1] + self.arc_radius[:, None] * np.cos(angles)
            ys = self.arc_centre[:, 1:] + self.arc_radius[:, None] * np.sin(angles)
            for quarter in range(4):
                passed = _within_sweep(np.full(len(self.arc_radius), quarter * np.pi / 2), self.arc_start_rad,
                                       self.arc_sweep_rad)
                extreme = self.arc_centre + self.arc_radius[:, None] * np.array(
                    [math.cos(quarter * np.pi / 2), math.sin(quarter * np.pi / 2)])
                xs = np.concatenate([xs, np.where(passed, extreme[:, 0], xs[:, 0])[:, None]], axis=1)
                ys = np.concatenate([ys, np.where(passed, extreme[:, 1], ys[:, 0])[:, None]], axis=1)
            arcs = np.stack([xs.min(axis=1), ys.min(axis=1), xs.max(axis=1), ys.max(axis=1)], axis=1)
        return np.concatenate([lines, arcs]) + np.array([-1.0, -1.0, 1.0, 1.0]) * self.radius_mm

    def select(self, keep: np.ndarray) -> Pieces:
        """The pieces whose index (lines first, then arcs) is in the boolean mask `keep`."""
        lines, arcs = keep[:len(self.line_start)], keep[len(self.line_start):]
        return Pieces(self.line_start[lines], self.line_end[lines], self.arc_centre[arcs], self.arc_radius[arcs],
                      self.arc_start_rad[arcs], self.arc_sweep_rad[arcs], self.radius_mm)

    def clearance_mm(self, points: np.ndarray) -> np.ndarray:
        """Distance of each point (P, 2) from the nearest piece less the tool radius (< 0: inside the swept area)."""
        best = np.full(len(points), np.inf)
        if len(self.line_start):
            a, d = self.line_start[None, :, :], (self.line_end - self.line_start)[None, :, :]
            rel = points[:, None, :] - a
            length2 = np.einsum("...i,...i->...", d, d)
            t = np.clip(np.einsum("...i,...i->...", rel, d) / np.maximum(length2, 1e-300), 0.0, 1.0)
            gap = rel - t[..., None] * d
            best = np.minimum(best, np.sqrt(np.einsum("...i,...i->...", gap, gap)).min(axis=1))
        if len(self.arc_radius):
            rel = points[:, None, :] - self.arc_centre[None, :, :]
            distance = np.hypot(rel[..., 0], rel[..., 1])
            inside = _within_sweep(np.arctan2(rel[..., 1], rel[..., 0]), self.arc_start_rad[None, :],
                                   self.arc_sweep_rad[None, :])
            ends = []
            for fraction in (0.0, 1.0):
                angle = self.arc_start_rad + fraction * self.arc_sweep_rad
                end = self.arc_centre + self.arc_radius[:, None] * np.stack([np.cos(angle), np.sin(angle)], axis=1)
                ends.append(np.hypot(*(points[:, None, :] - end[None, :, :]).transpose(2, 0, 1)))
            arc = np.where(inside, np.abs(distance - self.arc_radius[None, :]), np.minimum(*ends))
            best = np.minimum(best, arc.min(axis=1))
        return best - self.radius_mm


def _within_sweep(angle: np.ndarray, start: np.ndarray, sweep: np.ndarray) -> np.ndarray:
    """Whether each angle lies on the arc from `start` turning by `sweep` (signed, rad)."""
    along = np.where(sweep >= 0.0, np.mod(angle - start, 2 * np.pi), np.mod(start - angle, 2 * np.pi))
    return along <= np.abs(sweep) + 1e-12


def level_pieces(path: Toolpath, radius_mm: float) -> dict[float, Pieces]:
    """The moves of `path` grouped by the Z they cut at (their lowest), as lines and arcs of the tool centre."""
    motion = path.motion_mask
    starts, ends = path.start_poses(), path.poses()
    starts[0] = ends[0]  # the first move's start is unknown: the tool at its end
    arc_radius, arc_sweep = arc_sweeps_rad(path)
    arcs = path.arc_mask & motion
    lines = motion & ~arcs
    depth = np.round(np.minimum(starts[:, 2], ends[:, 2]), 9)
    levels = {}
    for z in np.unique(depth[motion]):
        here_lines, here_arcs = lines & (depth == z), arcs & (depth == z)
        centre = np.stack([path.center_x[here_arcs], path.center_y[here_arcs]], axis=1) \
            if here_arcs.any() and path.center_x is not None and path.center_y is not None else np.zeros((0, 2))
        start_angle = np.arctan2(starts[here_arcs, 1] - centre[:, 1], starts[here_arcs, 0] - centre[:, 0])
        levels[float(z)] = Pieces(starts[here_lines, :2], ends[here_lines, :2], centre, arc_radius[here_arcs],
                                  start_angle, arc_sweep[here_arcs], radius_mm)
    return levels


def clip_blades(points: np.ndarray, normals: np.ndarray, t_min: float, h: np.ndarray, pieces: Pieces) -> np.ndarray:
    """Where each blade (point + t normal, t from t_min to h) first enters the swept area of `pieces` (t_min when it
    starts inside); h where it never does. The pieces are first narrowed to those near the blades."""
    inner, outer = points + t_min * normals, points + h[:, None] * normals
    box = np.concatenate([np.minimum(inner, outer).min(axis=0), np.maximum(inner, outer).max(axis=0)])
    boxes = pieces.boxes()
    near = pieces.select((boxes[:, 0] <= box[2]) & (boxes[:, 2] >= box[0]) & (boxes[:, 1] <= box[3])
                         & (boxes[:, 3] >= box[1]))
    result = h.copy()
    if len(near.line_start) + len(near.arc_radius) == 0:
        return result
    t = np.full(len(points), t_min)
    active = np.arange(len(points))
    previous = t.copy()
    for _ in range(MAX_STEPS):
        if len(active) == 0:
            break
        clearance = near.clearance_mm(points[active] + t[active, None] * normals[active])
        entered = clearance <= 0.0
        hit = active[entered]
        first = hit[t[hit] == t_min]
        result[first] = t_min
        refine = hit[t[hit] > t_min]
        if len(refine):
            result[refine] = _bisect(points[refine], normals[refine], previous[refine], t[refine], near)
        going = active[~entered]
        previous[going] = t[going]
        t[going] += np.maximum(clearance[~entered], MIN_STEP_MM)
        active = going[t[going] < h[going]]
    return result


def _bisect(points: np.ndarray, normals: np.ndarray, outside: np.ndarray, inside: np.ndarray,
            pieces: Pieces) -> np.ndarray:
    """The entry between `outside` (clear of the swept area) and `inside` (in it) along each blade."""
    outside, inside = outside.copy(), inside.copy()
    for _ in range(BISECTIONS):
        middle = 0.5 * (outside + inside)
        into = pieces.clearance_mm(points + middle[:, None] * normals) <= 0.0
        inside = np.where(into, middle, inside)
        outside = np.where(into, outside, middle)
    return inside


def bore_entry_mm(grid: DesignGrid, bore_radius_mm: float) -> np.ndarray:
    """(M,) where each blade (point + t normal, t > 0) first enters the circle of `bore_radius_mm` about the axis
    (inf when it passes it): a ring's stock has no material there to cut."""
    p, n = grid.points, grid.normals
    pn = np.einsum("ij,ij->i", p, n)
    discriminant = pn * pn - (np.einsum("ij,ij->i", p, p) - bore_radius_mm ** 2)
    entry = -pn - np.sqrt(np.maximum(discriminant, 0.0))
    return np.where((discriminant > 0.0) & (entry > 0.0), entry, np.inf)


BORED_DISC_BLANKS = frozenset({INTERNAL_SPUR})
"""Gear kinds whose flat blank is a disc with a bore and whose outline is the hole cut in it (a ring: the removed
area is the hole less the bore); every other kind's outline is cut from a solid disc (the disc less the section)."""


def simulate_flat(spec: GearSpec, blank_radius_mm: float, operations: Sequence[Cut],
                  settings: SimSettings | None = None, station_depths_mm: np.ndarray | None = None,
                  bore_radius_mm: float = 0.0) -> SimResult:
    """Cut the flat blank (radius `blank_radius_mm`, the face width thick; a ring's with its bore of
    `bore_radius_mm`, 0: a solid disc) with every operation and measure the result against the design: rows over
    the face width at depths 0..b below the top face (plus the finishing step-downs `station_depths_mm` and the
    middles between them); `settings` default SimSettings()."""
    settings = settings or SimSettings()
    radii = [op.tool.diameter_mm / 2.0 for op in operations] or [0.5]
    spacing = point_spacing_mm(min(radii), settings.resolution_mm)
    b = spec.face_width_mm
    stations = np.unique(np.asarray(station_depths_mm if station_depths_mm is not None else (), float))
    stations = stations[(stations >= 0.0) & (stations <= b)]
    extra = np.concatenate([stations, 0.5 * (stations[1:] + stations[:-1])]) if len(stations) else np.zeros(0)
    check_design_size(spec, spacing, b, len(extra), settings.resolution_mm)
    grid = design_grid(spec, spacing, 0.0, b, extra)
    ring_bore_mm = bore_radius_mm if spec.kind in BORED_DISC_BLANKS else None
    return simulate_flat_grid(grid, blank_radius_mm, operations, settings, b, stations, ring_bore_mm)


def simulate_flat_grid(grid: DesignGrid, blank_radius_mm: float, operations: Sequence[Cut], settings: SimSettings,
                       face_width_mm: float, stations: np.ndarray | None = None,
                       ring_bore_radius_mm: float | None = None) -> SimResult:
    """`simulate_flat` on a given design grid (any outline with normals: a plain circle in tests);
    `ring_bore_radius_mm` None for an external gear's blank, else the grid is a ring's cut from a disc with that
    bore (0: solid)."""
    started = time.perf_counter()
    stock = StockCylinder(blank_radius_mm, 0.0, face_width_mm)
    t_min = -settings.gouge_range_mm
    initial = initial_blades(grid, stock, settings.leftover_range_mm)
    if ring_bore_radius_mm:
        initial = np.minimum(initial, bore_entry_mm(grid, ring_bore_radius_mm)[None, :, None])
    top = initial[:, :, 0]
    by_level: dict[float, np.ndarray] = {}  # Z -> blades cut by that level alone (teeth, M)
    seen: dict[bytes, np.ndarray] = {}  # levels with the same path and tool are cut once
    clipped = moves = 0
    for op in operations:
        moves += len(op.path)
        for z, pieces in level_pieces(op.path, op.tool.diameter_mm / 2.0).items():
            if z > 0.0:
                continue  # above the top face
            key = b"".join(np.ascontiguousarray(a).tobytes() for a in (
                pieces.line_start, pieces.line_end, pieces.arc_centre, pieces.arc_radius, pieces.arc_start_rad,
                pieces.arc_sweep_rad)) + np.float64(pieces.radius_mm).tobytes()
            if key not in seen:
                seen[key] = np.stack([clip_blades(grid.space_points(k), grid.space_normals(k), t_min, top[k], pieces)
                                      for k in range(grid.teeth)])
                clipped += len(pieces.line_start) + len(pieces.arc_radius)
            by_level[z] = np.minimum(by_level.get(z, top), seen[key])
    h = np.array(initial, dtype=float)
    deepest_first = sorted(by_level)
    reach = top.copy()
    levels_z = np.array(deepest_first)
    cumulative = []
    for z in deepest_first:
        reach = np.minimum(reach, by_level[z])
        cumulative.append(reach)
    for row, x in enumerate(grid.rows_x):  # row x is cut by the levels at Z <= -x: the shallowest of them holds all
        reaching = np.flatnonzero(levels_z <= -x + 1e-9)
        if len(reaching):
            h[:, :, row] = cumulative[int(reaching[-1])]
    if ring_bore_radius_mm is None:  # the blank's disc less the section
        removed_area = math.pi * blank_radius_mm ** 2 - section_areas(grid, h)
    else:  # a ring: its hole (the section's outline, counterclockwise) less the stock's bore
        removed_area = section_areas(grid, h) - math.pi * ring_bore_radius_mm ** 2
    removed = float((removed_area * grid.row_width).sum())
    return SimResult(grid, h, initial, stock, face_width_mm, settings, removed, time.perf_counter() - started,
                     clipped, 0, moves, np.asarray(stations if stations is not None else (), float))


__all__ = ["Pieces", "bore_entry_mm", "clip_blades", "level_pieces", "simulate_flat", "simulate_flat_grid"]
