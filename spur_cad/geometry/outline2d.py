"""The gear's transverse outline as exact arcs and lines, and its exact offset (docs/geometry.md).

Coordinates are the part frame's transverse plane (y, z) (`frames.py`: space 0's gap frame seen
from +X), origin on the gear axis, mm. An `Outline2D` is one closed loop with the material on its
left (counter-clockwise around a gear, clockwise around a hole), so "outward" (away from the
material) is always to the right of the direction of travel. Consumers: 2-D export (DXF, SVG), the
3-axis variant's arc toolpaths, internal gears (a ring is two loops).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from spur_cad.geometry.frames import turn_points
from spur_cad.geometry.internal import as_ring
from spur_cad.geometry.kinds import EXTERNAL_HELICAL, EXTERNAL_SPUR, INTERNAL_SPUR, GearKind
from spur_cad.geometry.profile import CircularArc, Segment
from spur_cad.geometry.sampling import segment_parameters
from spur_cad.geometry.spec import GearSpec

Point = tuple[float, float]

SNAP_MM = 1e-9
"""Ends of consecutive segments closer than this are the same point (snapped to identical floats)."""

_SAMPLE_FRACTION = 0.05  # the exact curves are sampled at this fraction of the fitting tolerance
_FIT_FRACTION = 0.9  # the biarcs must stay this fraction of the tolerance from the samples
_OFFSET_CHECK_MM = 1e-6  # an offset point closer than |d| minus this to the outline breaks it
_TRIM_SEARCH = 64  # segments searched on each side of a corner for the trimming intersection


def _right_normal(t: Point) -> Point:
    return t[1], -t[0]


@dataclass(frozen=True)
class Line2D:
    """Straight segment from start to end."""

    start_xy: Point
    end_xy: Point

    @property
    def length_mm(self) -> float:
        return math.hypot(self.end_xy[0] - self.start_xy[0], self.end_xy[1] - self.start_xy[1])

    @property
    def start_tangent(self) -> Point:
        """Unit direction of travel."""
        length = self.length_mm
        return (self.end_xy[0] - self.start_xy[0]) / length, (self.end_xy[1] - self.start_xy[1]) / length

    @property
    def end_tangent(self) -> Point:
        return self.start_tangent

    def point_at(self, t: float) -> Point:
        """The point at fraction t of the length (t = 0 start, 1 end)."""
        return (self.start_xy[0] + t * (self.end_xy[0] - self.start_xy[0]),
                self.start_xy[1] + t * (self.end_xy[1] - self.start_xy[1]))

    def reversed(self) -> Line2D:
        return Line2D(self.end_xy, self.start_xy)

    def mirrored(self) -> Line2D:
        """Mirrored in the y axis of the plane (first coordinate negated)."""
        return Line2D((-self.start_xy[0], self.start_xy[1]), (-self.end_xy[0], self.end_xy[1]))


@dataclass(frozen=True)
class Arc2D:
    """Circular arc from start to end about center; `counterclockwise` is the direction from start to end.

    start == end is a full circle.
    """

    start_xy: Point
    end_xy: Point
    center_xy: Point
    counterclockwise: bool

    @property
    def radius_mm(self) -> float:
        return math.hypot(self.start_xy[0] - self.center_xy[0], self.start_xy[1] - self.center_xy[1])

    @property
    def start_angle_rad(self) -> float:
        return math.atan2(self.start_xy[1] - self.center_xy[1], self.start_xy[0] - self.center_xy[0])

    @property
    def sweep_rad(self) -> float:
        """Signed sweep, positive counter-clockwise, 0 < |sweep| <= 2 pi."""
        a1 = math.atan2(self.end_xy[1] - self.center_xy[1], self.end_xy[0] - self.center_xy[0])
        a0 = self.start_angle_rad
        sweep = (a1 - a0) % (2.0 * math.pi) if self.counterclockwise else (a0 - a1) % (2.0 * math.pi)
        if sweep == 0.0:
            sweep = 2.0 * math.pi
        return sweep if self.counterclockwise else -sweep

    @property
    def length_mm(self) -> float:
        return self.radius_mm * abs(self.sweep_rad)

    def point_at(self, t: float) -> Point:
        """The point at fraction t of the sweep (t = 0 start, 1 end)."""
        angle = self.start_angle_rad + t * self.sweep_rad
        r = self.radius_mm
        return self.center_xy[0] + r * math.cos(angle), self.center_xy[1] + r * math.sin(angle)

    def _tangent_at(self, p: Point) -> Point:
        rx, ry = p[0] - self.center_xy[0], p[1] - self.center_xy[1]
        r = math.hypot(rx, ry)
        return (-ry / r, rx / r) if self.counterclockwise else (ry / r, -rx / r)

    @property
    def start_tangent(self) -> Point:
        return self._tangent_at(self.start_xy)

    @property
    def end_tangent(self) -> Point:
        return self._tangent_at(self.end_xy)

    def reversed(self) -> Arc2D:
        return Arc2D(self.end_xy, self.start_xy, self.center_xy, not self.counterclockwise)

    def mirrored(self) -> Arc2D:
        """Mirrored in the y axis of the plane (first coordinate negated; the direction flips)."""
        return Arc2D((-self.start_xy[0], self.start_xy[1]), (-self.end_xy[0], self.end_xy[1]),
                     (-self.center_xy[0], self.center_xy[1]), not self.counterclockwise)


Segment2D = Line2D | Arc2D


@dataclass(frozen=True)
class Outline2D:
    """One closed loop: each segment's end_xy is the next one's start_xy (identical floats), the last
    end is the first start; the material lies on the left (counter-clockwise around a gear)."""

    segments: tuple[Segment2D, ...]

    def __post_init__(self) -> None:
        if not self.segments:
            raise ValueError("an outline needs at least one segment")
        for previous, segment in zip(self.segments, self.segments[1:] + self.segments[:1]):
            if previous.end_xy != segment.start_xy:
                raise ValueError(f"outline not closed: {previous.end_xy} != {segment.start_xy}")

    def turned(self, angle_rad: float) -> Outline2D:
        """The loop turned counter-clockwise about the origin."""
        return Outline2D(tuple(_turned(s, angle_rad) for s in self.segments))


def _turn(p: Point, angle_rad: float) -> Point:
    y, z = turn_points(np.array([p], dtype=float), angle_rad)[0]
    return float(y), float(z)


def _turned(segment: Segment2D, angle_rad: float) -> Segment2D:
    if isinstance(segment, Line2D):
        return Line2D(_turn(segment.start_xy, angle_rad), _turn(segment.end_xy, angle_rad))
    return Arc2D(_turn(segment.start_xy, angle_rad), _turn(segment.end_xy, angle_rad),
                 _turn(segment.center_xy, angle_rad), segment.counterclockwise)


def closed_loop(segments: list[Segment2D]) -> Outline2D:
    """Snap each segment's start onto the previous end (gaps must be below SNAP_MM) and close the loop."""
    chain = list(closed_chain(segments))
    gap = _distance(chain[-1].end_xy, chain[0].start_xy)
    if gap > SNAP_MM:
        raise ValueError(f"gap of {gap:.3g} mm where the loop closes at {chain[0].start_xy}")
    chain[-1] = replace(chain[-1], end_xy=chain[0].start_xy)
    return Outline2D(tuple(chain))


