"""Cross-check of the fast simulation with OCP booleans on a subset of moves (slow, for tests and benchmarks).

The way CAD-based machining simulations are usually built: the stock is a B-rep solid, each move's
tool swept solid is subtracted from it (BRepAlgoAPI_Cut with all tools at once). Swept solids:
a move along X only is exact (the tool's silhouette extruded along X, plus the tool at both ends);
a move in Z only is the tool at its lower end (exact); any other move is the union of the tool at
poses `refine` times denser than the fast simulation's (so the boolean result is the better
approximation of the continuous sweep). The result is then probed along the same blades (lines
along the design normals) with BRepIntCurveSurface_Inter and compared with the fast simulation.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from OCP.TopoDS import TopoDS_Shape

from spur_cad.cad.ocp_compat import ListOfShape
from spur_cad.cam.ir import MoveKind, Toolpath
from spur_cad.cam.tools import Tool
from spur_cad.geometry.spec import GearSpec
from spur_cad.sim.simulate import Cut, SimResult, SimSettings, StockCylinder, pose_step_mm, simulate


@dataclass(frozen=True)
class CrossCheck:
    """Fast simulation vs OCP booleans on one subset of moves."""

    max_difference_mm: float
    compared_blades: int
    cut_blades: int
    fast_seconds: float
    occ_seconds: float
    tool_solids: int

    @property
    def speed_ratio(self) -> float:
        """How many times faster the fast simulation was on this subset."""
        return self.occ_seconds / self.fast_seconds


def _profile_face(points_and_arcs: list, plane_point) -> TopoDS_Shape:
    """A planar face bounded by a closed chain of segments and three-point arcs: each item is an end point, or
    (mid point, end point) for an arc, in 2-D profile coordinates mapped to 3-D by `plane_point`."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakeWire
    from OCP.GC import GC_MakeArcOfCircle, GC_MakeSegment

    wire = BRepBuilderAPI_MakeWire()
    start = points_and_arcs[0]
    current = start
    for item in [*points_and_arcs[1:], start]:
        if isinstance(item[0], tuple):
            mid, end = item
            curve = GC_MakeArcOfCircle(plane_point(*current), plane_point(*mid), plane_point(*end)).Value()
        else:
            end = item
            curve = GC_MakeSegment(plane_point(*current), plane_point(*end)).Value()
        wire.Add(BRepBuilderAPI_MakeEdge(curve).Edge())
        current = end
    return BRepBuilderAPI_MakeFace(wire.Wire(), True).Face()


def _tool_outline(tool: Tool, height: float, side: float) -> list:
    """The tool's half section on one side (`side` +1 or -1) from the tip: flat, corner arc, side to `height`."""
    radius, rt = tool.diameter_mm / 2.0, tool.effective_corner_radius_mm
    half_flat = radius - rt
    chain: list = []
    if half_flat > 0.0:
        chain.append((side * half_flat, 0.0))
    if rt > 0.0:
        mid = (side * (half_flat + rt * math.sin(math.pi / 4)), rt - rt * math.cos(math.pi / 4))
        chain.append((mid, (side * radius, rt)))
    chain.append((side * radius, height))
    return chain


def tool_solid(tool: Tool, height: float) -> TopoDS_Shape:
    """The tool as an OCP solid of revolution about +Z, tip centre at the origin (exact corner arcs)."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeRevol
    from OCP.gp import gp_Ax1, gp_Dir, gp_Pnt

    chain = [(0.0, 0.0), *_tool_outline(tool, height, 1.0), (0.0, height)]
    face = _profile_face(chain, lambda u, v: gp_Pnt(u, 0.0, v))  # the XZ plane
    return BRepPrimAPI_MakeRevol(face, gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 2.0 * math.pi).Shape()


def _silhouette_prism(tool: Tool, height: float, length: float) -> TopoDS_Shape:
    """The tool's section through its axis in the YZ plane (X = 0), extruded by `length` along +X."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism
    from OCP.gp import gp_Pnt, gp_Vec

    radius, rt = tool.diameter_mm / 2.0, tool.effective_corner_radius_mm
    half_flat = radius - rt
    chain: list = [(-radius, height), (-radius, rt)]  # down the left side, across the tip, up the right side
    if rt > 0.0:
        chain.append(((-half_flat - rt * math.sin(math.pi / 4), rt - rt * math.cos(math.pi / 4)), (-half_flat, 0.0)))
    chain.extend(_tool_outline(tool, height, 1.0))
    face = _profile_face(chain, lambda u, v: gp_Pnt(0.0, u, v))  # the YZ plane
    return BRepPrimAPI_MakePrism(face, gp_Vec(length, 0.0, 0.0)).Shape()


