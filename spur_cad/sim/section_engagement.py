"""Roughing engagement of passes turned to a flank (the flank strategy), measured on a model of each tooth space's
transverse section (docs/simulation.md, "Roughing engagement").

The height-field model (sim.engagement) holds, per column of the space, the top of the material: exact for a tool
whose axis stays near the space's axis, but a pass with A turned 20 degrees to a flank cuts across its columns. The
flank strategy's cutting moves are passes along X (or along the helical lead) that run over the whole stock from
beyond its front to beyond its back, so each removes the same region from every transverse section: the model is
one raster per space of the section (cells D/100 square, the space's axis up, a cell's material the stock inside
the space's sector), and a pass removes the cells inside the tool's footprint in the section, turned by the pass's
A: the tool's vertical strip from its tip up (a flat bottom or a corner radius), for a helical pass the union of its
slices across X each turned by a further twist x dx. Each pass measures, on the cells it removes, the width across
its motion (a_e, in the tool's frame) and the extent along the tool's axis (a_p); a column or row of cells counts
only where it holds at least two (a layer one cell thin is the raster's own edge, not a cut), a column across a
helical pass only where it is thicker than the spread of its slices' bottoms (a skim, as in sim.engagement). A
fed move inside the stock that is not such a pass is stamped at poses a cell apart and counted as one
(conservative: a section model cannot tell how far along X it reaches). Moves clear of the stock's X range meet
nothing.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np
from numba import njit

from spur_cad.cam.ir import MoveKind
from spur_cad.sim.engagement import (
    COLUMNS_PER_DIAMETER,
    LEAD_SAMPLES,
    Engagement,
    MeasuredCut,
    _bottom,
    move_minutes,
)

MAX_SECTION_CELLS = 20_000_000
"""Largest raster (cells of all spaces, 20 MB); beyond it the cells are larger."""
MIN_CELLS_PER_LINE = 2  # a column or row of removed cells counts toward a_e / a_p from this many cells


@njit(cache=True)
def _stamp(material, k, y0, z0, cell, y_t, z_t, c0, turns, widths, radius, half_flat, rt, reach, counts_u,
           counts_v):
    """Remove the cells of space k inside the tool's footprint (tool tip centre (y_t, z_t) in the machine frame,
    the section turned by c0 + turns[j] for slice j of half-width widths[j]); count the removed cells per column
    across the tool (u, from y_t - reach) and per row along its axis (v, from z_t). Returns the cells removed."""
    n_y, n_z = material.shape[1], material.shape[2]
    removed = 0
    for j in range(len(turns)):
        c, s = math.cos(c0 + turns[j]), math.sin(c0 + turns[j])
        w = widths[j]
        # the strip from the tip up to beyond the raster, in the space frame: its corners' bounding box
        top = 2.0 * (abs(y0) + abs(z0) + n_y * cell + n_z * cell)
        ys = (c * (y_t - w) + s * z_t, c * (y_t + w) + s * z_t, c * (y_t - w) + s * (z_t + top),
              c * (y_t + w) + s * (z_t + top))
        zs = (-s * (y_t - w) + c * z_t, -s * (y_t + w) + c * z_t, -s * (y_t - w) + c * (z_t + top),
              -s * (y_t + w) + c * (z_t + top))
        i_lo = max(int(math.floor((min(ys) - y0) / cell)), 0)
        i_hi = min(int(math.ceil((max(ys) - y0) / cell)), n_y - 1)
        m_lo = max(int(math.floor((min(zs) - z0) / cell)), 0)
        for i in range(i_lo, i_hi + 1):
            y = y0 + (i + 0.5) * cell
            for m in range(m_lo, n_z):
                if not material[k, i, m]:
                    continue
                z = z0 + (m + 0.5) * cell
                u = c * y - s * z  # the machine frame of this slice
                v = s * y + c * z
                d = abs(u - y_t)
                if d > w or v < z_t + _bottom(d, half_flat, rt):
                    continue
                material[k, i, m] = False
                removed += 1
                # across and along the tool in the pass's own frame (turn c0)
                cu, su = math.cos(c0), math.sin(c0)
                iu = int(math.floor((cu * y - su * z - (y_t - reach)) / cell))
                iv = int(math.floor((su * y + cu * z - z_t) / cell))
                if 0 <= iu < len(counts_u):
                    counts_u[iu] += 1
                if 0 <= iv < len(counts_v):
                    counts_v[iv] += 1
    return removed


def _extent(counts: np.ndarray, cell: float, least: int = MIN_CELLS_PER_LINE) -> float:
    """Extent of the lines holding at least `least` removed cells (0: none), one cell added."""
    lines = np.nonzero(counts >= least)[0]
    return float((lines[-1] - lines[0] + 1) * cell) if len(lines) else 0.0


class SectionModel:
    """Per tooth space, the section's cells (True: material), the space's axis up."""

    def __init__(self, teeth: int, blank_radius_mm: float, low_mm: float, cell_mm: float):
        self.teeth, self.blank_radius_mm = teeth, blank_radius_mm
        self.pitch_rad = 2.0 * math.pi / teeth
        half = math.pi / teeth
        y_max = blank_radius_mm * math.sin(half) if teeth > 2 else blank_radius_mm
        cells = teeth * (2.0 * y_max / cell_mm + 1) * ((blank_radius_mm - low_mm) / cell_mm + 1)
        cell_mm *= math.sqrt(max(cells / MAX_SECTION_CELLS, 1.0))
        self.cell = cell_mm
        n_y = max(1, math.ceil(2.0 * y_max / cell_mm))
        n_z = max(1, math.ceil((blank_radius_mm - low_mm) / cell_mm))
        self.y0, self.z0 = -n_y * cell_mm / 2.0, low_mm
        y = self.y0 + (np.arange(n_y) + 0.5) * cell_mm
        z = self.z0 + (np.arange(n_z) + 0.5) * cell_mm
        yy, zz = np.meshgrid(y, z, indexing="ij")
        inside = (yy * yy + zz * zz <= blank_radius_mm**2) & (np.abs(yy) <= zz * math.tan(half))
        self.material = np.ascontiguousarray(np.broadcast_to(inside, (teeth, n_y, n_z)))

    def space_and_turn(self, y: float, z: float, a_rad: float) -> tuple[int, float]:
        """The space the tool tip at (y, z) is in at A = a_rad (turned by the lead's share where helical), and the
        turn of the machine frame against that space's frame."""
        k = round(-(a_rad + math.atan2(y, z)) / self.pitch_rad)
        return k % self.teeth, a_rad + k * self.pitch_rad


def measure_section_engagement(teeth: int, blank_radius_mm: float, x_range_mm: tuple[float, float],
                               cuts: Sequence[MeasuredCut], twist_rad_per_mm: float = 0.0) -> Engagement:
    """Cut the operations in order on a fresh section model and measure every fed move (module docstring)."""
    smallest = min(cut.tool.diameter_mm for cut in cuts)
    low = min(_lowest_reach_mm(cut) for cut in cuts)
    model = SectionModel(teeth, blank_radius_mm, max(low, 0.0), smallest / COLUMNS_PER_DIAMETER)
    cell = model.cell
    x_lo, x_hi = x_range_mm
    parts = []
    for cut in cuts:
        path, tool = cut.path, cut.tool
        radius, rt = tool.diameter_mm / 2.0, tool.effective_corner_radius_mm
        if twist_rad_per_mm != 0.0:
            dx = np.linspace(-radius, radius, LEAD_SAMPLES)
            turns, widths = twist_rad_per_mm * dx, np.sqrt(np.maximum(radius * radius - dx * dx, 0.0))
        else:
            turns, widths = np.zeros(1), np.array([radius])
        reach = radius * math.sqrt(1.0 + (blank_radius_mm * twist_rad_per_mm) ** 2)
        start = path.start_poses()
        # a helical pass's slices turn about the gear axis: at |Y| from it their bottoms spread over 2 |twist| R |Y|,
        # a floor that thin is a skim, not engagement (a column across needs more cells than that to count)
        spread = 2.0 * abs(twist_rad_per_mm) * radius * (float(np.abs(path.y).max(initial=0.0)) + radius)
        least_across = max(MIN_CELLS_PER_LINE, math.ceil(spread / cell) + 1)
        fed = np.nonzero(path.kind == MoveKind.LINEAR)[0]
        n = len(fed)
        width, depth, removed, slack = np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n)
        for row, i in enumerate(fed):
            x0, y0, z0, a0 = start[i]
            x1, y1, z1, a1 = path.x[i], path.y[i], path.z[i], path.a[i]
            if max(x0, x1) < x_lo - radius or min(x0, x1) > x_hi + radius:
                continue  # clear of the stock
            a0r, a1r = math.radians(a0), math.radians(a1)
            along_lead = abs((a1r - a0r) + twist_rad_per_mm * (x1 - x0)) <= 1e-9 * max(1.0, abs(a1r - a0r))
            whole = (y0 == y1 and z0 == z1 and along_lead and min(x0, x1) <= x_lo - radius
                     and max(x0, x1) >= x_hi + radius)
            if whole:
                poses = [(y1, z1, a0r + twist_rad_per_mm * x0)]
            else:  # poses a cell apart (the lead's share of the turn taken out)
                travel = math.hypot(y1 - y0, z1 - z0) + math.hypot(y1, z1) * abs(a1r - a0r) + abs(x1 - x0)
                steps = max(1, math.ceil(travel / cell))
                t = np.linspace(0.0, 1.0, steps + 1)[1:]
                xs = x0 + t * (x1 - x0)
                poses = list(zip(y0 + t * (y1 - y0), z0 + t * (z1 - z0), a0r + t * (a1r - a0r) + twist_rad_per_mm * xs))
            counts_u = np.zeros(int(math.ceil(2.0 * reach / cell)) + 2, np.int64)
            counts_v = np.zeros(int(math.ceil(2.0 * blank_radius_mm / cell)) + 2, np.int64)
            cells = 0
            for y_t, z_t, turn in poses:
                k, c0 = model.space_and_turn(y_t, z_t, turn)
                cells += _stamp(model.material, k, model.y0, model.z0, cell, y_t, z_t, c0, turns, widths, radius,
                                radius - rt, rt, reach, counts_u, counts_v)
            removed[row] = cells * cell * cell * (x_hi - x_lo)
            across = _extent(counts_u, cell, least_across) / math.sqrt(1.0 + (z1 * twist_rad_per_mm) ** 2)
            width[row], depth[row] = min(across, tool.diameter_mm), _extent(counts_v, cell)
            # a helical pass's slices, turned about the gear axis, put their bottoms at heights up to
            # 2 |twist| R (|Y| + R) apart: the section shows the cut that much deeper than the tool's axial depth
            slack[row] = 2.0 * abs(twist_rad_per_mm) * radius * (abs(y1) + radius)
        d = tool.diameter_mm
        parts.append(dict(
            operation=(cut.name,) * n, index=fed, space=path.space[fed], level=path.station[fed],
            diameter_mm=np.full(n, d), radial_fraction=width / d, axial_depth_mm=depth, removed_mm3=removed,
            minutes=move_minutes(path)[fed], radial_step=np.full(n, cell / d), axial_slack_mm=slack))
    return Engagement(
        operation=tuple(name for p in parts for name in p["operation"]),
        **{key: np.concatenate([p[key] for p in parts]) for key in
           ("index", "space", "level", "diameter_mm", "radial_fraction", "axial_depth_mm", "removed_mm3", "minutes",
            "radial_step", "axial_slack_mm")},
        column_mm=cell, axial_step_mm=cell)


def _lowest_reach_mm(cut: MeasuredCut) -> float:
    """Below the least distance from the axis the operation's tool tips come (less a diameter): the model's floor."""
    moving = cut.path.motion_mask
    return float(np.hypot(cut.path.y[moving], cut.path.z[moving]).min(initial=np.inf)) - cut.tool.diameter_mm
