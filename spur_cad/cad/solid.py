"""Exact B-rep gear solid and stock with OCP/CadQuery, in the machine frame of docs/architecture.md.

Machine frame: gear axis = X, front face at X = 0, the gear occupies 0 <= X <= b; the
transverse plane is (Y, Z) with the gap frame's x -> Y and y -> Z, so tooth space 0 is
symmetric about +Z and space k is turned by k * 360/z degrees about +X (positive A).

A helical gear is the transverse outline swept along X while turning with the helix (OCP pipe
shell with an auxiliary helix of the gear's lead and hand), so its section at X is the outline
turned by X tan(beta) / r.

Transverse profile of one space: root arc and tip arcs are exact circles; fillet and involute
are B-splines interpolated by OCP (GeomAPI_Interpolate) through exact points with their exact
tangents, refined until the largest distance from the exact curve (checked by OCP's point
projection on dense exact points) is within the fit tolerance.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable

import numpy as np
from OCP.BRep import BRep_Builder
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut, BRepAlgoAPI_Fuse
from OCP.BRepBuilderAPI import (
    BRepBuilderAPI_MakeEdge,
    BRepBuilderAPI_MakeFace,
    BRepBuilderAPI_MakeWire,
    BRepBuilderAPI_NurbsConvert,
    BRepBuilderAPI_Sewing,
)
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepGProp import BRepGProp
from OCP.BRepLib import BRepLib
from OCP.BRepOffsetAPI import BRepOffsetAPI_MakePipeShell, BRepOffsetAPI_ThruSections
from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder, BRepPrimAPI_MakePrism
from OCP.Geom import Geom_BSplineCurve, Geom_CylindricalSurface
from OCP.Geom2d import Geom2d_Line
from OCP.GeomAbs import GeomAbs_Plane
from OCP.gp import gp_Ax2, gp_Ax3, gp_Circ, gp_Dir, gp_Dir2d, gp_Pnt, gp_Pnt2d, gp_Trsf, gp_Vec
from OCP.GProp import GProp_GProps
from OCP.ShapeFix import ShapeFix_Face
from OCP.ShapeUpgrade import ShapeUpgrade_UnifySameDomain
from OCP.TopAbs import TopAbs_FACE, TopAbs_SHELL
from OCP.TopExp import TopExp_Explorer
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS, TopoDS_Edge, TopoDS_Shape, TopoDS_Solid, TopoDS_Wire

from spur_cad.cad.ocp_compat import MakeSegment2d
from spur_cad.cad.section_edges import (  # noqa: F401  (re-exported: the names callers know from here)
    CHECK_POINTS_PER_SPAN,
    FIT_TOLERANCE_PER_MODULE,
    FittedCurve,
    arc_edge,
    default_fit_tolerance_mm,
    fit_segment,
    gear_face_edges,
    interpolate,
    machine_point,
    max_deviation,
    mirror_y,
    modified_face_edges,
    rotation_about_x,
    transformed_edge,
    travel_tangents,
)
from spur_cad.cad.specs import BlankFeatures, GearSolidReport, StockSpec
from spur_cad.errors import ArgumentError, WorkLimitError, require_instance
from spur_cad.geometry.internal import InternalGearSpec, as_ring
from spur_cad.geometry.kinds import EXTERNAL_HELICAL, EXTERNAL_SPUR, INTERNAL_SPUR, GearKind
from spur_cad.geometry.modifications import SIDES, FlankModifications, modified_tooth_space_profile
from spur_cad.geometry.sampling import segment_parameters
from spur_cad.geometry.spec import GearSpec

LOFT_SECTIONS_PER_ZONE = 5
"""Sections per smooth stretch of the face width in a lead-modified loft (spur gears; helical gears add one per
degree of helix turn)."""
LOFT_PRECISION_MM = 1e-7
"""ThruSections' approximation tolerance across the sections (its pres3d)."""
LOFT_SEWING_TOLERANCE_MM = 1e-6
"""Lofts of neighbouring stretches and the end faces are sewn along edges this close."""
MAX_LOFT_POLES = 1_000_000
"""A lead-modified gear is refused (WorkLimitError) rather than lofted through more section poles than this (the
estimate of `_check_loft_size`: the 17-tooth m = 2 gear with every modification has 57 000 spur and 180 000 at
20 degrees helix, built in about 3 s; 1 000 000 took 2.5 minutes on a 2-core machine)."""