def _place(shape: TopoDS_Shape, x: float, y: float, z: float, a_deg: float) -> TopoDS_Shape:
    """Machine pose -> part frame: move the tool tip to (x, y, z), then turn the part back by -A about X."""
    from OCP.gp import gp_Ax1, gp_Dir, gp_Pnt, gp_Trsf, gp_Vec
    from OCP.TopLoc import TopLoc_Location

    move, turn = gp_Trsf(), gp_Trsf()
    move.SetTranslation(gp_Vec(x, y, z))
    turn.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(1, 0, 0)), math.radians(-a_deg))
    return shape.Moved(TopLoc_Location(turn.Multiplied(move)))


def swept_solids(path: Toolpath, tool: Tool, stock: StockCylinder, resolution_mm: float, height: float,
                 refine: int = 2) -> list:
    """Tool solids whose union is what the moves of `path` remove from `stock` (see the module docstring);
    moves that cannot reach the stock (above it, or beyond its ends by more than the tool radius) are left out."""
    motion = (path.kind == MoveKind.RAPID) | (path.kind == MoveKind.LINEAR)
    x, y, z, a = (np.asarray(v, float)[motion] for v in (path.x, path.y, path.z, path.a))
    base = tool_solid(tool, height)
    radius = tool.diameter_mm / 2.0
    solids = [_place(base, x[0], y[0], z[0], a[0])]
    step = pose_step_mm(tool, resolution_mm) / refine
    for i in range(1, len(x)):
        x0, y0, z0, a0 = x[i - 1], y[i - 1], z[i - 1], a[i - 1]
        if (min(z0, z[i]) > stock.radius_mm or max(x0, x[i]) < stock.x_min - radius
                or min(x0, x[i]) > stock.x_max + radius):
            continue
        if y0 == y[i] and z0 == z[i] and a0 == a[i] and x0 != x[i]:
            lo, hi = min(x0, x[i]), max(x0, x[i])
            solids.append(_place(_silhouette_prism(tool, height, hi - lo), lo, y0, z0, a0))
            solids.append(_place(base, x[i], y[i], z[i], a[i]))
            continue
        if x0 == x[i] and y0 == y[i] and a0 == a[i]:
            solids.append(_place(base, x[i], y[i], min(z0, z[i]), a[i]))
            continue
        reach = max(math.hypot(y0, z0), math.hypot(y[i], z[i])) + tool.diameter_mm
        travel = abs(x[i] - x0) + math.hypot(y[i] - y0, z[i] - z0) + reach * abs(math.radians(a[i] - a0))
        here = step
        # flat bottom translating: its round edge
        if tool.effective_corner_radius_mm == 0.0 and z0 == z[i] and a0 == a[i]:
            here = math.sqrt(8.0 * radius * resolution_mm / 2.0) / refine
        pieces = max(1, math.ceil(travel / here))
        for f in np.arange(1, pieces + 1) / pieces:
            solids.append(_place(base, x0 + (x[i] - x0) * f, y0 + (y[i] - y0) * f, z0 + (z[i] - z0) * f,
                                 a0 + (a[i] - a0) * f))
    return solids


