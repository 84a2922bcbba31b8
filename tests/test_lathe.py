"""The blank's lathe program (issue 18, first point): spur_cad.cam.turning + spur_cad.post.lathe + the reader's
lathe mode.

Independent references: LinuxCNC's own interpreter rs274 (its canonical calls, X as a radius under G7), the
project's reader for the other dialects, and the stock solid (spur_cad.cad.solid.stock_shape) the
turned outline is compared with. The outline is computed here from the moves alone: the smallest diameter a
cutting point reaches over each Z (the insert a point, the blade the interval [z - width, z])."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from OCP.BRepAlgoAPI import BRepAlgoAPI_Common
from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
from OCP.gp import gp_Pnt

from spur_cad.cad.solid import stock_shape
from spur_cad.cam.turning import MAX_PASSES, LatheError, LatheSection, check_lathe_blank, plan_lathe
from spur_cad.dialects import lathe_names
from spur_cad.job import load_job
from spur_cad.post.lathe import lathe_extension, post_lathe
from spur_cad.verify.reader import ProgramReadError, read_program
from tests.ocp_helper import exact_bounds
from tests.rs274_helper import canon_args, run_rs274

REFERENCE = "resources/examples/reference_gear.toml"
DIALECTS = lathe_names()  # every dialect with lathe words
TOL = 1.5e-3  # the programs round to 0.001 mm


@pytest.fixture(scope="module")
def job():
    return load_job(REFERENCE)


def _variants(job) -> dict:
    """(stock, lathe) pairs: the reference (stub), no stub, a stub kept on the bar, a stub as wide as the blank,
    nothing for the blade to do."""
    no_stub = dataclasses.replace(job.stock, stub_diameter_mm=0.0, stub_length_mm=0.0)
    blank = 2.0 * job.stock.blank_radius_mm(job.gear)
    return {
        "stub": (job.stock, LatheSection()),
        "no_stub": (no_stub, LatheSection(face_stock_mm=2.5, depth_of_cut_mm=1.0, chamfer_mm=1.0)),
        "stub_kept": (job.stock, LatheSection(part_off=False, chamfer_mm=0.0, bar_diameter_mm=110.0)),
        "equal_stub": (dataclasses.replace(job.stock, stub_diameter_mm=blank, stub_length_mm=2.0),
                       LatheSection(parting_blade_width_mm=4.0)),
        "no_blade": (no_stub, LatheSection(part_off=False, chamfer_mm=0.0)),
    }


VARIANTS = ("stub", "no_stub", "stub_kept", "equal_stub", "no_blade")


def _posted(job, variant: str, dialect: str):
    stock, lathe = _variants(job)[variant]
    lathe = dataclasses.replace(lathe, dialect=dialect)
    plan = plan_lathe(job.gear, stock, lathe)
    return stock, lathe, plan, post_lathe(plan, lathe, job.job.name, ("blank for the reference gear",))


def _rs274_moves(canon: list[str]) -> list[tuple]:
    """(rapid, x diameter, z, feed, tool) from rs274's canonical calls (X is a radius there under G7)."""
    tool, feed, moves = 0, math.nan, []
    for line in canon:
        if line.startswith("CHANGE_TOOL("):
            tool = int(canon_args(line)[0])
        elif line.startswith("SET_FEED_RATE("):
            feed = canon_args(line)[0]
        elif line.startswith(("STRAIGHT_TRAVERSE(", "STRAIGHT_FEED(")):
            args = canon_args(line)
            rapid = line.startswith("STRAIGHT_TRAVERSE")
            moves.append((rapid, 2.0 * args[0], args[2], math.nan if rapid else feed, tool))
    return moves


def _reader_moves(text: str, dialect: str) -> list[tuple]:
    m = read_program(text, dialect, f"blank.{lathe_extension(dialect)}", lathe=True)
    assert np.all(m.y == 0.0) and np.all(m.a == 0.0)
    return list(zip(m.rapid.tolist(), m.x.tolist(), m.z.tolist(), m.feed.tolist(), m.tool.tolist()))


def _plan_moves(plan) -> list[tuple]:
    return [(m.rapid, m.x, m.z, m.feed, m.tool) for m in plan.moves]


