"""An independent 2-D silhouette checker for CAM toolpaths (test-side code, no tests here).

The checker knows only the toolpath IR arrays, the tool's dimensions, shapely and the designed
gear outline; it repeats none of the generators' mathematics (no contact points, no normals).

Frame (docs/architecture.md): gear axis = X = rotary axis A; Y, Z span the transverse plane with the
rotary axis at Y = Z = 0; the tool axis is +Z and the programmed point is the centre of the tool
tip. A point fixed to the part at p (as at A = 0) is at R(A) p when A is commanded, so a machine
point (Y, Z) at angle A is the part-frame point R(-A) (Y, Z) = (Y cos A + Z sin A, -Y sin A + Z cos A).
The rotation is written out here on purpose (not imported from spur_cad.cam.ir).

Accuracy
--------
- Tool silhouette: the rounded corners are CIRCUMSCRIBED polygons (every edge is tangent to the
  true corner circle, vertices lie outside it by at most `arc_tolerance_mm`, default 1e-5 mm).
  The polygon therefore contains the true silhouette and exceeds it by at most 0.01 um: the
  checker errs toward over-reporting penetration and under-reporting leftover, both by at most
  `arc_tolerance_mm`. Straight parts (flat bottom, sides, top) are exact.
- Penetration (see `penetration_depths_mm`): for a silhouette S and the design G, the larger of
  two one-sided depths: how far a point of the tool lies inside the design (max over S∩G of the
  distance to ∂G) and how far a point of the design boundary lies inside the tool (max over ∂G∩S
  of the distance to ∂S, i.e. how far the machined surface is from that design point). This is a
  Hausdorff-style gouge depth. For smooth contacts (corner arc on a flank, flat bottom on an arc,
  two circles along their common normal) both equal the depth along the common normal; at a
  sharp design corner (the tip edge of a tooth) chopped by a flat bottom the second is the one an
  inspection would measure (the corner is gone by that much), while the first is smaller.
  Both are evaluated on vertices: silhouette vertices inside G (dense on the curved corners) and
  design vertices inside S (exact curve samples, which catches a straight tool edge: a flat bottom
  crossing a design arc or corner without any tool vertex inside G). The result is within about
  the design's chordal tolerance plus `arc_tolerance_mm` of the exact value; use a design outline
  sampled at 1e-5 mm for ~0.02 um. (The vertex maximum could miss a deeper point in the middle of
  a straight tool edge only where that edge crosses the medial axis of the design, i.e. for a
  gouge as deep as half a tooth, which the vertices report as huge anyway.)
- Poses are discrete: the union of silhouettes at the poses does not include what the tool sweeps
  between them. Use `substeps` > 1 to interpolate moves linearly in Y, Z, A (what the control does
  for a linear move with A) before checking.
- Everything is 2-D: X is ignored, so the stock is treated as infinitely long in X (conservative
  for rapids, which may legitimately pass the stock beyond its faces).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import shapely
from shapely.geometry import Polygon

from spur_cad.cam.ir import Feature, MoveKind, Toolpath
from spur_cad.geometry import GearSpec, sample_profile

ARC_TOLERANCE_MM = 1e-5
"""Largest distance of the circumscribed corner polygon from the true corner circle."""

__all__ = [
    "ARC_TOLERANCE_MM",
    "cutting_direction_ok",
    "design_boundary",
    "leftover_mm",
    "max_penetration_mm",
    "penetration_depths_mm",
    "place_silhouettes",
    "rapid_clearances_mm",
    "rapids_clear_of_circle",
    "silhouettes_in_part_frame",
    "to_part_frame",
    "tool_silhouette",
    "tool_silhouette_coords",
]


# --------------------------------------------------------------------------- tool shape


def _circumscribed_arc(centre: tuple[float, float], radius: float, start_rad: float, end_rad: float,
                       tolerance_mm: float) -> np.ndarray:
    """Vertices of a polyline circumscribing the arc from start to end (counter-clockwise).

    The first and last vertices are the exact arc ends (where the tangents continue the adjoining
    straight edges); the others are intersections of tangents at equally spaced angles, at radius
    radius / cos(step / 2), so every edge touches the circle and no vertex is further than
    `tolerance_mm` outside it.
    """
    sweep = end_rad - start_rad
    max_step = 2.0 * math.acos(radius / (radius + tolerance_mm))
    n = max(1, math.ceil(sweep / max_step))
    step = sweep / n
    angles = start_rad + step * (np.arange(n) + 0.5)
    outer = radius / math.cos(step / 2.0)
    cx, cy = centre
    middle = np.stack([cx + outer * np.cos(angles), cy + outer * np.sin(angles)], axis=-1)
    first = [cx + radius * math.cos(start_rad), cy + radius * math.sin(start_rad)]
    last = [cx + radius * math.cos(end_rad), cy + radius * math.sin(end_rad)]
    return np.vstack([first, middle, last])


def tool_silhouette_coords(diameter_mm: float, corner_radius_mm: float, length_mm: float,
                           arc_tolerance_mm: float = ARC_TOLERANCE_MM) -> np.ndarray:
    """Counter-clockwise ring (M, 2), not closed, of the tool's axial section; tip centre at the origin."""
    if not (diameter_mm > 0.0 and length_mm > 0.0):
        raise ValueError(f"tool diameter {diameter_mm} and length {length_mm} must be positive")
    r = float(corner_radius_mm)
    half = diameter_mm / 2.0
    if not 0.0 <= r <= half + 1e-12:
        raise ValueError(f"corner radius {r} must be in [0, D/2 = {half}]")
    if length_mm < r:
        raise ValueError(f"tool length {length_mm} must be at least the corner radius {r}")
    r = min(r, half)
    half_flat = half - r
    if r == 0.0:
        return np.array([[-half, 0.0], [half, 0.0], [half, length_mm], [-half, length_mm]])
    right = _circumscribed_arc((half_flat, r), r, -math.pi / 2.0, 0.0, arc_tolerance_mm)
    left = _circumscribed_arc((-half_flat, r), r, math.pi, 1.5 * math.pi, arc_tolerance_mm)
    ring = np.vstack([right, [[half, length_mm], [-half, length_mm]], left])
    # A ball's two arcs meet at the tip centre; a side of length 0 leaves duplicates: drop them.
    keep = np.ones(len(ring), bool)
    keep[1:] = np.any(np.abs(np.diff(ring, axis=0)) > 1e-12, axis=1)
    ring = ring[keep]
    if np.allclose(ring[0], ring[-1], atol=1e-12, rtol=0.0):
        ring = ring[:-1]
    return ring