# --- biarc fitting --------------------------------------------------------------------------------

def _arc_from_tangent(p: np.ndarray, t: np.ndarray, q: np.ndarray) -> Segment2D:
    """The arc leaving p along unit tangent t and ending at q (a line if q lies on the tangent)."""
    w = q - p
    n = np.array([-t[1], t[0]])  # left normal
    s = float(n @ w)
    ww = float(w @ w)
    if abs(s) <= 1e-13 * math.sqrt(ww) * max(1.0, math.sqrt(ww)):
        return Line2D((float(p[0]), float(p[1])), (float(q[0]), float(q[1])))
    center = p + n * (ww / (2.0 * s))
    return Arc2D((float(p[0]), float(p[1])), (float(q[0]), float(q[1])),
                 (float(center[0]), float(center[1])), s > 0.0)


def biarc(p0: np.ndarray, t0: np.ndarray, p1: np.ndarray, t1: np.ndarray) -> list[Segment2D] | None:
    """The equal-distance biarc from p0 (tangent t0) to p1 (tangent t1), or None if it does not exist."""
    v = p1 - p0
    c = 1.0 - float(t0 @ t1)
    vt = float(v @ (t0 + t1))
    vv = float(v @ v)
    denominator = vt + math.sqrt(max(vt * vt + 2.0 * c * vv, 0.0))
    if not denominator > 0.0 or vv == 0.0:
        return None
    d = vv / denominator
    q0, q1 = p0 + d * t0, p1 - d * t1
    joint = 0.5 * (q0 + q1)
    first = _arc_from_tangent(p0, t0, joint)
    second = _arc_from_tangent(p1, -t1, joint).reversed()
    return [first, second]