def _same_moves(got: list[tuple], want: list[tuple]) -> None:
    assert len(got) == len(want)
    got_a, want_a = np.array(got, float), np.array(want, float)
    assert np.array_equal(got_a[:, 0], want_a[:, 0])  # rapid flags
    assert np.allclose(got_a[:, 1:3], want_a[:, 1:3], atol=TOL, rtol=0)
    assert np.allclose(got_a[:, 3], want_a[:, 3], atol=1e-9, rtol=0, equal_nan=True)
    assert np.array_equal(got_a[:, 4], want_a[:, 4])


# --- the turned outline, from moves alone ---------------------------------------------------------------


def turned_outline(moves: list[tuple], blade: int, width: float, zs: np.ndarray) -> np.ndarray:
    """The smallest diameter any feed move's cutting point reaches over each Z of `zs` (inf: not reached).
    The insert cuts at its program point; tool `blade` over [z - width, z]."""
    out = np.full(len(zs), np.inf)
    previous = None
    for rapid, x, z, _feed, tool in moves:
        if previous is not None and not rapid:
            out = np.minimum(out, _segment_min(*previous, x, z, width if tool == blade else 0.0, zs))
        previous = (x, z)
    return out


def _segment_min(x0, z0, x1, z1, w, zs):
    lo, hi = min(z0, z1), max(z0, z1)
    a, b = np.maximum(zs, lo), np.minimum(zs + w, hi)  # program points whose cutting width covers zs
    covered = a <= b + 1e-12
    if hi - lo < 1e-12:
        value = np.full(len(zs), min(x0, x1))
    else:
        at = lambda z: x0 + (x1 - x0) * (z - z0) / (z1 - z0)  # noqa: E731
        value = np.minimum(at(a), at(b))
    return np.where(covered, value, np.inf)


def _bbox(shape) -> tuple[float, ...]:
    return exact_bounds(shape)


def stock_diameters(spec, stock, x_mill: np.ndarray) -> tuple[np.ndarray, float]:
    """The stock solid's diameter at milling X positions (thin sections of the OCP solid) and its far X."""
    solid = stock_shape(spec, stock)
    far = _bbox(solid)[3]
    diameters = []
    for x in x_mill:
        section = BRepAlgoAPI_Common(solid, BRepPrimAPI_MakeBox(gp_Pnt(x - 0.005, -500.0, -500.0), 0.01, 1000.0,
                                                                1000.0).Shape()).Shape()
        box = _bbox(section)
        diameters.append(box[4] - box[1])
    return np.array(diameters), far


def outline_problems(job, stock, lathe, moves: list[tuple]) -> list[str]:
    """Everything wrong with the turned outline of `moves` against the stock solid and [lathe] (empty: right)."""
    spec, c, w, blade = job.gear, lathe.chamfer_mm, lathe.parting_blade_width_mm, lathe.parting_tool_number
    front, length = stock.front_margin_mm, stock.front_margin_mm + spec.face_width_mm + stock.back_margin_mm
    # the stock solid: diameters at sample positions away from the chamfers and the steps
    x_mill = np.concatenate([np.linspace(-front + c + 0.1, length - front - c - 0.1, 15),
                             np.linspace(length - front + 0.1, length - front + stock.stub_length_mm - 0.1, 10)
                             if stock.stub_length_mm > 0 else []])
    expected, far = stock_diameters(spec, stock, x_mill)
    zs = -(x_mill + front)
    end_z = -(far + front)
    got = turned_outline(moves, blade, w, zs)
    problems = [f"diameter {g:.4f} at Z {z:.3f}, the stock's is {e:.4f}"
                for z, g, e in zip(zs, got, expected) if abs(g - e) > TOL]
    d = 2.0 * stock.blank_radius_mm(spec)
    blank_zone = np.linspace(-length + 0.001, -0.001, 4001)
    lowest = turned_outline(moves, blade, w, blank_zone)
    floor = np.full(len(blank_zone), d)
    if c > 0:  # the chamfers: the front one always, the back one where the blank has a back edge
        floor = np.minimum(floor, d - 2.0 * c - 2.0 * blank_zone)
        if stock.stub_length_mm == 0 or stock.stub_diameter_mm < d - 1e-9:
            floor = np.minimum(floor, d - 2.0 * c + 2.0 * (blank_zone + length))
    if (lowest < floor - TOL).any():
        i = int(np.argmax(floor - lowest))
        problems.append(f"a feed move reaches diameter {lowest[i]:.4f} at Z {blank_zone[i]:.3f}, inside the "
                        f"blank ({floor[i]:.4f})")
    if c > 0:  # the front chamfer is cut on its 45 deg line (program points; the nose rounds it off)
        front_zone = np.linspace(-c + 0.01, -0.01, 20)
        line = d - 2.0 * c - 2.0 * front_zone
        if np.abs(turned_outline(moves, blade, w, front_zone) - line).max() > TOL:
            problems.append("the front chamfer is not on its 45 deg line")
    face = [(x, z) for rapid, x, z, _f, tool in moves if not rapid and tool != blade and x <= 0.0]
    if not face or abs(min(z for _x, z in face)) > TOL:
        problems.append(f"the face is not turned through the centre at Z 0 ({face[-3:]})")
    parting = [z for rapid, x, z, _f, tool in moves if not rapid and tool == blade and x <= 0.0]
    if lathe.part_off and (not parting or max(abs(z - end_z) for z in parting) > TOL):
        problems.append(f"the part-off is at {sorted(set(parting))}, the stock ends at Z {end_z:.3f}")
    if not lathe.part_off and parting:
        problems.append("parted off though part_off = false")
    return problems


