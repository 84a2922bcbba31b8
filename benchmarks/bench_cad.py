"""Gear solid + STEP for the reference gear, beside bd_warehouse's SpurGear (same machine, same run).

Deviation from the exact involute is measured the same way for both: section at mid face
width, dense points on the section edges, and for every point with a radius on the involute
flank the normal distance to the nearest exact involute flank, r_b * |polar angle difference|
(exact for involutes of one base circle). The unknown angular phase of the other model is
fitted first (ours should fit at phase 0).
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

import numpy as np
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepAlgoAPI import BRepAlgoAPI_Section
from OCP.gp import gp_Dir, gp_Pln, gp_Pnt
from OCP.TopAbs import TopAbs_EDGE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS
from scipy.optimize import minimize_scalar

from spur_cad.geometry import GearSpec, involute_function


def section_points(shape, origin: tuple[float, float, float], normal: tuple[float, float, float],
                   per_edge: int = 300) -> np.ndarray:
    """3-D points sampled on the edges of a planar section."""
    section = BRepAlgoAPI_Section(shape, gp_Pln(gp_Pnt(*origin), gp_Dir(*normal)))
    section.Build()
    points = []
    explorer = TopExp_Explorer(section.Shape(), TopAbs_EDGE)
    while explorer.More():
        curve = BRepAdaptor_Curve(TopoDS.Edge(explorer.Current()))
        for u in np.linspace(curve.FirstParameter(), curve.LastParameter(), per_edge):
            p = curve.Value(u)
            points.append((p.X(), p.Y(), p.Z()))
        explorer.Next()
    return np.array(points)


def involute_deviation_mm(spec: GearSpec, points_2d: np.ndarray, fit_phase: bool) -> tuple[float, float, float]:
    """(max normal distance from the exact involute flanks, form error, fitted phase in rad).

    The form error is the largest distance after also removing a constant thickness offset
    (the median signed deviation), i.e. what remains that is not a size difference.

    Points are (u, v) in the transverse plane with the gear centre at the origin; polar
    angles are measured from +v toward +u. Only points with form + 5% < R < tip - 5% of the
    flank height count (both models are involute there; their tips and roots differ).
    """
    rb = spec.base_radius_mm
    radius = np.hypot(points_2d[:, 0], points_2d[:, 1])
    low = spec.form_radius_mm + 0.05 * (spec.tip_radius_mm - spec.form_radius_mm)
    high = spec.tip_radius_mm - 0.05 * (spec.tip_radius_mm - spec.form_radius_mm)
    keep = (radius > low) & (radius < high)
    radius = radius[keep]
    polar = np.arctan2(points_2d[keep, 0], points_2d[keep, 1])
    flank = spec.base_half_space_angle_rad + np.array([involute_function(math.acos(rb / r)) for r in radius])
    pitch = 2 * math.pi / spec.teeth

    def signed(phase: float) -> np.ndarray:
        local = np.mod(polar - phase + pitch / 2, pitch) - pitch / 2  # angle from the nearest space axis
        return rb * (np.abs(local) - flank)  # > 0: flank lies inside the exact tooth (thinner tooth)

    phase = 0.0
    if fit_phase:
        grid = np.linspace(-pitch / 2, pitch / 2, 721)
        best = grid[int(np.argmin([np.median(np.abs(signed(p))) for p in grid]))]
        step = grid[1] - grid[0]
        phase = float(minimize_scalar(lambda p: float(np.abs(signed(p)).max()), bounds=(best - step, best + step),
                                      method="bounded", options={"xatol": 1e-12}).x)
    d = signed(phase)
    return float(np.abs(d).max()), float(np.abs(d - np.median(d)).max()), phase


def ours(spec: GearSpec) -> tuple[object, bytes]:
    """Our gear solid and its STEP bytes."""
    import cadquery as cq

    from spur_cad.cad.solid import build_gear_shape

    shape, _ = build_gear_shape(spec)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "gear.step"
        cq.exporters.export(cq.Workplane().add(cq.Solid(shape)), str(path), exportType="STEP")
        return shape, path.read_bytes()


def bd_warehouse_gear(spec: GearSpec) -> tuple[object, bytes]:
    """bd_warehouse's SpurGear of the same module, teeth, pressure angle and face width, and its STEP."""
    import build123d
    from bd_warehouse.gear import SpurGear

    gear = SpurGear(module=spec.module_mm, tooth_count=spec.teeth, pressure_angle=spec.pressure_angle_deg,
                    thickness=spec.face_width_mm, root_fillet=spec.rack_tip_radius_mm, align=None)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "gear.step"
        build123d.export_step(gear, str(path))
        return gear.wrapped, path.read_bytes()


def deviation_of_ours(spec: GearSpec, shape) -> tuple[float, float]:
    pts = section_points(shape, (spec.face_width_mm / 2, 0, 0), (1, 0, 0))
    return involute_deviation_mm(spec, pts[:, 1:3], fit_phase=True)


def deviation_of_bd_warehouse(nominal: GearSpec, shape) -> tuple[float, float]:
    """bd_warehouse builds along Z from z = 0 (align=None keeps its axis on the origin; its default
    Align.CENTER centres the bounding box, which for an odd tooth count moves the axis)."""
    pts = section_points(shape, (0, 0, nominal.face_width_mm / 2), (0, 0, 1))[:, 0:2]
    return involute_deviation_mm(nominal, pts - tip_circle_centre(pts), fit_phase=True)


def tip_circle_centre(points_2d: np.ndarray) -> np.ndarray:
    """Centre of the circle fitted (least squares) to the outermost points: bd_warehouse's SpurGear
    of 23 teeth has its axis about 0.14 mm off the origin, so it is re-centred before measuring."""
    radius = np.hypot(points_2d[:, 0], points_2d[:, 1])
    tip = points_2d[radius > radius.max() - 0.4]
    a = np.c_[2 * tip, np.ones(len(tip))]
    solution = np.linalg.lstsq(a, (tip**2).sum(axis=1), rcond=None)[0]
    return solution[:2]