def distances_to_segment(points: np.ndarray, segment: Segment2D) -> np.ndarray:
    """Distance of (N, 2) points to a line segment or an arc (the nearer end where the foot is off it)."""
    s = np.asarray(segment.start_xy)
    e = np.asarray(segment.end_xy)
    end_distance = np.minimum(np.hypot(*(points - s).T), np.hypot(*(points - e).T))
    if isinstance(segment, Line2D):
        d = e - s
        length2 = float(d @ d)
        if length2 == 0.0:
            return end_distance
        u = np.clip((points - s) @ d / length2, 0.0, 1.0)
        return np.hypot(*(points - (s + u[:, None] * d)).T)
    c = np.asarray(segment.center_xy)
    rel = points - c
    angle = np.arctan2(rel[:, 1], rel[:, 0])
    a0, sweep = segment.start_angle_rad, segment.sweep_rad
    offset = (angle - a0) % (2.0 * np.pi) if sweep > 0 else (a0 - angle) % (2.0 * np.pi)
    on_arc = offset <= abs(sweep)
    radial = np.abs(np.hypot(rel[:, 0], rel[:, 1]) - segment.radius_mm)
    return np.where(on_arc, radial, end_distance)


def _hermite_midpoints(points: np.ndarray, tangents: np.ndarray) -> np.ndarray:
    """Curve estimate halfway between consecutive samples (cubic Hermite with chord-length tangents)."""
    chord = np.hypot(*np.diff(points, axis=0).T)[:, None]
    return 0.5 * (points[:-1] + points[1:]) + chord / 8.0 * (tangents[:-1] - tangents[1:])


def fit_biarcs(points_xy: np.ndarray, tangents_xy: np.ndarray, tolerance_mm: float) -> list[Segment2D]:
    """A smooth open curve given by dense samples with unit tangents -> G1 biarcs (lines where straight)
    within tolerance_mm of every sample and of the curve between samples.

    Biarcs run from sample to sample (so their joints keep the samples' exact tangents); a span that
    strays too far is halved. Between samples the curve is estimated by cubic Hermite interpolation,
    so the samples must be dense enough for that estimate (the callers sample at a small fraction
    of the tolerance).
    """
    points = np.asarray(points_xy, dtype=float)
    tangents = np.asarray(tangents_xy, dtype=float)
    if points.ndim != 2 or points.shape[1] != 2 or tangents.shape != points.shape or len(points) < 2:
        raise ValueError("fit_biarcs needs (N, 2) points and tangents with N >= 2")
    if not (math.isfinite(tolerance_mm) and tolerance_mm > 0.0):
        raise ValueError(f"tolerance must be a positive number, got {tolerance_mm}")
    midpoints = _hermite_midpoints(points, tangents)
    segments: list[Segment2D] = []
    stack = [(0, len(points) - 1)]
    while stack:
        i, j = stack.pop()
        arcs = biarc(points[i], tangents[i], points[j], tangents[j])
        if arcs is not None and j > i + 1:
            checked = np.concatenate([points[i + 1:j], midpoints[i:j]])
            error = np.minimum(distances_to_segment(checked, arcs[0]), distances_to_segment(checked, arcs[1]))
            if float(error.max()) > tolerance_mm:
                arcs = None
        elif arcs is not None:
            error = np.minimum(distances_to_segment(midpoints[i:j], arcs[0]),
                               distances_to_segment(midpoints[i:j], arcs[1]))
            if float(error.max()) > tolerance_mm:
                raise ValueError(f"samples {i} and {j} are too far apart for a tolerance of {tolerance_mm} mm")
        if arcs is None:
            if j == i + 1:
                raise ValueError(f"no biarc between samples {i} and {j}: tangents do not fit the points")
            middle = (i + j) // 2
            stack.append((middle, j))  # popped second: segments come out in order
            stack.append((i, middle))
            continue
        segments.extend(arcs)
    return segments