def rapid_problems(moves: list[tuple], lathe: LatheSection, bar: float) -> list[str]:
    """Rapids that enter the bar: both ends of each rapid on the safe diameter (bar + 2 x clearance) or both
    beyond the bar's current end + clearance (the face stock until the face is turned); the blade over its
    width. The first move of each tool goes to the tool change point."""
    safe, cl, w = bar + 2.0 * lathe.clearance_mm, lathe.clearance_mm, lathe.parting_blade_width_mm
    end, problems, previous, tool = lathe.face_stock_mm, [], None, None
    for index, (rapid, x, z, _f, t) in enumerate(moves):
        width = w if t == lathe.parting_tool_number else 0.0
        if t != tool and (abs(x - (lathe.tool_change_x_mm or safe)) > TOL or abs(z - lathe.tool_change_z_mm) > TOL):
            problems.append(f"move {index}: tool {t}'s first move is not to the tool change point")
        if rapid and previous is not None:
            radial = min(previous[0], x) >= safe - TOL
            axial = min(previous[1], z) - width >= end + cl - TOL
            if not (radial or axial):
                problems.append(f"move {index}: rapid from {previous} to {(x, z)} enters the bar")
        if not rapid and t == lathe.turning_tool_number and x <= 0.0:
            end = min(end, z)
        previous, tool = (x, z), t
    return problems


# --- LinuxCNC's interpreter -----------------------------------------------------------------------------------


@pytest.mark.linuxcnc
@pytest.mark.parametrize("variant", VARIANTS)
def test_rs274_runs_the_linuxcnc_lathe_program_and_turns_the_stock(job, variant, rs274, tmp_path):
    stock, lathe, plan, text = _posted(job, variant, "linuxcnc")
    path = tmp_path / "blank.ngc"
    path.write_text(text)
    ok, canon, messages = run_rs274(path)
    assert ok, messages
    assert "SET_FEED_MODE(0, 1)" in canon  # G95: units per revolution
    assert f"SET_SPINDLE_MODE(0 {lathe.max_spindle_rpm:.4f})" in canon  # G96 D: CSS under the limit
    assert any(line.startswith("COMMENT(\"interpreter: Lathe diameter mode") for line in canon)
    assert not any(line.startswith("MESSAGE") for line in canon)
    moves = _rs274_moves(canon)
    _same_moves(moves, _plan_moves(plan))
    assert outline_problems(job, stock, lathe, moves) == []
    assert rapid_problems(moves, lathe, plan.geometry.bar_diameter) == []


# --- the reader, every dialect ------------------------------------------------------------------------------


@pytest.mark.parametrize("dialect", DIALECTS)
@pytest.mark.parametrize("variant", VARIANTS)
def test_the_reader_reads_every_dialect_and_the_outline_is_the_stock(job, variant, dialect):
    stock, lathe, plan, text = _posted(job, variant, dialect)
    moves = _reader_moves(text, dialect)
    _same_moves(moves, _plan_moves(plan))
    assert outline_problems(job, stock, lathe, moves) == []
    assert rapid_problems(moves, lathe, plan.geometry.bar_diameter) == []
    tools = {m[4] for m in moves}
    uses_blade = variant != "no_blade"
    assert tools == ({lathe.turning_tool_number, lathe.parting_tool_number} if uses_blade
                     else {lathe.turning_tool_number})