def probe_blades(shape, origins: np.ndarray, directions: np.ndarray, t_min: float, t_max: float) -> np.ndarray:
    """Outer end of the material on each blade (origin + t direction, t from t_min) in an OCP solid:
    the first boundary crossing after t_min (t_min when t_min is already outside, t_max when none)."""
    from OCP.BRepClass3d import BRepClass3d_SolidClassifier
    from OCP.BRepIntCurveSurface import BRepIntCurveSurface_Inter
    from OCP.gp import gp_Dir, gp_Lin, gp_Pnt
    from OCP.TopAbs import TopAbs_IN

    out = np.empty(len(origins))
    for i, (o, d) in enumerate(zip(origins, directions)):
        start = o + t_min * d
        classifier = BRepClass3d_SolidClassifier(shape, gp_Pnt(*start), 1e-7)
        if classifier.State() != TopAbs_IN:
            out[i] = t_min
            continue
        inter = BRepIntCurveSurface_Inter()
        inter.Init(shape, gp_Lin(gp_Pnt(*o), gp_Dir(*d)), 1e-7)
        crossings = []
        while inter.More():
            crossings.append(inter.W())
            inter.Next()
        after = [w for w in crossings if t_min < w <= t_max + 1e-9]
        out[i] = min(after) if after else t_max
    return out


def cross_check(spec: GearSpec, stock: StockCylinder, path: Toolpath, tool: Tool, settings: SimSettings,
                rows_x_range: tuple[float, float], station_x: np.ndarray | None = None, refine: int = 2,
                max_blades: int = 400, seed: int = 0) -> CrossCheck:
    """Remove `path` from the stock both ways and compare the blades it cut (a random sample of at most
    `max_blades`, plus as many uncut blades near them, which must stay uncut in both)."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt

    start = time.perf_counter()
    fast: SimResult = simulate(spec, stock, [Cut(path, tool)], settings, station_x=station_x,
                               rows_x_range=rows_x_range)
    fast_seconds = time.perf_counter() - start
    start = time.perf_counter()
    height = stock.radius_mm + 2.0 * tool.diameter_mm
    solids = swept_solids(path, tool, stock, settings.resolution_mm, height, refine)
    blank = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(stock.x_min, 0, 0), gp_Dir(1, 0, 0)), stock.radius_mm,
                                     stock.x_max - stock.x_min).Shape()
    arguments, tools = ListOfShape(), ListOfShape()
    arguments.Append(blank)
    for solid in solids:
        tools.Append(solid)
    removal = BRepAlgoAPI_Cut()
    removal.SetArguments(arguments)
    removal.SetTools(tools)
    removal.Build()
    if not removal.IsDone():
        raise RuntimeError("OCP could not remove the tool solids from the stock")
    result = removal.Shape()
    occ_seconds = time.perf_counter() - start
    cut = np.argwhere(fast.deviation < fast.initial - 1e-9)
    uncut = np.argwhere((fast.deviation >= fast.initial - 1e-9) & (fast.initial < settings.leftover_range_mm - 1e-9))
    rng = np.random.default_rng(seed)
    picks = [cut[rng.permutation(len(cut))[:max_blades]]]
    if len(uncut):
        picks.append(uncut[rng.permutation(len(uncut))[:max_blades // 4]])
    chosen = np.concatenate(picks)
    grid = fast.grid
    origins, directions = [], []
    for k, j, r in chosen:
        points, normals = grid.row_points(int(k), grid.rows_x[r])
        p, n = points[j], normals[j]
        origins.append((grid.rows_x[r], p[0], p[1]))
        directions.append((0.0, n[0], n[1]))
    occ_h = probe_blades(result, np.array(origins), np.array(directions), -settings.gouge_range_mm,
                         settings.leftover_range_mm)
    occ_h = np.minimum(occ_h, fast.initial[tuple(chosen.T)])
    fast_h = fast.deviation[tuple(chosen.T)]
    return CrossCheck(float(np.abs(occ_h - fast_h).max()), len(chosen), len(cut), fast_seconds, occ_seconds,
                      len(solids))