def _loft_sections_x_mm(spec: GearSpec, modifications: FlankModifications) -> list[np.ndarray]:
    """Face positions of the loft's sections, one array per smooth stretch between the end reliefs' starts (kinks
    along X); neighbouring stretches share their boundary section."""
    b = spec.face_width_mm
    kinks = sorted(set(modifications.right.lead_kinks_mm()) | set(modifications.left.lead_kinks_mm()))
    bounds = [0.0, *kinks, b]
    zones = []
    for x0, x1 in zip(bounds, bounds[1:]):
        turn_deg = math.degrees(abs(spec.section_turn_rad(x1) - spec.section_turn_rad(x0)))
        zones.append(np.linspace(x0, x1, LOFT_SECTIONS_PER_ZONE + math.ceil(turn_deg)))
    return zones


def _check_loft_size(spec: GearSpec, zones: list[np.ndarray], design: GearSolidReport) -> None:
    """Refuse a loft whose surfaces would hold more than MAX_LOFT_POLES poles, estimated before any fitting from the
    design flank's fit (poles per flank x 2 flanks x teeth x sections)."""
    sections = sum(len(xs) for xs in zones) - (len(zones) - 1)
    poles = sections * spec.teeth * 2 * (design.fillet_poles + design.involute_poles)
    if poles > MAX_LOFT_POLES:
        turn_deg = math.degrees(abs(spec.section_turn_rad(spec.face_width_mm)))
        raise WorkLimitError(f"the lead-modified flanks would be lofted through about {poles:.3g} B-spline poles "
                             f"(limit {MAX_LOFT_POLES:.3g}): {spec.teeth} teeth, {sections} sections along the face "
                             f"width ({LOFT_SECTIONS_PER_ZONE} per stretch between end reliefs plus one per degree of "
                             f"helix turn, {turn_deg:.0f} degrees here); a narrower face width, a smaller helix "
                             "angle or no lead modification would do")


