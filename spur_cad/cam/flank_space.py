"""The flank roughing's geometry of one tooth space (spur_cad.cam.flank_roughing, docs/cam.md "Flank roughing"):
the design grown by the finish stock around the space, where the tool may stand at a turn and a tip height
(`SpaceGeometry.limits`), and the flank's segments, each cut with A turned so that its chord is parallel to the
tool axis (steps 1 and 2 of flank_roughing's plan). Frames as in flank_roughing's docstring: the space frame has
the space's centre line up (+Z) and the gear axis at the origin; a turn by `theta` shows the section as
R(theta) p."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from spur_cad.cam.common import offset_flank
from spur_cad.cam.machine import MachineError, RoughingParams
from spur_cad.cam.tools import Tool
from spur_cad.geometry.frames import turn_points_by
from spur_cad.geometry.sampling import full_space_points, sample_profile
from spur_cad.geometry.spec import GearSpec

HELICAL_SLICES = 201
"""Slices of the tool across X for a helical gear: the sampled reach of their union is within about
(2 R / (n - 1))^2 / (8 R) of the exact one (0.02 um for R = 1.75 mm)."""
MAX_SEGMENTS_PER_FLANK = 40
TOL_MM = 1e-9
SEGMENT_BUDGET_FRACTION = 0.9
"""Each segment leaves at most this share of flank_allowance_mm - finish_stock_mm on its flank points: where two
segments' columns meet, the material between them stands a little farther from the design than either (measured:
up to 8 % more with the whole budget)."""


@dataclass(frozen=True)
class FlankSegment:
    """One segment of the right flank and how it is cut (turned frame); the left flank's are its mirror."""

    turn_deg: float
    tip_z_mm: float
    side_y_mm: float  # tool centre at the finishing position
    far_y_mm: float  # tool centre where it meets the other flank
    leftover_mm: float  # largest material left on the segment (horizontal, offset flank)
    low_height_mm: float  # the segment's ends on the space axis (space frame), for reports
    high_height_mm: float


def _largest(geometry):
    """The largest polygon of a shapely result (a buffer of one polygon is one, unless a sliver splits off)."""
    import shapely

    parts = shapely.get_parts(geometry)
    return max(parts, key=lambda part: part.area)


@dataclass(frozen=True)
class _Slices:
    """The tool's section as slices: half-widths and the extra turn each sees (one unturned slice for spur)."""

    half_widths_mm: np.ndarray
    turns_rad: np.ndarray

    @staticmethod
    def of(spec: GearSpec, tool: Tool) -> _Slices:
        radius = tool.diameter_mm / 2.0
        twist = abs(spec.section_turn_rad(1.0))
        if twist == 0.0:
            return _Slices(np.array([radius]), np.array([0.0]))
        dx = np.linspace(-radius, radius, HELICAL_SLICES)
        return _Slices(np.sqrt(np.maximum(radius * radius - dx * dx, 0.0)), twist * dx)


