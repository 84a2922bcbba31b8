"""Numba kernels: clip the blades (design point + t * normal, t in [t_min, h]) by tool positions.

The tool (flat, bull-nose or ball end mill, axis +Z, tip centre at the programmed point, shank
going up for ever) is the set of points within r_t of its core, the cylinder of radius half_flat
(flat half-width) above height r_t (corner radius); R = half_flat + r_t. Along a blade the distance
to that convex core minus r_t is a convex function with slope at most 1, so the first point of
the blade inside the tool is found exactly by Newton's method started at the blade's inner
end: from the left, a convex function's Newton iterates never pass its first root.

Each blade keeps h, the outer end of the material left along it (h < 0: gouge, h > 0:
leftover). A tool position removes everything from its first entry t_e outward, so
h <- min(h, t_e): the result does not depend on the order of the cuts.
Compiled lazily on first use (cache=True keeps the machine code between runs).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

INF = np.inf
_NEWTON_STEPS = 60
_F_TOLERANCE = 1e-10
CHUNK_GROUP = 8
"""Chunks per group circle, tested before its chunks (helical kernel)."""


@njit(cache=True, inline="always")
def _gap_parts(t, dx, ay, az, ny, nz, half_flat, rt):
    """(u, s, e, v, dist) of the blade point at t: its offset across the tool u, distance from the axis s,
    radial and axial distances to the core e and v, and its distance to the core."""
    u = ay + t * ny
    dz = az + t * nz
    s = math.sqrt(dx * dx + u * u)
    e = s - half_flat
    if e < 0.0:
        e = 0.0
    v = rt - dz
    if v < 0.0:
        v = 0.0
    return u, s, e, v, math.sqrt(e * e + v * v)


@njit(cache=True, inline="always")
def _gap(t, dx, ay, az, ny, nz, half_flat, rt):
    """G(t) = distance from the blade point to the tool's core minus r_t (<= 0 inside the tool); the blades a
    tool misses need no slope."""
    dist = _gap_parts(t, dx, ay, az, ny, nz, half_flat, rt)[4]
    if dist <= 1e-300:
        return -rt
    return dist - rt


@njit(cache=True, inline="always")
def _gap_and_slope(t, dx, ay, az, ny, nz, half_flat, rt):
    """G(t) as _gap gives it, and dG/dt."""
    u, s, e, v, dist = _gap_parts(t, dx, ay, az, ny, nz, half_flat, rt)
    if dist <= 1e-300:
        return -rt, 0.0
    ds = u * ny / s if s > 1e-300 else 0.0
    return dist - rt, (e * ds - v * nz) / dist


@njit(cache=True)
def first_entry(dx, ay, az, ny, nz, lo, hi, radius, half_flat, rt):
    """Smallest t in [lo, hi] where the blade point (dx, ay + t ny, az + t nz) relative to the tool tip
    is inside the tool; +inf when the blade misses the tool there.

    The tool is the set of points within r_t of its core (the cylinder of radius half_flat above height
    r_t), so G(t) = dist(core) - r_t is convex along the blade with |dG/dt| <= 1: Newton's method
    from the inner end climbs monotonically to the first root, and G(lo) > hi - lo rules a blade out.
    """
    if dx >= radius or dx <= -radius:
        return INF
    if rt <= 0.0:  # flat end mill: inside iff dz >= 0 within the side walls
        w = math.sqrt(radius * radius - dx * dx)
        if abs(ny) > 1e-15:
            t1 = (-w - ay) / ny
            t2 = (w - ay) / ny
            if t1 > t2:
                t1, t2 = t2, t1
            if t1 > lo:
                lo = t1
            if t2 < hi:
                hi = t2
        elif ay * ay > w * w:
            return INF
        if lo > hi:
            return INF
        if nz > 0.0:
            t = -az / nz
            if t < lo:
                t = lo
            return t if t <= hi else INF
        if az + lo * nz >= 0.0:
            return lo
        return INF
    if lo > hi:
        return INF
    f = _gap(lo, dx, ay, az, ny, nz, half_flat, rt)
    if f <= 0.0:
        return lo
    if f > hi - lo:
        return INF
    f, slope = _gap_and_slope(lo, dx, ay, az, ny, nz, half_flat, rt)  # the same G(lo), now with its slope
    if slope >= 0.0:
        return INF
    fh, slope_h = _gap_and_slope(hi, dx, ay, az, ny, nz, half_flat, rt)
    if fh > 0.0 and (slope_h <= 0.0 or f + fh > hi - lo):  # |slope| <= 1: min G >= (G(lo) + G(hi) - (hi - lo)) / 2
        return INF
    t = lo
    for _ in range(_NEWTON_STEPS):
        step = -f / slope
        t_next = t + step
        if t_next > hi:
            return INF
        f, slope = _gap_and_slope(t_next, dx, ay, az, ny, nz, half_flat, rt)
        if f <= _F_TOLERANCE:
            return t_next
        if slope >= 0.0 or f > hi - t_next:
            return INF
        if step < 1e-12:
            return t_next if f < 1e-7 else INF
        t = t_next
    return t


@njit(cache=True, inline="always")
def _turned_blade(c, s, px, pz_, nx, nz_, y, z):
    """A blade (design point p, normal n) turned by (cos, sin) = (c, s), relative to the tool tip at (y, z):
    (ay, az, ny, nz) as first_entry takes them."""
    return c * px - s * pz_ - y, s * px + c * pz_ - z, c * nx - s * nz_, s * nx + c * nz_


@njit(cache=True, inline="always")
def _chunk_gap(c, s, py, pz, y, z, half_flat, rt):
    """Distance from a chunk's centre (py, pz), turned by (cos, sin) = (c, s), to the tool's section at (y, z)
    (negative inside): a chunk whose circle radius is below it cannot meet the tool."""
    cy = c * py - s * pz
    cz = s * py + c * pz
    ddy = abs(cy - y) - half_flat
    ddz = z + rt - cz
    out = math.sqrt(max(ddy, 0.0) ** 2 + max(ddz, 0.0) ** 2)
    inside = min(max(ddy, ddz), 0.0)
    return out + inside - rt


@njit(cache=True, inline="always")
def chunk_reach(py, pz, chunk_radius, spread):
    """How far from a chunk's centre (py, pz) its blades can be when the design turns by +- spread about the axis
    (a helical design over the tool's width): its radius, plus how far the turn moves its centre (a turned disc
    is a disc of the same radius)."""
    return chunk_radius + spread * math.hypot(py, pz)


@njit(cache=True, inline="always")
def group_reach(gy, gz, group_radius, spread):
    """chunk_reach for a group circle, enough for every chunk in it: a chunk's centre c lies within the group's
    radius R of the group's centre C, so the turn moves it by at most spread (|C| + R)."""
    return group_radius + spread * (math.hypot(gy, gz) + group_radius)


