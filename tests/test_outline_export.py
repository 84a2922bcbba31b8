"""[export]: gear.dxf and gear.svg read back (ezdxf for the DXF, xml.etree for the SVG; bulges and SVG arcs turned
into circles here) against the exact outline and the exact offset curve (the points |d| from it); determinism across
processes; bad input exits 2 with one line."""

from __future__ import annotations

import io
import math
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from shapely.geometry import Point as ShapelyPoint
from shapely.geometry import Polygon

from spur_cad.job import parse_job
from spur_cad.pipeline import export_files
from tests.test_cli import run_cli
from tests.test_outline2d import _exact_neighbourhood, _exact_space, _polyline_distance, _turn

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "resources" / "examples" / "wire_edm_gear.toml"


def _job_text(offset_mm: float = 0.12, extra: str = "", gear: str = "") -> str:
    return f"""
[job]
name = "m1 z12 <wire> & \\"co\\""
[gear]
teeth = 12
module_mm = 1.0
rack_tip_radius_mm = 0.25
face_width_mm = 5.0
bore_diameter_mm = 4.0
keyway_width_mm = 1.5
keyway_depth_mm = 0.8
{gear}
[export]
dxf = true
svg = true
offset_mm = {offset_mm}
{extra}
"""


def _arc_points(p0, p1, sweep: float, n: int) -> np.ndarray:
    """n points on the arc from p0 to p1 turning by `sweep` (signed, counter-clockwise positive)."""
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    if sweep == 0.0:
        return p0 + np.linspace(0, 1, n)[:, None] * (p1 - p0)
    chord = p1 - p0
    c = float(np.hypot(*chord))
    left = np.array([-chord[1], chord[0]]) / c
    center = 0.5 * (p0 + p1) + left * (c / 2.0) / math.tan(sweep / 2.0)
    r = c / (2.0 * abs(math.sin(sweep / 2.0)))
    a0 = math.atan2(*(p0 - center)[::-1])
    angles = a0 + np.linspace(0.0, sweep, n)
    return center + r * np.stack([np.cos(angles), np.sin(angles)], axis=-1)


def _dxf_loops(content: bytes) -> dict[str, list[np.ndarray]]:
    """{layer: [dense points of each closed LWPOLYLINE]}, the bulges turned into arcs here."""
    doc = ezdxf.read(io.StringIO(content.decode("ascii")))
    assert doc.header["$INSUNITS"] == 4
    loops: dict[str, list[np.ndarray]] = {}
    for entity in doc.modelspace():
        assert entity.dxftype() == "LWPOLYLINE"
        assert entity.closed
        vertices = list(entity.get_points("xyb"))
        pieces = []
        for (x0, y0, bulge), (x1, y1, _) in zip(vertices, vertices[1:] + vertices[:1]):
            pieces.append(_arc_points((x0, y0), (x1, y1), 4.0 * math.atan(bulge), 40)[:-1])
        loops.setdefault(entity.dxf.layer, []).append(np.concatenate(pieces))
    return loops


def _svg_loops(content: bytes) -> tuple[str, dict[str, list[np.ndarray]]]:
    """(title, {group id: [dense points of each path]}) with SVG's y flipped back; arcs from their end points, radius
    and flags (large-arc 0 only, as written), solved here."""
    ns = {"s": "http://www.w3.org/2000/svg"}
    root = ET.fromstring(content)
    loops: dict[str, list[np.ndarray]] = {}
    for group in root.findall("s:g", ns):
        for path in group.findall("s:path", ns):
            tokens = re.findall(r"[MALZ]|-?\d+(?:\.\d+)?", path.get("d"))
            points, i, current = [], 0, None
            while i < len(tokens):
                command = tokens[i]
                if command == "M":
                    current = np.array([float(tokens[i + 1]), -float(tokens[i + 2])])
                    i += 3
                elif command == "L":
                    end = np.array([float(tokens[i + 1]), -float(tokens[i + 2])])
                    points.append(_arc_points(current, end, 0.0, 40)[:-1])
                    current, i = end, i + 3
                elif command == "A":
                    r, large, flag = float(tokens[i + 1]), tokens[i + 4], tokens[i + 5]
                    end = np.array([float(tokens[i + 6]), -float(tokens[i + 7])])
                    assert large == "0"
                    half = min(1.0, float(np.hypot(*(end - current))) / (2.0 * r))
                    sweep = 2.0 * math.asin(half) * (1.0 if flag == "0" else -1.0)  # flag 1: clockwise, y up
                    points.append(_arc_points(current, end, sweep, 40)[:-1])
                    current, i = end, i + 8
                else:
                    i += 1
            loops.setdefault(group.get("id"), []).append(np.concatenate(points))
    return root.find("s:title", ns).text, loops


def _check_on_offset(points: np.ndarray, spec, offset_mm: float) -> None:
    """Points of space 0's region lie |offset| (within 1 um) from the exact outline, outside it for a positive offset;
    and every exact point moved along its normal (unless trimmed away) lies within 1 um of the points' polyline."""
    exact = _exact_neighbourhood(spec)
    half = math.pi / spec.teeth
    mine = points[np.abs(np.arctan2(points[:, 0], points[:, 1])) <= half]
    assert np.abs(_polyline_distance(mine, exact) - abs(offset_mm)).max() <= 0.001
    space, normals = _exact_space(spec)
    pitch = 2.0 * math.pi / spec.teeth
    gear = Polygon(np.concatenate([_turn(space[1:], k * pitch) for k in range(spec.teeth)]))
    if offset_mm != 0.0:
        assert all(gear.contains(ShapelyPoint(p)) == (offset_mm < 0) for p in mine[::11])
    moved = space + offset_mm * normals
    kept = _polyline_distance(moved, exact) >= abs(offset_mm) - 1e-7
    ring = np.concatenate([points, points[:1]])
    assert _polyline_distance(moved[kept], ring).max() <= 0.001


