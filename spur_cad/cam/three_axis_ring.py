"""Internal gears (rings) in the 3-axis variant ([machine] axes = 3, [gear] internal = true; docs/cam.md).

The ring lies flat, clamped on its rim (the rim's outside is not cut), Z0 on the top face, XY origin on its axis.
Only the hole is cut: the machine frame is three_axis.py's.

- Roughing clears the hole from the centre out: a solid blank ([stock] inner_diameter_mm = 0) is entered by a
  helix at the centre (HELIX_RAMP_DEG), a blank with a bore by a plunge in the bore's air; then concentric
  passes at the tool centre, offsets of the ring's toothed inner outline toward the axis (shapely buffers of the
  exact outline sampled within a micrometre) `step_over_fraction` x D apart, from the centre out, the last one
  `finish_stock_mm` from the outline (into the tooth spaces as far as the tool fits). Levels of at most
  `max_level_depth_fraction` x D down to the face width plus the break-through. Climb: counterclockwise (the
  material on the right of the travel).
- Finishing: the toothed inner outline as arcs (outline2d.internal_gear_outline_arcs) offset by the tool radius
  into the hole, climb (counterclockwise), step-downs as for an external gear; each step enters and leaves on a
  quarter arc tangent to the middle of a tip, in the hole (air).
- The root: a flat end mill's side leaves a fillet of its radius at least in the spaces' outer ends; the form
  radius that results (three_axis_root.flat_mill_root) must reach out to the active profile's start, set by the
  mating pinion's tips when [gear] mating_pinion_teeth is given, else by the shaper cutter's mesh
  (three_axis_root.ring_active_profile_start).
"""

from __future__ import annotations

import math

import numpy as np

from spur_cad.cam.ir import MoveKind, Operation, Toolpath, ToolpathBuilder
from spur_cad.cam.machine import Machine, MachineError, RoughingParams
from spur_cad.cam.three_axis import (
    BREAK_THROUGH_MM,
    FINISH_STEP_DOWN_DIAMETERS,
    ROUGHING_ARC_SEGMENTS,
    ROUGHING_OUTLINE_TOLERANCE_MM,
    _add_segment,
    _climb,
    _levels,
    _started_at_nearest,
    flat_tool_recommendations,
)
from spur_cad.cam.tools import Tool
from spur_cad.geometry.internal import as_ring
from spur_cad.geometry.outline2d import Arc2D, Segment2D, internal_gear_outline_arcs, offset_outline
from spur_cad.geometry.sampling import gear_outline
from spur_cad.geometry.spec import GearSpec

HELIX_RAMP_DEG = 3.0
"""Ramp angle of the roughing helix that enters a solid blank at its centre (a slot of the tool's full width
going down gently: the side cuts, the bottom only the ramp's chip)."""
HELIX_RADIUS_FRACTION = 0.5
"""The entry helix's radius x the tool radius: the helix bores a hole of 1.5 D with no core left."""
SLIVER_AREA_FRACTION = 0.01
"""Parts of a roughing offset region smaller than this x step^2 beside the main one are dropped: the polygonal
buffer's chords leave such slivers between the cusps of large offsets (the true region is one piece: a ring's
spaces narrow outward)."""
CIRCLE_STEP_FRACTION = 0.1
"""A roughing pass whose polygon reaches beyond the circle of the tip radius less its offset (every point of which
is that offset from the outline: the tips are nearest) by at most this x the step is cut as that circle, two G3
half turns; the next pass out engages that much more."""
HELIX_START_ABOVE_MM = 0.1
"""The helix starts this far above the level it goes down from (the top face or the level above, cut)."""
AIR_BORE_MARGIN_MM = 0.5
"""A blank's bore is plunged into (no helix) only if it is wider than the roughing tool by twice this."""


def ring_finishing_loop(spec: GearSpec, tool: Tool, tolerance_mm: float) -> list[Segment2D]:
    """One finishing loop: the toothed inner outline offset by the tool radius into the hole, counterclockwise
    (climb), started at the middle of a tip arc."""
    _, inner = internal_gear_outline_arcs(spec, tolerance_mm)
    loop = _climb(offset_outline(inner, tool.diameter_mm / 2.0))
    tips = [i for i, s in enumerate(loop) if isinstance(s, Arc2D) and s.center_xy == (0.0, 0.0)
            and s.counterclockwise]
    if not tips:
        raise MachineError("the ring's finishing outline has no tip arc to enter on", field="axes", section="machine")
    radius_mm = {i: s.radius_mm for i, s in enumerate(loop) if isinstance(s, Arc2D)}
    innermost = min(radius_mm[i] for i in tips)
    i = max((k for k in tips if radius_mm[k] <= innermost + 1e-9), key=lambda k: loop[k].length_mm)
    arc = loop[i]
    assert isinstance(arc, Arc2D)  # i is one of the tip arcs found above
    middle = arc.point_at(0.5)
    first, second = Arc2D(arc.start_xy, middle, arc.center_xy, True), Arc2D(middle, arc.end_xy, arc.center_xy, True)
    return [second, *loop[i + 1:], *loop[:i], first]


