"""The B-rep gear solid against the exact geometry, measured with OCP: validity, volume, a
mid-face section, span measurement between two tangent planes, STEP round trip, build123d."""

from __future__ import annotations

import io
import math

import numpy as np
import pytest
import shapely
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepAlgoAPI import BRepAlgoAPI_Section
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakeVertex
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepClass3d import BRepClass3d_SolidClassifier
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.GeomAPI import GeomAPI_ProjectPointOnCurve
from OCP.gp import gp_Dir, gp_Pln, gp_Pnt
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_OUT, TopAbs_SHELL, TopAbs_SOLID
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS

import spur_cad
from spur_cad.cad.solid import (
    build_gear_shape,
    build_stock_shape,
    front_face_area_mm2,
    gear_shape,
    solid_volume_mm3,
    stock_shape,
)
from spur_cad.cad.specs import BlankFeatures, StockSpec
from spur_cad.cad.step import step_files
from spur_cad.errors import StockError
from spur_cad.geometry import gear_outline, sample_profile
from spur_cad.geometry.inspection import recommended_span_teeth, span_measurement
from spur_cad.geometry.sampling import polygon_area
from tests.gears import spec_of
from tests.ocp_helper import exact_bounds

CAD_CASES = ["reference_z23_m4", "undercut_z8", "shifted_z12", "small_module_z30", "pa25_sharp_rack_z17",
             "big_shift_corner_above_rolling_line_z30"]


def _box(shape):
    """The exact bounding box (OCP's optimal box on the geometry, not on a triangulation): an object with
    xmin ... zmax, as CadQuery's BoundingBox has."""
    names = ("xmin", "ymin", "zmin", "xmax", "ymax", "zmax")
    return type("Box", (), dict(zip(names, exact_bounds(shape))))


def _count(shape, kind) -> int:
    explorer, n = TopExp_Explorer(shape, kind), 0
    while explorer.More():
        n += 1
        explorer.Next()
    return n


def keyway_area_outside_bore(width: float, top: float, bore_radius: float) -> float:
    """Area of the keyway rectangle |Y| <= w/2, 0 <= Z <= top that lies outside the bore circle."""
    half = width / 2.0
    inside = half * math.sqrt(bore_radius**2 - half**2) + bore_radius**2 * math.asin(half / bore_radius)
    return width * top - inside


@pytest.mark.parametrize("name", CAD_CASES)
def test_solid_is_valid_closed_and_has_the_exact_volume(name):
    spec = spec_of(name)
    shape, report = build_gear_shape(spec)
    assert BRepCheck_Analyzer(shape).IsValid()
    assert _count(shape, TopAbs_SOLID) == 1 and _count(shape, TopAbs_SHELL) == 1
    exact_area = polygon_area(gear_outline(spec, 1e-7 * spec.module_mm))
    assert solid_volume_mm3(shape) == pytest.approx(exact_area * spec.face_width_mm, rel=1e-6)
    assert front_face_area_mm2(shape) == pytest.approx(exact_area, rel=1e-6)
    box = _box(shape)
    assert box.xmin == pytest.approx(0.0, abs=1e-6) and box.xmax == pytest.approx(spec.face_width_mm, abs=1e-6)
    assert max(box.ymax, box.zmax, -box.ymin, -box.zmin) <= spec.tip_radius_mm + 1e-6
    assert report.fit_tolerance_mm == pytest.approx(2.5e-6 * spec.module_mm)
    assert max(report.involute_max_deviation_mm, report.fillet_max_deviation_mm) <= report.fit_tolerance_mm


