"""Material removal by every IR move, measured along the design normals (point-vector method).

See docs/simulation.md for the choice of representation. Each move is linear in X, Y, Z, A
(as the IR defines it); the tool is applied in the part frame (the part turned back by A):

- a move along X only (roughing passes, along-X finishing) is clipped exactly as one swept
  tool (the union of the tool's slices along X is its slice nearest the axis);
- a move in Z only is the tool at its lower end (the tool is everything above its bottom);
- any other move (simultaneous Y/Z/A finishing moves, plunges with Y, index moves) is
  clipped at poses spaced `pose_step_mm` apart along the move's relative motion, so the
  cusps between them stay within half the resolution;
- moves that stay above every blade cut nothing and are skipped.
"""

from __future__ import annotations

import contextlib
import functools
import math
import os
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Callable, Sequence

import numpy as np

from spur_cad.cam.ir import Feature, MoveKind, Toolpath
from spur_cad.cam.tools import Tool
from spur_cad.errors import SimulationError
from spur_cad.geometry.spec import GearSpec
from spur_cad.sim.design import DesignGrid, design_grid, modification_removal_mm

if TYPE_CHECKING:  # numba loads with the kernels, when a simulation runs
    from spur_cad.geometry.modifications import FlankModifications
    from spur_cad.sim.engagement import Engagement

CHUNK_POINTS = 4
POSE_BATCH = 20000
MAX_THREADS = 4


@dataclass(frozen=True)
class DeviationPlace:
    """Where a deviation of the simulated gear is: its value (mm, + material), tooth space, feature, design
    point, X and finishing station (-1: none)."""

    value_mm: float
    space: int
    feature: str
    point: int
    x_mm: float
    station: int


@dataclass(frozen=True)
class SimSettings:
    """Resolution and blade lengths. `resolution_mm` bounds the simulation's own error: cusps
    between clipped poses (<= resolution / 2) and the spacing of design points and rows."""

    resolution_mm: float = 0.005
    gouge_range_mm: float = 0.5  # blades reach this far into the material (deeper gouges read as this)
    leftover_range_mm: float = 1.0  # and this far out of it (more leftover reads as this)

    def __post_init__(self) -> None:
        """Refuse settings that cannot work, once, when they are made (the simulators trust them)."""
        if not 0.0005 <= self.resolution_mm <= 0.1:
            raise SimulationError(f"[simulation] resolution_mm = {self.resolution_mm:g} must be in [0.0005, 0.1] mm",
                                  field="resolution_mm")
        for name in ("gouge_range_mm", "leftover_range_mm"):
            value = getattr(self, name)
            if not 10.0 * self.resolution_mm <= value <= 20.0:
                raise SimulationError(f"[simulation] {name} = {value:g} must be in [10 x resolution, 20] mm",
                                      field=name)


@dataclass(frozen=True)
class StockCylinder:
    """The stock the simulation starts from: a cylinder about X over [x_min, x_max]."""

    radius_mm: float
    x_min: float
    x_max: float


@dataclass(frozen=True)
class Cut:
    """One toolpath with the tool that cuts it."""

    path: Toolpath
    tool: Tool


