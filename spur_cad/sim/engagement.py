"""Roughing engagement measured on the material each move meets: radial engagement a_e, axial depth a_p,
removal rate (docs/simulation.md, "Roughing engagement").

The deviation simulator's blades hold only a band of 1.5 mm around the design, not the middle of a tooth space
that roughing clears, so the engagement has its own stock model: per tooth space a height field over rows along
X and columns across the space (the space's axis up), each cell holding the top of the material above it. A
cell's material is the stock cylinder inside the space's sector (between the tooth centre lines), so every
piece of the blank belongs to one space. Each fed move lowers the cells under the tool to the tool's bottom and
measures, on the cells it lowers, the width across the tool (a_e), the height from the lowest cut to the highest
material met (a_p) and the volume removed. A tool cuts everything above its bottom, so the cells' tops are
exact heights; only the positions across and along the space are sampled (columns D/100 apart, rows D/5).

Moves along X (or along a helical lead) are swept exactly: a row sees the tool's slices from its nearest
distance to the move (a helical design turns each slice by twist x dx; sampled). Other moves are sampled at
poses a column apart (Z-only moves: their lower end).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np
from numba import njit

from spur_cad.cam.ir import MoveKind, Toolpath
from spur_cad.cam.tools import Tool

COLUMNS_PER_DIAMETER = 100
ROWS_PER_DIAMETER = 5
LEAD_SAMPLES = 9  # slices sampled across a helical sweep's tool width
SKIM_FRACTION = 0.005  # a layer thinner than this x D is counted in the volume only, not in a_e or a_p
_EPS_MM = 1e-9
MAX_CELLS = 20_000_000
"""Largest height field (cells of all spaces, 160 MB); beyond it rows and columns are spaced wider alike (the
reference job has about 0.3 million)."""


@dataclass(frozen=True)
class MeasuredCut:
    """One roughing operation to measure: its name in summaries ("roughing", "roughing_bottom"), path, tool."""

    name: str
    path: Toolpath
    tool: Tool


@dataclass(frozen=True)
class Engagement:
    """Per fed (linear) move of the measured operations: where it is and what it met.

    `radial_fraction`: a_e / D (width of the material met across the direction of motion); `axial_depth_mm`:
    a_p (highest material met minus lowest cut); `removed_mm3`; `minutes` at the programmed feed. Moves that
    met no material have a_e = a_p = removed = 0."""

    operation: tuple[str, ...]
    index: np.ndarray  # the move's row in its toolpath
    space: np.ndarray
    level: np.ndarray
    diameter_mm: np.ndarray
    radial_fraction: np.ndarray
    axial_depth_mm: np.ndarray
    removed_mm3: np.ndarray
    minutes: np.ndarray
    radial_step: np.ndarray  # the model's sampling in a_e's direction / D (columns across, rows along X)
    column_mm: float  # the model's sampling across the space
    axial_step_mm: float = 0.0  # the model's sampling of a_p (0: exact heights)
    axial_slack_mm: np.ndarray | None = None  # per move, how much a_p may read deeper than the tool cuts (None: 0)

    @property
    def cutting(self) -> np.ndarray:
        return self.removed_mm3 > 0.0

    @property
    def measured(self) -> np.ndarray:
        """Moves whose a_e and a_p the model measures: not the tip lands' moves (level -1). A tip-land pass is
        centred on a tooth, over the centre line between two spaces' height fields, which the model holds apart;
        it is cut in the model (the volume counts), and its engagement is bounded by construction (every pass no
        deeper than the level depth limit, a slot's, whatever its width; cam.roughing)."""
        return self.level >= 0

    @property
    def max_radial_fraction(self) -> float:
        return float(self.radial_fraction[self.measured].max(initial=0.0))

    @property
    def max_axial_depth_mm(self) -> float:
        return float(self.axial_depth_mm[self.measured].max(initial=0.0))

    @property
    def mean_removal_rate_mm3_min(self) -> float:
        """Volume removed over the time of the moves that removed it (programmed feeds)."""
        minutes = float(self.minutes[self.cutting].sum())
        return float(self.removed_mm3.sum()) / minutes if minutes > 0.0 else 0.0


@dataclass(frozen=True)
class EngagementLimits:
    """The job's roughing limits ([roughing] keys). Levels (`max_axial_depth_mm` None): no pass deeper than
    max_level_depth_fraction x D, none engaged wider than step_over_fraction x D unless it is a slot. Flank strategy:
    no pass deeper than max_axial_depth_mm, none deeper than the slot limit engaged wider than step_over_fraction x D
    (its max_radial_engagement_fraction). `axial_depth_by_operation`: the flank strategy's axial depth limit of each
    operation where two-stage roughing's tools have their own (max_axial_depth_mm is then the larger)."""

    max_level_depth_fraction: float
    step_over_fraction: float
    max_axial_depth_mm: float | None = None
    axial_depth_by_operation: dict[str, float] | None = None


@njit(cache=True)
def _bottom(d, half_flat, rt):
    """Height of the tool's bottom above its tip at distance d from its axis (inf beyond its radius)."""
    if d <= half_flat:
        return 0.0
    e = d - half_flat
    if e > rt:
        return np.inf
    return rt - math.sqrt(rt * rt - e * e)


@njit(cache=True, inline="always")
def _lower(top, low, k, i, j, b, across, along, skim, acc):
    """Lower cell (k, i, j) to the tool's bottom b; record what it met in acc (see _stamp_all): its volume,
    and where it stood unless it was a skim (a layer thinner than `skim`)."""
    cut = max(b, low[j])
    t = top[k, i, j]
    if t <= cut + _EPS_MM:
        return
    top[k, i, j] = cut
    acc[0] += t - cut
    if t - cut <= skim:
        return
    acc[1] = min(acc[1], across)
    acc[2] = max(acc[2], across)
    acc[3] = min(acc[3], along)
    acc[4] = max(acc[4], along)
    acc[5] = max(acc[5], t)
    acc[6] = min(acc[6], cut)


@njit(cache=True)
def _segment_row(top, low, k, i, px, j_lo, j_hi, col0, col_w, ya, za, zb, ux, uy, length, radius, half_flat, rt, skim,
                 acc):
    """Row i (at px along X from the segment's start) of _stamp_segment, each cell at its distance from it."""
    for j in range(j_lo, j_hi + 1):
        py = col0 + (j + 0.5) * col_w - ya
        t = min(max(px * ux + py * uy, 0.0), length)
        across = py * ux - px * uy
        along = px * ux + py * uy - t
        d = math.sqrt(across * across + along * along)
        if d > radius:
            continue
        _lower(top, low, k, i, j, za + t / max(length, 1e-300) * (zb - za) + _bottom(d, half_flat, rt), across,
               along, skim, acc)


@njit(cache=True)
def _stamp_segment(top, low, k, row0, row_w, col0, col_w, c0, xa, xb, ya, yb, z, ux, uy, radius, half_flat, rt,
                   skim, acc, env):
    """The tool moved horizontally from (xa, ya) to (xb, yb) at height z in the design frame turned by c0 (a
    single pose when both ends are one; (ux, uy) its move's horizontal direction, (0, 0) for none): a cell's
    bottom is the tool's bottom at its distance from the segment (exact); `across` is the cell's signed offset
    across the motion, `along` along it (beyond the segment's ends). A pass along X has the same bottoms in
    every row along it: computed once (`env`, all inf on entry and on return)."""
    c, s = math.cos(c0), math.sin(c0)
    ya, za = c * ya + s * z, -s * ya + c * z
    yb, zb = c * yb + s * z, -s * yb + c * z
    length = math.hypot(xb - xa, yb - ya)
    if length > 0.0:
        ux, uy = (xb - xa) / length, (yb - ya) / length
    elif ux == 0.0 and uy == 0.0:
        ux = 1.0  # no direction: across is Y, along is X
    n_rows, n_cols = top.shape[1], top.shape[2]
    i_lo = max(int(math.floor((min(xa, xb) - radius - row0) / row_w)), 0)
    i_hi = min(int(math.ceil((max(xa, xb) + radius - row0) / row_w)), n_rows - 1)
    j_lo = max(int(math.floor((min(ya, yb) - radius - col0) / col_w)), 0)
    j_hi = min(int(math.ceil((max(ya, yb) + radius - col0) / col_w)), n_cols - 1)
    along_x = uy == 0.0 and za == zb
    if along_x:
        for j in range(j_lo, j_hi + 1):
            py = col0 + (j + 0.5) * col_w - ya
            if abs(py) <= radius:
                env[j] = za + _bottom(abs(py), half_flat, rt)
    for i in range(i_lo, i_hi + 1):
        px = row0 + (i + 0.5) * row_w - xa
        if along_x and 0.0 <= px * ux <= length:  # beside the segment: its distance is |py|
            for j in range(j_lo, j_hi + 1):
                if env[j] != np.inf:
                    _lower(top, low, k, i, j, env[j], (col0 + (j + 0.5) * col_w - ya) * ux, 0.0, skim, acc)
            continue
        _segment_row(top, low, k, i, px, j_lo, j_hi, col0, col_w, ya, za, zb, ux, uy, length, radius, half_flat, rt,
                     skim, acc)
    if along_x:
        for j in range(j_lo, j_hi + 1):
            env[j] = np.inf


@njit(cache=True)
def _lead_envelope(d_lo, d_hi, c0, y, z, radius, half_flat, rt, twist, col0, col_w, env, across, along, used):
    """Lowest tool bottom per column over the slices dx in [d_lo, d_hi] of a tool following a helical lead (each
    slice turned by twist * dx), with the column's offset across from the tool's axis slice and the cutting
    slice's dx; clears the columns `used` (first, last) by the previous envelope and sets the columns this one
    reaches."""
    for j in range(used[0], used[1] + 1):
        env[j] = np.inf
    y_axis = math.cos(c0) * y + math.sin(c0) * z
    n_cols = len(env)
    n_samples = 1 if d_hi - d_lo < 1e-9 else LEAD_SAMPLES
    j_min, j_max = n_cols, -1
    for s_i in range(n_samples):
        dx = d_lo if n_samples == 1 else d_lo + (d_hi - d_lo) * s_i / (n_samples - 1)
        phi = c0 + twist * dx
        c, s = math.cos(phi), math.sin(phi)
        yt = c * y + s * z
        w = math.sqrt(max(radius * radius - dx * dx, 0.0))
        j0 = max(int(math.ceil((yt - w - col0) / col_w - 0.5)), 0)
        j1 = min(int(math.floor((yt + w - col0) / col_w - 0.5)), n_cols - 1)
        for j in range(j0, j1 + 1):
            # the slice's bottom turned into the design frame: the machine point (c Y - s Z, s Y + c Z) of column
            # Y at height Z lies on the bottom, at the lateral offset taken at the tip's height (to first order)
            col_y = col0 + (j + 0.5) * col_w
            lateral = c * col_y - s * z - y
            b = (z + _bottom(math.sqrt(dx * dx + lateral * lateral), half_flat, rt) - s * col_y) / c
            if b < env[j]:
                env[j] = b
                across[j] = col0 + (j + 0.5) * col_w - y_axis
                along[j] = dx
        j_min, j_max = min(j_min, j0), max(j_max, j1)
    used[0], used[1] = j_min, j_max


@njit(cache=True)
def _stamp_lead(top, low, k, row0, row_w, col0, col_w, c0, x_lo, x_hi, y, z, radius, half_flat, rt, twist, skim, acc,
                env, across, along, used):
    """The tool following a helical lead from x_lo to x_hi (Y and Z fixed; c0: the design's turn at x_lo): a row
    sees the slices dx in [row - x_hi, row - x_lo], sampled; rows seeing the same slices share one envelope."""
    n_rows = top.shape[1]
    i_lo = max(int(math.floor((x_lo - radius - row0) / row_w)), 0)
    i_hi = min(int(math.ceil((x_hi + radius - row0) / row_w)), n_rows - 1)
    key_lo, key_hi = np.nan, np.nan
    for i in range(i_lo, i_hi + 1):
        xr = row0 + (i + 0.5) * row_w
        d_lo = max(xr - x_hi, -radius)
        d_hi = min(xr - x_lo, radius)
        if d_lo > d_hi:
            continue
        if d_lo != key_lo or d_hi != key_hi:
            _lead_envelope(d_lo, d_hi, c0, y, z, radius, half_flat, rt, twist, col0, col_w, env, across, along, used)
            key_lo, key_hi = d_lo, d_hi
        for j in range(used[0], used[1] + 1):
            if env[j] != np.inf:
                _lower(top, low, k, i, j, env[j], across[j], along[j], skim, acc)


@njit(cache=True)
def _stamp_all(top, low, row0, row_w, col0, col_w, stamps, move_of, n_moves, radius, half_flat, rt, twist, skim):
    """Apply stamps (k, c0, x_a, x_b, y_a, y_b, z, lead, u_x, u_y) in order; per move: removed (mm^2 x rows),
    across-offset min/max, along-offset min/max, highest material met, lowest cut."""
    acc = np.zeros((n_moves, 7))
    acc[:, 1] = np.inf
    acc[:, 2] = -np.inf
    acc[:, 3] = np.inf
    acc[:, 4] = -np.inf
    acc[:, 5] = -np.inf
    acc[:, 6] = np.inf
    n_cols = top.shape[2]
    env = np.full(n_cols, np.inf)
    across = np.zeros(n_cols)
    along = np.zeros(n_cols)
    used = np.array([0, -1])
    for n in range(stamps.shape[0]):
        st = stamps[n]
        if st[7] > 0.0:
            _stamp_lead(top, low, int(st[0]), row0, row_w, col0, col_w, st[1], st[2], st[3], st[4], st[6], radius,
                        half_flat, rt, twist, skim, acc[move_of[n]], env, across, along, used)
        else:
            _stamp_segment(top, low, int(st[0]), row0, row_w, col0, col_w, st[1], st[2], st[3], st[4], st[5], st[6],
                           st[8], st[9], radius, half_flat, rt, skim, acc[move_of[n]], env)
    return acc


class StockHeightField:
    """The engagement model's stock: per tooth space, the top of the material over rows (X) and columns (Y)."""

    def __init__(self, teeth: int, blank_radius_mm: float, x_min: float, x_max: float, column_mm: float,
                 row_mm: float, twist_rad_per_mm: float = 0.0):
        self.teeth = teeth
        self.pitch_rad = 2.0 * math.pi / teeth
        self.blank_radius_mm = blank_radius_mm
        self.twist = twist_rad_per_mm
        half = math.pi / teeth
        y_max = blank_radius_mm * math.sin(half) if teeth > 2 else blank_radius_mm
        n_cols = max(1, math.ceil(2.0 * y_max / column_mm))
        n_rows = max(1, math.ceil((x_max - x_min) / row_mm))
        self.col0, self.col_w = -y_max, 2.0 * y_max / n_cols
        self.row0, self.row_w = x_min, (x_max - x_min) / n_rows
        cols = self.col0 + (np.arange(n_cols) + 0.5) * self.col_w
        # A column's material: above the sector's edges (the tooth centre lines), below the blank.
        self.low = np.abs(cols) / math.tan(half) if teeth > 2 else np.full(n_cols, -blank_radius_mm)
        initial = np.sqrt(np.maximum(blank_radius_mm**2 - cols**2, 0.0))
        self.top = np.ascontiguousarray(np.broadcast_to(np.maximum(initial, self.low), (teeth, n_rows, n_cols)))

    def volume_mm3(self) -> float:
        """Material left in the model (for checks)."""
        return float((self.top - self.low).sum() * self.row_w * self.col_w)

    def space_and_turn(self, x: np.ndarray, a_rad: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The tooth space under a tool at (x, a) and the design's turn there (0: the space's axis on the tool)."""
        turn = a_rad + self.twist * x
        k = np.round(-turn / self.pitch_rad).astype(np.int64)
        return np.mod(k, self.teeth), turn + k * self.pitch_rad

    def cut(self, path: Toolpath, tool: Tool, column_mm: float) -> np.ndarray:
        """Cut the moves of `path` in order; (moves, 7) accumulators per move (see _stamp)."""
        radius = tool.diameter_mm / 2.0
        rt = tool.effective_corner_radius_mm
        stamps, move_of = self._stamps(path, radius, column_mm)
        return _stamp_all(self.top, self.low, self.row0, self.row_w, self.col0, self.col_w, stamps, move_of,
                          len(path), radius, radius - rt, rt, self.twist, self.skim_mm(tool))

    def skim_mm(self, tool: Tool) -> float:
        """Layers thinner than this count in the volume only: SKIM_FRACTION x D, and on a helical design the
        spread of its slices' bottoms at one column (turned by up to +-twist R, at most y_max from the axis), so
        that a pass beside the last one does not count the floor the last one's other slices left as width."""
        radius = tool.diameter_mm / 2.0
        return max(SKIM_FRACTION * tool.diameter_mm, 2.0 * abs(self.twist) * radius * abs(self.col0))

    def _stamps(self, path: Toolpath, radius: float, step_mm: float) -> tuple[np.ndarray, np.ndarray]:
        """(k, c0, x_a, x_b, y_a, y_b, z, lead, u_x, u_y) per stamp and its move, in the moves' order: one per
        horizontal move that does not turn A (spur design) or per sweep along the lead (helical design), poses a
        step apart along other moves (u: the move's horizontal direction), the lower end of Z-only moves; none
        for moves clear of the stock. The first move's start is unknown: its end pose only (as the deviation
        simulator does)."""
        start = path.start_poses()
        x0, y0, z0, a0 = start.T
        x1, y1, z1, a1 = path.x, path.y, path.z, path.a
        a0, a1 = np.radians(a0), np.radians(a1)
        dx, dy, dz, da = x1 - x0, y1 - y0, z1 - z0, a1 - a0
        x_lo, x_hi = self.row0, self.row0 + self.row_w * self.top.shape[1]
        moving = path.motion_mask & (np.minimum(z0, z1) < self.blank_radius_mm) \
            & (np.maximum(x0, x1) > x_lo - radius) & (np.minimum(x0, x1) < x_hi + radius)
        helical = self.twist != 0.0
        if helical:
            lead = np.abs(da + self.twist * dx) <= 1e-9 * np.maximum(1.0, np.abs(da))
            whole = moving & (dy == 0.0) & (dz == 0.0) & lead & (dx != 0.0)
        else:
            whole = moving & (dz == 0.0) & (da == 0.0) & ((dx != 0.0) | (dy != 0.0))
        idx = np.nonzero(whole)[0]
        backwards = x1[idx] < x0[idx] if helical else np.zeros(len(idx), bool)
        xa = np.where(backwards, x1[idx], x0[idx])  # a lead sweep starts at its smaller X
        k, c0 = self.space_and_turn(xa, np.where(backwards, a1[idx], a0[idx]))
        xb = np.where(backwards, x0[idx], x1[idx])
        flat = np.hypot(dx, dy)  # the moves' horizontal directions (none for moves in Z or A only)
        ux, uy = np.divide(dx, flat, out=np.zeros_like(dx), where=flat > 0), np.divide(dy, flat, out=np.zeros_like(dy),
                                                                                      where=flat > 0)
        whole_stamps = np.stack([k, c0, xa, xb, y0[idx], y1[idx], z1[idx], np.full(len(idx), float(helical)),
                                 ux[idx], uy[idx]], axis=-1)
        other = np.nonzero(moving & ~whole)[0]
        only_z = (dx[other] == 0.0) & (dy[other] == 0.0) & (da[other] == 0.0)
        reach = np.hypot(np.maximum(np.abs(y0), np.abs(y1)), np.maximum(np.abs(z0), np.abs(z1)))[other]
        travel = np.abs(dx[other]) + np.hypot(dy[other], dz[other]) + reach * np.abs(da[other] + self.twist * dx[other])
        pieces = np.where(only_z, 1, np.maximum(1, np.ceil(travel / step_mm))).astype(np.int64)
        move_of = np.repeat(other, pieces)
        offsets = np.arange(len(move_of)) - np.repeat(np.cumsum(pieces) - pieces, pieces)
        low_end = np.repeat(only_z, pieces)
        frac = np.where(low_end, 0.0, (offsets + 1) / np.repeat(pieces, pieces))
        px = x0[move_of] + dx[move_of] * frac
        py = y0[move_of] + dy[move_of] * frac
        pz = np.where(low_end, np.minimum(z0, z1)[move_of], z0[move_of] + dz[move_of] * frac)
        k, c0 = self.space_and_turn(px, a0[move_of] + da[move_of] * frac)
        pose_stamps = np.stack([k, c0, px, px, py, py, pz, np.full(len(px), float(helical)), ux[move_of],
                                uy[move_of]], axis=-1)
        stamps = np.concatenate([whole_stamps, pose_stamps])
        owner = np.concatenate([idx, move_of])
        order = np.argsort(owner, kind="stable")  # the moves' order: the material each one meets
        return np.ascontiguousarray(stamps[order], float), np.ascontiguousarray(owner[order], np.int64)


def move_minutes(path: Toolpath) -> np.ndarray:
    """Each move's time at its programmed feed (mm/min over the X/Y/Z path, or inverse time); 0 for rapids."""
    start = path.start_poses()
    length = np.sqrt((path.x - start[:, 0]) ** 2 + (path.y - start[:, 1]) ** 2 + (path.z - start[:, 2]) ** 2)
    linear = path.kind == MoveKind.LINEAR
    with np.errstate(divide="ignore", invalid="ignore"):
        minutes = np.where(path.inverse_time, 1.0 / path.feed, length / path.feed)
    return np.where(linear & np.isfinite(minutes), minutes, 0.0)


def measure_engagement(teeth: int, blank_radius_mm: float, x_range_mm: tuple[float, float],
                       cuts: Sequence[MeasuredCut], twist_rad_per_mm: float = 0.0) -> Engagement:
    """Cut the operations in order on a fresh stock and measure every fed move (docs/simulation.md)."""
    smallest = min(cut.tool.diameter_mm for cut in cuts)
    column_mm, row_mm = smallest / COLUMNS_PER_DIAMETER, smallest / ROWS_PER_DIAMETER
    half_width = blank_radius_mm * math.sin(math.pi / teeth) if teeth > 2 else blank_radius_mm
    cells = teeth * (2.0 * half_width / column_mm + 1) * ((x_range_mm[1] - x_range_mm[0]) / row_mm + 1)
    coarser = math.sqrt(max(cells / MAX_CELLS, 1.0))  # a huge gear with a small tool: coarser, within memory
    field = StockHeightField(teeth, blank_radius_mm, x_range_mm[0], x_range_mm[1], column_mm * coarser,
                             row_mm * coarser, twist_rad_per_mm)
    column_mm = field.col_w
    parts = []
    for cut in cuts:
        acc = field.cut(cut.path, cut.tool, column_mm)
        fed = np.nonzero(cut.path.kind == MoveKind.LINEAR)[0]
        acc, d = acc[fed], cut.tool.diameter_mm
        engaged = np.isfinite(acc[:, 5])  # met more than skims
        first, second = (np.where(engaged, acc[:, hi] - acc[:, lo], 0.0) for lo, hi in ((1, 2), (3, 4)))
        start = cut.path.start_poses()[fed]
        moved_x = np.abs(cut.path.x[fed] - start[:, 0])
        moved_y = np.abs(cut.path.y[fed] - start[:, 1])
        still = (moved_x == 0.0) & (moved_y == 0.0)  # Z (or A) only: the larger extent
        along_y = moved_y > moved_x  # a_e measured along X, to a row
        if field.twist == 0.0:  # segments: `first` is across the motion (Y for a move in Z only), `second` along
            across_y, across_x = np.where(along_y, 0.0, first), np.where(along_y, first, second)
        else:  # the lead's stamps: `first` is across Y, `second` along X; a pass along the lead sweeps a section
            # wider by sqrt(1 + (r twist)^2) at radius r
            across_y, across_x = first / np.sqrt(1.0 + (np.maximum(acc[:, 5], 0.0) * field.twist) ** 2), second
        across_y, across_x = across_y + field.col_w, across_x + field.row_w
        width = np.where(engaged, np.where(still, np.maximum(across_y, across_x),
                                           np.where(along_y, across_x, across_y)), 0.0)
        step = np.where(still, max(field.col_w, field.row_w), np.where(along_y, field.row_w, field.col_w))
        parts.append(dict(
            operation=(cut.name,) * len(fed), index=fed, space=cut.path.space[fed], level=cut.path.station[fed],
            diameter_mm=np.full(len(fed), d), radial_fraction=np.minimum(width, d) / d,
            axial_depth_mm=np.where(engaged, acc[:, 5] - acc[:, 6], 0.0),
            removed_mm3=acc[:, 0] * field.row_w * field.col_w, minutes=move_minutes(cut.path)[fed],
            radial_step=step / d))

    def joined(name: str) -> np.ndarray:
        """One per-move field of every cut, in the cuts' order."""
        return np.concatenate([p[name] for p in parts])

    return Engagement(
        operation=tuple(name for p in parts for name in p["operation"]), index=joined("index"),
        space=joined("space"), level=joined("level"), diameter_mm=joined("diameter_mm"),
        radial_fraction=joined("radial_fraction"), axial_depth_mm=joined("axial_depth_mm"),
        removed_mm3=joined("removed_mm3"), minutes=joined("minutes"), radial_step=joined("radial_step"),
        column_mm=field.col_w)


MAX_WARNED_MOVES = 5


def engagement_warnings(engagement: Engagement, limits: EngagementLimits) -> list[str]:
    """One warning per kind of overload (at most MAX_WARNED_MOVES moves named, then how many more), by the rules of
    EngagementLimits. Tolerances: 1.5 x the model's sampling in a_e's direction, in depth 1 um or 1.5 x its
    sampling there, plus the move's `axial_slack_mm`."""
    e = engagement
    tol_ae = 1.5 * e.radial_step
    slot_depth = limits.max_level_depth_fraction * e.diameter_mm
    wider = e.measured & (e.radial_fraction > limits.step_over_fraction + tol_ae)
    tol_ap = max(1e-3, 1.5 * e.axial_step_mm) + (e.axial_slack_mm if e.axial_slack_mm is not None else 0.0)
    if limits.max_axial_depth_mm is None:
        max_depth = slot_depth
        deep_text = ("beyond the slotting depth limit {lim:.3f} mm ([roughing] max_level_depth_fraction {f:g} x D "
                     "{d:g} mm)")
        wide = wider & (e.radial_fraction < 1.0 - tol_ae)
        wide_text = "beyond the step-over {f:g} D and not a slot ([roughing] step_over_fraction)"
        deep_fraction = limits.max_level_depth_fraction
    else:
        by_operation = limits.axial_depth_by_operation or {}
        max_depth = np.array([by_operation.get(operation, limits.max_axial_depth_mm) for operation in e.operation],
                             dtype=float)
        deep_text = "beyond the axial depth limit {lim:.3f} mm ([roughing] max_axial_depth_mm)"
        wide = wider & (e.axial_depth_mm > slot_depth + tol_ap)
        wide_text = ("beyond {f:g} D deeper than a slot ([roughing] max_radial_engagement_fraction; "
                     "max_level_depth_fraction)")
        deep_fraction = 0.0
    deep = e.measured & (e.axial_depth_mm > max_depth + tol_ap)
    out = []
    for mask, what, limit_text in ((deep, "axial depth {ap:.3f} mm", deep_text),
                                   (wide, "radial engagement {ae:.2f} D", wide_text)):
        moves = np.nonzero(mask)[0]
        if not len(moves):
            continue
        named = []
        for i in moves[:MAX_WARNED_MOVES]:
            fraction = deep_fraction if what.startswith("axial") else limits.step_over_fraction
            named.append(f"{e.operation[i]} move {e.index[i]} (tooth space {e.space[i]}, level {e.level[i]}): "
                         + what.format(ap=e.axial_depth_mm[i], ae=e.radial_fraction[i]) + " "
                         + limit_text.format(lim=max_depth[i], f=fraction, d=e.diameter_mm[i]))
        more = f"; and {len(moves) - MAX_WARNED_MOVES} more moves" if len(moves) > MAX_WARNED_MOVES else ""
        out.append("measured roughing engagement: " + "; ".join(named) + more)
    return out
