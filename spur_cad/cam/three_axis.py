"""The 3-axis variant ([machine] axes = 3, docs/cam.md): the blank clamped flat, the gear axis = machine Z, Z0 on
the blank's top face, the outline cut by the end mill's side.

Machine frame: X, Y = the part frame's transverse (y, z) of frames.py (tooth space 0 on +Y), the origin on the
gear axis; Z up, 0 on the top face, the bottom face at -face width. A spur gear's outline is symmetric, so which
face is up does not matter.

- Roughing: concentric passes around the gear at the roughing tool's centre, offsets (shapely buffers of the
  exact outline sampled within a micrometre) from the blank inward, `step_over_fraction` x D apart, down to
  `finish_stock_mm` from the outline; levels at most `max_level_depth_fraction` x D deep (the slot depth
  [roughing] allows: a pass may be engaged as a slot where the spaces are narrow), down to the face width plus
  the break-through. Climb (clockwise around the gear). A pass is entered from the previous one by a straight
  move to its nearest point (never into the next offset), each level from outside the blank.
- Finishing: the exact outline as arcs (outline2d.gear_outline_arcs, biarcs within the chordal tolerance)
  offset by the tool radius (offset_outline), climb (clockwise), at step-downs of at most one tool diameter to
  the face width plus the break-through; each step enters and leaves on a quarter arc tangent to the middle of
  a tip, outside the material.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from spur_cad.cam.ir import MoveKind, Operation, Toolpath, ToolpathBuilder
from spur_cad.cam.machine import Machine, MachineError, RoughingParams
from spur_cad.cam.setups import LYING_FLAT
from spur_cad.cam.three_axis_root import (
    FlatMillRoot,
    RootThickness,
    check_flat_mill_root,
    largest_flat_mill_radius_mm,
)
from spur_cad.cam.three_axis_tabs import (
    TabBand,
    ThreeAxisSection,
    cut_depth_mm,
    split_at_bands,
    tab_bands,
    tab_top_mm,
)
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.geometry.outline2d import Arc2D, Line2D, Outline2D, Segment2D, gear_outline_arcs, offset_outline
from spur_cad.geometry.sampling import gear_outline
from spur_cad.geometry.spec import GearSpec

BREAK_THROUGH_MM = 0.5
"""How far below the bottom face (Z = -face width) the last pass goes, so no skin is left; the blank sits on a
fixture or sacrificial plate relieved under the outline (docs/shop-floor.md)."""
FINISH_STEP_DOWN_DIAMETERS = 1.0
"""Largest finishing step-down, x D (the side of a small end mill cutting the finish stock)."""
ROUGHING_OUTLINE_TOLERANCE_MM = 0.001
"""Chordal tolerance of the outline roughing offsets (shapely polygons)."""
ROUGHING_ARC_SEGMENTS = 16
"""Segments per quarter circle of a roughing offset's corner arcs (shapely quad_segs; its chords cut into the
finish stock by at most r (1 - cos(pi / 64)), 0.12 % of the offset)."""


@dataclass(frozen=True)
class ThreeAxisFacts:
    """What the 3-axis plan decided besides its toolpaths (summary, program headers)."""

    root: FlatMillRoot  # the root the finishing tool leaves
    finishing_levels_mm: tuple[float, ...]  # Z of the finishing step-downs
    roughing_levels_mm: tuple[float, ...]  # Z of the roughing levels
    roughing_offsets_mm: tuple[float, ...]  # tool-centre offsets of the roughing passes from the outline
    arcs_per_level: int  # arcs (and lines) of one finishing loop


def check_three_axis(spec: GearSpec, finishing_tool: Tool | None, roughing_tool: Tool | None) -> FlatMillRoot | None:
    """Refuse what the 3-axis variant cannot cut: a helical gear (at [machine] axes), a finishing tool that is not
    a flat end mill, one whose root leaves the involute above the active profile's start (naming the largest
    radius that works); the root the finishing tool leaves (None without one)."""
    if not LYING_FLAT.cuts(spec.kind):
        raise MachineError(f"[machine] axes = 3 cuts spur gears only (helix_angle_deg = {spec.helix_angle_deg:g}: a "
                           "helical gear needs the rotary table, axes = 4)", field="axes", section="machine")
    for role, tool in (("roughing", roughing_tool), ("finishing", finishing_tool)):
        if tool is not None and not LYING_FLAT.accepts_tool_kind(tool.kind):
            raise ToolError(f"[machine] axes = 3 cuts with the side of a flat end mill: the {role} tool is "
                            f"{tool.kind}", field="kind", section=f"tools.{role}")
    if finishing_tool is None:
        return None
    return check_flat_mill_root(spec, finishing_tool)  # a ring's spaces open outward: three_axis_root.SPACES


def flat_tool_recommendations(spec: GearSpec, clearance_mm: float, roughing_max_diameter_mm: float):
    """The tool limits of a gear cut lying flat (summary.json's `tools`): the side cuts, so no flat width, corner,
    plunge allowance or generating tool; the finishing flat end mill up to the root analysis's largest; the flutes
    through the face width and the break-through."""
    from spur_cad.cam.recommend import ToolRecommendations

    flute = spec.face_width_mm + BREAK_THROUGH_MM
    return ToolRecommendations(0.0, 0.0, 0.0, roughing_max_diameter_mm, flute, flute + clearance_mm, 0.0,
                               2.0 * largest_flat_mill_radius_mm(spec))


def _levels(depth_mm: float, step_mm: float) -> list[float]:
    """Z of equal step-downs from 0 to -depth_mm, each at most step_mm."""
    n = max(1, math.ceil(depth_mm / step_mm - 1e-9))
    return [-depth_mm * (k + 1) / n for k in range(n)]


def _climb(outline: Outline2D) -> list[Segment2D]:
    """The loop clockwise around the material (climb milling with the spindle turning clockwise, M3)."""
    return [s.reversed() for s in reversed(outline.segments)]


def _entry_split(loop: list[Segment2D], bands: tuple[TabBand, ...] = ()) -> list[Segment2D]:
    """The loop started at the middle of its longest arc about the gear axis (a tip: convex, outside) that holds
    no tab."""
    tips = [i for i, s in enumerate(loop) if isinstance(s, Arc2D) and s.center_xy == (0.0, 0.0)
            and not s.counterclockwise and not any(band.holds(s.point_at(0.5)) for band in bands)]
    if not tips:
        raise MachineError("the finishing outline has no tip arc to enter on", field="axes", section="machine")
    i = max(tips, key=lambda k: loop[k].length_mm)
    arc = loop[i]
    assert isinstance(arc, Arc2D)  # i is one of the tip arcs found above
    middle = arc.point_at(0.5)
    first, second = Arc2D(arc.start_xy, middle, arc.center_xy, False), Arc2D(middle, arc.end_xy, arc.center_xy, False)
    return [second, *loop[i + 1:], *loop[:i], first]


def _lead_arcs(entry: tuple[float, float], tangent: tuple[float, float], radius_mm: float):
    """(lead-in start, lead-out end, centre, lead-in counterclockwise): quarter arcs tangent to the path at `entry`
    (running along `tangent`), on the side away from the gear axis."""
    ex, ey = entry
    r = math.hypot(ex, ey)
    nx, ny = ex / r, ey / r  # outward
    cx, cy = ex + radius_mm * nx, ey + radius_mm * ny
    tx, ty = tangent
    start = (cx - radius_mm * tx, cy - radius_mm * ty)
    end = (cx + radius_mm * tx, cy + radius_mm * ty)
    counterclockwise = (-(ey - cy)) * tx + (ex - cx) * ty > 0.0  # the ccw tangent at entry runs along `tangent`
    return start, end, (cx, cy), counterclockwise


def _add_segment(builder: ToolpathBuilder, segment: Segment2D, z: float, feed: float, station: int) -> None:
    x, y = segment.end_xy
    if isinstance(segment, Line2D):
        builder.move(MoveKind.LINEAR, x, y, z, 0.0, feed, station=station)
    else:
        builder.arc(not segment.counterclockwise, x, y, z, segment.center_xy[0], segment.center_xy[1], feed,
                    station=station)


ENGAGEMENT_SPACING_MM = 0.01
"""Spacing of the finishing loop's points whose radial engagement is measured."""


@dataclass(frozen=True)
class FinishingEngagement:
    """How wide the finishing tool cuts into what roughing leaves, and the step-down that allows."""

    max_radial_fraction: float  # largest radial engagement a_e / D along the loop (1: a full slot)
    step_down_mm: float  # the finishing step-down chosen
    limited: bool  # the step-down was cut to the slot depth [roughing] allows (the tool engages wider than a flank
    #                pass may: max_radial_engagement_fraction)


def finishing_loop(spec: GearSpec, tool: Tool, tolerance_mm: float,
                   bands: tuple[TabBand, ...] = ()) -> list[Segment2D]:
    """The finishing tool centre's loop: the outline's arcs offset by the tool radius, climb, from the middle of a
    tip without a tab."""
    return _entry_split(_climb(offset_outline(gear_outline_arcs(spec, tolerance_mm), tool.diameter_mm / 2.0)),
                        bands)


def _add_held(builder: ToolpathBuilder, pieces: list[tuple[Segment2D, bool]], z: float, tab_top: float,
              feed: float, station: int) -> None:
    """The pieces at Z `z`, those in a tab's band at the tab's top (risen to and come down from vertically)."""
    here = z
    for piece, held in pieces:
        target = max(z, tab_top) if held else z
        if target != here:
            builder.move(MoveKind.LINEAR, *piece.start_xy, target, 0.0, feed, station=station)
            here = target
        _add_segment(builder, piece, target, feed, station)
    if here != z:
        builder.move(MoveKind.LINEAR, *pieces[-1][0].end_xy, z, 0.0, feed, station=station)


def roughing_leaves(spec: GearSpec, roughing_tool: Tool, innermost_offset_mm: float):
    """The section roughing leaves at every level (shapely polygon): what its innermost pass's tool circles (centre
    `innermost_offset_mm` from the outline) do not reach."""
    from shapely.geometry import Polygon

    gear = Polygon(gear_outline(spec, ROUGHING_OUTLINE_TOLERANCE_MM))
    ring = gear.buffer(innermost_offset_mm, quad_segs=ROUGHING_ARC_SEGMENTS)
    return ring.buffer(-roughing_tool.diameter_mm / 2.0, quad_segs=4 * ROUGHING_ARC_SEGMENTS)


def finishing_engagement(loop: list[Segment2D], tool: Tool, material, params: RoughingParams) -> FinishingEngagement:
    """The radial engagement of the finishing loop in `material` (what roughing leaves): at each point a_e = r + the
    depth of the tool centre inside the material (negative outside), from 0 to D (a full slot). A loop engaged wider
    than `max_radial_engagement_fraction` x D is a pass deeper than a slot, which [roughing] limits to
    `max_level_depth_fraction` x D; the finishing step-down is cut to that (else one tool diameter)."""
    import shapely

    radius = tool.diameter_mm / 2.0
    points = np.concatenate([[segment.point_at(t) for t in np.linspace(0.0, 1.0, max(2, math.ceil(
        segment.length_mm / ENGAGEMENT_SPACING_MM) + 1))] for segment in loop])
    depth = shapely.distance(material.boundary, shapely.points(points))
    inside = shapely.contains_xy(material, points[:, 0], points[:, 1])
    engaged = np.clip(radius + np.where(inside, depth, -depth), 0.0, tool.diameter_mm)
    fraction = float(engaged.max()) / tool.diameter_mm
    limited = fraction > params.max_radial_engagement_fraction + 1e-9
    step = (params.max_level_depth_fraction if limited else FINISH_STEP_DOWN_DIAMETERS) * tool.diameter_mm
    return FinishingEngagement(fraction, min(step, FINISH_STEP_DOWN_DIAMETERS * tool.diameter_mm), limited)


def finishing_toolpath(spec: GearSpec, tool: Tool, machine: Machine, tolerance_mm: float, blank_radius_mm: float,
                       step_down_mm: float | None = None,
                       holding: ThreeAxisSection | None = None) -> tuple[Toolpath, list[float], int]:
    """The finishing program (see the module docstring): (toolpath, Z levels, segments per loop); step-downs of at
    most `step_down_mm` (default one tool diameter); `holding`: tabs or an onion skin (three_axis_tabs)."""
    radius = tool.diameter_mm / 2.0
    holding = holding or ThreeAxisSection()
    bands = tuple(tab_bands(spec, holding, radius))
    loop = finishing_loop(spec, tool, tolerance_mm, bands)
    pieces = split_at_bands(loop, list(bands))
    tab_top = tab_top_mm(spec, holding)
    lead = max(radius, 0.5)
    start, end, centre, ccw = _lead_arcs(loop[0].start_xy, loop[0].start_tangent, lead)
    feed, safe_z = tool.feed_mm_min(machine), machine.clearance_mm
    step = FINISH_STEP_DOWN_DIAMETERS * tool.diameter_mm if step_down_mm is None else step_down_mm
    levels = _levels(cut_depth_mm(spec, holding, BREAK_THROUGH_MM), step)
    builder = ToolpathBuilder(Operation.FINISHING, tool.tool_number, tool.spindle_rpm(machine))
    for index, z in enumerate(levels):
        builder.move(MoveKind.RAPID, start[0], start[1], safe_z, 0.0)
        builder.move(MoveKind.LINEAR, start[0], start[1], z, 0.0, feed / 2.0, station=index)
        builder.arc(not ccw, loop[0].start_xy[0], loop[0].start_xy[1], z, centre[0], centre[1], feed, station=index)
        if bands and z < tab_top:
            _add_held(builder, pieces, z, tab_top, feed, index)
        else:
            for segment in loop:
                _add_segment(builder, segment, z, feed, index)
        builder.arc(not ccw, end[0], end[1], z, centre[0], centre[1], feed, station=index)
        builder.move(MoveKind.RAPID, end[0], end[1], safe_z, 0.0)
    return builder.build(), levels, len(loop)


def roughing_toolpath(spec: GearSpec, tool: Tool, machine: Machine, params: RoughingParams, blank_radius_mm: float,
                      holding: ThreeAxisSection | None = None) -> tuple[Toolpath, list[float], list[float]]:
    """The roughing program (see the module docstring): (toolpath, Z levels, tool-centre offsets outermost first);
    `holding`: tabs or an onion skin (three_axis_tabs)."""
    from shapely.geometry import Point, Polygon
    from shapely.geometry.polygon import orient

    radius = tool.diameter_mm / 2.0
    gear = Polygon(gear_outline(spec, ROUGHING_OUTLINE_TOLERANCE_MM))
    innermost = radius + params.finish_stock_mm
    blank = Point(0.0, 0.0).buffer(blank_radius_mm, quad_segs=256).exterior
    farthest = max(gear.exterior.distance(Point(p)) for p in blank.coords)  # from the blank's edge to the gear
    step = params.step_over_fraction * tool.diameter_mm
    count = max(0, math.ceil((farthest + radius - step - innermost) / step))
    offsets = [innermost + k * step for k in range(count, -1, -1)]
    rings = []
    for offset in offsets:
        shape = orient(gear.buffer(offset, quad_segs=ROUGHING_ARC_SEGMENTS), sign=-1.0)  # exterior clockwise
        shapes = getattr(shape, "geoms", [shape])
        if len(shapes) != 1 or len(shapes[0].interiors):
            raise MachineError(f"3-axis roughing: the offset {offset:.3f} mm around the gear encloses a pocket the "
                               "tool would have to plunge into; use a smaller roughing tool",
                               field="diameter_mm", section="tools.roughing")
        rings.append((offset, shapes[0].exterior))
    feed, safe_z = tool.feed_mm_min(machine), machine.clearance_mm
    holding = holding or ThreeAxisSection()
    bands, tab_top = tab_bands(spec, holding, radius), tab_top_mm(spec, holding)
    levels = _levels(cut_depth_mm(spec, holding, BREAK_THROUGH_MM), params.max_level_depth_fraction * tool.diameter_mm)
    outside = blank_radius_mm + radius + machine.clearance_mm
    builder = ToolpathBuilder(Operation.ROUGHING, tool.tool_number, tool.spindle_rpm(machine))
    for index, z in enumerate(levels):
        if bands and z < tab_top:
            _roughing_level_with_tabs(builder, rings, z, tab_top, bands, outside, feed, safe_z, index,
                                      machine.clearance_mm)
            continue
        here: np.ndarray | None = None
        for _, ring in rings:
            coords = np.asarray(ring.coords)[:-1]
            if here is None:  # the level starts outside the blank, on the ray through the first ring's nearest point
                first = coords[int(np.argmax(np.hypot(coords[:, 0], coords[:, 1])))]
                away = first / np.hypot(*first) * max(outside, float(np.hypot(*first)) + machine.clearance_mm)
                builder.move(MoveKind.RAPID, float(away[0]), float(away[1]), safe_z, 0.0)
                builder.move(MoveKind.LINEAR, float(away[0]), float(away[1]), z, 0.0, feed / 2.0, station=index)
                here = away
                start = int(np.argmax(np.hypot(coords[:, 0], coords[:, 1])))
                ordered = np.concatenate([coords[start:], coords[:start + 1]])
            else:  # from the previous ring's end straight to this ring's nearest point (the segment between stays
                ordered = _started_at_nearest(coords, here)  # outside this ring's offset: it meets it only there)
            for x, y in ordered:
                builder.move(MoveKind.LINEAR, float(x), float(y), z, 0.0, feed, station=index)
            here = ordered[-1]
        if here is not None:
            builder.move(MoveKind.RAPID, float(here[0]), float(here[1]), safe_z, 0.0)
    return builder.build(), levels, offsets


def _roughing_level_with_tabs(builder: ToolpathBuilder, rings: list, z: float, tab_top: float, bands: list[TabBand],
                              outside: float, feed: float, safe_z: float, index: int, clearance_mm: float) -> None:
    """One roughing level below the tabs' top: the same passes as without tabs (entered the same way), the lines
    in a tab's band at the tab's top."""
    points: list[np.ndarray] = []
    for _, ring in rings:
        coords = np.asarray(ring.coords)[:-1]
        if not points:
            start = int(np.argmax(np.hypot(coords[:, 0], coords[:, 1])))
            first = coords[start]
            away = first / np.hypot(*first) * max(outside, float(np.hypot(*first)) + clearance_mm)
            points = [away, *np.concatenate([coords[start:], coords[:start + 1]])]
        else:
            points.extend(_started_at_nearest(coords, points[-1]))
    builder.move(MoveKind.RAPID, float(points[0][0]), float(points[0][1]), safe_z, 0.0)
    builder.move(MoveKind.LINEAR, float(points[0][0]), float(points[0][1]), z, 0.0, feed / 2.0, station=index)
    lines = [Line2D((float(a[0]), float(a[1])), (float(b[0]), float(b[1]))) for a, b in zip(points[:-1], points[1:])
             if (a[0], a[1]) != (b[0], b[1])]
    pieces = split_at_bands(list[Segment2D](lines), bands)
    _add_held(builder, pieces, z, tab_top, feed, index)
    builder.move(MoveKind.RAPID, float(points[-1][0]), float(points[-1][1]), safe_z, 0.0)


def _started_at_nearest(coords: np.ndarray, point: np.ndarray) -> np.ndarray:
    """The closed polyline `coords` (first point not repeated) started and ended at its point nearest `point`."""
    a, b = coords, np.roll(coords, -1, axis=0)
    d = b - a
    t = np.clip(np.einsum("ij,ij->i", point - a, d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300), 0.0, 1.0)
    feet = a + t[:, None] * d
    i = int(np.argmin(np.hypot(*(feet - point).T)))
    return np.concatenate([[feet[i]], coords[i + 1:], coords[:i + 1], [feet[i]]])


@dataclass(frozen=True)
class ThreeAxisFinishingFacts:
    """The finishing facts of the 3-axis variant (FinishingResult.facts: summary and report)."""

    tool_radius_mm: float
    form_diameter_mm: float  # where the tool's contour leaves the involute
    rack_form_diameter_mm: float  # the rack-generated involute's start
    active_start_diameter_mm: float  # the active profile's start (mesh with the basic rack)
    root_fillet_radius_mm: float  # the smallest concave radius the root is left with
    step_downs: int
    segments_per_loop: int  # arcs and lines of one finishing loop
    arcs_per_loop: int
    root_thickness: RootThickness  # the tooth's chord at the root form circle and mid-fillet, cut vs rack-generated
    engagement: FinishingEngagement | None = None  # against what roughing leaves (None without roughing)
    generated_by: str = "rack"  # what generates the reference profile: the basic "rack", a ring's shaper "cutter"

    def report_text(self) -> str:
        t, generated = self.root_thickness, f"{self.generated_by}-generated"
        return (f"Finishing (3 axes): the outline as {self.arcs_per_loop} arcs and "
                f"{self.segments_per_loop - self.arcs_per_loop} lines per loop, offset by the tool radius "
                f"{self.tool_radius_mm:g} mm, in {self.step_downs} step-downs (climb). The tool's side leaves the "
                f"involute at diameter {self.form_diameter_mm:.3f} mm ({generated} {self.rack_form_diameter_mm:.3f}"
                f" mm, active profile from {self.active_start_diameter_mm:.3f} mm) and a root fillet of "
                f"{self.root_fillet_radius_mm:.3f} mm radius at least. Root thickness (tooth chord): "
                f"{t.form_thickness_mm:.4f} mm at the root form diameter {t.form_diameter_mm:.3f} mm ({generated} "
                f"{t.rack_form_thickness_mm:.4f} mm), {t.fillet_thickness_mm:.4f} mm at diameter "
                f"{t.fillet_diameter_mm:.3f} mm, the fillet's middle ({generated} "
                f"{t.rack_fillet_thickness_mm:.4f} mm).{self._engagement_text()}")

    def _engagement_text(self) -> str:
        e = self.engagement
        if e is None:
            return ""
        text = (f" Its radial engagement in what roughing leaves reaches {100 * e.max_radial_fraction:.0f} % of D, "
                f"step-down {e.step_down_mm:.3f} mm")
        return text + (" (the slot depth [roughing] max_level_depth_fraction allows: roughing cannot reach the root)."
                       if e.limited else ".")