def _lead_arcs_inside(entry: tuple[float, float], tangent: tuple[float, float], radius_mm: float):
    """(lead-in start, lead-out end, centre, lead-in counterclockwise): quarter arcs tangent to the path at `entry`
    (running along `tangent`), toward the gear axis (the hole's air)."""
    ex, ey = entry
    r = math.hypot(ex, ey)
    nx, ny = -ex / r, -ey / r  # toward the axis
    cx, cy = ex + radius_mm * nx, ey + radius_mm * ny
    tx, ty = tangent
    start = (cx - radius_mm * tx, cy - radius_mm * ty)
    end = (cx + radius_mm * tx, cy + radius_mm * ty)
    counterclockwise = (-(ey - cy)) * tx + (ex - cx) * ty > 0.0
    return start, end, (cx, cy), counterclockwise


def ring_finishing_toolpath(spec: GearSpec, tool: Tool, machine: Machine, tolerance_mm: float,
                            step_down_mm: float | None = None) -> tuple[Toolpath, list[float], int]:
    """The ring's finishing program (see the module docstring): (toolpath, Z levels, segments per loop); step-downs
    of at most `step_down_mm` (default one tool diameter)."""
    loop = ring_finishing_loop(spec, tool, tolerance_mm)
    lead = max(tool.diameter_mm / 2.0, 0.5)
    start, end, centre, ccw = _lead_arcs_inside(loop[0].start_xy, loop[0].start_tangent, lead)
    feed, safe_z = tool.feed_mm_min(machine), machine.clearance_mm
    step = FINISH_STEP_DOWN_DIAMETERS * tool.diameter_mm if step_down_mm is None else step_down_mm
    levels = _levels(spec.face_width_mm + BREAK_THROUGH_MM, step)
    builder = ToolpathBuilder(Operation.FINISHING, tool.tool_number, tool.spindle_rpm(machine))
    for index, z in enumerate(levels):
        builder.move(MoveKind.RAPID, start[0], start[1], safe_z, 0.0)
        builder.move(MoveKind.LINEAR, start[0], start[1], z, 0.0, feed / 2.0, station=index)
        builder.arc(not ccw, loop[0].start_xy[0], loop[0].start_xy[1], z, centre[0], centre[1], feed, station=index)
        for segment in loop:
            _add_segment(builder, segment, z, feed, index)
        builder.arc(not ccw, end[0], end[1], z, centre[0], centre[1], feed, station=index)
        builder.move(MoveKind.RAPID, end[0], end[1], safe_z, 0.0)
    return builder.build(), levels, len(loop)


def ring_roughing_leaves(spec: GearSpec, roughing_tool: Tool, outermost_offset_mm: float):
    """The section roughing leaves at every level (shapely polygon): the rim's disc less what the outermost pass's
    tool circles (centre `outermost_offset_mm` from the outline) and those inside it reach."""
    from shapely.geometry import Point, Polygon

    hole = Polygon(gear_outline(spec, ROUGHING_OUTLINE_TOLERANCE_MM))
    reached = hole.buffer(-outermost_offset_mm, quad_segs=ROUGHING_ARC_SEGMENTS).buffer(
        roughing_tool.diameter_mm / 2.0, quad_segs=4 * ROUGHING_ARC_SEGMENTS)
    return Point(0.0, 0.0).buffer(as_ring(spec).rim_outer_diameter_mm / 2.0, quad_segs=64).difference(reached)


def ring_roughing_rings(spec: GearSpec, tool: Tool, params: RoughingParams, inner_radius_mm: float,
                        helix_radius_mm: float) -> list[tuple[float, np.ndarray]]:
    """The roughing passes (tool-centre offset from the outline, counterclockwise polyline without its closing
    point), innermost (nearest the axis) first; only passes that reach material: beyond the helix's cut or the
    blank's bore."""
    from shapely.geometry import Polygon
    from shapely.geometry.polygon import orient

    radius = tool.diameter_mm / 2.0
    hole = Polygon(gear_outline(spec, ROUGHING_OUTLINE_TOLERANCE_MM))
    step = params.step_over_fraction * tool.diameter_mm
    rings = []
    offset = radius + params.finish_stock_mm
    while True:
        shape = hole.buffer(-offset, quad_segs=ROUGHING_ARC_SEGMENTS)
        if shape.is_empty:
            break
        shapes = sorted(getattr(shape, "geoms", [shape]), key=lambda part: -part.area)
        slivers = [part for part in shapes[1:] if part.area <= SLIVER_AREA_FRACTION * step * step]
        shapes = [shapes[0], *shapes[1 + len(slivers):]]
        if len(shapes) != 1 or len(shapes[0].interiors):
            raise MachineError(f"3-axis roughing of a ring: the offset {offset:.3f} mm inside the outline splits "
                               "into separate pockets; use a smaller roughing tool", field="diameter_mm",
                               section="tools.roughing")
        coords = np.asarray(orient(shapes[0], sign=1.0).exterior.coords)[:-1]
        reach = float(np.hypot(*coords.T).max())
        if reach + radius <= max(inner_radius_mm, helix_radius_mm + radius) + 1e-9:
            break  # this pass and those inside it cut nothing the bore or the helix has not
        rings.append((offset, coords))
        offset += step
    return rings[::-1]