@njit(cache=True)
def _sector_range(y, z, a, spread, radius, blade_len, pitch, teeth):
    """Sectors (tooth spaces, unreduced index range) whose blades may meet the tool at (y, z) when the design
    is turned by a +- spread (spread > 0: a helical design over the tool's width)."""
    if z - blade_len <= 0.0:
        return 0, teeth - 1
    half = math.atan2(abs(y) + radius + blade_len, z - blade_len) + spread
    first = math.ceil((-half - a) / pitch - 0.5)
    last = math.floor((half - a) / pitch + 0.5)
    if last - first + 1 >= teeth:
        return 0, teeth - 1
    return first, last


@njit(cache=True)
def _clip_at_pose(x, y, z, a, x_end, h, h_top, points, normals, chunk_start, chunk_centre, chunk_radius,
                  rows, t_min, t_max, radius, half_flat, rt, reach, blade_len, pitch, teeth):
    """Clip the blades by the tool at (x, y, z, a); with x_end > x, by the tool swept along X from x to x_end
    (the union of the slices is the slice nearest the axis: t_e(dx) grows with |dx|)."""
    if z > reach:
        return 0
    first, last = _sector_range(y, z, a, 0.0, radius, blade_len, pitch, teeth)
    r_lo = np.searchsorted(rows, x - radius, side="right")
    r_hi = np.searchsorted(rows, x_end + radius, side="left")
    if r_lo >= r_hi:
        return 0
    r_in = np.searchsorted(rows, x, side="left")  # rows[r_in:r_out] lie within [x, x_end]
    r_out = np.searchsorted(rows, x_end, side="right")
    cuts = 0
    n_chunks = len(chunk_radius)
    for k in range(first, last + 1):
        sector = k % teeth
        theta = a + k * pitch
        c = math.cos(theta)
        s = math.sin(theta)
        for ci in range(n_chunks):
            if _chunk_gap(c, s, chunk_centre[ci, 0], chunk_centre[ci, 1], y, z, half_flat, rt) > chunk_radius[ci]:
                continue
            for j in range(chunk_start[ci], chunk_start[ci + 1]):
                ay, az, ny, nz = _turned_blade(c, s, points[j, 0], points[j, 1], normals[j, 0], normals[j, 1], y, z)
                top = h_top[sector, j]
                deepest = first_entry(0.0, ay, az, ny, nz, t_min, top, radius, half_flat, rt)
                if deepest == INF:
                    continue
                hrow = h[sector, j]
                for r in range(r_in, r_out):  # rows within the sweep see the slice through the tool axis
                    if deepest < hrow[r]:
                        hrow[r] = deepest
                        cuts += 1
                # Outside the sweep the slice at distance |dx| shrinks as |dx| grows: the entry only grows
                # (a lower bound for the next row outward), and no slice wider than reach_x meets the blade.
                u_in = ay + t_min * ny
                u_out = ay + top * ny
                dy_min = 0.0 if u_in * u_out <= 0.0 else min(abs(u_in), abs(u_out))
                dz_top = max(az + t_min * nz, az + top * nz)
                slice_radius = radius
                if dz_top < rt:
                    slice_radius = half_flat + math.sqrt(max(rt * rt - (rt - dz_top) ** 2, 0.0))
                reach_x2 = slice_radius * slice_radius - dy_min * dy_min
                if reach_x2 <= 0.0:
                    continue
                reach_x = math.sqrt(reach_x2)
                cuts += _walk_rows(hrow, rows, r_out, r_hi, 1, x_end, reach_x, deepest, ay, az, ny, nz, radius,
                                   half_flat, rt)
                cuts += _walk_rows(hrow, rows, r_in - 1, r_lo - 1, -1, x, reach_x, deepest, ay, az, ny, nz, radius,
                                   half_flat, rt)
    return cuts


