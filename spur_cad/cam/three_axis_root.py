"""The root a flat end mill's side leaves on a gear cut lying flat ([machine] axes = 3, docs/cam.md).

The tool's circle (radius r_t) rolls along the exact tooth-space outline; where the outline is concave more
tightly than r_t (the rack-generated fillet near the root) or the space is too narrow, the circle cannot follow
it and leaves a fillet of radius r_t instead. What is left is the outline "closed" by a disk of r_t. This module
finds where the tool's contour leaves the involute (the form radius that results) and compares it with the start
of the active profile: the involute must be cut down to there.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from spur_cad.cam.tools import Tool, ToolError
from spur_cad.errors import SpurCadError
from spur_cad.geometry.internal import as_ring, mating_pinion_mesh
from spur_cad.geometry.kinds import EXTERNAL_HELICAL, EXTERNAL_SPUR, INTERNAL_SPUR, GearKind
from spur_cad.geometry.mate import GearPair, PairMember, pair_facts
from spur_cad.geometry.spec import GearSpec

if TYPE_CHECKING:  # scipy.spatial costs 0.3-0.4 s to import: loaded by the 3-axis plan that uses it, not by every run
    from scipy.spatial import cKDTree

ROOT_SAMPLE_SPACING_MM = 0.005
"""Spacing of the exact outline's samples the tool circle is tested against: the nearest sample is farther than
the curve by at most (spacing / 2)^2 / (2 r_t), 6 nm for r_t = 0.5 mm. The involute's lowest reached point is then
refined to 1/200 of it."""


@dataclass(frozen=True)
class FlatMillRoot:
    """What a flat end mill of radius `tool_radius_mm` leaves at the root of every space."""

    tool_radius_mm: float
    form_radius_mm: float  # where the tool's contour leaves the involute (the rack-generated form radius at least)
    rack_form_radius_mm: float  # the rack-generated involute's start
    active_start_radius_mm: float  # start of the active profile (mesh with the basic rack)
    fillet_radius_mm: float  # the smallest concave radius of the root that results (r_t when the tool leaves the
    #                          rack's fillet, else the rack fillet's own smallest radius)
    tool_leaves_rack_fillet: bool  # the tool cannot follow the rack-generated fillet everywhere
    internal: bool = False  # a ring: its spaces open toward the axis, root and form radius above the active profile

    @property
    def fits(self) -> bool:
        """The involute is cut down to (a ring: out to) the start of the active profile."""
        if self.internal:
            return self.form_radius_mm >= self.active_start_radius_mm - 1e-9
        return self.form_radius_mm <= self.active_start_radius_mm + 1e-9


def active_profile_start_radius_mm(spec: GearSpec) -> float:
    """Radius where the active profile starts: in mesh with the real mate when the job gives one ([mate]:
    spec.active_profile_start_diameter_mm), else with the basic rack: the line of action meets the mating
    rack's addendum line (h_a* m below the rolling line shifted by x m); the base radius if that is below it.
    A ring's without a mate: ring_active_profile_start(spec)'s radius."""
    if spec.active_profile_start_diameter_mm > 0.0:
        return spec.active_profile_start_diameter_mm / 2.0
    return SPACES[spec.kind].active_start(spec)[0]


def rack_active_profile_start(spec: GearSpec) -> tuple[float, str]:
    """Where an external gear's active profile starts in mesh with the basic rack, and what sets it."""
    alpha = spec.pressure_angle_rad
    r, rb = spec.reference_radius_mm, spec.base_radius_mm
    depth = (spec.addendum_coefficient - spec.profile_shift_coefficient) * spec.module_mm
    along = r * math.sin(alpha) - depth / math.sin(alpha)  # from the base circle's tangent point
    return math.sqrt(rb * rb + max(along, 0.0) ** 2), "the basic rack"