def test_the_blocks_each_dialect_needs(job):
    siemens = _posted(job, "stub", "siemens")[3].splitlines()
    assert siemens[siemens.index("G18 G90 G71 G95 G40 DIAMON") + 1:][:2] == ["G54", "LIMS=3000"]
    assert 'WORKPIECE(,,,"CYLINDER",192,1.0,-66.0,-63.0,105.0)' in siemens
    assert ["T1 D1", "G96 S200 M3", "M8"] == siemens[siemens.index("T1 D1"):][:3]
    assert ["T2 D1", "G96 S100 M3", "M8"] == siemens[siemens.index("T2 D1"):][:3]
    assert not any("M6" in line for line in siemens)
    assert siemens[-3:] == ["M9", "M5", "M30"]
    fanuc = _posted(job, "stub", "fanuc")[3].splitlines()
    assert fanuc[:2] == ["%", "O2000 (REFERENCE GEAR Z23 M4)"] and fanuc[-5:] == ["M09", "M05", "G97", "M30", "%"]
    assert ["G21 G18 G40 G99", "G54", "G50 S3000"] == fanuc[fanuc.index("G21 G18 G40 G99"):][:3]
    assert ["T0101", "G96 S200 M03", "M08"] == fanuc[fanuc.index("T0101"):][:3]
    assert "T0202" in fanuc and not any(line.startswith("G90") for line in fanuc)
    linuxcnc = _posted(job, "stub", "linuxcnc")[3].splitlines()
    assert ["G7", "G18 G21 G90 G40 G95", "G54"] == linuxcnc[linuxcnc.index("G7"):][:3]
    assert ["T1 M6 G43", "G96 D3000 S200 M3", "M8"] == linuxcnc[linuxcnc.index("T1 M6 G43"):][:3]
    reversed_ = post_lathe(plan_lathe(job.gear, job.stock, LatheSection(spindle_direction="M4", work_offset="G56",
                                                                         dialect="fanuc")),
                           LatheSection(spindle_direction="M4", work_offset="G56", dialect="fanuc"), "t")
    assert "G96 S200 M04" in reversed_ and "\nG56\n" in reversed_
    assert {lathe_extension(d) for d in DIALECTS} == {"mpf", "nc", "ngc"}


def test_the_passes_follow_the_keys(job):
    """Facing in passes of at most depth_of_cut, roughing to the diameter + 2 x allowance, the finishing pass
    on the blank diameter, the stub's plunges overlapping."""
    stock, lathe = _variants(job)["no_stub"]
    plan = plan_lathe(job.gear, stock, lathe)
    facing = sorted({m.z for m in plan.moves if m.operation == "facing" and not m.rapid and m.x < 0 and m.feed < 0.5})
    assert facing == pytest.approx([0.0, 2.5 / 3, 5.0 / 3])
    d = plan.geometry.blank_diameter
    roughing = sorted({round(m.x, 9) for m in plan.moves if m.operation == "roughing" and not m.rapid
                       and m.feed == lathe.roughing_feed_mm_rev})
    assert roughing[0] == pytest.approx(d + 2 * lathe.finish_allowance_mm)
    steps = np.diff([plan.geometry.bar_diameter, *roughing[::-1]])
    assert np.all(np.abs(steps) <= 2 * lathe.depth_of_cut_mm + 1e-9)
    assert any(m.operation == "finishing" and m.x == d and m.z == -plan.geometry.blank_length for m in plan.moves)
    reference = plan_lathe(job.gear, job.stock, LatheSection())
    plunges = sorted({m.z for m in reference.moves if m.operation == "stub finishing" and not m.rapid})
    assert np.diff(plunges).max() <= 0.75 * 3.0 + 1e-9