def _fit_section_family(segments: list, fit_tolerance_mm: float) -> list[Geom_BSplineCurve]:
    """B-splines through the same segment of every section, all on one set of parameters (fractions of each
    segment's parameter range, chosen on the middle section), so they share degree and knots and the loft needs
    no knot merging; refined together until every one is within the tolerance of its exact segment."""
    reference = segments[len(segments) // 2]
    chordal = 0.01
    for _ in range(12):
        params = segment_parameters(reference, chordal)
        fractions = (params - reference.start) / (reference.end - reference.start)
        curves, worst = [], 0.0
        for segment in segments:
            t = segment.start + fractions * (segment.end - segment.start)
            curve = interpolate(segment.points(t), travel_tangents(segment, t), fractions)
            check = np.concatenate([np.linspace(a, b, CHECK_POINTS_PER_SPAN, endpoint=False)[1:]
                                    for a, b in zip(t, t[1:])])
            worst = max(worst, max_deviation(curve, segment.points(check)))
            curves.append(curve)
        if worst <= fit_tolerance_mm:
            return curves
        chordal /= 4.0
    raise RuntimeError(f"could not fit the modified {reference.label} within {fit_tolerance_mm} mm")


def _modified_section_wires(spec: GearSpec, modifications: FlankModifications, xs: np.ndarray,
                            fit_tolerance_mm: float) -> list[TopoDS_Wire]:
    """The modified outline at each face position in `xs` as a wire in its plane X, turned with the helix; each
    flank segment fitted on the same parameters in every section (`_fit_section_family`)."""
    profile = spec.tooth_space_profile()
    fitted, tip_angles = {}, {}
    for side in SIDES:
        sections = [modified_tooth_space_profile(profile, modifications.side(side), float(x)) for x in xs]
        flanks = [[seg for seg in section.segments if seg.label in ("fillet", "involute") and seg.end > seg.start]
                  for section in sections]
        if len({len(segments) for segments in flanks}) != 1:
            raise RuntimeError("the modified sections differ in their segments (a relief start at the tip?)")
        fitted[side] = [_fit_section_family([segments[k] for segments in flanks], fit_tolerance_mm)
                        for k in range(len(flanks[0]))]
        tip_angles[side] = [section.tip.start for section in sections]
    mirror = mirror_y()
    pitch = 2.0 * math.pi / spec.teeth
    v = profile.root_arc_half_angle_rad
    wires = []
    for j, x in enumerate(xs):
        right = [BRepBuilderAPI_MakeEdge(family[j]).Edge() for family in fitted["right"]]
        left = [transformed_edge(BRepBuilderAPI_MakeEdge(family[j]).Edge(), mirror) for family in fitted["left"]]
        space_edges = list(reversed(left))
        if v > 0.0:
            space_edges.append(arc_edge(spec.root_radius_mm, -v, v))
        space_edges.extend(right)
        space_edges.append(arc_edge(spec.tip_radius_mm, tip_angles["right"][j], pitch - tip_angles["left"][j]))
        place = rotation_about_x(spec.section_turn_rad(float(x)))
        shift = gp_Trsf()
        shift.SetTranslation(gp_Vec(float(x), 0.0, 0.0))
        place.Multiply(shift)
        wire_maker = BRepBuilderAPI_MakeWire()
        for k in range(spec.teeth):
            space = place.Multiplied(rotation_about_x(-k * pitch))
            for edge in space_edges:
                wire_maker.Add(transformed_edge(edge, space))
        if not wire_maker.IsDone():
            raise RuntimeError("the modified transverse outline did not close into a wire")
        wires.append(wire_maker.Wire())
    return wires


def _loft_lead_modified(spec: GearSpec, modifications: FlankModifications, fit_tolerance_mm: float,
                        design: GearSolidReport) -> TopoDS_Shape:
    """A gear with lead modifications: B-spline surfaces through modified sections along X (OCP's ThruSections, a
    shell per smooth stretch of the face width between the end reliefs' starts), every section fitted on the same
    parameters; the shells and the two end faces sewn into one solid (a boolean fuse of the stretches took
    minutes)."""
    zones = _loft_sections_x_mm(spec, modifications)
    _check_loft_size(spec, zones, design)
    every_x = np.concatenate([zones[0], *(xs[1:] for xs in zones[1:])])
    wires = _modified_section_wires(spec, modifications, every_x, fit_tolerance_mm)
    sewing = BRepBuilderAPI_Sewing(LOFT_SEWING_TOLERANCE_MM)
    first = 0
    for xs in zones:
        loft = BRepOffsetAPI_ThruSections(False, False, LOFT_PRECISION_MM)
        loft.CheckCompatibility(False)
        for wire in wires[first:first + len(xs)]:
            loft.AddWire(wire)
        loft.Build()
        if not loft.IsDone():
            raise RuntimeError("the loft through the modified sections failed")
        sewing.Add(loft.Shape())
        first += len(xs) - 1
    for wire in (wires[0], wires[-1]):
        sewing.Add(BRepBuilderAPI_MakeFace(wire, True).Face())
    sewing.Perform()
    shells = TopExp_Explorer(sewing.SewedShape(), TopAbs_SHELL)
    if not shells.More():
        raise RuntimeError("sewing the lofted flanks gave no shell")
    solid = TopoDS_Solid()
    builder = BRep_Builder()
    builder.MakeSolid(solid)
    builder.Add(solid, TopoDS.Shell(shells.Current()))
    shells.Next()
    if shells.More():
        raise RuntimeError("sewing the lofted flanks gave more than one shell")
    BRepLib.OrientClosedSolid_s(solid)
    return solid


def _extrude(edges: list[TopoDS_Edge], length: float) -> TopoDS_Shape:
    wire_maker = BRepBuilderAPI_MakeWire()
    for edge in edges:
        wire_maker.Add(edge)
    if not wire_maker.IsDone():
        raise RuntimeError("the transverse outline did not close into a wire")
    face = BRepBuilderAPI_MakeFace(wire_maker.Wire(), True)
    if not face.IsDone():
        raise RuntimeError("could not make the transverse face")
    return BRepPrimAPI_MakePrism(face.Face(), gp_Vec(length, 0.0, 0.0)).Shape()


def _sweep_helical(edges: list[TopoDS_Edge], spec: GearSpec) -> TopoDS_Shape:
    """The transverse outline swept along X over the face width while turning with the helix: OCP's pipe
    shell along a straight spine, the twist taken from an auxiliary helix of the gear's lead and hand
    (each section at X is the outline turned by spec.section_turn_rad(X))."""
    wire_maker = BRepBuilderAPI_MakeWire()
    for edge in edges:
        wire_maker.Add(edge)
    if not wire_maker.IsDone():
        raise RuntimeError("the transverse outline did not close into a wire")
    b = spec.face_width_mm
    spine = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(gp_Pnt(0.0, 0.0, 0.0), gp_Pnt(b, 0.0, 0.0)).Edge()).Wire()
    helix = _helix_along_x(spec.lead_mm, b, spec.reference_radius_mm, spec.hand == "left")
    pipe = BRepOffsetAPI_MakePipeShell(spine)
    pipe.SetMode(helix, False)
    pipe.Add(wire_maker.Wire())
    pipe.Build()
    if not pipe.IsDone() or not pipe.MakeSolid():
        raise RuntimeError("the helical sweep of the transverse outline failed")
    return pipe.Shape()