def _dense(segment, spacing_mm: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points, normals (into the space) and parameters of one exact segment, about `spacing_mm` apart."""
    coarse = segment.points(np.linspace(segment.start, segment.end, 257))
    length = float(np.hypot(*np.diff(coarse, axis=0).T).sum())
    parameters = np.linspace(segment.start, segment.end, max(2, math.ceil(length / spacing_mm) + 1))
    return segment.points(parameters), segment.normals(parameters), parameters


@dataclass(frozen=True)
class _SpaceSamples:
    """The exact outline of one space sampled once (a tree of both sides) and its involute's and fillet's points
    with normals into the space."""

    tree: cKDTree
    involute: tuple[np.ndarray, np.ndarray, np.ndarray]  # points, normals, parameters
    fillet: tuple[np.ndarray, np.ndarray, np.ndarray] | None


def _space_samples(spec: GearSpec) -> _SpaceSamples:
    from scipy.spatial import cKDTree

    profile = spec.tooth_space_profile()
    parts = {segment.label: _dense(segment, ROOT_SAMPLE_SPACING_MM) for segment in profile.segments}
    right = np.concatenate([p for p, _, _ in parts.values()])
    tree = cKDTree(np.concatenate([right, right * np.array([-1.0, 1.0])]))
    return _SpaceSamples(tree, parts["involute"], parts.get("fillet"))


def flat_mill_root(spec: GearSpec, tool_radius_mm: float, samples: _SpaceSamples | None = None) -> FlatMillRoot:
    """The root a flat end mill of radius `tool_radius_mm` leaves (see the module docstring): the involute's
    lowest point whose tool circle (centre on the normal into the space, r_t away) stays clear of the whole space
    outline (both sides, root, fillets) within 0.1 um."""
    profile = spec.tooth_space_profile()
    samples = samples or _space_samples(spec)
    limit = tool_radius_mm - 1e-7  # only whether a sample is closer than this matters (a fast query)

    def lowest_reached(points: np.ndarray, normals: np.ndarray) -> int:
        clearance, _ = samples.tree.query(points + tool_radius_mm * normals, distance_upper_bound=limit)
        unreached = np.flatnonzero(clearance < limit)
        return 0 if len(unreached) == 0 else min(int(unreached[-1]) + 1, len(points) - 1)

    points, normals, parameters = samples.involute
    first = lowest_reached(points, normals)
    form = float(np.hypot(*points[first]))
    if first > 0:  # refined between the last sample not reached and the first reached
        involute = profile.involute
        fine = np.linspace(parameters[first - 1], parameters[first], 201)
        fine_points = involute.points(fine)
        form = float(np.hypot(*fine_points[lowest_reached(fine_points, involute.normals(fine))]))
    follows = profile.min_fillet_curvature_radius_mm >= tool_radius_mm and first == 0
    if samples.fillet is not None and follows:  # the tool follows the fillet's curvature: is the space wide enough?
        fillet_points, fillet_normals, _ = samples.fillet
        follows = bool(np.all(samples.tree.query(fillet_points + tool_radius_mm * fillet_normals,
                                                 distance_upper_bound=limit)[0] >= limit))
    fillet_radius = profile.min_fillet_curvature_radius_mm if follows and samples.fillet is not None \
        else tool_radius_mm
    spaces = SPACES[spec.kind]
    form = min(form, profile.form_radius_mm) if spaces.internal else max(form, profile.form_radius_mm)
    return FlatMillRoot(tool_radius_mm, form, profile.form_radius_mm, active_profile_start_radius_mm(spec),
                        float(fillet_radius), not follows, spaces.internal)


def largest_flat_mill_radius_mm(spec: GearSpec, resolution_mm: float = 0.005) -> float:
    """The largest flat end mill radius (to `resolution_mm`, rounded down) whose root leaves the involute no higher
    than the start of the active profile; 0 when none does."""
    samples = _space_samples(spec)
    low, high = 0.0, spec.space_width_mm / 2.0
    while high - low > resolution_mm:
        middle = 0.5 * (low + high)
        if flat_mill_root(spec, middle, samples).fits:
            low = middle
        else:
            high = middle
    return math.floor(low / resolution_mm) * resolution_mm


def ring_active_profile_start(spec: GearSpec) -> tuple[float, str]:
    """Where an internal gear's active profile starts (its largest radius on the involute) and what sets it: the
    mating pinion's tip circle when `mating_pinion_teeth` is given (no shift, addendum h_a* m, at the
    zero-backlash centre distance), else the shaper cutter's teeth and shift as a mating gear with the addendum
    (h_a* + x_0) m at the cutting centre distance (the ring's analogue of the basic rack's addendum line). Along
    the line of action the ring's roll length is the pinion's plus a sin(alpha_w) (both base tangent points lie on
    one side of the pitch point)."""
    ring = as_ring(spec)
    m = spec.module_mm
    if ring.mating_pinion_teeth:
        centre_distance, alpha_w, pinion_base, pinion_tip = mating_pinion_mesh(ring)
        source = f"the {ring.mating_pinion_teeth}-tooth mating pinion's tips"
    else:
        cutter, mesh = ring.shaper_cutter().spec, ring.cutting_mesh()
        centre_distance, alpha_w = mesh.centre_distance_mm, ring.cutting_pressure_angle_rad
        pinion_base = cutter.base_radius_mm
        pinion_tip = cutter.reference_radius_mm + (spec.addendum_coefficient + cutter.profile_shift_coefficient) * m
        source = f"the {cutter.teeth}-tooth shaper cutter's mesh (as a mating gear of addendum h_a* m)"
    roll_mm = centre_distance * math.sin(alpha_w) + math.sqrt(max(pinion_tip**2 - pinion_base**2, 0.0))
    return math.hypot(spec.base_radius_mm, roll_mm), source


ROOT_THICKNESS_TOLERANCE_MM = 0.0002
"""Chordal tolerance of the outline the root thickness is measured on (shapely polygons; their disks' arcs are
finer: ROOT_THICKNESS_QUAD_SEGMENTS)."""
ROOT_THICKNESS_QUAD_SEGMENTS = 256
"""Segments per quarter circle of the tool's disk when the tooth is closed by it (sag r (1 - cos(pi / 1024)): 5 nm
per mm of tool radius)."""


@dataclass(frozen=True)
class RootThickness:
    """The tooth's chordal thickness near the root, cut by a flat end mill's side (radius `tool_radius_mm`) and as
    the basic rack generates it: at the rack's form circle (the root form circle, where its involute starts) and at
    the fillet's middle (halfway between the root and form circles)."""

    tool_radius_mm: float
    form_diameter_mm: float
    form_thickness_mm: float  # cut by the tool
    rack_form_thickness_mm: float
    fillet_diameter_mm: float
    fillet_thickness_mm: float
    rack_fillet_thickness_mm: float