# --- the gear outline -----------------------------------------------------------------------------

def _fitted_segment(segment: Segment, tolerance_mm: float, roll_sign: int = 1) -> list[Segment2D]:
    """One exact profile segment (root to tip direction) as arcs and lines within tolerance_mm (`roll_sign`: the
    gear kind's; -1, a ring's segment, whose roll runs negative and whose space lies right of its direction)."""
    if isinstance(segment, CircularArc):
        a, b = segment.points(np.array([segment.start, segment.end]))
        # polar angle grows clockwise in the profile frame: start -> end is clockwise about the axis
        return [Arc2D((float(a[0]), float(a[1])), (float(b[0]), float(b[1])), (0.0, 0.0), False)]
    params = segment_parameters(segment, tolerance_mm * _SAMPLE_FRACTION)
    points = segment.points(params)
    normals = segment.normals(params)
    tangents = roll_sign * np.stack([normals[:, 1], -normals[:, 0]], axis=-1)  # root -> tip, normal into the space
    if float(np.sum(tangents[:-1] * np.diff(points, axis=0))) <= 0.0:
        raise ValueError(f"the {segment.label}'s normals do not match its direction")
    return fit_biarcs(points, tangents, tolerance_mm * _FIT_FRACTION)


def _space_segments(spec: GearSpec, tolerance_mm: float) -> list[Segment2D]:
    """Tooth space 0 counter-clockwise from the right tip corner to the next space's right tip corner."""
    profile = spec.tooth_space_profile()
    right: list[Segment2D] = []  # root -> tip, root arc half excluded
    for segment in profile.segments:
        if segment.label in ("root", "tip"):
            continue
        right.extend(_fitted_segment(segment, tolerance_mm, spec.kind.roll_sign))
    right = list(closed_chain(right))
    left = [s.mirrored() for s in right]
    down = [s.reversed() for s in reversed(right)]
    root_start = down[-1].end_xy
    root_end = left[0].start_xy
    middle: list[Segment2D] = []
    if root_start != root_end:
        middle.append(Arc2D(root_start, root_end, (0.0, 0.0), True))
    next_corner = _turn(right[-1].end_xy, 2.0 * math.pi / spec.teeth)
    tip = Arc2D(left[-1].end_xy, next_corner, (0.0, 0.0), True)
    return down + middle + left + [tip]


def closed_chain(segments: list[Segment2D]) -> tuple[Segment2D, ...]:
    """Snap each segment's start onto the previous one's end (an open chain; gaps below SNAP_MM)."""
    out = [segments[0]]
    for segment in segments[1:]:
        end = out[-1].end_xy
        gap = math.hypot(segment.start_xy[0] - end[0], segment.start_xy[1] - end[1])
        if gap > SNAP_MM:
            raise ValueError(f"gap of {gap:.3g} mm between consecutive segments at {end}")
        out.append(replace(segment, start_xy=end))
    return tuple(out)