def _helix_along_x(lead_mm: float, length_mm: float, radius_mm: float, left_hand: bool) -> TopoDS_Wire:
    """A helix about +X from the origin over `length_mm` (as CadQuery's Wire.makeHelix makes it: a line in the
    (u, v) domain of a cylinder, its 3-D curve built from it)."""
    surface = Geom_CylindricalSurface(gp_Ax3(gp_Pnt(0.0, 0.0, 0.0), gp_Dir(1.0, 0.0, 0.0)), radius_mm)
    line = Geom2d_Line(gp_Pnt2d(0.0, 0.0), gp_Dir2d(-2.0 * math.pi if left_hand else 2.0 * math.pi, lead_mm))
    turns = length_mm / lead_mm
    segment = MakeSegment2d(line.Value(0.0),
                                line.Value(turns * math.sqrt((2.0 * math.pi) ** 2 + lead_mm ** 2))).Value()
    wire = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(segment, surface).Edge()).Wire()
    BRepLib.BuildCurves3d_s(wire, 1e-6, MaxSegment=2000)
    return wire


def _cut(shape: TopoDS_Shape, tool: TopoDS_Shape) -> TopoDS_Shape:
    cut = BRepAlgoAPI_Cut(shape, tool)
    cut.Build()
    if not cut.IsDone():
        raise RuntimeError("boolean cut failed")
    return cut.Shape()


def _x_cylinder(radius: float, x0: float, x1: float) -> TopoDS_Shape:
    return BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(x0, 0, 0), gp_Dir(1, 0, 0)), radius, x1 - x0).Shape()


def _ring_shape(edges: list[TopoDS_Edge], spec: InternalGearSpec) -> TopoDS_Shape:
    """An internal gear: the transverse face between the rim circle (rim_outer_diameter_mm) and the toothed inner
    outline, extruded over 0 <= X <= b (a face with a hole: no boolean, which took a minute on a 60-tooth ring)."""
    circle = gp_Circ(gp_Ax2(gp_Pnt(0.0, 0.0, 0.0), gp_Dir(1.0, 0.0, 0.0)), spec.rim_outer_diameter_mm / 2.0)
    rim = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(circle).Edge()).Wire()
    inner = BRepBuilderAPI_MakeWire()
    for edge in edges:
        inner.Add(edge)
    if not inner.IsDone():
        raise RuntimeError("the ring's toothed outline did not close into a wire")
    maker = BRepBuilderAPI_MakeFace(rim, True)
    maker.Add(inner.Wire())
    if not maker.IsDone():
        raise RuntimeError("could not make the ring's transverse face")
    fix = ShapeFix_Face(maker.Face())
    fix.FixOrientation()  # the hole's wire runs opposite to the rim's, whichever way the outline was traced
    fix.Perform()
    return BRepPrimAPI_MakePrism(fix.Face(), gp_Vec(spec.face_width_mm, 0.0, 0.0)).Shape()


def _toothed_disc(spec: GearSpec, edges: list[TopoDS_Edge], tolerance_mm: float, report: GearSolidReport,
                  modifications: FlankModifications | None) -> TopoDS_Shape:
    """An external gear's toothed body: the front face's outline extruded along X or swept along the helix (the
    kind's `solid`); with `modifications` the modified outline, or a loft through modified sections when they
    modify the lead."""
    if modifications is not None and not modifications.is_zero:
        if modifications.has_lead:
            return _loft_lead_modified(spec, modifications, tolerance_mm, report)
        edges = modified_face_edges(spec, modifications, 0.0, tolerance_mm)
    return _sweep_helical(edges, spec) if spec.kind.solid == "sweep" else _extrude(edges, spec.face_width_mm)