def root_thickness(spec: GearSpec, tool_radius_mm: float) -> RootThickness:
    """The tooth's root thickness the tool leaves beside the rack-generated one (see RootThickness): what a disk of
    the tool's radius cannot reach in the spaces stays (the gear closed by the disk, shapely buffers), and each
    tooth's chord is where a circle about the axis crosses it."""
    from shapely.geometry import LineString, Polygon

    from spur_cad.geometry.sampling import gear_outline

    outline = Polygon(gear_outline(spec, ROOT_THICKNESS_TOLERANCE_MM))
    gear, cut = SPACES[spec.kind].gear_and_cut(spec, outline, tool_radius_mm)
    form = spec.tooth_space_profile().form_radius_mm
    fillet = 0.5 * (spec.root_radius_mm + form)
    middle = math.pi / 2.0 + math.pi / spec.teeth  # tooth 0's centre: between spaces 0 (on +Y) and 1

    def chord(shape, radius_mm: float) -> float:
        turns = middle + np.linspace(-math.pi / spec.teeth, math.pi / spec.teeth, 20001)
        arc = LineString(np.stack([radius_mm * np.cos(turns), radius_mm * np.sin(turns)], axis=1))
        pieces = shape.intersection(arc)
        pieces = getattr(pieces, "geoms", [pieces])
        piece = max(pieces, key=lambda p: p.length)
        (x0, y0), (x1, y1) = piece.coords[0], piece.coords[-1]
        return math.hypot(x1 - x0, y1 - y0)

    return RootThickness(tool_radius_mm, 2 * form, chord(cut, form), chord(gear, form), 2 * fillet,
                         chord(cut, fillet), chord(gear, fillet))


def active_profile_start_source(spec: GearSpec) -> str:
    """What sets the start of the active profile, as a message names it."""
    if spec.active_profile_start_diameter_mm > 0.0:
        return "set by the mate's tips"
    return f"set by {SPACES[spec.kind].active_start(spec)[1]}: no [mate]"


def _fits_text(spec: GearSpec) -> str:
    largest = largest_flat_mill_radius_mm(spec)
    return f"D {2 * largest:.2f} mm fits" if largest > 0.0 else "none fits"


def _remedies(spec: GearSpec) -> str:
    """What the designer can change when no flat end mill reaches the active profile, each with the largest tool
    it would allow (found as for the job itself): the real mate (one like the gear at the standard centre distance
    as the example), half the rack tip radius, 0.2 more profile shift, a protuberance rack."""
    options = []
    if spec.active_profile_start_diameter_mm == 0.0 and SPACES[spec.kind].mate_remedy:
        pair = GearPair(PairMember(spec.teeth, profile_shift_coefficient=spec.profile_shift_coefficient),
                        PairMember(spec.teeth), spec.module_mm, spec.pressure_angle_deg, spec.helix_angle_deg)
        sap = pair_facts(pair).start_of_active_profile_diameter_mm
        mated = dataclasses.replace(spec, active_profile_start_diameter_mm=sap)
        options.append(f"[mate] (a z{spec.teeth} mate: SAP {sap:.3f} mm, {_fits_text(mated)})")
    if spec.rack_tip_radius_mm > 0.0:
        smaller = dataclasses.replace(spec, rack_tip_radius_mm=round(spec.rack_tip_radius_mm / 2.0, 6))
        options.append(f"rack_tip_radius_mm {smaller.rack_tip_radius_mm:g} ({_fits_text(smaller)})")
    try:
        shifted = dataclasses.replace(spec, profile_shift_coefficient=spec.profile_shift_coefficient + 0.2)
        options.append(f"profile shift {shifted.profile_shift_coefficient:g} ({_fits_text(shifted)})")
    except SpurCadError:
        pass
    return ", ".join(options) + " or a protuberance rack"