class SpaceGeometry:
    """The design grown by the finish stock around one space: its boundary right of the space's centre line as a
    dense closed polyline and its mirror (for the tool's limits), the flank offset by normals (for the segments),
    and as polygons for the stock model."""

    def __init__(self, spec: GearSpec, tool: Tool, params: RoughingParams, blank_radius_mm: float):
        import shapely

        self.blank = blank_radius_mm
        samples = sample_profile(spec.tooth_space_profile(), 1e-6 * spec.module_mm)
        # The design right of the space's axis (the half space's boundary closed through the gear's axis) grown by
        # the finish stock: its boundary is the grown design exactly (round where the design has corners: the tip
        # edge; right where the normal offset would loop: an undercut's cusp), up to arcs of 256 chords per turn.
        half = shapely.Polygon(np.concatenate([samples.points, [[0.0, 0.0]]])).buffer(0.0)
        grown_half = half.buffer(params.finish_stock_mm, quad_segs=64) if params.finish_stock_mm > 0.0 else half
        ring = np.asarray(shapely.get_exterior_ring(_largest(grown_half)).coords)
        self.right = ring  # closed (its first vertex repeated last): every edge of the boundary is an edge here
        self.left = self.right * np.array([-1.0, 1.0])
        self.max_radius_mm = float(np.hypot(*self.right.T).max())
        self.flank, _, _ = offset_flank(spec, params.finish_stock_mm)
        self.slices = _Slices.of(spec, tool)
        pitch = 2.0 * math.pi / spec.teeth
        space = full_space_points(sample_profile(spec.tooth_space_profile(), 1e-4 * spec.module_mm))
        chunks = [turn_points_by(space, k * pitch) for k in (-1, 0, 1)]  # spaces -1, 0, 1: the teeth beside space 0
        ring = np.concatenate(chunks + [np.zeros((1, 2))])
        design = shapely.Polygon(ring).buffer(0.0)
        self.design = design
        grown = design.buffer(params.finish_stock_mm, quad_segs=16) if params.finish_stock_mm > 0.0 else design
        angles = np.linspace(-pitch, pitch, 129)
        wedge = shapely.Polygon(np.concatenate(
            [[[0.0, 0.0]], (blank_radius_mm + 1.0) * np.stack([np.sin(angles), np.cos(angles)], axis=1)]))
        blank = shapely.Point(0.0, 0.0).buffer(blank_radius_mm, quad_segs=512)
        self.stock = blank.intersection(wedge).difference(grown)
        self.keep = design.buffer(params.flank_allowance_mm, quad_segs=16)

    def limits(self, turn_rad: float, tip_z_mm: float, sides: str = "both") -> tuple[float, float]:
        """(largest tool-centre y short of the right side, smallest short of the left side) at this turn and tip
        height: no point of the grown design inside any slice of the tool (its boundary's vertices above the tip
        and the points where its edges cross the tip's height). `sides` "left": only the second (the first inf)."""
        right = math.inf if sides == "left" else -self._reach(self.right, turn_rad, tip_z_mm, 1.0)
        return right, self._reach(self.left, turn_rad, tip_z_mm, -1.0)

    def _reach(self, points: np.ndarray, turn_rad: float, tip_z_mm: float, sign: float) -> float:
        """-min (sign 1) or max (sign -1) over the slices of (y -/+ half-width) of the polyline's points at or
        above the tip height. The slices' extra turns move a point by at most |p| max|turn| (`shift`): only points
        within that (and a radius) of the unturned slice's extreme can decide, so only they are turned."""
        slices = self.slices
        half = slices.half_widths_mm
        radius = float(half.max())
        turned = turn_points_by(points, turn_rad)
        shift = float(np.abs(slices.turns_rad).max()) * self.max_radius_mm
        if shift == 0.0:
            low, high = _edge_reach(turned[None], tip_z_mm)
            return float(-(low[0] - radius)) if sign > 0 else float(high[0] + radius)
        y = sign * turned[:, 0]  # the side's y, toward +y
        near = turned[:, 1] >= tip_z_mm - shift - 1e-9  # above the tip in some slice
        if not near.any():
            return -math.inf
        sure = turned[:, 1] >= tip_z_mm + shift  # above it in every slice: they bound the answer
        keep = near & (y <= y[sure].min() + 2.0 * shift + radius) if sure.any() else near
        keep = keep | np.roll(keep, 1) | np.roll(keep, -1)  # the neighbours: the edges crossing the tip height
        keep[0], keep[-1] = keep[0] or keep[1], keep[-1] or keep[-2]
        index = np.flatnonzero(keep)
        subset = turn_points_by(points[index], turn_rad + slices.turns_rad)
        low, high = _edge_reach(subset, tip_z_mm, np.diff(index) == 1)
        if sign > 0:
            return float(-np.min(low - half))
        return float(np.max(high + half))