# --- errors ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("changes, field", [
    ({"bar_diameter_mm": 100.0}, "bar_diameter_mm"),  # the blank is 101 mm
    ({"parting_tool_number": 1}, "parting_tool_number"),
    ({"bar_diameter_mm": math.nan}, "bar_diameter_mm"),
    ({"depth_of_cut_mm": 1e9}, "depth_of_cut_mm"),
    ({"clearance_mm": math.inf}, "clearance_mm"),
    ({"program_number": 10**20}, "program_number"),
    ({"max_spindle_rpm": -1.0}, "max_spindle_rpm"),
    ({"turning_tool_number": 100}, "turning_tool_number"),
    ({"finish_allowance_mm": 2.0}, "finish_allowance_mm"),  # above depth_of_cut_mm
    ({"dialect": "haas"}, "dialect"),
    ({"work_offset": "G53"}, "work_offset"),
    ({"chamfer_mm": 15.0}, "chamfer_mm"),  # more than the 10.5 mm shoulder
    ({"chamfer_mm": 2.0}, "chamfer_mm"),  # the finishing cut at the front chamfer would exceed depth_of_cut_mm
    ({"parting_max_depth_mm": 50.0}, "parting_max_depth_mm"),  # the part-off needs 53 mm
    ({"tool_change_z_mm": 2.0}, "tool_change_z_mm"),
    ({"tool_change_x_mm": 100.0}, "tool_change_x_mm"),
    ({"bar_diameter_mm": 2000.0, "depth_of_cut_mm": 0.05, "finish_allowance_mm": 0.0, "chamfer_mm": 0.0},
     "depth_of_cut_mm"),  # the passes bound: 19,000 roughing passes
])
def test_settings_that_cannot_turn_the_blank_are_refused(job, changes, field):
    """Refused naming the key: by the section when it is made (its own keys), else by the plan (against the
    stock)."""
    with pytest.raises(LatheError) as raised:
        plan_lathe(job.gear, job.stock, dataclasses.replace(LatheSection(), **changes))
    assert raised.value.field == field and raised.value.section == "lathe"
    assert raised.value.key == f"lathe.{field}"


def test_the_passes_bound_is_checked_before_any_move(job):
    lathe = LatheSection(bar_diameter_mm=2000.0, depth_of_cut_mm=0.05, finish_allowance_mm=0.0, chamfer_mm=0.0)
    with pytest.raises(LatheError, match=f"{MAX_PASSES:,}"):
        check_lathe_blank(job.gear, job.stock, lathe)


def test_a_wrong_type_is_refused(job):
    with pytest.raises(LatheError) as raised:
        plan_lathe(job.gear, job.stock, LatheSection(part_off="yes"))
    assert raised.value.field == "part_off"


@pytest.mark.parametrize("dialect", DIALECTS)
def test_user_text_stays_in_one_inert_comment(job, dialect):
    title = "gear (MSG, hello)\nM30\n%\r; G0 X0"
    lathe = LatheSection(dialect=dialect)
    plan = plan_lathe(job.gear, job.stock, lathe)
    text = post_lathe(plan, lathe, title, ("note\n(DEBUG, x)", "x" * 1000))
    lines = text.splitlines()
    hits = [line for line in lines if "HELLO" in line.upper()]
    assert len(hits) == 1
    comment = (lambda line: line.startswith(";")) if dialect == "siemens" else \
        (lambda line: line.startswith("(") and line.endswith(")") and line.count("(") == 1
         or line.startswith("O2000 (") and line.count("(") == 1)
    assert comment(hits[0])
    assert all(comment(line) for line in lines if "DEBUG" in line.upper() or "XXXX" in line.upper())
    assert max(len(line) for line in lines) <= 250
    assert lines.count("%") == (2 if dialect == "fanuc" else 0)
    assert sum(line.strip() in ("M30", "M30 ") for line in lines) == 1
    _same_moves(_reader_moves(text, dialect), _plan_moves(plan))


# --- the checks themselves see a planted fault ------------------------------------------------------------


def test_the_outline_check_sees_a_wrong_diameter(job):
    """A finishing pass 0.05 mm under the blank diameter, a stub 0.05 mm thick, a part-off 1 mm short of the end,
    a rapid through the bar: each is reported."""
    stock, lathe, plan, _ = _posted(job, "stub", "fanuc")
    moves = _plan_moves(plan)
    d = plan.geometry.blank_diameter
    gouge = [(r, x - 0.05 if abs(x - d) < 1e-9 and not r else x, z, f, t) for r, x, z, f, t in moves]
    assert any("inside the blank" in p for p in outline_problems(job, stock, lathe, gouge))
    thick = [(r, x + 0.05 if abs(x - 80.0) < 1e-9 else x, z, f, t) for r, x, z, f, t in moves]
    assert any("the stock's is 80" in p for p in outline_problems(job, stock, lathe, thick))
    short = [(r, x, z + 1.0 if x < 0 and t == 2 else z, f, t) for r, x, z, f, t in moves]
    assert any("part-off" in p for p in outline_problems(job, stock, lathe, short))
    crash = list(moves)
    i = next(i for i, m in enumerate(moves) if m[0] and m[1] < 105.0 and m[2] > 0)  # a rapid to a roughing pass
    crash[i] = (True, moves[i][1], -5.0, math.nan, moves[i][4])
    assert rapid_problems(crash, lathe, plan.geometry.bar_diameter)