def gear_outline_loops(spec: GearSpec, tolerance_mm: float) -> tuple[Outline2D, ...]:
    """The gear's transverse outline as the closed loops its kind has, root and tip arcs exact, involute and fillet
    by biarcs within tolerance_mm: an external gear's toothed loop (counter-clockwise, starting at space 0's right
    tip corner; space k is space 0 turned by k 360/z degrees counter-clockwise, as `sampling.gear_outline`; a
    helical gear's: the transverse section at the front face); a ring's rim circle (counter-clockwise) and toothed
    inner loop (clockwise: the material on its left)."""
    if not (math.isfinite(tolerance_mm) and tolerance_mm > 0.0):
        raise ValueError(f"tolerance must be a positive number, got {tolerance_mm}")
    loops = _OUTLINES.get(spec.kind)
    if loops is None:
        raise ValueError(f"no outline is known for a {spec.kind.name} gear (geometry/outline2d.py, _OUTLINES)")
    return loops(spec, tolerance_mm)


def gear_outline_arcs(spec: GearSpec, tolerance_mm: float) -> Outline2D:
    """The transverse outline of an external gear (all teeth) as arcs and lines: its one loop of
    `gear_outline_loops`."""
    loops = gear_outline_loops(spec, tolerance_mm)
    if len(loops) != 1:
        raise ValueError("an internal gear's outline is two loops: use internal_gear_outline_arcs")
    return loops[0]


def internal_gear_outline_arcs(spec: GearSpec, tolerance_mm: float) -> tuple[Outline2D, Outline2D]:
    """An internal gear's transverse outline: the rim circle (counter-clockwise) and the toothed inner outline
    (clockwise: the material on its left), its two loops of `gear_outline_loops`."""
    loops = gear_outline_loops(spec, tolerance_mm)
    if len(loops) != 2:
        raise ValueError("not an internal gear: use gear_outline_arcs")
    rim, teeth = loops
    return rim, teeth


def _toothed_loop(spec: GearSpec, tolerance_mm: float) -> Outline2D:
    """All teeth's spaces, counter-clockwise (an external gear's outline; a ring's inner outline reversed)."""
    space = _space_segments(spec, tolerance_mm)
    pitch = 2.0 * math.pi / spec.teeth
    segments: list[Segment2D] = []
    for k in range(spec.teeth):
        segments.extend(space if k == 0 else [_turned(s, k * pitch) for s in space])
    return closed_loop(segments)


def _external_loops(spec: GearSpec, tolerance_mm: float) -> tuple[Outline2D, ...]:
    return (_toothed_loop(spec, tolerance_mm),)


def _ring_loops(spec: GearSpec, tolerance_mm: float) -> tuple[Outline2D, ...]:
    rim_top = (0.0, as_ring(spec).rim_outer_diameter_mm / 2.0)
    rim = Outline2D((Arc2D(rim_top, rim_top, (0.0, 0.0), True),))
    teeth = _toothed_loop(spec, tolerance_mm)
    return rim, Outline2D(tuple(segment.reversed() for segment in reversed(teeth.segments)))


_OUTLINES: dict[GearKind, Callable[[GearSpec, float], tuple[Outline2D, ...]]] = {
    EXTERNAL_SPUR: _external_loops, EXTERNAL_HELICAL: _external_loops, INTERNAL_SPUR: _ring_loops}
"""Each gear kind's transverse outline loops, by the kind object."""


# --- exact offset ---------------------------------------------------------------------------------

def _offset_segment(segment: Segment2D, distance_mm: float) -> Segment2D | None:
    """Parallel line or concentric arc `distance_mm` to the right; None where an arc's radius reaches zero."""
    if isinstance(segment, Line2D):
        nx, ny = _right_normal(segment.start_tangent)
        dx, dy = nx * distance_mm, ny * distance_mm
        return Line2D((segment.start_xy[0] + dx, segment.start_xy[1] + dy),
                      (segment.end_xy[0] + dx, segment.end_xy[1] + dy))
    r = segment.radius_mm
    new_r = r + distance_mm if segment.counterclockwise else r - distance_mm
    if new_r <= SNAP_MM:
        return None
    cx, cy = segment.center_xy
    k = new_r / r
    return Arc2D((cx + (segment.start_xy[0] - cx) * k, cy + (segment.start_xy[1] - cy) * k),
                 (cx + (segment.end_xy[0] - cx) * k, cy + (segment.end_xy[1] - cy) * k),
                 segment.center_xy, segment.counterclockwise)