def _edge_reach(points: np.ndarray, tip_z_mm: float,
                edges: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Per slice (points (m, n, 2), a polyline each), the least and the largest y of the polyline at or above the
    height: its vertices above it and its edges' crossings of it (inf / -inf where none); `edges` (n - 1,): which
    consecutive points are joined (all by default)."""
    y, z = points[..., 0], points[..., 1]
    above = z >= tip_z_mm - 1e-12  # a vertex at the tip height touches the flat bottom
    low_y = np.where(above, y, np.inf).min(axis=1)
    high_y = np.where(above, y, -np.inf).max(axis=1)
    za, zb, ya, yb = z[:, :-1], z[:, 1:], y[:, :-1], y[:, 1:]
    crosses = (za - tip_z_mm) * (zb - tip_z_mm) < 0.0
    if edges is not None:
        crosses = crosses & edges
    t = np.where(crosses, (tip_z_mm - za) / np.where(crosses, zb - za, 1.0), 0.0)
    at = ya + t * (yb - ya)
    low_y = np.minimum(low_y, np.where(crosses, at, np.inf).min(axis=1))
    high_y = np.maximum(high_y, np.where(crosses, at, -np.inf).max(axis=1))
    return low_y, high_y


def _evaluate(geo: SpaceGeometry, i0: int, i1: int, radius: float) -> FlankSegment | None:
    """The segment of offset-flank points i0..i1 cut with its chord vertical, or turned less (where the tool does
    not fit between the flanks at that turn, or where the flank above overhangs it): of the turns tried, the one
    leaving least on the segment; None if the tool fits at none."""
    points = geo.flank[i0:i1 + 1]
    chord = points[-1] - points[0]
    full = math.atan2(chord[0], chord[1])
    best = None
    for fraction in (1.0, 0.75, 0.5, 0.25, 0.0):
        turn = full * fraction
        turned = turn_points_by(points, turn)
        tip_z = float(turned[:, 1].min())
        side, far = geo.limits(turn, tip_z)
        if far <= side + TOL_MM:
            leftover = max(float((turned[:, 0] - (side + radius)).max()), 0.0)
            if best is None or leftover < best.leftover_mm - 1e-9:
                best = FlankSegment(math.degrees(turn), tip_z, side, far, leftover, float(points[0, 1]),
                                    float(points[-1, 1]))
    return best


def flank_segments(geo: SpaceGeometry, lowest_height_mm: float, budget_mm: float, radius: float,
                   params: RoughingParams) -> list[FlankSegment]:
    """Segments of the right offset flank from the lowest level to its tip edge, each the longest whose leftover
    stays within the budget (bisection over the end point), bottom to top."""
    heights = geo.flank[:, 1]
    i0 = int(np.searchsorted(heights, lowest_height_mm)) if np.all(np.diff(heights) >= 0) else \
        int(np.argmax(heights >= lowest_height_mm))
    i0 = min(max(i0, 0), len(heights) - 2)
    last = len(heights) - 1
    segments: list[FlankSegment] = []
    while i0 < last:
        if len(segments) == MAX_SEGMENTS_PER_FLANK:
            raise MachineError(f"[roughing] flank_allowance_mm = {params.flank_allowance_mm:g} would need more than "
                               f"{MAX_SEGMENTS_PER_FLANK} flank segments per flank; raise it",
                               field="flank_allowance_mm", section="roughing")
        whole = _evaluate(geo, i0, last, radius)
        if whole is not None and whole.leftover_mm <= budget_mm:
            segments.append(whole)
            break
        lo, hi, best = i0 + 1, last, None
        while lo <= hi:
            mid = (lo + hi) // 2
            segment = _evaluate(geo, i0, mid, radius)
            if segment is not None and segment.leftover_mm <= budget_mm:
                best, lo = (mid, segment), mid + 1
            else:
                hi = mid - 1
        if best is None:
            raise MachineError(f"[roughing] flank_allowance_mm = {params.flank_allowance_mm:g}: the tool's side "
                               f"cannot rough the flank at height {heights[i0]:.3f} mm within it; raise it or "
                               "choose strategy = \"levels\"", field="flank_allowance_mm", section="roughing")
        i0 = best[0]
        segments.append(best[1])
    return segments


def flank_segment_count(spec: GearSpec, tool: Tool, params: RoughingParams, blank_radius_mm: float,
                        lowest_height_mm: float) -> int:
    """How many segments each flank is cut into (flank_segments; for a bound of the work before planning it)."""
    geo = SpaceGeometry(spec, tool, params, blank_radius_mm)
    return len(flank_segments(geo, lowest_height_mm,
                              SEGMENT_BUDGET_FRACTION * (params.flank_allowance_mm - params.finish_stock_mm),
                              tool.diameter_mm / 2.0, params))


def clean_up_segment(geo: SpaceGeometry, piece, turns_deg: list[float]) -> FlankSegment | None:
    """A single column that takes a piece of the right half the runs left (where two segments' columns meet): of
    turns between the segments', the first at which the tool, its tip at the piece's lowest point and as far toward
    the flank as the design allows, covers the piece; None if none does."""
    points = np.asarray(piece.exterior.coords)
    low, high = min(turns_deg), max(turns_deg)
    for turn_deg in sorted(np.linspace(low, high, 9), key=lambda t: abs(t - 0.5 * (low + high))):
        turned = turn_points_by(points, math.radians(turn_deg))
        tip = float(turned[:, 1].min())
        side, far = geo.limits(math.radians(turn_deg), tip)
        radius = float(geo.slices.half_widths_mm.max())
        if far <= side + TOL_MM and turned[:, 0].min() >= side - radius - 1e-9 and \
                turned[:, 0].max() <= side + radius + 1e-9:
            return FlankSegment(float(turn_deg), tip, side, far, 0.0, float(points[:, 1].min()),
                                float(points[:, 1].max()))
    return None