@njit(cache=True)
def _walk_rows(hrow, rows, start, stop, step, x_edge, reach_x, deepest, ay, az, ny, nz, radius, half_flat, rt):
    """Clip one blade on the rows outside the sweep, walking away from the edge `x_edge` of the
    sweep (step +1 beyond its end, -1 before its start) until the slice no longer reaches."""
    cuts = 0
    lower = deepest
    for r in range(start, stop, step):
        dx = (rows[r] - x_edge) * step
        if dx > reach_x:
            break
        current = hrow[r]
        if lower >= current:
            continue
        entry = first_entry(dx, ay, az, ny, nz, lower, current, radius, half_flat, rt)
        if entry < current:
            hrow[r] = entry
            lower = entry
            cuts += 1
    return cuts


@njit(cache=True)
def clip_poses(poses, x_end, h, h_top, points, normals, chunk_start, chunk_centre, chunk_radius, rows, t_min, t_max,
               radius, half_flat, rt, reach, blade_len, pitch, teeth):
    """Clip by a batch of tool positions (N, 4): x, y, z, a (rad); x_end[i] > x[i] sweeps along X.

    `h_top[sector, point]` is an upper bound of the blade's h over all rows (h only falls)."""
    cuts = 0
    for i in range(poses.shape[0]):
        cuts += _clip_at_pose(poses[i, 0], poses[i, 1], poses[i, 2], poses[i, 3], x_end[i], h, h_top, points, normals,
                              chunk_start, chunk_centre, chunk_radius, rows, t_min, t_max, radius, half_flat, rt, reach,
                              blade_len, pitch, teeth)
    return cuts


# --- Helical gears: the design of row r is the transverse design turned by twist * rows[r] ---------------------
#
# A tool pose (x, y, z, a) meets row r at dx = rows[r] - x with the row's design turned by
# a + twist * rows[r] = c0 + twist * dx (c0 = a + twist * x) into the machine frame. A move that
# follows the lead (A falls by twist * dX while X rises, Y and Z fixed) keeps c0: every row then
# sees the same tool slices at the same angles, as a function of dx alone, so one table of entries
# per blade over dx in [-R, R] serves every row (the helical counterpart of the sweep along X).


@njit(cache=True)
def _blade_entry(dx, theta, px, pz_, nx, nz_, y, z, lo, hi, radius, half_flat, rt):
    """First entry of one blade (design point p, normal n, turned by theta) into the tool slice at dx."""
    ay, az, ny, nz = _turned_blade(math.cos(theta), math.sin(theta), px, pz_, nx, nz_, y, z)
    return first_entry(dx, ay, az, ny, nz, lo, hi, radius, half_flat, rt)