def _on_segment(p: Point, segment: Segment2D) -> bool:
    return float(distances_to_segment(np.array([p]), segment)[0]) <= SNAP_MM * 10


def _intersections(a: Segment2D, b: Segment2D) -> list[Point]:
    """Points where segment a meets segment b (lines and arcs, within their extents)."""
    candidates: list[Point] = []
    if isinstance(a, Line2D) and isinstance(b, Line2D):
        d1 = np.subtract(a.end_xy, a.start_xy)
        d2 = np.subtract(b.end_xy, b.start_xy)
        det = d1[0] * -d2[1] - d1[1] * -d2[0]
        if abs(det) > 1e-300:
            rhs = np.subtract(b.start_xy, a.start_xy)
            u = (rhs[0] * -d2[1] - rhs[1] * -d2[0]) / det
            candidates.append((a.start_xy[0] + u * d1[0], a.start_xy[1] + u * d1[1]))
    elif isinstance(a, Arc2D) and isinstance(b, Arc2D):
        c1, c2 = np.asarray(a.center_xy), np.asarray(b.center_xy)
        r1, r2 = a.radius_mm, b.radius_mm
        d = float(np.hypot(*(c2 - c1)))
        if d > 0.0 and abs(r1 - r2) <= d <= r1 + r2:
            along = (d * d + r1 * r1 - r2 * r2) / (2.0 * d)
            h = math.sqrt(max(r1 * r1 - along * along, 0.0))
            u = (c2 - c1) / d
            base = c1 + along * u
            for sign in (1.0, -1.0):
                candidates.append((float(base[0] - sign * h * u[1]), float(base[1] + sign * h * u[0])))
    else:
        line, arc = (a, b) if isinstance(a, Line2D) else (b, a)
        assert isinstance(line, Line2D) and isinstance(arc, Arc2D)  # one of each, as the caller pairs them
        s = np.asarray(line.start_xy)
        direction = np.subtract(line.end_xy, line.start_xy)
        f = s - np.asarray(arc.center_xy)
        qa, qb, qc = float(direction @ direction), 2.0 * float(f @ direction), float(f @ f) - arc.radius_mm ** 2
        disc = qb * qb - 4.0 * qa * qc
        if qa > 0.0 and disc >= 0.0:
            for sign in (1.0, -1.0):
                u = (-qb + sign * math.sqrt(disc)) / (2.0 * qa)
                candidates.append((float(s[0] + u * direction[0]), float(s[1] + u * direction[1])))
    return [p for p in candidates if _on_segment(p, a) and _on_segment(p, b)]


def _trimmed(segment: Segment2D, start: Point | None = None, end: Point | None = None) -> Segment2D:
    return replace(segment, start_xy=start if start is not None else segment.start_xy,
                   end_xy=end if end is not None else segment.end_xy)


def _distance(p: Point, q: Point) -> float:
    return math.hypot(p[0] - q[0], p[1] - q[1])


def _trim_corner(chain: list[Segment2D], following: list[Segment2D]) -> tuple[int, int, Point]:
    """Where the offset chain before a corner first meets the one after it: (segments dropped at the end
    of `chain`, segments dropped at the start of `following`, the meeting point); fewest dropped first."""
    limit_back, limit_forward = min(_TRIM_SEARCH, len(chain)), min(_TRIM_SEARCH, len(following))
    for total in range(limit_back + limit_forward - 1):
        for back in range(max(0, total - limit_forward + 1), min(total, limit_back - 1) + 1):
            forward = total - back
            a, b = chain[-1 - back], following[forward]
            points = _intersections(a, b)
            if points:
                best = min(points, key=lambda p: _distance(p, a.end_xy) + _distance(p, b.start_xy))
                return back, forward, best
    raise ValueError("the offset breaks the outline: the curves on either side of a corner do not meet")