def test_bore_and_keyway_remove_exactly_their_area():
    spec = spec_of("reference_z23_m4")
    features = BlankFeatures(bore_diameter_mm=30.0, keyway_width_mm=8.0, keyway_depth_mm=3.3)
    shape, _ = build_gear_shape(spec, features)
    assert BRepCheck_Analyzer(shape).IsValid() and _count(shape, TopAbs_SOLID) == 1
    area = (polygon_area(gear_outline(spec, 1e-6)) - math.pi * 15.0**2
            - keyway_area_outside_bore(8.0, 15.0 + 3.3, 15.0))
    assert solid_volume_mm3(shape) == pytest.approx(area * spec.face_width_mm, rel=1e-6)
    assert front_face_area_mm2(shape) == pytest.approx(area, rel=1e-6)  # the volume summary.json gives
    # The keyway is on the +Z side (under tooth space 0): a point there is outside the material.
    assert BRepClass3d_SolidClassifier(shape, gp_Pnt(10.0, 0.0, 17.0), 1e-7).State() == TopAbs_OUT
    assert BRepClass3d_SolidClassifier(shape, gp_Pnt(10.0, 0.0, -17.0), 1e-7).State() != TopAbs_OUT


@pytest.mark.parametrize("features, words", [
    (dict(bore_diameter_mm=80.0), "wall"),
    (dict(bore_diameter_mm=30.0, keyway_width_mm=8.0, keyway_depth_mm=30.0), "keyway reaches"),
])
def test_blank_features_that_do_not_suit_the_gear_are_refused_by_the_scripts_entry_point(features, words):
    """Against the gear: checked where the features meet it (gear_shape, the job loader)."""
    with pytest.raises(spur_cad.GearSpecError, match=words):
        gear_shape(spec_of("reference_z23_m4"), BlankFeatures(**features))


@pytest.mark.parametrize("features, words", [
    (dict(bore_diameter_mm=30.0, keyway_width_mm=8.0), "both keyway_width_mm and keyway_depth_mm"),
    (dict(keyway_width_mm=8.0, keyway_depth_mm=3.0), "needs a bore"),
    (dict(bore_diameter_mm=8.0, keyway_width_mm=8.0, keyway_depth_mm=3.0), "smaller than the bore"),
    (dict(bore_diameter_mm=-1.0), "must be zero"),
])
def test_blank_features_that_cannot_exist_are_refused_when_made(features, words):
    with pytest.raises(spur_cad.GearSpecError, match=words):
        BlankFeatures(**features)


def _section_points(shape, x: float, per_edge: int = 400) -> np.ndarray:
    section = BRepAlgoAPI_Section(shape, gp_Pln(gp_Pnt(x, 0, 0), gp_Dir(1, 0, 0)))
    section.Build()
    assert section.IsDone()
    points = []
    explorer = TopExp_Explorer(section.Shape(), TopAbs_EDGE)
    while explorer.More():
        curve = BRepAdaptor_Curve(TopoDS.Edge(explorer.Current()))
        for u in np.linspace(curve.FirstParameter(), curve.LastParameter(), per_edge):
            p = curve.Value(u)
            assert abs(p.X() - x) < 1e-7
            points.append((p.Y(), p.Z()))
        explorer.Next()
    return section.Shape(), np.array(points)


@pytest.mark.parametrize("name", [n if n == "reference_z23_m4" else pytest.param(n, marks=pytest.mark.slow)
                                  for n in CAD_CASES])