@njit(cache=True)
def _clip_twisted_pose(x, y, z, a, x_end, h, h_top, points, normals, chunk_start, chunk_centre, chunk_radius,
                       rows, t_min, radius, half_flat, rt, reach, blade_len, pitch, teeth, twist, dx_step, row_first,
                       row_stop, samples, row_cos, row_sin, row_bottom, row_half_width, group_start, group_centre,
                       group_radius):
    """Clip the blades of a helical design by the tool at (x, y, z, a) or, with x_end > x, by the tool
    following the lead from x to x_end (entries sampled every dx_step over the tool's width); only the rows
    row_first <= r < row_stop. `samples` and the `row_*` arrays are work space (as long as clip_poses_twisted
    makes them). `group_*` are chunk_groups' circles around consecutive chunks, tested before their chunks."""
    if z > reach:
        return 0
    spread = abs(twist) * radius
    c0 = a + twist * x
    first, last = _sector_range(y, z, c0, spread, radius, blade_len, pitch, teeth)
    r_lo = max(np.searchsorted(rows, x - radius, side="right"), row_first)
    r_hi = min(np.searchsorted(rows, x_end + radius, side="left"), row_stop)
    if r_lo >= r_hi:
        return 0
    sweep = x_end > x
    n_samples = 0
    if sweep:
        n_samples = 2 * int(math.ceil(radius / dx_step)) + 1  # odd: dx = 0 is a sample
    cuts = 0
    if not sweep:
        # The tool's slice at row r (dx = rows[r] - x) lies in the box |u - y| <= sqrt(R^2 - dx^2), w >= z + its
        # lowest point (the corner's bottom there): computed once per pose, not per tooth space and chunk
        for r in range(r_lo, r_hi):
            dx = rows[r] - x
            corner_dx = max(abs(dx) - half_flat, 0.0)
            row_bottom[r - r_lo] = rt - math.sqrt(max(rt * rt - corner_dx * corner_dx, 0.0))
            row_half_width[r - r_lo] = math.sqrt(max(radius * radius - dx * dx, 0.0))
    for k in range(first, last + 1):
        sector = k % teeth
        theta0 = c0 + k * pitch
        c = math.cos(theta0)
        s = math.sin(theta0)
        if not sweep:  # the rows' turns for this sector, computed once, not once per blade
            for r in range(r_lo, r_hi):
                theta = theta0 + twist * (rows[r] - x)
                row_cos[r - r_lo] = math.cos(theta)
                row_sin[r - r_lo] = math.sin(theta)
        for gi in range(len(group_radius)):
            gy = group_centre[gi, 0]
            gz = group_centre[gi, 1]
            if _chunk_gap(c, s, gy, gz, y, z, half_flat, rt) > group_reach(gy, gz, group_radius[gi], spread):
                continue  # then every chunk of the group misses too (chunk_groups)
            for ci in range(group_start[gi], group_start[gi + 1]):
                py = chunk_centre[ci, 0]
                pz = chunk_centre[ci, 1]
                if _chunk_gap(c, s, py, pz, y, z, half_flat, rt) > chunk_reach(py, pz, chunk_radius[ci], spread):
                    continue
                if not sweep:
                    for r in range(r_lo, r_hi):
                        dx = rows[r] - x
                        rc = row_cos[r - r_lo]  # as _blade_entry turns the blade, with the row's cos and sin
                        rs = row_sin[r - r_lo]
                        # a chunk whose circle misses the box holding the tool's slice has no blade to clip here
                        if _chunk_gap(rc, rs, py, pz, y, z + row_bottom[r - r_lo], row_half_width[r - r_lo],
                                      0.0) > chunk_radius[ci]:
                            continue
                        for j in range(chunk_start[ci], chunk_start[ci + 1]):
                            current = h[sector, j, r]
                            ay, az, ny, nz = _turned_blade(rc, rs, points[j, 0], points[j, 1], normals[j, 0],
                                                           normals[j, 1], y, z)
                            entry = first_entry(dx, ay, az, ny, nz, t_min, min(h_top[sector, j], current), radius,
                                                half_flat, rt)
                            if entry < current:
                                h[sector, j, r] = entry
                                cuts += 1
                    continue
                for j in range(chunk_start[ci], chunk_start[ci + 1]):
                    px = points[j, 0]
                    pz_ = points[j, 1]
                    nx = normals[j, 0]
                    nz_ = normals[j, 1]
                    top = h_top[sector, j]
                    hrow = h[sector, j]
                    deepest = INF
                    for i in range(n_samples):
                        dx = -radius + 2.0 * radius * i / (n_samples - 1)
                        samples[i] = _blade_entry(dx, theta0 + twist * dx, px, pz_, nx, nz_, y, z, t_min, top,
                                                  radius, half_flat, rt)
                        if samples[i] < deepest:
                            deepest = samples[i]
                    if deepest == INF:
                        continue
                    for r in range(r_lo, r_hi):
                        lo_dx = max(rows[r] - x_end, -radius)  # the slices this row sees during the move
                        hi_dx = min(rows[r] - x, radius)
                        if lo_dx <= -radius and hi_dx >= radius:
                            entry = deepest
                        else:
                            entry = INF
                            i_lo = int(math.ceil((lo_dx + radius) / (2.0 * radius) * (n_samples - 1) - 1e-9))
                            i_hi = int(math.floor((hi_dx + radius) / (2.0 * radius) * (n_samples - 1) + 1e-9))
                            for i in range(max(i_lo, 0), min(i_hi, n_samples - 1) + 1):
                                if samples[i] < entry:
                                    entry = samples[i]
                            for dx in (lo_dx, hi_dx):  # the move's own end poses, exactly
                                e = _blade_entry(dx, theta0 + twist * dx, px, pz_, nx, nz_, y, z, t_min, top,
                                                 radius, half_flat, rt)
                                if e < entry:
                                    entry = e
                        if entry < hrow[r]:
                            hrow[r] = entry
                            cuts += 1
    return cuts