@dataclass(frozen=True)
class SimResult:
    """Deviation of every design point (h: (teeth, M, rows), mm; < 0 gouge, > 0 leftover) and facts."""

    grid: DesignGrid
    deviation: np.ndarray
    initial: np.ndarray
    stock: StockCylinder
    face_width_mm: float
    settings: SimSettings
    removed_volume_mm3: float
    seconds: float
    poses_clipped: int
    x_sweeps: int
    moves: int
    station_x: np.ndarray = field(default_factory=lambda: np.zeros(0))
    engagement: Engagement | None = None  # roughing engagement, measured by the caller (spur_cad.sim.engagement)

    @property
    def gear_rows(self) -> np.ndarray:
        """Rows inside the face width (0 <= X <= b): where the part's surface is measured."""
        x = self.grid.rows_x
        return (x >= -1e-9) & (x <= self.face_width_mm + 1e-9)

    @property
    def gear_deviation(self) -> np.ndarray:
        """The deviation inside the face width (space, point, row): a view, not a copy, when those rows are one
        run (the rows are in X order), for the statistics of a big gear's millions of points."""
        rows = np.nonzero(self.gear_rows)[0]
        if len(rows) and rows[-1] - rows[0] + 1 == len(rows):
            return self.deviation[:, :, rows[0]:rows[-1] + 1]
        return self.deviation[:, :, self.gear_rows]

    @property
    def max_gouge_mm(self) -> float:
        """Largest gouge inside the face width (0 when none)."""
        return float(max(0.0, -self.gear_deviation.min()))

    @property
    def max_leftover_mm(self) -> float:
        """Largest leftover inside the face width (0 when none)."""
        return float(max(0.0, self.gear_deviation.max()))

    def station_of_row(self) -> np.ndarray:
        """Nearest finishing station index per row (-1 without finishing stations)."""
        if len(self.station_x) == 0:
            return np.full(len(self.grid.rows_x), -1)
        return np.abs(self.grid.rows_x[:, None] - self.station_x[None, :]).argmin(axis=1)

    @property
    def uncut_points(self) -> int:
        """Design points of the face width never cut below the blade's outer end (their leftover is
        at least leftover_range_mm, and the removed volume overestimates there)."""
        top = self.settings.leftover_range_mm - 1e-9
        return int(np.count_nonzero(self.gear_deviation >= top))

    def worst(self, gouge: bool) -> DeviationPlace:
        """Where the largest gouge (or leftover) is: space, feature, X, station, value (mm)."""
        from spur_cad.sim.statistics import space_blocks

        dev = self.gear_deviation
        best, k, j, r = np.inf, 0, 0, 0
        first_space = 0
        for block in space_blocks(dev):  # argmin of a strided view would copy all of it: block by block
            flat = int(np.argmin(block) if gouge else np.argmax(block))
            value = float(block.flat[flat]) * (1.0 if gouge else -1.0)
            if value < best:  # the first place of the extreme, as numpy's argmin over the whole gives
                best = value
                k, j, r = (int(i) for i in np.unravel_index(flat, block.shape))
                k += first_space
            first_space += block.shape[0]
        row = np.nonzero(self.gear_rows)[0][r]
        return DeviationPlace(float(dev[k, j, r]), int(k), self.grid.feature_names()[j], int(j),
                              float(self.grid.rows_x[row]), int(self.station_of_row()[row]))


def finishing_stations(path: Toolpath | None) -> np.ndarray:
    """X of the transverse finishing stations found in the IR (cutting moves that do not move X)."""
    if path is None or len(path) == 0:
        return np.zeros(0)
    start_x = path.start_poses()[:, 0]
    cutting = (path.kind == MoveKind.LINEAR) & (path.feature != Feature.NONE) & (path.x == start_x)
    return np.unique(path.x[cutting])


def pose_step_mm(tool: Tool, resolution_mm: float) -> float:
    """Spacing of clipped poses along a move: the cusp between two copies of a corner of radius r a
    distance l apart is l^2 / (8 r); keep it within resolution / 2 (sharp flat tools: resolution / 2)."""
    radius = tool.effective_corner_radius_mm if tool.effective_corner_radius_mm > 0.0 else 0.0
    if radius == 0.0:
        return resolution_mm / 2.0
    return math.sqrt(8.0 * radius * resolution_mm / 2.0)


def _tool_shape(tool: Tool) -> tuple[float, float, float]:
    """(R, half_flat, r_t): outer radius, flat half-width, corner radius."""
    radius = tool.diameter_mm / 2.0
    rt = tool.effective_corner_radius_mm
    return radius, radius - rt, rt