def _toothed_ring(spec: GearSpec, edges: list[TopoDS_Edge], tolerance_mm: float, report: GearSolidReport,
                  modifications: FlankModifications | None) -> TopoDS_Shape:
    """An internal gear's body: `_ring_shape` (a ring's flanks are not modified: its kind does not follow
    modifications)."""
    return _ring_shape(edges, as_ring(spec))


_BODY_SHAPES: dict[GearKind, Callable[[GearSpec, list[TopoDS_Edge], float, GearSolidReport,
                                       FlankModifications | None], TopoDS_Shape]] = {
    EXTERNAL_SPUR: _toothed_disc, EXTERNAL_HELICAL: _toothed_disc, INTERNAL_SPUR: _toothed_ring}
"""How each gear kind's toothed body is made from its front face's edges, by the kind object."""


def build_gear_shape(spec: GearSpec, features: BlankFeatures = BlankFeatures(),
                     fit_tolerance_mm: float | None = None,
                     modifications: FlankModifications | None = None) -> tuple[TopoDS_Shape, GearSolidReport]:
    """The gear as an OCP solid in the machine frame, with a report of the spline fits (the design flanks'; an
    internal gear: a ring whose outside is the rim, rim_outer_diameter_mm).

    `fit_tolerance_mm` defaults to 2.5e-6 x module (see default_fit_tolerance_mm). With `modifications` the
    flanks are the modified ones: profile modifications only, the modified outline extruded or swept as the
    design's; lead modifications, a loft through modified sections (`_loft_lead_modified`). The features suit the
    gear: checked where they meet it (the job loader, gear_shape), not here."""
    require_instance(spec, GearSpec, "spec")
    require_instance(features, BlankFeatures, "features")
    tolerance = default_fit_tolerance_mm(spec) if fit_tolerance_mm is None else fit_tolerance_mm
    edges, report = gear_face_edges(spec, tolerance)
    b = spec.face_width_mm
    body = _BODY_SHAPES.get(spec.kind)
    if body is None:
        raise ValueError(f"no solid is known for a {spec.kind.name} gear (cad/solid.py, _BODY_SHAPES)")
    shape = body(spec, edges, tolerance, report, modifications)
    if features.bore_diameter_mm > 0.0:
        shape = _cut(shape, _x_cylinder(features.bore_diameter_mm / 2.0, -1.0, b + 1.0))
    if features.keyway_width_mm > 0.0:
        w = features.keyway_width_mm
        top = features.bore_diameter_mm / 2.0 + features.keyway_depth_mm
        box = BRepPrimAPI_MakeBox(gp_Pnt(-1.0, -w / 2.0, 0.0), gp_Pnt(b + 1.0, w / 2.0, top)).Shape()
        shape = _cut(shape, box)
    if not BRepCheck_Analyzer(shape).IsValid():
        raise RuntimeError("the gear solid failed OCP's validity check")
    return shape, report


def build_stock_shape(spec: GearSpec, stock: StockSpec = StockSpec()) -> TopoDS_Shape:
    """The blank: cylinder over the face width plus margins, and the holding stub toward +X (the stock suits the
    gear: checked where they meet, the job loader or stock_shape)."""
    require_instance(spec, GearSpec, "spec")
    require_instance(stock, StockSpec, "stock")
    x_start, x_end = stock.blank_x_range_mm(spec)
    shape = _x_cylinder(stock.blank_radius_mm(spec), x_start, x_end)
    if stock.stub_length_mm > 0.0:
        fuse = BRepAlgoAPI_Fuse(shape, _x_cylinder(stock.stub_diameter_mm / 2.0, x_end,
                                                   x_end + stock.stub_length_mm))
        fuse.Build()
        unify = ShapeUpgrade_UnifySameDomain(fuse.Shape(), True, True, True)  # the seam between blank and stub
        unify.AllowInternalEdges(False)
        unify.Build()
        shape = unify.Shape()
    return shape


