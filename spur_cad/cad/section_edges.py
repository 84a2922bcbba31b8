"""The transverse section's edges of the gear solid (spur_cad.cad.solid), in the machine frame: root and tip arcs
as exact circles, fillet and involute as B-splines interpolated by OCP (GeomAPI_Interpolate) through exact points
with their exact tangents, refined until the largest distance from the exact curve (OCP's point projection on
dense exact points) is within the fit tolerance; the whole outline of every space, and the outline of a section of
a gear with flank modifications."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from OCP.BRepBuilderAPI import (
    BRepBuilderAPI_MakeEdge,
    BRepBuilderAPI_Transform,
)
from OCP.GC import GC_MakeArcOfCircle
from OCP.Geom import Geom_BSplineCurve, Geom_Curve
from OCP.GeomAPI import GeomAPI_Interpolate, GeomAPI_ProjectPointOnCurve
from OCP.gp import gp_Ax1, gp_Ax2, gp_Dir, gp_Pnt, gp_Trsf, gp_Vec
from OCP.TopoDS import TopoDS, TopoDS_Edge

from spur_cad.cad.ocp_compat import Array1OfVec, HArray1OfBoolean, HArray1OfPnt, HArray1OfReal
from spur_cad.cad.specs import GearSolidReport
from spur_cad.geometry.modifications import SIDES, FlankModifications, modified_tooth_space_profile
from spur_cad.geometry.profile import Segment
from spur_cad.geometry.sampling import segment_parameters
from spur_cad.geometry.spec import GearSpec

FIT_TOLERANCE_PER_MODULE = 2.5e-6  # B-spline vs exact curve, x module: 0.01 um at m = 4
CHECK_POINTS_PER_SPAN = 8


@dataclass(frozen=True)
class FittedCurve:
    """A B-spline in the machine frame and its measured largest distance from the exact curve."""

    curve: Geom_BSplineCurve
    max_deviation_mm: float
    poles: int


def machine_point(x_gap: float, y_gap: float) -> gp_Pnt:
    """Gap-frame (x, y) on the front face X = 0 -> machine (0, Y = x, Z = y)."""
    return gp_Pnt(0.0, float(x_gap), float(y_gap))


def interpolate(points: np.ndarray, tangents: np.ndarray,
                 parameters: np.ndarray | None = None) -> Geom_BSplineCurve:
    """OCP interpolation through `points` with the given unit tangents at every point; on the given increasing
    `parameters` (they fix the knots), else on OCP's chord-length ones."""
    n = len(points)
    poles = HArray1OfPnt(1, n)
    vectors = Array1OfVec(1, n)
    flags = HArray1OfBoolean(1, n)
    for i, ((x, y), (tx, ty)) in enumerate(zip(points, tangents), start=1):
        poles.SetValue(i, machine_point(x, y))
        vectors.SetValue(i, gp_Vec(0.0, float(tx), float(ty)))
        flags.SetValue(i, True)
    if parameters is None:
        interpolation = GeomAPI_Interpolate(poles, False, 1e-9)
    else:
        knots = HArray1OfReal(1, n)
        for i, value in enumerate(parameters, start=1):
            knots.SetValue(i, float(value))
        interpolation = GeomAPI_Interpolate(poles, knots, False, 1e-9)
    interpolation.Load(vectors, flags, True)
    interpolation.Perform()
    if not interpolation.IsDone():
        raise RuntimeError("OCP B-spline interpolation failed")
    return interpolation.Curve()


def max_deviation(curve: Geom_Curve, exact_points: np.ndarray) -> float:
    """Largest distance from exact points to the curve, by OCP's orthogonal projection."""
    worst = 0.0
    first, last = curve.FirstParameter(), curve.LastParameter()
    for x, y in exact_points:
        point = machine_point(x, y)
        projector = GeomAPI_ProjectPointOnCurve(point, curve, first, last)
        if projector.NbPoints() > 0:
            distance = projector.LowerDistance()
        else:  # nearest is an end point
            distance = min(point.Distance(curve.Value(first)), point.Distance(curve.Value(last)))
        worst = max(worst, distance)
    return worst


def default_fit_tolerance_mm(spec: GearSpec) -> float:
    """Spline fit tolerance scaled with the module, so small gears keep the same relative accuracy."""
    return FIT_TOLERANCE_PER_MODULE * spec.module_mm


def travel_tangents(segment: Segment, params: np.ndarray) -> np.ndarray:
    """Unit tangents of a segment at `params` in its direction of travel (the normal into the space turned right;
    an internal gear's space lies right of travel, so its tangents are reversed)."""
    points = segment.points(params)
    normals = segment.normals(params)
    tangents = np.stack([normals[:, 1], -normals[:, 0]], axis=-1)
    if np.dot(tangents[0], points[-1] - points[0]) < 0.0:
        tangents = -tangents
    return tangents