def tool_silhouette(diameter_mm: float, corner_radius_mm: float, length_mm: float,
                    arc_tolerance_mm: float = ARC_TOLERANCE_MM) -> Polygon:
    """The tool's section through its axis, tip centre at the origin, axis along +Z.

    Union of the rectangle [-D/2, D/2] x [r, L], the rectangle [-d/2, d/2] x [0, r] (d = D - 2r)
    and two corner discs of radius r centred at (+-d/2, r); corners circumscribed (module doc).
    """
    return Polygon(tool_silhouette_coords(diameter_mm, corner_radius_mm, length_mm, arc_tolerance_mm))


# --------------------------------------------------------------------------- placing the tool


def to_part_frame(y: np.ndarray, z: np.ndarray, a_deg: np.ndarray) -> np.ndarray:
    """Machine (Y, Z) at rotary angle A (degrees) -> part frame: R(-A) (Y, Z). Broadcasts; (..., 2)."""
    a = np.radians(np.asarray(a_deg, float))
    c, s = np.cos(a), np.sin(a)
    y, z = np.asarray(y, float), np.asarray(z, float)
    return np.stack([y * c + z * s, -y * s + z * c], axis=-1)


def place_silhouettes(y: np.ndarray, z: np.ndarray, a_deg: np.ndarray, diameter_mm: float,
                      corner_radius_mm: float, length_mm: float,
                      arc_tolerance_mm: float = ARC_TOLERANCE_MM) -> np.ndarray:
    """Silhouettes (object array of Polygons) at machine poses (Y, Z, A), expressed in the part frame."""
    ring = tool_silhouette_coords(diameter_mm, corner_radius_mm, length_mm, arc_tolerance_mm)
    y, z, a = np.broadcast_arrays(np.atleast_1d(np.asarray(y, float)), np.atleast_1d(np.asarray(z, float)),
                                  np.atleast_1d(np.asarray(a_deg, float)))
    if y.size == 0:
        return np.empty(0, dtype=object)
    machine_y = ring[None, :, 0] + y[:, None]
    machine_z = ring[None, :, 1] + z[:, None]
    coords = to_part_frame(machine_y, machine_z, a[:, None])  # (N, M, 2)
    return shapely.polygons(coords)