def build_flat_stock_shape(spec: GearSpec, stock: StockSpec, features: BlankFeatures = BlankFeatures()) -> TopoDS_Shape:
    """The blank of a gear cut lying flat ([machine] axes = 3): a disk of the blank diameter over the face width
    (X 0 to b: the programs' Z0 is its top face, the gear's), through its bore when the job gives one (it is
    clamped on it; a ring's: [stock] inner_diameter_mm, clamped on its rim); no holding stub. The stock suits the
    gear: the job loader checked it (StockSpec.validate)."""
    require_instance(spec, GearSpec, "spec")
    require_instance(stock, StockSpec, "stock")
    shape = _x_cylinder(stock.blank_radius_mm(spec), 0.0, spec.face_width_mm)
    bore_mm = stock.flat_bore_diameter_mm(spec, features)  # a ring: its blank's bore
    if bore_mm > 0.0:
        shape = _cut(shape, _x_cylinder(bore_mm / 2.0, -1.0, spec.face_width_mm + 1.0))
    return shape


FRAMES = ("machine", "part")
"""Where a front-end's gear or stock lies. "machine": the machine frame of docs/architecture.md (axis X, front
face at X = 0, what the toolpaths and STEP files use). "part": the part's own frame, as CadQuery and build123d
users place parts: axis Z, the gear's centre (mid-face, on the axis) at the origin; machine X, Y, Z become part
Z, X, Y (a proper rotation, so a helix keeps its hand), so tooth space 0 is symmetric about +Y."""


def part_frame_transform(face_width_mm: float) -> gp_Trsf:
    """The rigid motion taking the machine frame to the part frame (see FRAMES): (x, y, z) -> (y, z, x - b/2)."""
    trsf = gp_Trsf()
    trsf.SetValues(0.0, 1.0, 0.0, 0.0,
                   0.0, 0.0, 1.0, 0.0,
                   1.0, 0.0, 0.0, -face_width_mm / 2.0)
    return trsf


def in_frame(shape: TopoDS_Shape, spec: GearSpec, frame: str) -> TopoDS_Shape:
    """`shape` (built in the machine frame) located in `frame`: the same geometry, moved, not re-modelled."""
    if frame not in FRAMES:
        raise ArgumentError(f"frame must be one of {', '.join(FRAMES)}, got {frame!r}")
    if frame == "machine":
        return shape
    return shape.Moved(TopLoc_Location(part_frame_transform(spec.face_width_mm)))


def gear_shape(spec: GearSpec, features: BlankFeatures = BlankFeatures(), fit_tolerance_mm: float | None = None,
               frame: str = "machine") -> TopoDS_Shape:
    """The gear solid as an OCP shape in `frame` (see FRAMES): needs OCP only, neither CadQuery nor build123d.
    Scripts' entry point: the features are checked against the gear here, once (GearSpecError)."""
    require_instance(spec, GearSpec, "spec")
    require_instance(features, BlankFeatures, "features")
    require_instance(frame, str, "frame")
    in_frame(TopoDS_Shape(), spec, frame)  # an unknown frame is refused before the solid is built
    features.validate(spec)
    shape, _ = build_gear_shape(spec, features, fit_tolerance_mm)
    return in_frame(shape, spec, frame)


def stock_shape(spec: GearSpec, stock: StockSpec = StockSpec(), frame: str = "machine") -> TopoDS_Shape:
    """The stock as an OCP shape in `frame` (see FRAMES). Scripts' entry point: the stock is checked against the
    gear here, once (StockError)."""
    require_instance(spec, GearSpec, "spec")
    require_instance(stock, StockSpec, "stock")
    require_instance(frame, str, "frame")
    in_frame(TopoDS_Shape(), spec, frame)
    stock.validate(spec)
    return in_frame(build_stock_shape(spec, stock), spec, frame)


def make_gear(spec: GearSpec, features: BlankFeatures = BlankFeatures(),
              fit_tolerance_mm: float | None = None, frame: str = "machine"):
    """The gear solid as a CadQuery Workplane in `frame` (default the machine frame: axis X, front face at X = 0).
    CadQuery is imported here, for the scripts that want it (spur_cad[cadquery]): the pipeline works on OCP shapes."""
    import cadquery as cq

    shape = gear_shape(spec, features, fit_tolerance_mm, frame)
    return cq.Workplane("YZ" if frame == "machine" else "XY").add(cq.Solid(shape))


