"""Flank roughing (docs/method.md, "Roughing at the tool's limit"): each tooth space cleared by the end mill's side at
full depth, the rotary table turned so that a flank segment's chord is parallel to the tool axis.

Frames: the space frame has the space's centre line up (+Z, heights are radii) and the gear axis at the origin;
turning A by `theta` from the space's own A shows the section as R(theta) p (counter-clockwise), the "turned
frame" in which the tool is a vertical half-strip [y - D/2, y + D/2] x [z_tip, oo) (spur gears). A helical pass
follows the lead (roughing.follow_lead): the tool's slice at dx from its axis sees the section turned by a further
dx tan(beta) / r, so the tool's section is the union of those slices turned (its reach and its corners' sag
follow from that union exactly, flank_space's `_Slices`).

Plan of one space (the same for every space, so computed once; docs/cam.md "Flank roughing"; steps 1 and 2 are
flank_space.py's):

1. Each flank (offset by the finish stock) is cut into segments from the lowest level (where the space is as wide
   as the tool) to the tip edge; a segment is as long as the material the tool's side leaves on it, measured
   horizontally in its turned frame, stays within SEGMENT_BUDGET_FRACTION x (flank_allowance_mm -
   finish_stock_mm).
2. For a segment, A is turned so that its chord is vertical (or less, where the tool would not fit); the tool's
   finishing position is the farthest toward the flank at which no point of the design grown by the finish stock
   lies inside the tool; its tip is at the segment's lower end.
3. Each segment is a run per flank: positions a radial engagement of at most max_radial_engagement_fraction x D
   apart, from where the tool finds nothing more to cut on its side of the space toward the flank, each at full
   depth in tiers (each from the top of the material left under the one before: at most the axial depth limit;
   at most max_level_depth_fraction x D where the tool is engaged wider; a sliver of a bottom tier before the
   flank's own position is left to later passes). A run that meets the other flank first cuts the column touching
   it first, then the positions beyond it with the tip raised clear of that flank, then back to its flank. A
   column down the middle takes the bottom, and a column each the pieces left where two segments' columns meet.
4. A stock model of the section (shapely polygons) follows every pass: it gives each pass's radial engagement and
   axial depth, the feed raised by chip thinning so the largest chip equals feed_per_tooth_mm, and the check that
   nothing farther than the flank allowance from the design is left (`uncut_mm2`).
5. Two-stage roughing: a second, smaller tool's plan starts from the section the first leaves in every space
   (stock_after_all_spaces) and cuts only what needs cutting there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from spur_cad.cam.flank_space import (
    SEGMENT_BUDGET_FRACTION,
    TOL_MM,
    FlankSegment,
    SpaceGeometry,
    clean_up_segment,
    flank_segment_count,
    flank_segments,
)
from spur_cad.cam.machine import MachineError, RoughingParams
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.geometry.spec import GearSpec

__all__ = ["UNCUT_MM2", "FlankLimits", "FlankPass", "FlankPlan", "FlankSegment", "chip_thinning_factor",
           "default_axial_depth_mm", "flank_segment_count", "plan_flank_roughing", "stock_after_all_spaces"]

EMPTY_AREA_MM2 = 1e-8  # the stock model's slivers below this are no material
MAX_POSITIONS = 100_000  # a run's positions (bounded by the space's width over the radial engagement)
UNCUT_MM2 = 1e-4  # a plan leaving more than this (stock model) beyond the flank allowance is incomplete


def chip_thinning_factor(radial_engagement_mm: float, diameter_mm: float, cap: float) -> float:
    """Feed factor that keeps the largest chip at f_z: D / (2 sqrt(a_e (D - a_e))) below half the diameter (the
    chip's thickest point is where the edge leaves the cut), 1 from there on; at most `cap`."""
    a_e = radial_engagement_mm
    if a_e >= diameter_mm / 2.0:
        return 1.0
    if a_e <= 0.0:
        return cap
    return min(cap, diameter_mm / (2.0 * math.sqrt(a_e * (diameter_mm - a_e))))


@dataclass(frozen=True)
class FlankLimits:
    """The engagement limits a flank roughing plan keeps (from [roughing] and the tool)."""

    diameter_mm: float
    radial_engagement_mm: float  # largest a_e of a pass deeper than a slot
    axial_depth_mm: float  # largest a_p of any pass
    slot_depth_mm: float  # largest a_p of a pass wider than radial_engagement_mm
    feed_factor_cap: float

    @staticmethod
    def of(tool: Tool, params: RoughingParams) -> FlankLimits:
        """The job's limits; the axial depth never beyond the flutes (when the tool gives their length)."""
        axial = params.max_axial_depth_mm or default_axial_depth_mm(tool)
        if tool.flute_length_mm > 0.0:
            axial = min(axial, tool.flute_length_mm)
        slot = min(params.max_level_depth_fraction * tool.diameter_mm, axial)
        return FlankLimits(tool.diameter_mm, params.max_radial_engagement_fraction * tool.diameter_mm, axial, slot,
                           params.max_feed_factor)


def default_axial_depth_mm(tool: Tool) -> float:
    """The axial depth limit when [roughing] max_axial_depth_mm is 0: the flute length, at most 3 D (the catalogue
    range for side milling with a small radial engagement with solid carbide end mills)."""
    return min(tool.flute_length_mm, 3.0 * tool.diameter_mm) if tool.flute_length_mm > 0.0 else \
        3.0 * tool.diameter_mm

@dataclass(frozen=True)
class FlankPass:
    """One pass along X of a space (turned frame: machine Y, Z at A = the space's A + turn)."""

    turn_deg: float
    y_mm: float
    z_mm: float
    radial_engagement_mm: float
    axial_depth_mm: float
    feed_factor: float
    run: int  # index of the (segment, side) run
    removed_mm2: float = 0.0  # the section's material the pass cuts (stock model)


@dataclass(frozen=True)
class FlankPlan:
    segments: tuple[FlankSegment, ...]
    passes: tuple[FlankPass, ...]
    limits: FlankLimits
    uncut_mm2: float  # what the plan leaves beyond the flank allowance (stock model; 0 when complete)
    stock: object = None  # shapely polygon: the section of space 0 and its neighbours' halves as the passes leave it
    start_stock: object = None  # the same before the passes

    @property
    def lowest_z_mm(self) -> float:
        return min(p.z_mm for p in self.passes)

    @property
    def max_radial_engagement_fraction(self) -> float:
        return max(p.radial_engagement_mm for p in self.passes) / self.limits.diameter_mm

    @property
    def max_axial_depth_mm(self) -> float:
        return max(p.axial_depth_mm for p in self.passes)

    @property
    def removed_mm2(self) -> float:
        """Section area one space's passes remove (stock model)."""
        return sum(p.removed_mm2 for p in self.passes)


class _Stock:
    """The material of one space's section (space frame) as the passes leave it, in shapely polygons."""

    def __init__(self, polygon):
        self.polygon = polygon

    def view(self, turn_deg: float, side: int):
        """The stock in a run's frame: turned, and mirrored for the left flank so that the passes step toward +u."""
        from shapely import affinity

        turned = affinity.rotate(self.polygon, turn_deg, origin=(0.0, 0.0))
        return turned if side > 0 else affinity.scale(turned, -1.0, 1.0, origin=(0.0, 0.0))

    def store(self, view, turn_deg: float, side: int) -> None:
        from shapely import affinity

        back = view if side > 0 else affinity.scale(view, -1.0, 1.0, origin=(0.0, 0.0))
        self.polygon = affinity.rotate(back, -turn_deg, origin=(0.0, 0.0))


def _polygons(geometry):
    """The polygonal parts of a shapely result with some area (intersections also return lines and points)."""
    import shapely

    parts = shapely.get_parts(geometry)
    return [part for part in parts if part.geom_type == "Polygon" and part.area >= EMPTY_AREA_MM2]


def _material(view, cut):
    import shapely

    parts = _polygons(view.intersection(cut))
    return shapely.MultiPolygon(parts) if parts else None


SMALL_TIER_FRACTION = 0.05
"""A tier under another at a position before the flank's own is left to later passes when it cuts less than this
fraction of a full side pass (radial engagement x axial depth)."""
BAND_SAMPLE_MM = 0.02  # heights at which a pass's material is measured across


def _tiers(material, u: float, radius: float, z_tip: float, step: float, limits: FlankLimits,
           direction: int = 1) -> list[tuple[float, float, float]]:
    """The tiers (z of the tool tip, top of the material it cuts, a_e) that cut the material in the tool's reach at
    position u, top first, each as deep as allowed: at most the slot depth where the material reaches farther than
    `step` from the tool's leading edge (u + radius; u - radius for `direction` -1), else at most the axial depth
    limit. The reach is measured on lines BAND_SAMPLE_MM apart, each line's taken as the largest of it and its
    neighbours, then checked exactly on the tier."""
    import shapely

    top = material.bounds[3]
    count = max(2, math.ceil((top - z_tip) / BAND_SAMPLE_MM) + 1)
    heights = np.linspace(z_tip, top, count)
    lines = shapely.linestrings(np.stack([np.stack([np.full(count, u - radius - 1.0), heights], axis=1),
                                          np.stack([np.full(count, u + radius + 1.0), heights], axis=1)], axis=1))
    bounds = shapely.bounds(shapely.intersection(material, lines))
    far_side = bounds[:, 0] if direction > 0 else bounds[:, 2]
    reach = np.where(np.isnan(far_side), 0.0, np.minimum(direction * (u - far_side) + radius, 2.0 * radius))
    padded = np.concatenate([[reach[0]], reach, [reach[-1]]])
    reach = np.maximum(reach, np.maximum(padded[:-2], padded[2:]))
    tiers = []
    high = top
    while high > z_tip + 1e-9:
        high = _reach(material, u, radius, z_tip, high, direction)[1]  # each tier's depth from the material's top
        if high <= z_tip + 1e-9:
            break
        low = max(high - limits.axial_depth_mm, z_tip)
        wide = (heights >= low - 1e-12) & (heights <= high + 1e-12) & (reach > step + 1e-6)
        if wide.any():
            highest_wide = float(heights[wide].max())
            low = highest_wide + BAND_SAMPLE_MM if highest_wide < high - limits.slot_depth_mm else \
                max(high - limits.slot_depth_mm, z_tip)
        a_e, top_here = _reach(material, u, radius, low, high, direction)
        if a_e > step + 1e-6 and high - low > limits.slot_depth_mm:  # wider between the lines: a slot tier
            low = max(high - limits.slot_depth_mm, z_tip)
            a_e, top_here = _reach(material, u, radius, low, high, direction)
        if a_e > 0.0:
            tiers.append((low, top_here, a_e))
        high = low
    return tiers


def _reach(material, u: float, radius: float, low: float, high: float, direction: int = 1) -> tuple[float, float]:
    """How far the material between two heights reaches from the tool's leading edge (u + radius advancing
    toward +u, `direction` 1; u - radius toward -u), and its top (0, low: none there)."""
    import shapely

    parts = _material(material, shapely.box(u - radius, low, u + radius, high))
    if parts is None:
        return 0.0, low
    far_side = parts.bounds[0] if direction > 0 else parts.bounds[2]
    return float(min(direction * (u - far_side) + radius, 2.0 * radius)), float(parts.bounds[3])


def _floor_mm(geo: SpaceGeometry, segment: FlankSegment, u: float, top_z: float) -> float:
    """The lowest tool tip at position u of a segment's run: the segment's tip where the tool is clear of the
    other flank there, else the height from which it is (bisection: the far limit falls as the tip rises)."""
    if u >= segment.far_y_mm - TOL_MM:
        return segment.tip_z_mm
    turn = math.radians(segment.turn_deg)
    low, high = segment.tip_z_mm, top_z
    if geo.limits(turn, high, "left")[1] > u:
        return top_z
    while high - low > 1e-7:
        mid = 0.5 * (low + high)
        low, high = (mid, high) if geo.limits(turn, mid, "left")[1] > u else (low, mid)
    return high


def _run_order(geo: SpaceGeometry, segment: FlankSegment, step: float, own_material,
               top_z: float) -> list[tuple[float, float, int]]:
    """A run's positions in cutting order as (u, tip height, the side the tool advances into: 1 toward +u), see
    _run_passes; `own_material(u, floor)`: whether the tool there meets material it must cut."""
    u_final, u_far, tip = segment.side_y_mm, segment.far_y_mm, segment.tip_z_mm
    for k in range(MAX_POSITIONS):
        u = u_final - k * step
        if u <= u_far + TOL_MM:  # the other flank: its column first, then beyond it, then back to the flank
            beyond = []
            for j in range(1, MAX_POSITIONS):
                floor = _floor_mm(geo, segment, u_far - j * step, top_z)
                if floor >= top_z or not own_material(u_far - j * step, floor):
                    break
                beyond.append((u_far - j * step, floor, -1))
            return [(u_far, tip, 1)] + beyond + [(v, tip, 1) for v in np.linspace(u_far, u_final, k + 1)[1:]]
        if not own_material(u, tip):
            return [(v, tip, 1) for v in u_final - step * np.arange(k)[::-1]]
    raise MachineError(f"flank roughing: a run would need more than {MAX_POSITIONS} positions", field="diameter_mm",
                       section="tools.roughing")


def _run_passes(stock: _Stock, geo: SpaceGeometry, segment: FlankSegment, side: int, run: int,
                limits: FlankLimits, model_radius: float, top_z: float, centre: bool = False,
                final_always: bool = True) -> list[FlankPass]:
    """The passes of one run (a segment's turn, one flank), the stock model updated after each; each position is
    cut at full depth in tiers (slot levels where the tool would be engaged wider than the radial limit).
    Positions step from the flank toward the middle of the space until the tool finds no more material that needs
    cutting on its own side of the space's centre line; they are then cut from there to the flank. Where the tool
    meets the other flank first, the column touching it is cut first (a slot in levels), then the positions beyond
    it with the tip raised clear of that flank, stepping away from the flank, then the positions back to the
    flank. `centre`: the one position of a segment on the space's centre line (the bottom's clean-up).
    `final_always`: the flank's own column is cut even where nothing in it needs cutting (it leaves the flank
    even); a second tool's plan leaves it out there."""
    import shapely
    from shapely import affinity

    turn = segment.turn_deg * side
    view = stock.view(turn, side)
    keep = _Stock(geo.keep).view(turn, side)  # within the flank allowance of the design: need not be cut
    half = affinity.rotate(shapely.box(0.0, -1e3, 1e3, 1e3), turn * side, origin=(0.0, 0.0))  # own side, turned
    u_final, tip = segment.side_y_mm, segment.tip_z_mm
    step = limits.radial_engagement_mm

    def box(u: float, floor: float):
        return shapely.box(u - model_radius, floor, u + model_radius, top_z)

    def own_material(u: float, floor: float) -> bool:
        """Material to cut on the run's side of the space's centre line, in the tool's reach at u or anywhere
        farther from the flank (a piece the tool's column misses at u may stand beyond it)."""
        reach = shapely.box(u - 1e3, floor, u + model_radius, top_z)
        return _material(view.intersection(half).difference(keep), reach) is not None

    order = [(u_final, tip, 1)] if centre else _run_order(geo, segment, step, own_material, top_z)
    passes: list[FlankPass] = []
    for u, floor, direction in order:
        material = _material(view, box(u, floor))
        needed = _material(view.difference(keep), box(u, floor))
        if material is None or (needed is None and (u != u_final or not final_always)):
            continue
        tiers = _tiers(material, u, model_radius, floor, step, limits, direction)
        if u != u_final:  # the tiers below the last needed material are left out
            lowest_needed = needed.bounds[1]
            while len(tiers) > 1 and tiers[-1][1] <= lowest_needed + 1e-9 and tiers[-2][0] >= lowest_needed - 1e-9:
                tiers.pop()
            small = SMALL_TIER_FRACTION * step * limits.axial_depth_mm
            while len(tiers) > 1 and material.intersection(shapely.box(u - model_radius, tiers[-1][0], u + model_radius,
                                                                       tiers[-2][0])).area < small:
                tiers.pop()  # a sliver at the bottom: later positions, the bottom column or a clean-up column take it
        ceiling = top_z
        for low, high, a_e in tiers:
            factor = chip_thinning_factor(a_e, limits.diameter_mm, limits.feed_factor_cap)
            area = material.intersection(shapely.box(u - model_radius, low, u + model_radius, ceiling)).area
            passes.append(FlankPass(turn, u * side, low, a_e, high - low, factor, run, float(area)))
            ceiling = low
        view = view.difference(box(u, tiers[-1][0]))
    stock.store(view, turn, side)
    return passes


def plan_flank_roughing(spec: GearSpec, tool: Tool, params: RoughingParams, blank_radius_mm: float,
                        lowest_height_mm: float, model_radius_mm: float, land_half_width_mm: float,
                        start_stock=None) -> FlankPlan:
    """The passes of one tooth space (module docstring); `lowest_height_mm`: the lowest level (the space as wide
    as the tool's transverse width), `model_radius_mm`: the tool's half-width in the stock model (its transverse
    radius for a helical gear), `land_half_width_mm`: how far the tip passes clear each side of a tooth's centre
    line (what they leave is not the runs' to take). `start_stock`: the section as a first tool left it
    (stock_after_all_spaces), for a second tool's plan (two-stage roughing). Pure."""
    import shapely.affinity

    geo = SpaceGeometry(spec, tool, params, blank_radius_mm)
    limits = FlankLimits.of(tool, params)
    budget = SEGMENT_BUDGET_FRACTION * (params.flank_allowance_mm - params.finish_stock_mm)
    segments = flank_segments(geo, lowest_height_mm, budget, tool.diameter_mm / 2.0, params)
    if not segments:
        raise ToolError("flank roughing: no flank segment above the lowest level", field="diameter_mm",
                        section="tools.roughing")
    first = geo.stock if start_stock is None else start_stock
    stock = _Stock(first)
    passes: list[FlankPass] = []
    run = 0
    for side in (1, -1):
        for segment in segments:  # the lowest (longest) first: the higher ones take what it leaves
            passes.extend(_run_passes(stock, geo, segment, side, run, limits, model_radius_mm,
                                      blank_radius_mm + 1.0, final_always=start_stock is None))
            run += 1
    # the bottom of the space between the lowest segments' columns, straight down the middle to the lowest level
    bottom = FlankSegment(0.0, lowest_height_mm, 0.0, 0.0, 0.0, lowest_height_mm, lowest_height_mm)
    passes.extend(_run_passes(stock, geo, bottom, 1, run, limits, model_radius_mm, blank_radius_mm + 1.0,
                              centre=True))
    # what the runs left where two segments' columns meet: a column each, turned between the segments' turns
    turns = [segment.turn_deg for segment in segments] + [0.0] * (len(segments) == 1)
    for piece in _polygons(_uncut(geo, stock, spec, params, lowest_height_mm, land_half_width_mm)):
        if piece.area < 0.1 * UNCUT_MM2:  # a sliver: not worth a pass
            continue
        side = 1 if piece.centroid.x >= 0.0 else -1
        mirrored = piece if side > 0 else shapely.affinity.scale(piece, -1.0, 1.0, origin=(0.0, 0.0))
        column = clean_up_segment(geo, mirrored, turns)
        if column is not None:
            run += 1
            passes.extend(_run_passes(stock, geo, column, side, run, limits, model_radius_mm, blank_radius_mm + 1.0,
                                      centre=True))
    uncut = _uncut(geo, stock, spec, params, lowest_height_mm, land_half_width_mm)
    return FlankPlan(tuple(segments), tuple(passes), limits, float(uncut.area), stock.polygon, first)


def stock_after_all_spaces(spec: GearSpec, plan: FlankPlan, land_half_width_mm: float, finish_stock_mm: float):
    """The section stock a plan leaves once every space is cut, for a second tool's plan to start from: its stock
    model cuts space 0 with its neighbours uncut, so what space 0's passes removed, turned by a pitch each way, is
    removed too; and the tip lands' columns (`land_half_width_mm` each side of a tooth's centre line) down to the
    tip radius + finish stock (the tip passes' floor)."""
    import shapely
    from shapely import affinity

    pitch_deg = 360.0 / spec.teeth
    removed = shapely.difference(plan.start_stock, plan.stock, grid_size=GRID_MM)
    top = 2.0 * (spec.tip_radius_mm + 10.0 * spec.module_mm)
    lands = [affinity.rotate(shapely.box(-land_half_width_mm, spec.tip_radius_mm + finish_stock_mm, land_half_width_mm,
                                         top), sign * pitch_deg / 2.0, origin=(0.0, 0.0)) for sign in (-1.0, 1.0)]
    cuts = [affinity.rotate(removed, sign * pitch_deg, origin=(0.0, 0.0)) for sign in (-1.0, 0.0, 1.0)] + lands
    stock = shapely.difference(plan.start_stock, shapely.union_all(cuts, grid_size=GRID_MM), grid_size=GRID_MM)
    return shapely.union_all(_polygons(stock))


GRID_MM = 1e-7
"""The precision grid of stock_after_all_spaces's overlays (turned copies of one outline meet at nearly the same
points: without a grid GEOS may find them not noded)."""


def _uncut(geo: SpaceGeometry, stock: _Stock, spec: GearSpec, params: RoughingParams, lowest_height_mm: float,
           land_half_width_mm: float):
    """What the stock model's section still holds in the space farther than flank_allowance_mm (+1 um) from the
    design above the lowest level, less the tip lands' columns (their passes reach `land_half_width_mm` each side of
    a tooth's centre line)."""
    import shapely
    from shapely import affinity

    half = math.pi / spec.teeth
    angles = np.linspace(-half, half, 65)
    sector = shapely.Polygon(np.concatenate([[[0.0, 0.0]], 2.0 * geo.blank * np.stack([np.sin(angles),
                                                                                       np.cos(angles)], axis=1)]))
    above = shapely.box(-geo.blank, lowest_height_mm, geo.blank, 2.0 * geo.blank)
    band = geo.design.buffer(params.flank_allowance_mm + 1e-3, quad_segs=32)
    lands = shapely.union_all([affinity.rotate(shapely.box(-land_half_width_mm, spec.tip_radius_mm, land_half_width_mm,
                                                           2.0 * geo.blank), sign * math.degrees(half),
                                               origin=(0.0, 0.0)) for sign in (-1.0, 1.0)])
    return stock.polygon.intersection(sector).intersection(above).difference(band).difference(lands)