def decompose(path: Toolpath, tool: Tool, resolution_mm: float, reach_mm: float,
              flat_step_mm: float | None = None,
              x_range: tuple[float, float] = (-np.inf, np.inf),
              twist_rad_per_mm: float = 0.0) -> tuple[np.ndarray, np.ndarray, int]:
    """Poses (N, 4: x, y, z, a rad) and their X-sweep ends (N,) that together remove what the moves remove.

    Returns (poses, x_end, number of sweeps). Markers carry no motion and are skipped; the first
    row's start is unknown (the IR says so): it is clipped at its end pose only. A sweep is a move
    along X only (spur design) or a move following the lead (helical design: A falls by
    twist * dX, Y and Z fixed); its pose is its end with the smaller X.
    """
    motion = path.motion_mask
    if not motion.any():
        return np.zeros((0, 4)), np.zeros(0), 0
    ends, starts = path.poses()[motion], path.start_poses()[motion]
    starts[0] = ends[0]  # markers carry the pose unchanged; only the first move's start is unknown
    x, y, z, a = ends.T
    x0, y0, z0, a0 = starts.T
    a, a0 = np.radians(a), np.radians(a0)
    dx, dy, dz, da = x - x0, y - y0, z - z0, a - a0
    radius = tool.diameter_mm / 2.0
    above = (np.minimum(z0, z) > reach_mm) | (np.maximum(x0, x) < x_range[0] - radius) \
        | (np.minimum(x0, x) > x_range[1] + radius)
    if twist_rad_per_mm == 0.0:
        lead = da == 0.0
    else:  # the generators compute A from X; allow for rounding only
        lead = np.abs(da + twist_rad_per_mm * dx) <= 1e-9 * np.maximum(1.0, np.abs(da))
    along_x = ~above & (dy == 0.0) & (dz == 0.0) & lead & (dx != 0.0)
    only_z = ~above & (dx == 0.0) & (dy == 0.0) & (da == 0.0)
    general = ~above & ~along_x & ~only_z
    general[0] = False
    only_z[0] = not above[0]  # first row: its end pose only
    backwards = along_x & (x < x0)
    sweep_a = np.where(backwards, a, a0)[along_x]
    sweeps = np.stack([np.minimum(x0, x)[along_x], y[along_x], z[along_x], sweep_a], axis=-1)
    sweep_end = np.maximum(x0, x)[along_x]
    lows = np.stack([x[only_z], y[only_z], np.minimum(z0, z)[only_z], a[only_z]], axis=-1)
    idx = np.nonzero(general)[0]
    step = np.full(len(idx), pose_step_mm(tool, resolution_mm))
    if flat_step_mm is not None and tool.effective_corner_radius_mm == 0.0:
        # A flat tool moving horizontally without turning (roughing's steps across a level) leaves no cusp on
        # its flat bottom; its round edge (radius D/2) does, as a corner of that radius.
        step[(dz[idx] == 0.0) & (da[idx] == 0.0)] = flat_step_mm
    radius_from_axis = np.maximum(np.hypot(y0[idx], z0[idx]), np.hypot(y[idx], z[idx])) + tool.diameter_mm / 2.0
    turn = np.abs(da[idx]) + abs(twist_rad_per_mm) * np.abs(dx[idx])  # a helical design also turns along X
    travel = np.abs(dx[idx]) + np.hypot(dy[idx], dz[idx]) + np.minimum(radius_from_axis, reach_mm) * turn
    pieces = np.maximum(1, np.ceil(travel / step)).astype(np.int64)
    move_of = np.repeat(idx, pieces)
    offsets = np.arange(len(move_of)) - np.repeat(np.cumsum(pieces) - pieces, pieces)
    frac = (offsets + 1) / np.repeat(pieces, pieces)
    interp = np.stack([x0[move_of] + dx[move_of] * frac, y0[move_of] + dy[move_of] * frac,
                       z0[move_of] + dz[move_of] * frac, a0[move_of] + da[move_of] * frac], axis=-1)
    poses = np.concatenate([sweeps, lows, interp])
    x_end = np.concatenate([sweep_end, lows[:, 0], interp[:, 0]])
    return poses, x_end, int(along_x.sum())


