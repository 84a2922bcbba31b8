"""Roughing (docs/method.md): per tooth space, horizontal levels, zig-zag passes along X.

The tool works on the design profile offset by the finish stock (so it never comes closer
than that to the design). Levels are chosen bottom-up on that offset flank so that the
staircase left between two levels is at most (flank allowance - finish stock): horizontally
on the involute, as a straight distance on the concave fillet; the fillet/involute junction
is always a level, and no level is deeper than the slotting limit below the one above.
The lowest level is where the offset space is exactly as wide as the tool.

Helical gears: the same levels and passes in the transverse section, each move following the lead
(A falls by the section turn of its X advance, Y and Z fixed; inverse-time feed), so the tool
keeps its place in the turning tooth space. A slice of the tool at a distance dx from its axis meets
a section turned by dx tan(beta) / r against the slice through the axis: seen in one section, the
tool sweeps a width of D sqrt(1 + (r_blank tan(beta) / r)^2) (largest at the blank radius), and the
levels and passes are planned for that width (`transverse_radius_mm`). The turn also lowers a slice's
corner at y from the space's centre line by up to |y| D tan(beta) / (2 r): each level only fills the
space as wide as it is that much lower (`_OffsetFlank.reach_width`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from spur_cad.cam.common import PLUNGE_FEED_FRACTION, apply_inverse_time, offset_flank, safe_height_mm
from spur_cad.cam.ir import Feature, MoveKind, Operation, Toolpath, ToolpathBuilder
from spur_cad.cam.machine import Machine, MachineError, RoughingParams
from spur_cad.cam.recommend import space_half_width_mm
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.geometry.kinds import EXTERNAL_HELICAL
from spur_cad.geometry.spec import GearSpec


@dataclass(frozen=True)
class RoughingLevels:
    """Level heights (tool tip Z with the space axis up), top to bottom, and their half-width reach."""

    heights_mm: np.ndarray
    half_widths_mm: np.ndarray  # largest |Y| the tool edge may reach at each level (offset flank)
    junction_height_mm: float | None

    @property
    def lowest_height_mm(self) -> float:
        return float(self.heights_mm[-1])


def estimated_roughing_moves(spec: GearSpec, tool: Tool, params: RoughingParams,
                             blank_radius_mm: float) -> tuple[int, str]:
    """An upper bound of the moves roughing_toolpath makes, from the inputs alone (no levels computed),
    and the [roughing] key that drives it most.

    Levels: the depth limit alone needs (blank - root) / max depth of them; the flank staircase
    budget adds at most (half a pitch, more than the flank's horizontal extent) / budget. Passes per
    level: the widest level is narrower than a pitch. The tip lands: at most as many cuts as the depth limit
    needs, each at most 2 r_blank tan(pi / z) wide (tip_half_width_mm)."""
    max_depth = params.max_level_depth_fraction * tool.diameter_mm
    if params.strategy == "flank":
        return _estimated_flank_moves(spec, tool, params, blank_radius_mm)
    budget = params.flank_allowance_mm - params.finish_stock_mm
    depth_levels = math.ceil((blank_radius_mm - spec.root_radius_mm) / max_depth)
    flank_levels = math.ceil(spec.pitch_mm / 2.0 / budget)
    passes = math.ceil(spec.pitch_mm / (params.step_over_fraction * tool.diameter_mm)) + 1
    tip_passes = math.ceil(2.0 * blank_radius_mm * math.tan(math.pi / spec.teeth)
                           / (params.step_over_fraction * tool.diameter_mm)) + 1
    moves = spec.teeth * ((depth_levels + flank_levels + 2) * (2 * passes + 4) + 4
                          + depth_levels * (2 * tip_passes + 4) + 6)
    driver = max((depth_levels, "max_level_depth_fraction"), (flank_levels, "flank_allowance_mm"),
                 (passes, "step_over_fraction"))[1]
    return moves, driver


def _estimated_flank_moves(spec: GearSpec, tool: Tool, params: RoughingParams,
                           blank_radius_mm: float) -> tuple[int, str]:
    """An upper bound of the flank strategy's moves (cam.flank_roughing): its flank segments are found first (a
    bounded search: at most MAX_SEGMENTS_PER_FLANK bisections over the flank's points), then per space 2 segments
    + 1 runs, each at most (twice the space's width at the blank) / the radial engagement + 2 positions, each cut
    in at most 2 (depth / slot depth) + 2 tiers (narrow and wide tiers alternate at worst), each pass with at most
    10 moves (its link's three, itself in three legs, a return's two, a clamp and a release); the tip lands as
    the levels'."""
    from spur_cad.cam.flank_roughing import flank_segment_count

    points, _, junction = offset_flank(spec, params.finish_stock_mm)
    flank = _OffsetFlank(points, junction, abs(spec.section_turn_rad(1.0)) * tool.diameter_mm / 2.0)
    lowest = _lowest_level(flank, tool, transverse_radius_mm(spec, tool, blank_radius_mm))
    runs = 2 * flank_segment_count(spec, tool, params, blank_radius_mm, lowest) + 1
    step = params.max_radial_engagement_fraction * tool.diameter_mm
    slot = params.max_level_depth_fraction * tool.diameter_mm
    width = 2.0 * blank_radius_mm * math.tan(math.pi / spec.teeth)
    positions = math.ceil(2.0 * width / step) + 2
    tiers = 2 * math.ceil((blank_radius_mm - spec.root_radius_mm) / slot) + 2
    tip_passes = math.ceil(width / (params.step_over_fraction * tool.diameter_mm)) + 1
    moves = spec.teeth * (runs * positions * tiers * 10 + 6 + tiers * (2 * tip_passes + 4))
    driver = "max_radial_engagement_fraction" if positions >= tiers else "max_level_depth_fraction"
    return moves, driver


@dataclass(frozen=True)
class _OffsetFlank:
    """The right flank offset by the finish stock (root to tip edge) and what the levels ask of it."""

    points: np.ndarray
    junction: float | None  # height of the fillet/involute junction
    sag: float = 0.0  # helical: a slice turned by phi lowers a corner at y by |y phi|, at most sag * |y|

    def reach_width(self, h: float) -> float:
        """Half-width the tool may fill at level h: the width where its corners can sink to (`sag`)."""
        if self.sag == 0.0:
            return self.width(h)
        return self.width(h - self.sag * self.width(h))

    @property
    def tip_edge_height(self) -> float:
        return float(self.points[-1, 1])

    def width(self, h: float) -> float:
        return space_half_width_mm(self.points, h)

    def point(self, h: float) -> np.ndarray:
        """Point of the offset flank at height h (first crossing from the root, tip edge above it)."""
        flank, y = self.points, self.points[:, 1]
        if h >= self.tip_edge_height:
            return flank[-1]
        i = int(np.nonzero((y[:-1] <= h) & (y[1:] >= h))[0][0]) if np.any((y[:-1] <= h) & (y[1:] >= h)) else 0
        t = (h - y[i]) / (y[i + 1] - y[i]) if y[i + 1] != y[i] else 0.0
        return flank[i] + t * (flank[i + 1] - flank[i])

    def staircase(self, h_low: float, h_high: float) -> float:
        """Material left between two levels: horizontal on the involute, straight on the fillet."""
        p_low, p_high = self.point(h_low), self.point(min(h_high, self.tip_edge_height))
        on_fillet = self.junction is not None and h_high <= self.junction + 1e-12
        if on_fillet:
            return float(np.hypot(*(p_high - p_low)))
        return float(p_high[0] - p_low[0])


def transverse_radius_mm(spec: GearSpec, tool: Tool, blank_radius_mm: float) -> float:
    """Half the width the tool sweeps in one transverse section while it follows the lead (its radius for a
    spur gear): the slice at dx from the axis is turned by dx * twist, an arc of up to r_blank * twist * dx."""
    stretch = blank_radius_mm * abs(spec.section_turn_rad(1.0))
    return tool.diameter_mm / 2.0 * math.sqrt(1.0 + stretch * stretch)


def _lowest_level(flank: _OffsetFlank, tool: Tool, radius: float) -> float:
    """Where the offset space is exactly as wide as the tool's transverse width 2 radius (bisection on a
    monotone test)."""
    low, high = float(flank.points[:, 1].min()), flank.tip_edge_height
    if flank.reach_width(high) < radius:
        swept = "" if flank.sag == 0.0 else f" (it sweeps {2 * radius:.3f} mm along the helical lead)"
        raise ToolError(f"roughing tool diameter {tool.diameter_mm:g} mm{swept} does not fit the tooth space even at "
                        f"the tip (space width {2 * flank.reach_width(high):.3f} mm there, finish stock included)",
                        field="diameter_mm", section="tools.roughing")
    for _ in range(100):
        mid = 0.5 * (low + high)
        low, high = (mid, high) if flank.reach_width(mid) < radius else (low, mid)
    return high


def _next_level(flank: _OffsetFlank, h: float, max_depth: float, budget: float, params: RoughingParams) -> float:
    """The highest level above `h` whose staircase stays within the budget (the junction is always a level)."""
    ceiling = min(h + max_depth, flank.tip_edge_height)
    if flank.junction is not None and h < flank.junction - 1e-9:
        ceiling = min(ceiling, flank.junction)
    if flank.staircase(h, ceiling) <= budget:
        return ceiling
    lo, hi = h, ceiling  # largest height whose staircase is within budget (it grows with height)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if flank.staircase(h, mid) <= budget else (lo, mid)
    if lo - h < 1e-6:
        raise MachineError(f"[roughing] flank_allowance_mm = {params.flank_allowance_mm:g} is too small for "
                           "this flank: the levels would be less than 1 nm apart", field="flank_allowance_mm",
                           section="roughing")
    return lo


def lowest_roughing_level(spec: GearSpec, tool: Tool, params: RoughingParams,
                          blank_radius_mm: float) -> RoughingLevels:
    """The lowest of roughing_levels alone (all the flank strategy reads of them), without the levels above."""
    points, _, junction = offset_flank(spec, params.finish_stock_mm)
    flank = _OffsetFlank(points, junction, abs(spec.section_turn_rad(1.0)) * tool.diameter_mm / 2.0)
    lowest = _lowest_level(flank, tool, transverse_radius_mm(spec, tool, blank_radius_mm))
    return RoughingLevels(np.array([lowest]), np.array([flank.reach_width(lowest)]), junction)


def roughing_levels(spec: GearSpec, tool: Tool, params: RoughingParams, blank_radius_mm: float) -> RoughingLevels:
    """Levels as described in the module docstring (pure function)."""
    points, _, junction = offset_flank(spec, params.finish_stock_mm)
    # A slice at dx from the tool axis is turned by dx * twist, |dx| <= D / 2 (module docstring).
    flank = _OffsetFlank(points, junction, abs(spec.section_turn_rad(1.0)) * tool.diameter_mm / 2.0)
    budget = params.flank_allowance_mm - params.finish_stock_mm
    max_depth = params.max_level_depth_fraction * tool.diameter_mm
    heights = [_lowest_level(flank, tool, transverse_radius_mm(spec, tool, blank_radius_mm))]
    top = blank_radius_mm - max_depth  # the first level cuts at most max_depth below the blank
    while True:
        h = heights[-1]
        if h >= flank.tip_edge_height - 1e-9 or flank.staircase(h, flank.tip_edge_height) <= budget:
            if h >= top - 1e-9:
                break
            heights.append(min(h + max_depth, top))  # only the depth limit is left to satisfy
            continue
        heights.append(_next_level(flank, h, max_depth, budget, params))
    levels = np.array(heights[::-1])
    half_widths = np.array([flank.reach_width(h) for h in levels])
    return RoughingLevels(levels, half_widths, junction)


TURNS_A_ALONG_X = frozenset({EXTERNAL_HELICAL})
"""Gear kinds whose roughing passes along X turn A with X (along the lead: follow_lead), so the table must turn
while cutting and cannot be clamped; the passes of every other kind keep A."""


def _check_clamp(spec: GearSpec, machine: Machine, params: RoughingParams) -> None:
    """Clamping the table for each space needs the machine's codes and a table that stays still (spur gears)."""
    if not params.clamp_rotary:
        return
    if not (machine.rotary_clamp_code and machine.rotary_unclamp_code):
        raise MachineError("[roughing] clamp_rotary needs [machine] rotary_clamp_code and rotary_unclamp_code",
                           field="clamp_rotary", section="roughing")
    if spec.kind in TURNS_A_ALONG_X:
        raise MachineError("[roughing] clamp_rotary cannot be used for a helical gear: its passes turn A along the "
                           "lead", field="clamp_rotary", section="roughing")


def check_helical_roughing_machine(spec: GearSpec, machine: Machine) -> None:
    """Helical roughing turns A with X while cutting: a table that only indexes cannot run it."""
    if spec.kind in TURNS_A_ALONG_X and not machine.rotary_simultaneous:
        raise MachineError(f"roughing a helical gear (helix_angle_deg = {spec.helix_angle_deg:g}) turns A with X "
                           "along the lead while cutting, but [machine] rotary_simultaneous = false (the table only "
                           "indexes)", field="rotary_simultaneous", section="machine")


def roughing_toolpath(spec: GearSpec, tool: Tool, machine: Machine, params: RoughingParams,
                      blank_radius_mm: float, back_margin_mm: float = 0.0, stub_radius_mm: float = 0.0,
                      front_margin_mm: float = 0.0, levels: RoughingLevels | None = None,
                      tips: bool = True, flank_plan=None, stub_length_mm: float = 0.0) -> Toolpath:
    """The roughing operation as IR (pure function); `levels` when the caller has computed them already. `tips`:
    after each space, the passes over the tip land beside it (tip_heights_mm; two-stage roughing's bottom tool
    leaves them to the larger tool). `flank_plan`: the flank strategy's plan when the caller has it (flank_plan_for);
    `stub_length_mm`: the holding stub's (whether the flank strategy's passes may run on over it). The inputs are
    trusted: checked when the plan's inputs were made (cam.plan.CamInputs)."""
    _check_clamp(spec, machine, params)
    check_helical_roughing_machine(spec, machine)
    if levels is None:
        levels = roughing_levels(spec, tool, params, blank_radius_mm)
    radius = tool.diameter_mm / 2.0
    sweep_radius = transverse_radius_mm(spec, tool, blank_radius_mm)
    x_front = -(front_margin_mm + radius + machine.clearance_mm)
    x_back = spec.face_width_mm + radius + machine.clearance_mm
    if params.strategy == "flank":
        return _flank_toolpath(spec, tool, machine, params, blank_radius_mm, back_margin_mm, stub_radius_mm,
                               front_margin_mm, flank_plan or flank_plan_for(spec, tool, params, blank_radius_mm,
                                                                             levels, tips), tips, stub_length_mm)
    if stub_radius_mm > levels.lowest_height_mm:
        _check_stub_margin(x_back, radius, back_margin_mm, machine)
    safe_z = safe_height_mm(blank_radius_mm, machine)
    feed = tool.feed_mm_min(machine)
    step = params.step_over_fraction * tool.diameter_mm
    pitch_deg = 360.0 / spec.teeth
    space_offsets = [_pass_offsets(max(half_width - sweep_radius, 0.0), step) for half_width in levels.half_widths_mm]
    tip_heights = tip_heights_mm(spec, tool, params, blank_radius_mm) if tips else np.zeros(0)
    tip_offsets = _pass_offsets(tip_half_width_mm(spec, tool, params, levels, blank_radius_mm) - radius, step)
    builder = ToolpathBuilder(Operation.ROUGHING, tool.tool_number, tool.spindle_rpm(machine))
    passes = _Passes(builder, x_front, x_back, safe_z, feed)
    for k in range(spec.teeth):
        a = -k * pitch_deg
        if params.clamp_rotary and k > 0:
            builder.move(MoveKind.UNCLAMP_ROTARY, *builder.last_pose(), space=k)
        builder.move(MoveKind.RAPID, x_front, 0.0, safe_z, a, space=k)
        if params.clamp_rotary:
            builder.move(MoveKind.CLAMP_ROTARY, x_front, 0.0, safe_z, a, space=k)
        passes.levels(a, k, levels.heights_mm, space_offsets, range(len(space_offsets)), Feature.LEVEL)
        if len(tip_heights):  # the tip land of the tooth between spaces k and k + 1, its axis up
            a_tip = a - pitch_deg / 2.0
            if params.clamp_rotary:
                builder.move(MoveKind.UNCLAMP_ROTARY, *builder.last_pose(), space=k)
            builder.move(MoveKind.RAPID, x_front, tip_offsets[0], safe_z, a_tip, space=k)
            if params.clamp_rotary:
                builder.move(MoveKind.CLAMP_ROTARY, x_front, tip_offsets[0], safe_z, a_tip, space=k)
            passes.levels(a_tip, k, tip_heights, [tip_offsets] * len(tip_heights), [-1] * len(tip_heights),
                          Feature.TIP)
    path = builder.build()
    if spec.kind in TURNS_A_ALONG_X:
        path = follow_lead(path, spec, machine)
    return path


@dataclass
class _Passes:
    """Writes zig-zag passes along X at given heights for one A (a space's levels, a tip land's passes)."""

    builder: ToolpathBuilder
    x_front: float
    x_back: float
    safe_z: float
    feed: float
    air_feed: float = math.nan  # with x_material: the passes cross the air outside it at this feed, and the tool
    x_material: tuple[float, float] | None = None  # goes down in front of the blank and up at the passes' ends at it

    def levels(self, a: float, space: int, heights, offsets, stations, feature: Feature) -> None:
        """From the front at each height (back to the front above the cleared level before going down), Y steps
        beside the part; then up to the safe height."""
        builder, x_front, safe_z, feed = self.builder, self.x_front, self.safe_z, self.feed
        up, down = (feed, PLUNGE_FEED_FRACTION * feed) if self.x_material is None else (self.air_feed, self.air_feed)
        x_here = x_front
        for height, ys, station in zip(heights, offsets, stations):
            if x_here != x_front:  # come back to the front, above the cleared level, before going down
                builder.move(MoveKind.LINEAR, x_here, builder.last_pose()[1], safe_z, a, up, space=space,
                             station=station)
                builder.move(MoveKind.RAPID, x_front, ys[0], safe_z, a, space=space, station=station)
                x_here = x_front
            builder.move(MoveKind.LINEAR, x_front, ys[0], height, a, down, space=space, station=station)
            for j, y in enumerate(ys):
                if j > 0 and self.x_material is None:
                    builder.move(MoveKind.LINEAR, x_here, y, height, a, feed, space=space, station=station,
                                 feature=feature)
                elif j > 0:  # the step to the next pass beyond the stock's end: in the air
                    builder.move(MoveKind.LINEAR, x_here, y, height, a, self.air_feed, space=space, station=station)
                x_to = self.x_back if x_here == x_front else x_front
                legs = [(x_to, True)] if self.x_material is None else _pass_legs(x_here, x_to, self.x_material)
                for x_leg, cutting in legs:
                    builder.move(MoveKind.LINEAR, x_leg, y, height, a, feed if cutting else self.air_feed,
                                 space=space, station=station, feature=feature if cutting else Feature.NONE)
                x_here = x_to
        builder.move(MoveKind.LINEAR, x_here, builder.last_pose()[1], safe_z, a, up, space=space)


def _pass_offsets(reach_mm: float, step_mm: float) -> np.ndarray:
    """Y of the passes of one level: -reach..reach at most `step_mm` apart (one pass at 0 without reach)."""
    if reach_mm <= 0.0:
        return np.array([0.0])
    n = max(1, math.ceil(2.0 * reach_mm / step_mm - 1e-9))
    return np.linspace(-reach_mm, reach_mm, n + 1)


def tip_heights_mm(spec: GearSpec, tool: Tool, params: RoughingParams, blank_radius_mm: float) -> np.ndarray:
    """Heights of the passes over a tip land (tool tip Z with the tooth's axis up), top to bottom: the blank
    taken down to the tip radius + finish stock in equal cuts of at most the level depth limit; none when the
    blank stands no higher. A flat tool bottom at Z >= r_a + stock is farther than that from the axis at every
    Y (and in every section a helical pass turns through): it cannot come nearer the design."""
    floor = spec.tip_radius_mm + params.finish_stock_mm
    depth = blank_radius_mm - floor
    if depth <= 1e-9:
        return np.zeros(0)
    cuts = math.ceil(depth / (params.max_level_depth_fraction * tool.diameter_mm) - 1e-9)
    return blank_radius_mm - depth * np.arange(1, cuts + 1) / cuts


def tip_half_width_mm(spec: GearSpec, tool: Tool, params: RoughingParams, levels: RoughingLevels,
                      blank_radius_mm: float) -> float:
    """Half-width the tip passes clear (the tooth's axis up): out to the side of the column the space's highest
    level at or below the offset flank's tip edge cleared (its passes' reach + D / 2, the space's axis up; above
    it, the staircase of the levels higher up may stand above the tip circle beside the tooth's corner). That
    side, turned by half a pitch, is farthest from the tooth's axis at the blank's radius."""
    tip_edge = offset_flank(spec, params.finish_stock_mm)[0][-1, 1]
    below = np.flatnonzero(levels.heights_mm <= tip_edge + 1e-9)
    level = int(below[0]) if len(below) else len(levels.heights_mm) - 1
    reach = max(float(levels.half_widths_mm[level]) - transverse_radius_mm(spec, tool, blank_radius_mm), 0.0)
    cleared = reach + tool.diameter_mm / 2.0
    half_pitch = math.pi / spec.teeth
    return max((blank_radius_mm * math.sin(half_pitch) - cleared) / math.cos(half_pitch), 0.0)


def follow_lead(path: Toolpath, spec: GearSpec, machine: Machine) -> Toolpath:
    """The moves with A turned by the helix at their X (A - turn(X), the same space under the tool at every X),
    feeds of moves that now turn A in inverse time; markers follow their pose."""
    turn_deg = np.degrees(spec.section_turn_rad(1.0)) * path.x
    return apply_inverse_time(path.replace(a=path.a - turn_deg), machine)


def _tip_offsets_mm(spec: GearSpec, tool: Tool, params: RoughingParams) -> np.ndarray:
    """Y of the flank strategy's tip passes (the tooth's axis up): the tool's sides from one tip edge of the land
    (grown by the finish stock) to the other (one pass on the axis when the tool is wider than the land). What
    stands above the tip circle beyond the tip edges is the flank runs' (their completeness check and clean-up
    columns stop at the land's columns, land_half_width_mm). The passes are at most the slot depth deep
    (tip_heights_mm), so each may be engaged across the whole diameter: they step by TIP_STEP_FRACTION x D."""
    tip_edge = offset_flank(spec, params.finish_stock_mm)[0][-1]
    half_pitch = math.pi / spec.teeth
    edge = tip_edge[0] * math.cos(half_pitch) - tip_edge[1] * math.sin(half_pitch)  # the edge in the tooth's frame
    return _pass_offsets(max(abs(edge) - tool.diameter_mm / 2.0, 0.0), TIP_STEP_FRACTION * tool.diameter_mm)


TIP_STEP_FRACTION = 0.9
"""The flank strategy's step between tip passes, x D (a little overlap between neighbouring passes)."""


def _check_stub_margin(x_back: float, radius: float, back_margin_mm: float, machine: Machine) -> None:
    """A pass ending at x_back reaches x_back + D/2 beyond the gear's front face; a holding stub standing as high as
    the passes starts back_margin_mm behind the back face: refuse a margin shorter than that reach."""
    needed = 2.0 * radius + machine.clearance_mm  # the tool edge stands this far behind the back face
    if back_margin_mm < needed - 1e-9:
        raise MachineError(f"the roughing tool would cut into the holding stub: its passes run to X = {x_back:.3f} mm "
                           f"(its edge {x_back + radius:.3f} mm); make [stock] back_margin_mm at least {needed:.3f} mm",
                           field="back_margin_mm", section="stock")


@dataclass
class _Clamp:
    """[roughing] clamp_rotary for the flank strategy: A clamped before every cut, unclamped before every move
    that turns it (between runs, to the tip land, to the next space); nothing without the key."""

    builder: ToolpathBuilder
    enabled: bool
    held: bool = False

    def hold(self, space: int) -> None:
        if self.enabled and not self.held:
            self.builder.move(MoveKind.CLAMP_ROTARY, *self.builder.last_pose(), space=space)
            self.held = True

    def release(self, space: int) -> None:
        if self.enabled and self.held:
            self.builder.move(MoveKind.UNCLAMP_ROTARY, *self.builder.last_pose(), space=space)
            self.held = False


def _link_poses(previous, following, floor_z_mm: float) -> list[tuple[float, float, float]]:
    """The (Y, Z, turn) poses a link between two passes goes through after leaving the first: straight within a
    run; between runs up to the higher pass's Z (at least `floor_z_mm`) first, across (Y and A), then down. With
    the floor at the passes' least distance from the axis (_passes_floor_mm), a link across comes no nearer the
    axis (and a holding stub) than the passes do."""
    if previous is None or previous.run == following.run:
        return [(following.y_mm, following.z_mm, following.turn_deg)]
    high = max(previous.z_mm, following.z_mm, floor_z_mm)
    return [(previous.y_mm, high, previous.turn_deg), (following.y_mm, high, following.turn_deg),
            (following.y_mm, following.z_mm, following.turn_deg)]


def _passes_floor_mm(plan, radius: float) -> float:
    """The flat tool bottom's least distance from the gear axis over a space's passes."""
    return min(p.z_mm if abs(p.y_mm) <= radius else math.hypot(abs(p.y_mm) - radius, p.z_mm) for p in plan.passes)


ENTRY_GAP_MM = 0.2
"""How far before the stock's end a flank pass slows from the largest feed to its cutting feed (at most the
machine's clearance)."""


def _pass_legs(x_from: float, x_to: float, x_material: tuple[float, float]) -> list[tuple[float, bool]]:
    """The legs of a pass along X from x_from to x_to as (end X, cutting): the air before and after the X range
    where the tool can meet the stock (`x_material`, low to high) is crossed at the largest feed."""
    low, high = x_material
    ends = [x for x in ((low, high) if x_to > x_from else (high, low)) if min(x_from, x_to) < x < max(x_from, x_to)]
    legs, x_here = [], x_from
    for x in ends + [x_to]:
        middle = 0.5 * (x_here + x)
        legs.append((x, low <= middle <= high))
        x_here = x
    return legs


def _closest_to_axis_mm(plan, radius: float) -> float:
    """The flat tool bottom's least distance from the gear axis over a space's passes and links (Y and Z
    interpolated along each leg, sampled at 65 points; A does not change the distance)."""
    legs: list[tuple[float, float]] = []
    previous, floor = None, _passes_floor_mm(plan, radius)
    for p in plan.passes:
        legs.extend((y, z) for y, z, _ in _link_poses(previous, p, floor))
        previous = p
    points = np.array(legs)
    t = np.linspace(0.0, 1.0, 65)[:, None, None]
    path = (points[:-1] + t * (points[1:] - points[:-1])).reshape(-1, 2) if len(points) > 1 else points
    y, z = np.abs(path[:, 0]), path[:, 1]
    return float(np.where(y <= radius, z, np.hypot(y - radius, z)).min())


def flank_plan_for(spec: GearSpec, tool: Tool, params: RoughingParams, blank_radius_mm: float,
                   levels: RoughingLevels, tips: bool = True, first=None):
    """The flank strategy's plan of one space (cam.flank_roughing) for these levels' lowest height; `first`: the
    flank plan and tool of two-stage roughing's first tool, whose stock this plan starts from (the first tool cuts
    the tip lands)."""
    from spur_cad.cam.flank_roughing import plan_flank_roughing, stock_after_all_spaces

    radius = transverse_radius_mm(spec, tool, blank_radius_mm)
    if first is None:
        return plan_flank_roughing(spec, tool, params, blank_radius_mm, levels.lowest_height_mm, radius,
                                   land_half_width_mm(spec, tool, params) if tips else 0.0)
    first_plan, first_tool = first
    land = land_half_width_mm(spec, first_tool, params)
    return plan_flank_roughing(spec, tool, params, blank_radius_mm, levels.lowest_height_mm, radius, land,
                               stock_after_all_spaces(spec, first_plan, land, params.finish_stock_mm))


def land_half_width_mm(spec: GearSpec, tool: Tool, params: RoughingParams) -> float:
    """How far the flank strategy's tip passes clear each side of a tooth's centre line (the tool's side beyond
    the last pass)."""
    return float(_tip_offsets_mm(spec, tool, params)[-1]) + tool.diameter_mm / 2.0


def _flank_toolpath(spec: GearSpec, tool: Tool, machine: Machine, params: RoughingParams, blank_radius_mm: float,
                    back_margin_mm: float, stub_radius_mm: float, front_margin_mm: float, plan, tips: bool,
                    stub_length_mm: float) -> Toolpath:
    """The flank strategy (cam.flank_roughing) as IR: every space's passes in the plan's order, linked outside the
    blank (the passes run from in front of it to beyond its back, or back to the front along their own cleared
    column where a holding stub stands higher than the passes), then the tip land's passes."""
    from spur_cad.cam.flank_roughing import UNCUT_MM2

    radius = tool.diameter_mm / 2.0
    tip_offsets = _tip_offsets_mm(spec, tool, params)
    floor = _passes_floor_mm(plan, radius)
    stub_below = stub_radius_mm + machine.clearance_mm <= _closest_to_axis_mm(plan, radius)
    # beyond the blank's back only where nothing stands there: no stub, or one lower than every pass and long
    # enough that the tool, 2 r + clearance beyond the margin, stays over it (not over what grips it)
    free_back = stub_radius_mm <= 0.0 or (stub_below and stub_length_mm >= 2.0 * (radius + machine.clearance_mm))
    x_front = -(front_margin_mm + radius + machine.clearance_mm)
    x_back = spec.face_width_mm + radius + machine.clearance_mm
    if not free_back and not stub_below:
        _check_stub_margin(x_back, radius, back_margin_mm, machine)
    safe_z = safe_height_mm(blank_radius_mm, machine)
    feed = tool.feed_mm_min(machine)
    air = machine.max_feed_mm_min
    pitch_deg = 360.0 / spec.teeth
    tip_heights = tip_heights_mm(spec, tool, params, blank_radius_mm) if tips else np.zeros(0)
    # where the tool can meet the stock along X (its edge at the stock's ends, an entry gap before): the passes
    # cross the air beyond at the largest feed
    gap = min(ENTRY_GAP_MM, machine.clearance_mm)
    x_material = (-(front_margin_mm + radius + gap),
                  spec.face_width_mm + back_margin_mm + radius + gap if free_back else x_back)
    # the passes turn (and link, and the tip passes go down and up) there too: beyond the stock's ends, the tool
    # meets nothing in any pose, and the air legs of clearance - gap at each end cost a stop-and-go each at the
    # machine's accelerations (issue 29: 9 % of a narrow-spaced gear's roughing)
    x_front, x_back = x_material
    builder = ToolpathBuilder(Operation.ROUGHING, tool.tool_number, tool.spindle_rpm(machine))
    clamp = _Clamp(builder, params.clamp_rotary)
    for k in range(spec.teeth):
        a = -k * pitch_deg
        first = plan.passes[0]
        clamp.release(k)
        builder.move(MoveKind.RAPID, x_front, first.y_mm, safe_z, a + first.turn_deg, space=k)
        x_here, previous = x_front, None
        for p in plan.passes:
            a_pass = a + p.turn_deg
            # the link, outside the blank at this end of the passes (in the air: the machine's largest feed)
            for y_link, z_link, turn_link in _link_poses(previous, p, floor):
                if a + turn_link != builder.last_pose()[3]:
                    clamp.release(k)
                builder.move(MoveKind.LINEAR, x_here, y_link, z_link, a + turn_link, air, space=k, station=p.run)
            clamp.hold(k)
            previous = p
            x_end = x_back if x_here == x_front else x_front
            for x_to, cutting in _pass_legs(x_here, x_end, x_material):
                builder.move(MoveKind.LINEAR, x_to, p.y_mm, p.z_mm, a_pass,
                             min(feed * p.feed_factor, air) if cutting else air, space=k, station=p.run,
                             feature=Feature.LEVEL if cutting else Feature.NONE)
            if free_back:
                x_here = x_end
            else:  # back to the front along the column this pass cleared, just above its floor
                lift = min(0.1, 0.5 * machine.clearance_mm)
                builder.move(MoveKind.LINEAR, x_end, p.y_mm, p.z_mm + lift, a_pass, air, space=k, station=p.run)
                builder.move(MoveKind.LINEAR, x_front, p.y_mm, p.z_mm + lift, a_pass, air, space=k, station=p.run)
        builder.move(MoveKind.LINEAR, x_here, builder.last_pose()[1], safe_z, builder.last_pose()[3], air, space=k)
        if len(tip_heights):  # the tip land of the tooth between spaces k and k + 1, its axis up
            a_tip = a - pitch_deg / 2.0
            clamp.release(k)
            builder.move(MoveKind.RAPID, x_front, tip_offsets[0], safe_z, a_tip, space=k)
            clamp.hold(k)
            passes = _Passes(builder, x_front, x_back, safe_z, feed, air, x_material)
            passes.levels(a_tip, k, tip_heights, [tip_offsets] * len(tip_heights), [-1] * len(tip_heights),
                          Feature.TIP)
    path = builder.build()
    if plan.uncut_mm2 > UNCUT_MM2:
        path = path.replace(warnings=path.warnings + (
            f"flank roughing leaves {plan.uncut_mm2:.3g} mm^2 of each tooth space's section farther than "
            "flank_allowance_mm from the design (its stock model); finishing would meet it: choose [roughing] "
            "strategy = \"levels\"",))
    if spec.kind in TURNS_A_ALONG_X:
        path = follow_lead(path, spec, machine)
    return path