def make_stock(spec: GearSpec, stock: StockSpec = StockSpec(), frame: str = "machine"):
    """The stock (blank cylinder, optional holding stub) as a CadQuery Workplane in `frame`."""
    import cadquery as cq

    shape = stock_shape(spec, stock, frame)
    return cq.Workplane("YZ" if frame == "machine" else "XY").add(cq.Solid(shape))


def _wrapped_shape(source) -> TopoDS_Shape | None:
    """The OCP shape inside a CadQuery Workplane or Shape, a build123d Shape, or an OCP shape (None otherwise).
    A front-end's object can exist only once its module is imported, so each is looked up in sys.modules and
    neither front-end is imported (or needs to be installed) here."""
    if isinstance(source, TopoDS_Shape):
        return source
    cq = sys.modules.get("cadquery")
    if cq is not None and isinstance(source, cq.Workplane):
        held = [value for value in source.vals() if isinstance(value, cq.Shape)]
        return held[0].wrapped if held else TopoDS_Shape()
    if cq is not None and isinstance(source, cq.Shape):
        return source.wrapped
    bd = sys.modules.get("build123d")
    if bd is not None and isinstance(source, bd.Shape):
        return source.wrapped if source.wrapped is not None else TopoDS_Shape()
    return None


def to_build123d(source, features: BlankFeatures = BlankFeatures(), *, frame: str = "machine"):
    """A build123d Solid. From a GearSpec: the gear itself, built in `frame` ("machine" or "part", see FRAMES),
    with no CadQuery involved (spur_cad[build123d]). From a CadQuery Workplane or Shape, or an OCP shape: the same
    OCP shape wrapped (no copy, no re-modelling; `frame` must then be left "machine", and `features` unused).
    What it returns composes in a BuildPart like any build123d Solid (add, subtract, locate)."""
    import build123d

    if isinstance(source, GearSpec):
        return build123d.Solid(gear_shape(source, features, frame=frame))
    shape = _wrapped_shape(source)
    if shape is None:
        raise ArgumentError(f"source must be a GearSpec, a CadQuery Workplane or Shape, or an OCP shape, "
                            f"got {type(source).__name__}")
    if frame != "machine":
        raise ArgumentError("frame applies to a GearSpec; a shape given is wrapped where it lies")
    if shape.IsNull():
        raise ArgumentError("source holds no solid")
    return build123d.Solid(shape)


def solid_volume_mm3(shape: TopoDS_Shape, tolerance: float = 1e-9) -> float:
    """Volume by OCP's adaptive integration on a NURBS copy of the shape.

    OCP's default integration on surfaces of linear extrusion of B-splines (our flank faces)
    is off by about 1e-4 relative; converted to NURBS, the adaptive variant agrees with
    area x face width to 1e-12.
    """
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(BRepBuilderAPI_NurbsConvert(shape, True).Shape(), props, tolerance, True)
    return props.Mass()


def front_face_area_mm2(shape: TopoDS_Shape) -> float:
    """Area of the shape's planar face on the front plane X = 0 (the gear's transverse section there).

    The gear solid is that section moved along X over the face width, straight (spur) or screwed (helical),
    and its bore and keyway are prisms along X too, so its volume is this area times the face width: exact,
    and a thirtieth of the cost of integrating the volume (solid_volume_mm3). A helical solid's integrated
    volume differs from it by about 5e-7 relative: the pipe shell approximates the screw surfaces."""
    explorer = TopExp_Explorer(shape, TopAbs_FACE)
    areas = []
    while explorer.More():
        face = TopoDS.Face(explorer.Current())
        surface = BRepAdaptor_Surface(face)
        if surface.GetType() == GeomAbs_Plane:
            plane = surface.Plane()
            if abs(abs(plane.Axis().Direction().X()) - 1.0) < 1e-12 and abs(plane.Location().X()) < 1e-9:
                props = GProp_GProps()
                BRepGProp.SurfaceProperties_s(face, props, 1e-12, True)
                areas.append(props.Mass())
        explorer.Next()
    if len(areas) != 1:
        raise RuntimeError(f"the solid has {len(areas)} faces on the plane X = 0, not one")
    return areas[0]