def _chunks(grid: DesignGrid, t_min: float, t_max: float | np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Groups of consecutive design points with a circle holding all their blades, from t_min to t_max (per
    point, or one for all: the circles shrink as the material left along the blades does)."""
    m = len(grid.points)
    start = np.arange(0, m + CHUNK_POINTS - 1, CHUNK_POINTS)
    start[-1] = m
    start = np.unique(np.minimum(start, m))
    inner = grid.points + t_min * grid.normals
    outer = grid.points + np.reshape(t_max, (-1, 1)) * grid.normals
    centres, radii = [], []
    for lo, hi in zip(start[:-1], start[1:]):
        ends = np.concatenate([inner[lo:hi], outer[lo:hi]])
        centre = 0.5 * (ends.min(axis=0) + ends.max(axis=0))
        centres.append(centre)
        radii.append(float(np.hypot(*(ends - centre).T).max()) + 1e-9)
    return start.astype(np.int64), np.array(centres), np.array(radii)


def initial_blades(grid: DesignGrid, stock: StockCylinder, t_max: float) -> np.ndarray:
    """Blade outer ends before cutting: where the normal leaves the stock cylinder (at most t_max). The same in
    every tooth space and row, so a read-only view of one value per design point, not a copy per space and row
    (a big gear's array of the whole gear is hundreds of megabytes)."""
    p, n = grid.points, grid.normals
    pn = np.einsum("ij,ij->i", p, n)
    inside = stock.radius_mm**2 - np.einsum("ij,ij->i", p, p)
    exit_t = -pn + np.sqrt(np.maximum(pn * pn + inside, 0.0))
    h0 = np.minimum(exit_t, t_max)
    return np.broadcast_to(h0[None, :, None], (grid.teeth, len(p), len(grid.rows_x)))


def section_areas(grid: DesignGrid, h: np.ndarray) -> np.ndarray:
    """Area of the whole simulated transverse section per row (shoelace over all spaces' points p + h n)."""
    areas = np.zeros(h.shape[2])
    for k in range(grid.teeth):
        p = grid.space_points(k)
        n = grid.space_normals(k)
        q = p[:, :, None] + n[:, :, None] * h[k][:, None, :]  # (M, 2, rows)
        nxt_p = grid.space_points(k + 1)[0]
        nxt_n = grid.space_normals(k + 1)[0]
        nxt = nxt_p[:, None] + nxt_n[:, None] * h[(k + 1) % grid.teeth][0][None, :]
        ys = np.concatenate([q[:, 0, :], nxt[0][None, :]])
        zs = np.concatenate([q[:, 1, :], nxt[1][None, :]])
        areas += 0.5 * (ys[:-1] * zs[1:] - ys[1:] * zs[:-1]).sum(axis=0)
    return areas


def simulate(spec: GearSpec, stock: StockCylinder, operations: Sequence[Cut],
             settings: SimSettings = SimSettings(), *, station_x: np.ndarray | None = None,
             rows_x_range: tuple[float, float] | None = None,
             progress: Callable[[float], None] | None = None, threads: int | None = None,
             modifications: FlankModifications | None = None) -> SimResult:
    """Cut the stock with every operation in order and measure the result against the design (the modified
    design when `modifications` are given: the deviations then read from the modified flanks).

    `station_x`: finishing station positions (rows are added there and halfway between them, where
    the scallop ridges stand). `rows_x_range` limits the rows (default: the stock's X extent). `threads`: see
    simulate_grid.
    """
    started = time.perf_counter()
    corner_radii = [op.tool.effective_corner_radius_mm for op in operations
                    if op.tool.effective_corner_radius_mm > 0.0] or [0.5]
    spacing = point_spacing_mm(min(corner_radii), settings.resolution_mm)
    stations = np.unique(np.asarray(station_x if station_x is not None else np.zeros(0), float))
    extra = np.concatenate([stations, 0.5 * (stations[1:] + stations[:-1])]) if len(stations) else np.zeros(0)
    x_lo, x_hi = rows_x_range if rows_x_range is not None else (stock.x_min, stock.x_max)
    check_design_size(spec, spacing, x_hi - x_lo, len(extra), settings.resolution_mm)
    grid = design_grid(spec, spacing, x_lo, x_hi, extra)
    result = simulate_grid(grid, stock, operations, settings, face_width_mm=spec.face_width_mm, station_x=stations,
                           progress=progress, started=started, threads=threads)
    if modifications is None:
        return result
    return replace(result, deviation=result.deviation + modification_removal_mm(spec, grid, modifications)[None])


MAX_DESIGN_VALUES = 60_000_000
"""Largest design grid (points per space x rows x spaces) simulated: about 0.5 GB per array of
deviations (the reference job at 5 um has some 2 million); larger grids are refused beforehand."""


def check_design_size(spec: GearSpec, spacing_mm: float, length_mm: float, extra_rows: int,
                      resolution_mm: float) -> None:
    """Refuse (SimulationError naming [simulation] resolution_mm) a design grid above MAX_DESIGN_VALUES.

    The space boundary (tooth centre to tooth centre) is shorter than the tip circle's pitch arc plus
    three times the whole depth on each side, which bounds the points per space."""
    boundary = 2.0 * math.pi * spec.tip_radius_mm / spec.teeth + 6.0 * (spec.tip_radius_mm - spec.root_radius_mm)
    values = spec.teeth * (boundary / spacing_mm + 2) * (length_mm / spacing_mm + extra_rows + 3)
    if values > MAX_DESIGN_VALUES:
        raise SimulationError(f"the simulation would measure about {values:.2g} design points (limit "
                              f"{MAX_DESIGN_VALUES:.0e}); raise [simulation] resolution_mm (now {resolution_mm:g} mm) "
                              "or set [simulation] enabled = false", field="resolution_mm",
                              section="simulation")


def point_spacing_mm(corner_radius_mm: float, resolution_mm: float) -> float:
    """Spacing of design points and rows: a surface bulging with radius r between two samples l apart
    rises at most l^2 / (8 r) above them; r is the smallest corner radius (at most 1 mm), the rise
    resolution / 2."""
    return math.sqrt(8.0 * min(corner_radius_mm, 1.0) * resolution_mm / 2.0)


def simulate_grid(grid: DesignGrid, stock: StockCylinder, operations: Sequence[Cut],
                  settings: SimSettings = SimSettings(), *, face_width_mm: float, station_x: np.ndarray | None = None,
                  progress: Callable[[float], None] | None = None, started: float | None = None,
                  threads: int | None = None) -> SimResult:
    """`simulate` on a given design grid (any outline with normals, e.g. a plain cylinder in tests). A helical
    design is clipped on `threads` threads (default: simulation_threads()), with the same result for any number."""
    started = time.perf_counter() if started is None else started
    res = settings.resolution_mm
    x_lo, x_hi = float(grid.rows_x[0]), float(grid.rows_x[-1])
    t_min, t_max = -settings.gouge_range_mm, settings.leftover_range_mm
    initial = initial_blades(grid, stock, t_max)
    h = initial.copy()
    blade_ends = np.concatenate([grid.points + t_min * grid.normals, grid.points + t_max * grid.normals])
    reach = float(np.hypot(*blade_ends.T).max()) + 1e-9
    blade_len = max(settings.gouge_range_mm, settings.leftover_range_mm)
    twist = grid.twist_rad_per_mm
    batches = []
    sweeps = moves = 0
    for op in operations:
        radius, half_flat, rt = _tool_shape(op.tool)
        flat_step = math.sqrt(8.0 * radius * res / 2.0)
        poses, x_end, n_sweeps = decompose(op.path, op.tool, res, reach, flat_step, (x_lo, x_hi), twist)
        sweeps += n_sweeps
        moves += len(op.path)
        # Lead sweeps sample the tool's slices so that the design turns by at most resolution / 2 between them
        # and the slices change no more than between two clipped poses of a move (a lead sweep is horizontal:
        # a flat tool's round edge, radius D / 2, sets its spacing, as for roughing's steps across a level).
        pose_step = flat_step if rt == 0.0 else pose_step_mm(op.tool, res)
        dx_step = min(0.5 * res / (reach * abs(twist)), pose_step, radius) if twist else 0.0
        for lo in range(0, len(poses), POSE_BATCH):
            batches.append((poses[lo:lo + POSE_BATCH], x_end[lo:lo + POSE_BATCH], radius, half_flat, rt, dx_step))
    total = sum(len(b[0]) for b in batches)
    done = 0
    n_threads = min(threads or simulation_threads(), len(grid.rows_x)) if twist else 1
    with ThreadPoolExecutor(max_workers=n_threads) if n_threads > 1 else contextlib.nullcontext() as pool:
        for poses, x_end, radius, half_flat, rt, dx_step in batches:
            done += _clip_batch(grid, h, poses, x_end, radius, half_flat, rt, dx_step, t_min, t_max, reach, blade_len,
                                n_threads, pool)
            if progress is not None:
                progress(done / max(total, 1))
    # Rows stand for slabs of the stock; the stock's length outside the rows' span is not counted.
    stock_area = math.pi * stock.radius_mm**2
    removed = float(((stock_area - section_areas(grid, h)) * grid.row_width).sum())
    return SimResult(grid, h, initial, stock, face_width_mm, settings, removed, time.perf_counter() - started,
                     total, sweeps, moves, np.asarray(station_x if station_x is not None else (), float))


def _clip_batch(grid: DesignGrid, h: np.ndarray, poses: np.ndarray, x_end: np.ndarray, radius: float,
                half_flat: float, rt: float, dx_step: float, t_min: float, t_max: float, reach: float,
                blade_len: float, threads: int, pool: ThreadPoolExecutor | None) -> int:
    """Clip h by one batch of poses (simulate_grid's loop); a helical design on `threads` threads of `pool`.
    Returns the batch's number of poses."""
    from spur_cad.sim.kernel import clip_poses, clip_poses_twisted

    h_top = np.ascontiguousarray(h.max(axis=2))
    # Blades only shorten, so each batch's chunk circles need hold them from t_min to their longest h only.
    chunk_start, chunk_centre, chunk_radius = _chunks(grid, t_min, np.maximum(h_top.max(axis=0), t_min))
    if grid.twist_rad_per_mm:
        clip = functools.partial(clip_poses_twisted, np.ascontiguousarray(poses), np.ascontiguousarray(x_end), h,
                                 h_top, grid.points, grid.normals, chunk_start, chunk_centre, chunk_radius,
                                 grid.rows_x, t_min, radius, half_flat, rt, reach, blade_len, grid.pitch_rad,
                                 grid.teeth, grid.twist_rad_per_mm, dx_step)
        _on_row_blocks(clip, len(grid.rows_x), threads, pool)
    else:
        clip_poses(np.ascontiguousarray(poses), np.ascontiguousarray(x_end), h, h_top, grid.points, grid.normals,
                   chunk_start, chunk_centre, chunk_radius, grid.rows_x, t_min, t_max, radius, half_flat, rt, reach,
                   blade_len, grid.pitch_rad, grid.teeth)
    return len(poses)


def simulation_threads() -> int:
    """Threads the kernels run on: the processors this process may use, at most MAX_THREADS."""
    return max(1, min(len(os.sched_getaffinity(0)), MAX_THREADS))


def _on_row_blocks(clip: Callable[[int, int], object], rows: int, threads: int,
                   pool: ThreadPoolExecutor | None) -> None:
    """Run clip(first_row, stop_row) on disjoint blocks of rows, one per thread of `pool` (the kernel releases the
    GIL; one pool for a whole simulation: starting threads per batch cost 0.1 s on the helical example). Rows are
    independent (each blade's h is clipped by a minimum, searched from the same bounds whatever the other rows
    hold), so the result is bit for bit that of one call on all rows."""
    if threads <= 1 or pool is None:
        clip(0, rows)
        return
    edges = np.linspace(0, rows, threads + 1).round().astype(int)
    for future in [pool.submit(clip, int(lo), int(hi)) for lo, hi in zip(edges[:-1], edges[1:])]:
        future.result()


def shifted(path: Toolpath, mask: np.ndarray, dy: np.ndarray | float = 0.0, dz: np.ndarray | float = 0.0) -> Toolpath:
    """A copy of `path` with the moves in `mask` moved by (dy, dz) in machine Y/Z (for planted-fault checks)."""
    y, z = path.y.copy(), path.z.copy()
    y[mask] += np.broadcast_to(dy, y.shape)[mask] if np.ndim(dy) else dy
    z[mask] += np.broadcast_to(dz, z.shape)[mask] if np.ndim(dz) else dz
    return subset(path, np.ones(len(path), bool), y=y, z=z)


def subset(path: Toolpath, mask: np.ndarray, **replace) -> Toolpath:
    """The moves of `path` selected by `mask` (optionally with replaced x/y/z/a arrays of full length)."""
    arrays = {name: replace.get(name, getattr(path, name))[mask] for name in
              ("kind", "x", "y", "z", "a", "feed", "inverse_time", "space", "station", "feature")}
    return Toolpath(operation=path.operation, tool_number=path.tool_number, spindle_rpm=path.spindle_rpm,
                    warnings=path.warnings, **arrays)


__all__ = ["Cut", "SimResult", "SimSettings", "SimulationError", "StockCylinder", "decompose", "finishing_stations",
           "simulate", "simulate_grid", "shifted", "subset"]