@pytest.mark.parametrize("offset_mm", [0.0, 0.12])
def test_dxf_read_back_lies_on_the_exact_outline_and_its_offset(offset_mm):
    job = parse_job(_job_text(offset_mm))
    files = export_files(job)
    loops = _dxf_loops(files["gear.dxf"])
    assert sorted(loops) == ["BORE", "OUTLINE"] and len(loops["OUTLINE"]) == 1 and len(loops["BORE"]) == 1
    _check_on_offset(loops["OUTLINE"][0], job.gear, offset_mm)
    # the bore: offset into the hole; off the keyway (|y| > 0.75 + offset) its points are on the circle r - d
    bore = loops["BORE"][0]
    below = bore[(bore[:, 1] < 1.5)]
    assert np.abs(np.hypot(*below.T) - (2.0 - offset_mm)).max() <= 1e-6
    assert bore[:, 1].max() == pytest.approx(2.0 + 0.8 - offset_mm, abs=1e-9)


def test_svg_read_back_lies_on_the_exact_offset_and_escapes_the_name():
    job = parse_job(_job_text(0.12))
    content = export_files(job)["gear.svg"]
    title, loops = _svg_loops(content)
    assert title.startswith("spur_cad") and 'm1 z12 <wire> & "co"' in title
    assert b"<wire>" not in content
    assert sorted(loops) == ["BORE", "OUTLINE"]
    _check_on_offset(loops["OUTLINE"][0], job.gear, 0.12)
    assert re.search(rb'width="[\d.]+mm"', content)


@pytest.mark.slow  # two whole runs (5 s)
def test_two_runs_in_two_processes_give_the_same_bytes(tmp_path):
    """Fresh processes with different hash seeds (ezdxf orders some tables by sets; times and GUIDs change)."""
    script = ("import sys; from spur_cad.job import load_job; from spur_cad.pipeline import export_files; "
              "files = export_files(load_job(sys.argv[1])); "
              "sys.stdout.buffer.write(files['gear.dxf'] + b'@@' + files['gear.svg'])")
    job = tmp_path / "job.toml"
    job.write_text(_job_text(0.12))
    outputs = []
    for seed in ("1", "2"):
        env = {**os.environ, "PYTHONHASHSEED": seed}
        result = subprocess.run([sys.executable, "-c", script, str(job)], capture_output=True, env=env, check=True,
                                cwd=ROOT, timeout=120)
        outputs.append(result.stdout)
    assert outputs[0] == outputs[1]
    assert b"$TDCREATE" in outputs[0] and b"2451544.5" in outputs[0]


def test_no_export_writes_nothing():
    job = parse_job(_job_text().replace("dxf = true\nsvg = true", "dxf = false\nsvg = false"))
    assert export_files(job) == {}


@pytest.mark.parametrize(("replace", "expected"), [
    (("offset_mm = 0.12", "offset_mm = nan"), r"\[export\] offset_mm must be a finite number, got nan"),
    # the undercut fillet's smallest curvature radius is 0.393 mm (rack tip radius 0.25 mm)
    (("offset_mm = 0.12", "offset_mm = 0.4"), r"offset_mm = 0.4 mm is too big for the root.* 0.3929 mm"),
    (("offset_mm = 0.12", "offset_mm = -1.0"), r"offset_mm = -1: the gear's outline: .*breaks the outline"),
    (("offset_mm = 0.12", "offset_mm = 2.5"), r"too big for the root"),
    (("face_width_mm = 5.0", "face_width_mm = 5.0\nhelix_angle_deg = 15.0"), r"\[export\] dxf = true: a helical"),
])
def test_bad_export_exits_2_with_one_line(tmp_path, replace, expected):
    job = tmp_path / "job.toml"
    job.write_text(_job_text(0.12).replace(*replace))
    result = run_cli("run", str(job), "--out", str(tmp_path / "out"))
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and re.search(expected, lines[0]), lines
    assert re.match(rf"spur-cad: error: {re.escape(str(job))}:\d+: ", lines[0]), lines[0]
    assert not (tmp_path / "out").exists()


def test_bore_offset_that_fills_the_bore_is_refused():
    with pytest.raises(Exception, match=r"offset_mm.*the bore"):
        parse_job(_job_text(0.12, gear="").replace("bore_diameter_mm = 4.0", "bore_diameter_mm = 0.2")
                  .replace("keyway_width_mm = 1.5\nkeyway_depth_mm = 0.8\n", ""))


@pytest.mark.slow
def test_the_cli_writes_gear_dxf_and_svg_in_the_output_set(tmp_path):
    out = tmp_path / "out"
    result = run_cli("run", str(EXAMPLE), "--out", str(out))
    assert result.returncode == 0, result.stderr
    names = {p.name for p in out.iterdir()}
    assert {"gear.dxf", "gear.svg", "gear.step", "summary.json"} <= names
    job = parse_job(EXAMPLE.read_text())
    loops = _dxf_loops((out / "gear.dxf").read_bytes())
    _check_on_offset(loops["OUTLINE"][0], job.gear, job.export.offset_mm)