def _interpolated_poses(toolpath: Toolpath, rows: np.ndarray, substeps: int,
                        include_start: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(row, Y, Z, A) of poses along the moves ending at `rows`, linear in Y, Z, A.

    t = j / substeps for j = 1..substeps (j = 0 too when include_start); row 0 has no start pose
    and contributes its end pose only.
    """
    if substeps < 1:
        raise ValueError(f"substeps must be at least 1, got {substeps}")
    rows = np.asarray(rows, int)
    j0 = 0 if include_start else 1
    t = np.arange(j0, substeps + 1) / substeps
    prev = np.maximum(rows - 1, 0)
    y0, z0, a0 = toolpath.y[prev], toolpath.z[prev], toolpath.a[prev]
    y1, z1, a1 = toolpath.y[rows], toolpath.z[rows], toolpath.a[rows]
    tt = t[None, :]
    ys = y0[:, None] + (y1 - y0)[:, None] * tt
    zs = z0[:, None] + (z1 - z0)[:, None] * tt
    as_ = a0[:, None] + (a1 - a0)[:, None] * tt
    owner = np.broadcast_to(rows[:, None], ys.shape)
    first = rows == 0
    if first.any():  # no previous pose: keep only the end pose (t = 1) of row 0
        keep = ~first[:, None] | (tt == 1.0)
    else:
        keep = np.ones(ys.shape, bool)
    return owner[keep], ys[keep], zs[keep], as_[keep]


def _selected_rows(toolpath: Toolpath, mask: np.ndarray) -> np.ndarray:
    """Row indices from a boolean mask (one entry per row) or an array of row indices."""
    mask = np.asarray(mask)
    if mask.dtype == bool:
        if mask.shape != (len(toolpath),):
            raise ValueError(f"boolean mask has shape {mask.shape}, the toolpath has {len(toolpath)} rows")
        return np.flatnonzero(mask)
    if mask.size and not np.issubdtype(mask.dtype, np.integer):
        raise TypeError(f"mask must be booleans or row indices, got dtype {mask.dtype}")
    rows = mask.astype(int).ravel()
    if rows.size and (rows.min() < 0 or rows.max() >= len(toolpath)):
        raise IndexError(f"row indices must be in [0, {len(toolpath)})")
    return rows


def silhouettes_in_part_frame(toolpath: Toolpath, diameter_mm: float, corner_radius_mm: float, length_mm: float,
                              mask: np.ndarray | None = None, *, substeps: int = 1,
                              arc_tolerance_mm: float = ARC_TOLERANCE_MM) -> list[Polygon]:
    """Tool silhouettes in the part frame at the end poses of the selected rows (default: motion rows).

    `mask` is either a boolean array with one entry per row or an array of row indices.

    With substeps > 1, each selected move is also sampled at j / substeps (j = 1..substeps) of the way
    from the previous row's pose, linearly in Y, Z, A; the list then holds substeps polygons per row
    (one for row 0), in row order.
    """
    rows = _selected_rows(toolpath, toolpath.motion_mask if mask is None else mask)
    _, y, z, a = _interpolated_poses(toolpath, rows, substeps, include_start=False)
    return list(place_silhouettes(y, z, a, diameter_mm, corner_radius_mm, length_mm, arc_tolerance_mm))


# --------------------------------------------------------------------------- penetration


def _boundary_segments(polygon: Polygon) -> np.ndarray:
    """All boundary edges of a polygon (exterior and holes) as 2-point LineStrings."""
    chunks = []
    for ring in (polygon.exterior, *polygon.interiors):
        c = np.asarray(ring.coords)
        chunks.append(np.stack([c[:-1], c[1:]], axis=1))
    return shapely.linestrings(np.concatenate(chunks))


def _boundary_vertices(polygon: Polygon) -> np.ndarray:
    chunks = [np.asarray(ring.coords)[:-1] for ring in (polygon.exterior, *polygon.interiors)]
    return np.concatenate(chunks)


def penetration_depths_mm(design_polygon: Polygon, silhouettes: Sequence[Polygon]) -> np.ndarray:
    """For each silhouette S, how deep it reaches into the design G (0 when it does not).

    depth(S) = max( max over vertices v of S strictly inside G of dist(v, ∂G),
                    max over vertices w of ∂G strictly inside S of dist(w, ∂S) ),
    a Hausdorff-style gouge depth (module doc). Use it to find the offending poses;
    max_penetration_mm is its maximum.
    """
    sils = np.asarray(list(silhouettes), dtype=object) if not isinstance(silhouettes, np.ndarray) else silhouettes
    depths = np.zeros(len(sils))
    if len(sils) == 0:
        return depths
    if not isinstance(design_polygon, Polygon):
        raise TypeError("design_polygon must be a shapely Polygon")

    # (a) silhouette vertices strictly inside the design: distance to the design boundary.
    coords, owner = shapely.get_coordinates(sils, return_index=True)
    minx, miny, maxx, maxy = design_polygon.bounds
    near = (coords[:, 0] > minx) & (coords[:, 0] < maxx) & (coords[:, 1] > miny) & (coords[:, 1] < maxy)
    coords, owner = coords[near], owner[near]
    if len(coords):
        shapely.prepare(design_polygon)
        inside = shapely.contains_xy(design_polygon, coords[:, 0], coords[:, 1])
        coords, owner = coords[inside], owner[inside]
    if len(coords):
        tree = shapely.STRtree(_boundary_segments(design_polygon))
        _, dist = tree.query_nearest(shapely.points(coords), return_distance=True, all_matches=False)
        np.maximum.at(depths, owner, dist)

    # (b) design vertices strictly inside a silhouette: distance to that silhouette's boundary.
    vertices = shapely.points(_boundary_vertices(design_polygon))
    tree = shapely.STRtree(sils)
    point_index, sil_index = tree.query(vertices, predicate="within")
    if len(point_index):
        dist = shapely.distance(vertices[point_index], shapely.get_exterior_ring(sils[sil_index]))
        np.maximum.at(depths, sil_index, dist)
    return depths


def max_penetration_mm(design_polygon: Polygon, silhouettes: Sequence[Polygon]) -> float:
    """Deepest reach of any silhouette into the designed part (0 if none); see penetration_depths_mm."""
    depths = penetration_depths_mm(design_polygon, silhouettes)
    return float(depths.max()) if len(depths) else 0.0


# --------------------------------------------------------------------------- leftover


def leftover_mm(boundary_points: np.ndarray, silhouettes: Sequence[Polygon]) -> np.ndarray:
    """For each design point (part frame), its distance to the union of the silhouettes (0 inside/touching).

    The silhouettes are unioned (shapely.union_all, GEOS's cascaded robust overlay), the union's
    boundary is cut into 2-point segments held in an STRtree, and each point's distance is an
    indexed nearest query; points strictly inside the union get 0. (Distance to a union is also the
    smallest distance to its members; querying the silhouettes directly gives the same numbers to
    1e-14 mm but is ~6x slower for thousands of overlapping tools.) Points with no silhouette at
    all get +inf.
    """
    pts = np.asarray(boundary_points, float).reshape(-1, 2)
    result = np.full(len(pts), np.inf)
    sils = np.asarray(list(silhouettes), dtype=object) if not isinstance(silhouettes, np.ndarray) else silhouettes
    if len(pts) == 0 or len(sils) == 0:
        return result
    union = shapely.union_all(sils)
    rings = shapely.get_rings(shapely.get_parts(union))
    chunks = []
    for ring in rings:
        c = shapely.get_coordinates(ring)
        chunks.append(np.stack([c[:-1], c[1:]], axis=1))
    tree = shapely.STRtree(shapely.linestrings(np.concatenate(chunks)))
    (point_index, _), dist = tree.query_nearest(shapely.points(pts), return_distance=True, all_matches=False)
    result[point_index] = dist
    shapely.prepare(union)
    result[shapely.contains_xy(union, pts[:, 0], pts[:, 1])] = 0.0
    return result


# --------------------------------------------------------------------------- design points


def design_boundary(spec: GearSpec, spaces: Sequence[int], labels: Sequence[str] = ("root", "fillet", "involute"),
                    tolerance_mm: float = 1e-4) -> tuple[np.ndarray, np.ndarray]:
    """Dense points of both halves of the given tooth spaces in the part frame, and their segment labels.

    Right half as sampled (gap frame of space 0: x -> Y, y -> Z), left half its mirror (x -> -x,
    the shared point on the symmetry axis kept once); space k turned counter-clockwise by
    k * 2 pi / z. Returns (points (N, 2), labels (N,) str array).
    """
    samples = sample_profile(spec.tooth_space_profile(), tolerance_mm)
    names = np.array(samples.label_names())
    keep = np.isin(names, list(labels))
    right = samples.points[keep]
    right_names = names[keep]
    mirrored = right * np.array([-1.0, 1.0])
    off_axis = np.abs(right[:, 0]) > 0.0
    half_pair = np.concatenate([right, mirrored[off_axis]])
    pair_names = np.concatenate([right_names, right_names[off_axis]])
    points, out_names = [], []
    for k in spaces:
        angle = 2.0 * math.pi * k / spec.teeth
        c, s = math.cos(angle), math.sin(angle)
        x, y = half_pair[:, 0], half_pair[:, 1]
        points.append(np.stack([c * x - s * y, s * x + c * y], axis=-1))
        out_names.append(pair_names)
    if not points:
        return np.zeros((0, 2)), np.zeros(0, dtype=str)
    return np.concatenate(points), np.concatenate(out_names)


# --------------------------------------------------------------------------- rapids


def rapid_clearances_mm(toolpath: Toolpath, diameter_mm: float, corner_radius_mm: float, length_mm: float,
                        radius_mm: float, substeps: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """(rapid row indices, clearance of each) from the disc of `radius_mm` about the rotary axis.

    Each rapid is interpolated from the previous row's pose linearly in Y, Z, A (t = j / substeps,
    j = 0..substeps); the clearance is the smallest distance from the axis to the silhouette minus
    the radius: positive means clear, <= 0 touching or cutting (it bottoms out at -radius when the
    silhouette covers the axis). Linear interpolation is an assumption: a control may move the axes
    of a G0 independently (dog-leg), which this does not model.
    """
    rows = np.flatnonzero(toolpath.kind == MoveKind.RAPID)
    if len(rows) == 0:
        return rows, np.zeros(0)
    owner, y, z, a = _interpolated_poses(toolpath, rows, substeps, include_start=True)
    sils = place_silhouettes(y, z, a, diameter_mm, corner_radius_mm, length_mm)
    dist = shapely.distance(shapely.points(0.0, 0.0), sils) - radius_mm
    clearance = np.full(len(toolpath), np.inf)
    np.minimum.at(clearance, owner, dist)
    return rows, clearance[rows]


def rapids_clear_of_circle(toolpath: Toolpath, diameter_mm: float, corner_radius_mm: float, length_mm: float,
                           radius_mm: float, substeps: int = 8) -> float:
    """Smallest clearance of any rapid from the stock disc (see rapid_clearances_mm); +inf without rapids."""
    _, clearance = rapid_clearances_mm(toolpath, diameter_mm, corner_radius_mm, length_mm, radius_mm, substeps)
    return float(clearance.min()) if len(clearance) else math.inf


# --------------------------------------------------------------------------- cutting direction


def cutting_direction_ok(toolpath: Toolpath, feature: Feature, *, include_start: bool = True,
                         tolerance_mm: float = 1e-9) -> list[bool]:
    """For each contiguous run of motion rows labelled `feature`: does the contact radius never increase?

    The contact point is unknown to the checker; the proxy is the radius of the tool tip centre in
    the part frame, |R(-A) (Y, Z)| (which equals hypot(Y, Z), a rotation keeps lengths). With
    include_start, the pose the run's first move starts from (the previous row) is part of the run.
    A run passes when every step changes the radius by at most +tolerance_mm.
    """
    selected = np.flatnonzero((toolpath.feature == int(feature)) & toolpath.motion_mask)
    if len(selected) == 0:
        return []
    breaks = np.flatnonzero(np.diff(selected) != 1) + 1
    radius = np.hypot(*to_part_frame(toolpath.y, toolpath.z, toolpath.a).T)
    verdicts = []
    for run in np.split(selected, breaks):
        if include_start and run[0] > 0:
            run = np.concatenate([[run[0] - 1], run])
        verdicts.append(bool(np.all(np.diff(radius[run]) <= tolerance_mm)))
    return verdicts