def test_mid_face_section_matches_exact_profile_within_1um(name):
    spec = spec_of(name)
    shape, _ = build_gear_shape(spec)
    section, section_points = _section_points(shape, spec.face_width_mm / 2)
    # Section -> exact: distance of every section point to the dense exact outline (1e-7 mm polyline);
    # machine (Y, Z) and the gap frame's (x, y) are the same axes.
    ring = gear_outline(spec, 1e-7 * spec.module_mm)
    segments = shapely.linestrings(np.stack([ring, np.roll(ring, -1, axis=0)], axis=1))
    _, forward = shapely.STRtree(segments).query_nearest(shapely.points(section_points),
                                                         return_distance=True, all_matches=False)
    assert forward.max() < 1e-3 + 1e-7 * spec.module_mm
    # Exact -> section: dense exact samples of three spaces, distance to the section edges by OCP's
    # orthogonal projection onto each nearby edge curve.
    edges = []
    explorer = TopExp_Explorer(section, TopAbs_EDGE)
    while explorer.More():
        edge = TopoDS.Edge(explorer.Current())
        curve = BRep_Tool.Curve_s(edge, 0.0, 0.0)
        first, last = BRep_Tool.Range_s(edge)
        box = _box(edge)
        edges.append((curve, first, last, np.array([box.ymin, box.zmin]) - 0.5, np.array([box.ymax, box.zmax]) + 0.5))
        explorer.Next()
    samples = sample_profile(spec.tooth_space_profile(), 1e-4)
    pitch = 2 * math.pi / spec.teeth
    worst = 0.0
    for k in (0, 1, spec.teeth - 1):
        c, s = math.cos(k * pitch), math.sin(k * pitch)
        for side in (1.0, -1.0):
            for x, y in samples.points:
                xs = side * x
                yz = np.array([xs * c - y * s, xs * s + y * c])
                point = gp_Pnt(spec.face_width_mm / 2, *yz)
                best = math.inf
                for curve, first, last, low, high in edges:
                    if np.all(yz >= low) and np.all(yz <= high):
                        projector = GeomAPI_ProjectPointOnCurve(point, curve, first, last)
                        ends = min(point.Distance(curve.Value(first)), point.Distance(curve.Value(last)))
                        best = min(best, projector.LowerDistance() if projector.NbPoints() else ends, ends)
                worst = max(worst, best)
    assert worst < 1e-3


def _face_nearest(shape, point: gp_Pnt):
    explorer, best = TopExp_Explorer(shape, TopAbs_FACE), (math.inf, None)
    vertex = BRepBuilderAPI_MakeVertex(point).Vertex()
    while explorer.More():
        face = TopoDS.Face(explorer.Current())
        d = BRepExtrema_DistShapeShape(vertex, face).Value()
        if d < best[0]:
            best = (d, face)
        explorer.Next()
    return best


def _extreme_along(face, direction: np.ndarray, lowest: bool) -> float:
    """min (or max) of direction . p over the face, from OCP's distance to a far plane."""
    far = 1e4
    sign = -1.0 if lowest else 1.0
    origin = gp_Pnt(5.0, *(sign * far * direction))
    normal = gp_Dir(0.0, float(direction[0]), float(direction[1]))
    plane = BRepBuilderAPI_MakeFace(gp_Pln(origin, normal), -1e5, 1e5, -1e5, 1e5).Face()
    distance = BRepExtrema_DistShapeShape(face, plane).Value()
    return sign * (far - distance)