def unreachable_message(spec: GearSpec, tool: Tool, root: FlatMillRoot) -> str:
    """One line: where the tool's side leaves the involute, the active profile's start and what sets it, then the
    largest tool that works, or when none does what the designer can change and with what effect."""
    spaces = SPACES[spec.kind]
    head = (f"a D {tool.diameter_mm:g} mm flat end mill's side leaves the {spaces.involute} at diameter "
            f"{2 * root.form_radius_mm:.3f} mm, {spaces.beyond} the active profile's start at "
            f"{2 * root.active_start_radius_mm:.3f} mm ({active_profile_start_source(spec)})")
    largest = largest_flat_mill_radius_mm(spec)
    if largest > 0.0:
        return f"{head}; the largest tool radius that works is {largest:.3f} mm (D {2 * largest:.2f} mm)"
    return f"{head}; no flat end mill fits; change: {_remedies(spec)}"


def check_flat_mill_root(spec: GearSpec, finishing_tool: Tool) -> FlatMillRoot:
    """The root the finishing tool leaves in the spaces (an external gear's or a ring's); ToolError (one line,
    unreachable_message) when its fillet reaches the active profile."""
    root = flat_mill_root(spec, finishing_tool.diameter_mm / 2.0)
    if not root.fits:
        raise ToolError(unreachable_message(spec, finishing_tool, root), field="diameter_mm",
                        section="tools.finishing")
    return root


def _external_gear_and_cut(spec: GearSpec, outline, tool_radius_mm: float) -> tuple:
    """An external gear: its section, and the section closed by the tool's disk."""
    return outline, outline.buffer(tool_radius_mm, quad_segs=ROOT_THICKNESS_QUAD_SEGMENTS).buffer(
        -tool_radius_mm, quad_segs=ROOT_THICKNESS_QUAD_SEGMENTS)


def _ring_gear_and_cut(spec: GearSpec, outline, tool_radius_mm: float) -> tuple:
    """A ring: the rim disc less the hole; the tool's disk opens the hole instead."""
    from shapely.geometry import Point

    rim = Point(0.0, 0.0).buffer(as_ring(spec).rim_outer_diameter_mm / 2.0, quad_segs=ROOT_THICKNESS_QUAD_SEGMENTS)
    return rim.difference(outline), rim.difference(outline.buffer(
        -tool_radius_mm, quad_segs=ROOT_THICKNESS_QUAD_SEGMENTS).buffer(tool_radius_mm,
                                                                        quad_segs=ROOT_THICKNESS_QUAD_SEGMENTS))


@dataclass(frozen=True)
class Spaces:
    """Which way one gear kind's tooth spaces open, as a flat end mill's root is read there:
    - `internal`: toward the axis (a ring: its root and form radius lie outward of the active profile);
    - `active_start`: where the active profile starts without a [mate], and what sets it;
    - `gear_and_cut`: the gear's section (shapely) and what the tool's disk leaves of it (root_thickness);
    - `mate_remedy`: a mate like the gear is a remedy the message offers (external gears);
    - `involute` / `beyond`: the message's words for the flank and for the side of the active profile's start."""

    internal: bool
    active_start: Callable[[GearSpec], tuple[float, str]]
    gear_and_cut: Callable[[GearSpec, Any, float], tuple]
    mate_remedy: bool
    involute: str
    beyond: str


OUTWARD = Spaces(False, rack_active_profile_start, _external_gear_and_cut, True, "involute", "above")
RING = Spaces(True, ring_active_profile_start, _ring_gear_and_cut, False, "ring's involute", "inside")
SPACES: dict[GearKind, Spaces] = {EXTERNAL_SPUR: OUTWARD, EXTERNAL_HELICAL: OUTWARD, INTERNAL_SPUR: RING}
"""How each gear kind's spaces open."""