# --- the reader's lathe mode and the milling additions ---------------------------------------------------------

LATHE_HEAD = {"linuxcnc": "G7\nG18 G21 G90 G40 G95\nG54\nT1 M6 G43\nG96 D3000 S200 M3\n",
              "siemens": "G18 G90 G71 G95 G40 DIAMON\nG54\nLIMS=3000\nT1 D1\nG96 S200 M3\n",
              "fanuc": "%\nO2000 (T)\nG21 G18 G40 G99\nG54\nG50 S3000\nT0101\nG96 S200 M03\n"}


@pytest.mark.parametrize("dialect, body, message", [
    ("linuxcnc", "G0 X100 Z2\nG0 Y1\n", "X and Z only"),
    ("fanuc", "G0 X100 Z2\nG0 A10\n", "X and Z only"),
    ("siemens", "G0 X100 Z2\nG1 U-2 F0.1\n", "X and Z only"),
    ("linuxcnc", "G8\nG0 X100 Z2\n", "radius"),
    ("siemens", "DIAMOF\nG0 X100 Z2\n", "radius"),
    ("linuxcnc", "G94\nG0 X100 Z2\nG1 X90 F100\n", "per revolution"),
    ("fanuc", "G98\nG0 X100 Z2\nG1 X90 F100\n", "per revolution"),
    ("fanuc", "G0 X100 Z2\nG90 X90 Z-10 F0.2\n", "turning cycle"),
    ("fanuc", "G50 X100 Z2\n", "G50"),
    ("fanuc", "T1\n", "T0101"),
    ("siemens", "G26 X100\n", "G26"),
])
def test_the_lathe_reader_refuses_what_it_cannot_read(dialect, body, message):
    text = LATHE_HEAD[dialect] + body + "M30\n"
    with pytest.raises(ProgramReadError, match=message):
        read_program(text, dialect, "p", lathe=True)


def test_the_lathe_reader_reads_tools_feeds_and_diameters():
    text = LATHE_HEAD["fanuc"] + "G0 X100 Z2\nG1 X90 F0.15\nT0303\nG97 S800 M04\nG0 X95 Z1\nM30\n%\n"
    m = read_program(text, "fanuc", "p", lathe=True)
    assert m.x.tolist() == [100.0, 90.0, 95.0] and m.tool.tolist() == [1, 1, 3]
    assert m.feed[1] == 0.15 and m.spindle_rpm.tolist() == [200.0, 200.0, 800.0]
    siemens = 'WORKPIECE(,,,"CYLINDER",192,1,-66,-63,105)\n' + LATHE_HEAD["siemens"] + \
        "G0 X100 Z2\nG96 S180 LIMS=2500 M4\nT=2 D1\nG1 X80 F0.05\nM30\n"
    m = read_program(siemens, "siemens", "p", lathe=True)
    assert m.tool.tolist() == [1, 2] and m.x.tolist() == [100.0, 80.0]
    with pytest.raises(ProgramReadError, match="lathe dialect"):
        read_program(siemens, "haas", "p", lathe=True)


def test_the_milling_reader_takes_workpiece_and_okuma_work_offsets():
    siemens = 'WORKPIECE(,"",,"BOX",240,25,0,0,-30,-20,30,20)\nG71 G90 G94 G17 G40\nT1 D1\nM6\nS1000 M3\n' \
        "G0 X1 Y2 Z3 A0\nM30\n"
    assert read_program(siemens, "siemens", "p").x.tolist() == [1.0]
    okuma = "G21 G90 G94 G17 G40 G80\nG15 H1\nT1 M06\nS1000 M03\nG0 X1 Y2 Z3 A0\nM30\n"
    assert read_program(okuma, "okuma", "p").z.tolist() == [3.0]
    for bad in ("G15\n", "G15 H0\n", "G15 H1 X5\n"):
        with pytest.raises(ProgramReadError, match="G15"):
            read_program(okuma.replace("G15 H1\n", bad), "okuma", "p")
    with pytest.raises(ProgramReadError):
        read_program(okuma.replace("G21", "G21 G7"), "okuma", "p")  # a lathe code in a milling program