@pytest.mark.parametrize("name", ["reference_z23_m4", "shifted_z12", "pa14_5_z40", "undercut_z8"])
def test_span_measured_between_tangent_planes_on_the_solid(name):
    spec = spec_of(name)
    shape, _ = build_gear_shape(spec)
    k = recommended_span_teeth(spec)
    expected = span_measurement(spec, k)
    pitch = 2 * math.pi / spec.teeth
    # Flank faces: right flank of space 0 and left flank of the space k pitches clockwise (toward +Y).
    samples = sample_profile(spec.tooth_space_profile(), 1e-3)
    involute = samples.points[np.array(samples.label_names()) == "involute"]
    mid = involute[len(involute) // 2]
    c, s = math.cos(-k * pitch), math.sin(-k * pitch)
    left_x = -mid[0]
    right_face = _face_nearest(shape, gp_Pnt(spec.face_width_mm / 2, mid[0], mid[1]))
    left_face = _face_nearest(shape, gp_Pnt(spec.face_width_mm / 2, left_x * c - mid[1] * s, left_x * s + mid[1] * c))
    assert right_face[0] < 1e-6 and left_face[0] < 1e-6
    # Anvils are perpendicular to the bisector of the k-tooth group (at k pitch/2 clockwise from +Z).
    half = k * pitch / 2
    across = np.array([math.cos(half), -math.sin(half)])  # in (Y, Z): perpendicular to the bisector
    low = _extreme_along(right_face[1], across, lowest=True)
    high = _extreme_along(left_face[1], across, lowest=False)
    assert high - low == pytest.approx(expected.length_mm, abs=1e-3)


def test_stock_volume_and_stub():
    spec = spec_of("reference_z23_m4")
    stock = StockSpec(radial_allowance_mm=1.0, front_margin_mm=2.0, back_margin_mm=3.0, stub_diameter_mm=60.0,
                      stub_length_mm=25.0)
    shape = build_stock_shape(spec, stock)
    assert BRepCheck_Analyzer(shape).IsValid() and _count(shape, TopAbs_SOLID) == 1
    expected = math.pi * 51.0**2 * (2.0 + spec.face_width_mm + 3.0) + math.pi * 30.0**2 * 25.0
    assert solid_volume_mm3(shape) == pytest.approx(expected, rel=1e-6)
    box = _box(shape)
    assert (box.xmin, box.xmax) == pytest.approx((-2.0, spec.face_width_mm + 28.0), abs=1e-6)


@pytest.mark.parametrize("stock, words", [
    (dict(radial_allowance_mm=-1.0), r"\[stock\] radial_allowance_mm must be in \[0, 50\] mm, got -1"),
    (dict(stub_diameter_mm=20.0), "needs both"),
])
def test_stock_that_cannot_exist_is_refused_when_made(stock, words):
    with pytest.raises(StockError, match=words):
        StockSpec(**stock)


def test_stock_that_does_not_suit_the_gear_is_refused_by_the_scripts_entry_point():
    with pytest.raises(StockError, match="larger than the blank"):
        stock_shape(spec_of("reference_z23_m4"), StockSpec(stub_diameter_mm=200.0, stub_length_mm=5.0))


def test_step_round_trip_and_assembly_names(tmp_path):
    spec = spec_of("reference_z23_m4")
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_Reader

    original = spur_cad.gear_shape(spec)
    files = step_files(original, spur_cad.stock_shape(spec))
    for name, content in files.items():
        (tmp_path / name).write_bytes(content)
        assert b"SI_UNIT(.MILLI.,.METRE.)" in content, name
    step_reader = STEPControl_Reader()
    assert step_reader.ReadFile(str(tmp_path / "gear.step")) == IFSelect_RetDone
    step_reader.TransferRoots()
    reimported = step_reader.OneShape()
    assert BRepCheck_Analyzer(reimported).IsValid()
    assert solid_volume_mm3(reimported) == pytest.approx(solid_volume_mm3(original), rel=1e-9)
    a, b = _box(reimported), _box(original)
    for attr in ("xmin", "xmax", "ymin", "ymax", "zmin", "zmax"):
        assert getattr(a, attr) == pytest.approx(getattr(b, attr), abs=1e-6)
    # Part names survive in the assembly (read with OCP's XCAF reader, not CadQuery's writer).
    from OCP.STEPCAFControl import STEPCAFControl_Reader
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_Name
    from OCP.TDF import TDF_ChildIterator
    from OCP.TDocStd import TDocStd_Document

    doc = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
    reader = STEPCAFControl_Reader()
    reader.SetNameMode(True)
    reader.ReadFile(str(tmp_path / "job.step"))
    assert reader.Transfer(doc)
    names = set()
    iterator = TDF_ChildIterator(doc.Main(), True)
    while iterator.More():
        attribute = TDataStd_Name()
        if iterator.Value().FindAttribute(TDataStd_Name.GetID_s(), attribute):
            names.add(attribute.Get().ToExtString())
        iterator.Next()
    assert {"gear", "stock"} <= names, names


@pytest.mark.cadquery
def test_build123d_wraps_the_same_shape():
    import build123d

    spec = spec_of("shifted_z12")
    gear = spur_cad.make_gear(spec)
    solid = spur_cad.to_build123d(gear)
    assert isinstance(solid, build123d.Solid) and solid.is_valid
    assert solid.wrapped.IsSame(gear.val().wrapped)
    assert solid_volume_mm3(solid.wrapped) == pytest.approx(
        polygon_area(gear_outline(spec, 1e-6)) * spec.face_width_mm, rel=1e-6)
    # build123d's own (default-integration) volume agrees to OCP's default accuracy.
    assert solid.volume == pytest.approx(gear.val().Volume(), rel=1e-12)


def test_import_spur_cad_does_not_load_cadquery():
    import subprocess
    import sys

    code = "import sys, spur_cad; spur_cad.GearSpec(teeth=20, module_mm=2); print('cadquery' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=False)
    assert out.stdout.strip() == "False", out.stderr


def test_job_step_writes_the_parts_colour_styles_in_the_parts_order_whatever_order_occt_adds_them(tmp_path):
    """OCCT adds the two parts' colour styles last, in an order keyed by the shapes' addresses (it changed from
    run to run): job.step puts them in the parts' order, so that two runs write the same bytes. Here the stock's
    style (11 entities, with its translucency) is planted before the gear's (9) on purpose, whatever order OCCT
    chose, so both moves are made (each block over the other): the same bytes come out, the gear's colour first."""
    import re

    from OCP.IFSelect import IFSelect_RetDone

    from spur_cad.cad.step import (
        GEAR_COLOUR,
        STOCK_COLOUR,
        _assembly_writer,
        _styles_in_part_order,
        style_blocks,
        swap_style_blocks,
    )

    spec = spec_of("reference_z23_m4")
    gear, stock = spur_cad.gear_shape(spec), spur_cad.stock_shape(spec)
    written = step_files(gear, stock, "2023-11-14T22:13:20")["job.step"]
    writer = _assembly_writer(gear, stock, "2023-11-14T22:13:20")
    model = writer.ChangeWriter().Model()
    if [part for part, _, _ in style_blocks(model)] == [1, 0]:
        swap_style_blocks(model, *style_blocks(model))
    blocks = style_blocks(model)
    assert [(part, size) for part, _, size in blocks] == [(0, 9), (1, 11)]
    swap_style_blocks(model, *blocks)  # the stock's 11 entities moved before the gear's 9
    assert [(part, size) for part, _, size in style_blocks(model)] == [(1, 11), (0, 9)]
    _styles_in_part_order(model)  # and the gear's 9 back before the stock's 11
    assert [part for part, _, _ in style_blocks(model)] == [0, 1]
    assert writer.Write(str(tmp_path / "job.step")) == IFSelect_RetDone
    assert (tmp_path / "job.step").read_bytes() == written
    colours = [tuple(round(float(v), 6) for v in match) for match in
               re.findall(rb"COLOUR_RGB\('[^']*',([0-9.eE+-]+),([0-9.eE+-]+),([0-9.eE+-]+)\)", written)]
    assert colours == [GEAR_COLOUR[:3], STOCK_COLOUR[:3]]


def test_brep_text_reads_back_as_the_same_solid_in_the_format_freecad_020_reads():
    """The workbench hands solids to FreeCAD as BREP text (OCP's writer, no front-end): read back by OCP's reader
    it is the same solid, and it is written in format version 3, the newest OCCT 7.6 (FreeCAD 0.20) reads."""
    from OCP.BRep import BRep_Builder
    from OCP.BRepTools import BRepTools
    from OCP.TopoDS import TopoDS_Shape

    from spur_cad.cad.brep import brep_text

    shape = spur_cad.gear_shape(spec_of("shifted_z12"))
    text = brep_text(shape)
    assert text.splitlines()[1].startswith("CASCADE Topology V3")
    read = TopoDS_Shape()
    BRepTools.Read_s(read, io.BytesIO(text.encode("ascii")), BRep_Builder())
    assert BRepCheck_Analyzer(read).IsValid()
    assert solid_volume_mm3(read) == pytest.approx(solid_volume_mm3(shape), rel=1e-12)