def offset_outline(outline: Outline2D, distance_mm: float) -> Outline2D:
    """Exact offset: positive = outward (away from the material). Lines to parallel lines, arcs to
    concentric arcs; corners closed (arc around a convex corner, trim at a concave one); an arc whose
    radius would reach zero is removed; raises ValueError where the offset breaks the outline.

    "Breaks" means a part of the result comes closer than |distance_mm| to the outline (the offset
    of one part runs into another, e.g. a tooth space narrower than twice the distance), or a trim
    finds no intersection within reach.
    """
    if not math.isfinite(distance_mm):
        raise ValueError(f"offset distance must be a finite number, got {distance_mm}")
    if distance_mm == 0.0:
        return outline
    originals = outline.segments
    items = [(i, s) for i, s in ((i, _offset_segment(o, distance_mm)) for i, o in enumerate(originals))
             if s is not None]
    if not items:
        raise ValueError(f"an offset of {distance_mm:g} mm removes the whole outline")
    m = len(items)
    joins = [_join_kind(originals, items[k], items[(k + 1) % m], distance_mm) for k in range(m)]
    # Start after a join that needs no trim, so that the loop closes without one.
    first = next((k + 1 for k in range(m) if joins[k] != "trim"), 0) % m
    items, joins = items[first:] + items[:first], joins[first:] + joins[:first]
    out: list[Segment2D] = [items[0][1]]
    p = 1
    while p < m:
        kind, following = joins[p - 1], items[p][1]
        if kind == "snap":
            out.append(_trimmed(following, start=out[-1].end_xy))
        elif kind == "arc":
            out.append(Arc2D(out[-1].end_xy, following.start_xy, originals[items[p - 1][0]].end_xy,
                             distance_mm > 0.0))
            out.append(following)
        else:
            ahead = [s for _, s in items[p:p + _TRIM_SEARCH]]
            back, forward, point = _trim_corner(out, ahead)
            del out[len(out) - back:]
            out[-1] = _trimmed(out[-1], end=point)
            out.append(_trimmed(ahead[forward], start=point))
            p += forward
        p += 1
    if joins[-1] == "arc":
        out.append(Arc2D(out[-1].end_xy, out[0].start_xy, originals[items[-1][0]].end_xy, distance_mm > 0.0))
    elif joins[-1] == "trim":
        raise ValueError("the offset breaks the outline: every corner needs trimming")
    out = [s for s in out if _distance(s.start_xy, s.end_xy) > SNAP_MM or _is_full_circle(s)]
    result = closed_loop(out)
    _check_offset(outline, result, distance_mm)
    return result


def _is_full_circle(segment: Segment2D) -> bool:
    return isinstance(segment, Arc2D) and segment.start_xy == segment.end_xy


def _join_kind(originals: tuple[Segment2D, ...], item: tuple[int, Segment2D], following: tuple[int, Segment2D],
               distance_mm: float) -> str:
    """How the offsets of two consecutive kept segments meet: "snap" (already), "arc" (around a convex
    corner, seen from the offset's side), or "trim" (they overlap: concave corner or removed arcs between)."""
    (i, a), (j, b) = item, following
    n = len(originals)
    if (i + 1) % n != j:
        return "trim"
    if _distance(a.end_xy, b.start_xy) <= SNAP_MM:
        return "snap"
    turn = _cross(originals[i].end_tangent, originals[j].start_tangent)
    return "arc" if turn * distance_mm > 0.0 else "trim"


def _cross(a: Point, b: Point) -> float:
    return a[0] * b[1] - a[1] * b[0]


def _check_offset(outline: Outline2D, offset: Outline2D, distance_mm: float) -> None:
    """Every offset segment's ends and middle lie |distance_mm| or further from the whole outline."""
    probes = np.array([p for s in offset.segments for p in (s.start_xy, s.point_at(0.5))])
    nearest = np.full(len(probes), np.inf)
    for segment in outline.segments:
        nearest = np.minimum(nearest, distances_to_segment(probes, segment))
    short = nearest < abs(distance_mm) - _OFFSET_CHECK_MM
    if short.any():
        y, z = probes[int(np.argmax(short))]
        raise ValueError(f"an offset of {distance_mm:g} mm breaks the outline near ({y:.4f}, {z:.4f}) mm: "
                         f"it comes within {float(nearest[short].min()):.4f} mm of the outline")