@njit(cache=True)
def chunk_groups(chunk_centre, chunk_radius):
    """Circles around CHUNK_GROUP consecutive chunks, each holding its chunks' circles: (first chunk of each group
    and one past the last, centres, radii). The distance to the tool's section (_chunk_gap) is 1-Lipschitz in the
    centre, so a group whose distance exceeds its group_reach has no chunk within its chunk_reach."""
    n_chunks = len(chunk_radius)
    n_groups = (n_chunks + CHUNK_GROUP - 1) // CHUNK_GROUP
    start = np.empty(n_groups + 1, np.int64)
    centre = np.empty((n_groups, 2))
    radius = np.empty(n_groups)
    for g in range(n_groups):
        lo = g * CHUNK_GROUP
        hi = min(lo + CHUNK_GROUP, n_chunks)
        start[g] = lo
        y_lo = min(chunk_centre[lo:hi, 0] - chunk_radius[lo:hi])
        y_hi = max(chunk_centre[lo:hi, 0] + chunk_radius[lo:hi])
        z_lo = min(chunk_centre[lo:hi, 1] - chunk_radius[lo:hi])
        z_hi = max(chunk_centre[lo:hi, 1] + chunk_radius[lo:hi])
        centre[g, 0] = 0.5 * (y_lo + y_hi)
        centre[g, 1] = 0.5 * (z_lo + z_hi)
        reach = 0.0
        for ci in range(lo, hi):
            reach = max(reach, math.hypot(chunk_centre[ci, 0] - centre[g, 0], chunk_centre[ci, 1] - centre[g, 1])
                        + chunk_radius[ci])
        radius[g] = reach * (1.0 + 1e-12) + 1e-9
    start[n_groups] = n_chunks
    return start, centre, radius


@njit(cache=True, nogil=True)
def clip_poses_twisted(poses, x_end, h, h_top, points, normals, chunk_start, chunk_centre, chunk_radius, rows, t_min,
                       radius, half_flat, rt, reach, blade_len, pitch, teeth, twist, dx_step, row_first, row_stop):
    """`clip_poses` for a helical design (row r turned by twist * rows[r], rad/mm); x_end[i] > x[i] is a move
    following the lead from x to x_end (A falling by twist * dX). Only rows row_first <= r < row_stop are
    clipped: every row is independent of the others, so threads given disjoint rows (the GIL released) give
    the same result as one thread given all."""
    cuts = 0
    samples = np.empty(2 * int(math.ceil(radius / dx_step)) + 1 if dx_step > 0.0 else 1)
    row_cos = np.empty(len(rows))
    row_sin = np.empty(len(rows))
    row_bottom = np.empty(len(rows))
    row_half_width = np.empty(len(rows))
    group_start, group_centre, group_radius = chunk_groups(chunk_centre, chunk_radius)
    for i in range(poses.shape[0]):
        cuts += _clip_twisted_pose(poses[i, 0], poses[i, 1], poses[i, 2], poses[i, 3], x_end[i], h, h_top, points,
                                   normals, chunk_start, chunk_centre, chunk_radius, rows, t_min, radius, half_flat, rt,
                                   reach, blade_len, pitch, teeth, twist, dx_step, row_first, row_stop, samples,
                                   row_cos, row_sin, row_bottom, row_half_width, group_start, group_centre,
                                   group_radius)
    return cuts