def fit_segment(segment: Segment, fit_tolerance_mm: float) -> FittedCurve:
    """B-spline through exact points and tangents of a fillet/involute, refined until within tolerance."""
    chordal = 0.01
    for _ in range(12):
        params = segment_parameters(segment, chordal)
        points = segment.points(params)
        curve = interpolate(points, travel_tangents(segment, params))
        check = np.concatenate([np.linspace(a, b, CHECK_POINTS_PER_SPAN, endpoint=False)[1:]
                                for a, b in zip(params, params[1:])])
        deviation = max_deviation(curve, segment.points(check))
        if deviation <= fit_tolerance_mm:
            return FittedCurve(curve, deviation, curve.NbPoles())
        chordal /= 4.0
    raise RuntimeError(f"could not fit the {segment.label} within {fit_tolerance_mm} mm")


def arc_edge(radius: float, theta_start: float, theta_end: float) -> TopoDS_Edge:
    """Exact circular arc about the gear axis between two polar angles (gap frame, clockwise from +y)."""
    mid = 0.5 * (theta_start + theta_end)
    p = [machine_point(radius * math.sin(t), radius * math.cos(t)) for t in (theta_start, mid, theta_end)]
    return BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(p[0], p[1], p[2]).Value()).Edge()


def mirror_y() -> gp_Trsf:
    """Mirror in the plane Y = 0 (the space's symmetry plane)."""
    trsf = gp_Trsf()
    trsf.SetMirror(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 1, 0)))
    return trsf


def rotation_about_x(angle_rad: float) -> gp_Trsf:
    trsf = gp_Trsf()
    trsf.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(1, 0, 0)), angle_rad)
    return trsf


def transformed_edge(edge: TopoDS_Edge, trsf: gp_Trsf) -> TopoDS_Edge:
    return TopoDS.Edge(BRepBuilderAPI_Transform(edge, trsf, True).Shape())


def gear_face_edges(spec: GearSpec, fit_tolerance_mm: float) -> tuple[list[TopoDS_Edge], GearSolidReport]:
    """Edges of the whole transverse outline on the front face, in order around the gear."""
    profile = spec.tooth_space_profile()
    fillet_seg, involute_seg = profile.fillet, profile.involute
    involute = fit_segment(involute_seg, fit_tolerance_mm)
    right: list[TopoDS_Edge] = []
    fillet = None
    if fillet_seg is not None and fillet_seg.end > fillet_seg.start:
        fillet = fit_segment(fillet_seg, fit_tolerance_mm)
        right.append(BRepBuilderAPI_MakeEdge(fillet.curve).Edge())
    right.append(BRepBuilderAPI_MakeEdge(involute.curve).Edge())
    mirror = mirror_y()
    left = [transformed_edge(edge, mirror) for edge in right]
    v = profile.root_arc_half_angle_rad
    space_edges = list(reversed(left))
    if v > 0.0:
        space_edges.append(arc_edge(spec.root_radius_mm, -v, v))
    space_edges.extend(right)
    tip = profile.tip
    pitch = 2.0 * math.pi / spec.teeth
    # Tip land of the tooth clockwise of space 0: from its right flank's end to the next space's left flank.
    space_edges.append(arc_edge(spec.tip_radius_mm, tip.start, pitch - tip.start))
    edges: list[TopoDS_Edge] = []
    for k in range(spec.teeth):
        # Space k is turned by +k*pitch about +X; the unit above is ordered clockwise, so walk k downward.
        rotation = rotation_about_x(-k * pitch)
        edges.extend(transformed_edge(edge, rotation) for edge in space_edges)
    report = GearSolidReport(
        fit_tolerance_mm=fit_tolerance_mm,
        fillet_max_deviation_mm=fillet.max_deviation_mm if fillet else 0.0,
        involute_max_deviation_mm=involute.max_deviation_mm,
        fillet_poles=fillet.poles if fillet else 0, involute_poles=involute.poles,
        edges_per_space=len(space_edges))
    return edges, report


def modified_face_edges(spec: GearSpec, modifications: FlankModifications, x_face_mm: float,
                        fit_tolerance_mm: float) -> list[TopoDS_Edge]:
    """Edges of the whole transverse outline of a modified gear at face position X, drawn on the plane X = 0 and
    not turned by the helix: each flank side moved by its modifications there (spur_cad.geometry.modifications;
    the left side fitted from its own modified profile and mirrored), the involute split at the reliefs' starts."""
    profile = spec.tooth_space_profile()
    halves, tip_angles = {}, {}
    for side in SIDES:
        modified = modified_tooth_space_profile(profile, modifications.side(side), x_face_mm)
        halves[side] = [BRepBuilderAPI_MakeEdge(fit_segment(seg, fit_tolerance_mm).curve).Edge()
                        for seg in modified.segments if seg.label in ("fillet", "involute") and seg.end > seg.start]
        tip_angles[side] = modified.tip.start
    mirror = mirror_y()
    space_edges = [transformed_edge(edge, mirror) for edge in reversed(halves["left"])]
    v = profile.root_arc_half_angle_rad
    if v > 0.0:
        space_edges.append(arc_edge(spec.root_radius_mm, -v, v))
    space_edges.extend(halves["right"])
    pitch = 2.0 * math.pi / spec.teeth
    space_edges.append(arc_edge(spec.tip_radius_mm, tip_angles["right"], pitch - tip_angles["left"]))
    edges: list[TopoDS_Edge] = []
    for k in range(spec.teeth):
        rotation = rotation_about_x(-k * pitch)
        edges.extend(transformed_edge(edge, rotation) for edge in space_edges)
    return edges