def ring_roughing_toolpath(spec: GearSpec, tool: Tool, machine: Machine, params: RoughingParams,
                           inner_radius_mm: float) -> tuple[Toolpath, list[float], list[float]]:
    """The ring's roughing program (see the module docstring): (toolpath, Z levels, tool-centre offsets from the
    outline, outermost pass (the finish stock's) first)."""
    radius = tool.diameter_mm / 2.0
    air_bore = inner_radius_mm >= radius + AIR_BORE_MARGIN_MM
    helix_radius = 0.0 if air_bore else HELIX_RADIUS_FRACTION * radius
    rings = ring_roughing_rings(spec, tool, params, inner_radius_mm if air_bore else 0.0, helix_radius)
    feed, safe_z = tool.feed_mm_min(machine), machine.clearance_mm
    levels = _levels(spec.face_width_mm + BREAK_THROUGH_MM, params.max_level_depth_fraction * tool.diameter_mm)
    step_mm = params.step_over_fraction * tool.diameter_mm
    pitch_mm = 2.0 * math.pi * helix_radius * math.tan(math.radians(HELIX_RAMP_DEG))
    builder = ToolpathBuilder(Operation.ROUGHING, tool.tool_number, tool.spindle_rpm(machine))
    top = 0.0
    for index, z in enumerate(levels):
        if air_bore:  # down in the bore's air at the centre
            builder.move(MoveKind.RAPID, 0.0, 0.0, safe_z, 0.0)
            builder.move(MoveKind.LINEAR, 0.0, 0.0, z, 0.0, feed / 2.0, station=index)
            here = np.zeros(2)
        else:  # a helix from the level above (cleared) down to z, then a flat turn at z
            builder.move(MoveKind.RAPID, helix_radius, 0.0, safe_z, 0.0)
            builder.move(MoveKind.LINEAR, helix_radius, 0.0, top + HELIX_START_ABOVE_MM, 0.0, feed / 2.0,
                         station=index)
            _helix(builder, helix_radius, top + HELIX_START_ABOVE_MM, z, pitch_mm, feed, index)
            here = np.array([helix_radius, 0.0])
        for offset, coords in rings:
            circle_mm = spec.tip_radius_mm - offset
            if np.hypot(*coords.T).max() - circle_mm <= CIRCLE_STEP_FRACTION * step_mm:  # beyond the spaces
                here = _circle(builder, circle_mm, here, z, feed, index)
                continue
            ordered = _started_at_nearest(coords, here)
            for x, y in ordered:
                builder.move(MoveKind.LINEAR, float(x), float(y), z, 0.0, feed, station=index)
            here = ordered[-1]
        builder.move(MoveKind.RAPID, float(here[0]), float(here[1]), safe_z, 0.0)
        top = z
    return builder.build(), levels, [offset for offset, _ in reversed(rings)]


def _helix(builder: ToolpathBuilder, radius_mm: float, top_mm: float, z_mm: float, pitch_mm: float, feed: float,
           station: int) -> None:
    """Counterclockwise half turns about the axis from (radius, 0, top_mm) down to z at most `pitch_mm` a turn,
    then one flat turn at z."""
    turns = max(1, math.ceil((top_mm - z_mm) / pitch_mm - 1e-9))
    halves = 2 * turns
    for k in range(1, halves + 1):
        x = radius_mm if k % 2 == 0 else -radius_mm
        builder.arc(False, x, 0.0, top_mm + (z_mm - top_mm) * k / halves, 0.0, 0.0, feed, station=station)
    builder.arc(False, -radius_mm, 0.0, z_mm, 0.0, 0.0, feed, station=station)
    builder.arc(False, radius_mm, 0.0, z_mm, 0.0, 0.0, feed, station=station)


def ring_tool_recommendations(spec: GearSpec, clearance_mm: float):
    """The tool limits of a ring cut lying flat (summary.json's `tools`): flat_tool_recommendations, any roughing
    end mill that enters the hole (its tip circle)."""
    return flat_tool_recommendations(spec, clearance_mm, 2.0 * spec.tip_radius_mm)


def _circle(builder: ToolpathBuilder, radius_mm: float, here: np.ndarray, z_mm: float, feed: float,
            station: int) -> np.ndarray:
    """A full counterclockwise circle about the axis at z, entered by a straight move from `here` outward along
    its ray; returns where it ends (its start)."""
    direction = here / np.hypot(*here) if np.hypot(*here) > 0.0 else np.array([1.0, 0.0])
    start = radius_mm * direction
    builder.move(MoveKind.LINEAR, float(start[0]), float(start[1]), z_mm, 0.0, feed, station=station)
    builder.arc(False, float(-start[0]), float(-start[1]), z_mm, 0.0, 0.0, feed, station=station)
    builder.arc(False, float(start[0]), float(start[1]), z_mm, 0.0, 0.0, feed, station=station)
    return start
