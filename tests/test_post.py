"""G-code posts: LinuxCNC programs checked by LinuxCNC's own interpreter (rs274), every dialect read
back by an independent reader (tests/gcode_reader.py) and compared with the toolpath IR, G93
feeds against an independent integral of the tool's path over the part, and golden programs."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from spur_cad.cam.finishing import finishing_toolpath
from spur_cad.cam.ir import MoveKind
from spur_cad.cam.machine import Machine, RoughingParams
from spur_cad.cam.roughing import roughing_toolpath
from spur_cad.cam.strategies import FinishingParams
from spur_cad.post import DIALECT_NAMES, PostError, PostSettings, ProgramInfo, post_program
from tests.gcode_reader import inlined_lines, read_program
from tests.gears import CAM_GEARS, spec_of, tools_for
from tests.rs274_helper import canon_args, run_rs274
from tests.tiers import sweep

DECIMALS = {"linuxcnc": (4, 4), "fanuc": (3, 3), "haas": (3, 3), "siemens": (4, 4), "okuma": (3, 3)}
INFO = ProgramInfo("spur_cad test (program)", ("gear: z = test",))
CLEARANCE = 1.0


@pytest.fixture(scope="module")
def cam_paths():
    """Roughing and finishing IR for the CAM issue's test gears (a few finishing stations each)."""
    paths = {}
    for name in CAM_GEARS:
        spec = spec_of(name)
        roughing_tool, finishing_tool = tools_for(name)
        blank = spec.tip_radius_mm + 0.5
        roughing = roughing_toolpath(spec, roughing_tool, Machine(), RoughingParams(
            flank_allowance_mm=0.1 * spec.module_mm, finish_stock_mm=0.005 * spec.module_mm, strategy="levels"), blank)
        finishing = finishing_toolpath(spec, finishing_tool, Machine(), FinishingParams(strategy="perimeter",
            target_scallop_mm=0.005, step_over_mm=spec.face_width_mm / 2), blank)
        paths[name] = (spec, roughing_tool, finishing_tool, roughing, finishing)
    return paths


def motion_rows(path, rotary_sign: int = 1) -> list[tuple[bool, np.ndarray]]:
    rows = np.flatnonzero(path.motion_mask)
    poses = path.poses()[rows] * np.array([1, 1, 1, rotary_sign])
    return [(bool(path.kind[i] == MoveKind.RAPID), pose) for i, pose in zip(rows, poses)]


def assert_folded_moves_as_flat(moves_by_mode: dict[bool, list[tuple[bool, np.ndarray]]]) -> None:
    """The folded program's moves (read back, calls expanded) are the flat program's, one for one."""
    assert len(moves_by_mode[True]) == len(moves_by_mode[False])
    for (r1, p1), (r2, p2) in zip(moves_by_mode[True], moves_by_mode[False]):
        assert r1 == r2 and np.allclose(p1, p2, atol=1e-9)


def assert_same_moves(written: list[tuple[bool, np.ndarray]], path, linear_decimals: int, rotary_decimals: int,
                      rotary_sign: int = 1, wrapped: bool = False) -> None:
    """Every IR move appears, in order, within the output precision; IR moves missing from the
    program are no-ops at that precision (they end where the last written move ended)."""
    tol = np.array([0.5 * 10.0 ** -linear_decimals] * 3 + [10.0 ** -rotary_decimals]) + 1e-9

    def close(a, b):
        d = np.abs(np.asarray(a) - np.asarray(b))
        if wrapped:
            d[3] = min(d[3] % 360.0, 360.0 - d[3] % 360.0)
        return bool(np.all(d <= tol))

    j = 0
    for rapid, pose in motion_rows(path, rotary_sign):
        if j < len(written) and close(written[j][1], pose):
            assert written[j][0] == rapid, (j, pose)
            j += 1
        else:
            assert j > 0 and close(written[j - 1][1], pose), f"IR pose {pose} missing after written move {j}"
    assert j == len(written), f"{len(written) - j} written moves not in the IR"


def canonical_moves(canon: list[str]) -> list[tuple[bool, np.ndarray]]:
    return [(line.startswith("STRAIGHT_TRAVERSE"), np.array(canon_args(line)[:4]))
            for line in canon if line.startswith(("STRAIGHT_TRAVERSE", "STRAIGHT_FEED"))]


def reader_moves(text: str, dialect: str) -> list[tuple[bool, np.ndarray]]:
    return [(m.rapid, np.array(m.end)) for m in read_program(text, dialect).moves]


def write(tmp_path, name: str, text: str):
    target = tmp_path / name
    target.write_text(text)
    return target


# --- LinuxCNC programs through LinuxCNC's interpreter -------------------------------------------

@pytest.mark.linuxcnc
@pytest.mark.parametrize("name", CAM_GEARS)
def test_rs274_accepts_every_program_and_reproduces_the_ir(name, cam_paths, tmp_path):
    *_, roughing, finishing = cam_paths[name]
    for operation, path in (("roughing", roughing), ("finishing", finishing)):
        canon_by_mode = {}
        for folded in (False, True):
            program = post_program(path, PostSettings(folded=folded), INFO)
            ok, canon, messages = run_rs274(write(tmp_path, f"{operation}_{folded}.ngc", program.text))
            assert ok, messages
            moves = canonical_moves(canon)
            assert_same_moves(moves, path, 4, 4)
            canon_by_mode[folded] = [line for line in canon if line.startswith("STRAIGHT")]
        assert canon_by_mode[True] == canon_by_mode[False]


def canonical_straight_moves(canon: list[str]):
    """(is a feed move, inverse time in effect, feed rate, start pose or None, end pose) for every straight move of
    rs274's canonical output, following its feed mode and feed rate calls."""
    inverse, rate, pose = False, None, None
    for line in canon:
        if "feed mode set to inverse time" in line:
            inverse = True
        elif "feed mode set to units per minute" in line:
            inverse = False
        elif line.startswith("SET_FEED_RATE"):
            rate = canon_args(line)[0]
        elif line.startswith(("STRAIGHT_FEED", "STRAIGHT_TRAVERSE")):
            end = np.array(canon_args(line)[:4])
            yield line.startswith("STRAIGHT_FEED"), inverse, rate, pose, end
            pose = end


def relative_path_length(start, end, substeps: int = 64) -> float:
    """Length of the tool tip's path over the part for a move interpolated linearly in X, Y, Z, A
    (the part turned back by A: p = R(-A) (y, z)), by dense polyline."""
    t = np.linspace(0.0, 1.0, substeps + 1)[:, None]
    x, y, z, a = (np.asarray(start) + (np.asarray(end) - np.asarray(start)) * t).T
    ang = np.radians(a)
    py, pz = y * np.cos(ang) + z * np.sin(ang), -y * np.sin(ang) + z * np.cos(ang)
    return float(np.sum(np.sqrt(np.diff(x) ** 2 + np.diff(py) ** 2 + np.diff(pz) ** 2)))


@pytest.mark.linuxcnc
@pytest.mark.parametrize("name", ["reference_z23_m4", "undercut_z8"])
def test_rs274_g93_feed_gives_the_relative_path_time(name, cam_paths, tmp_path):
    _, _, tool, _, finishing = cam_paths[name]
    machine = Machine()
    feed = tool.feed_mm_min(machine)
    program = post_program(finishing, PostSettings(folded=True), INFO)
    ok, canon, messages = run_rs274(write(tmp_path, "f.ngc", program.text))
    assert ok, messages
    checked = 0
    for feed_move, inverse, rate, pose, end in canonical_straight_moves(canon):
        if inverse and feed_move and pose is not None:
            cartesian = float(np.linalg.norm(end[:3] - pose[:3]))
            assert cartesian > 1e-3, "a G93 move without X/Y/Z motion: its time cannot be read back"
            minutes = cartesian / rate  # rs274 reports the inverse-time feed as a cartesian rate
            intended = max(relative_path_length(pose, end) / feed,
                           abs(end[3] - pose[3]) / machine.max_rotary_speed_deg_min)
            tolerance = 4e-4 / feed + 1e-4 * intended + 0.5e-4 * intended ** 2
            assert minutes == pytest.approx(intended, abs=tolerance), (pose, end)
            checked += 1
    assert checked > 100


@pytest.mark.linuxcnc
@pytest.mark.slow
@pytest.mark.parametrize("strategy, least_moves", [("perimeter", 700_000), ("generating", 7_000)])
def test_folded_reference_finishing_is_15x_smaller_and_runs_the_same(tmp_path, strategy, least_moves):
    from spur_cad.job import parse_job
    from spur_cad.pipeline import plan_cam
    from tests.gears import reference_job_text

    job = parse_job(reference_job_text(strategy))
    assert job.gear.face_width_mm == 20.0  # full face width, as the shop cut it
    path = plan_cam(job).finishing.toolpath
    flat = post_program(path, PostSettings(folded=False), INFO)
    folded = post_program(path, PostSettings(folded=True), INFO)
    assert flat.lines >= 15 * folded.lines, (flat.lines, folded.lines)
    canon = {}
    for label, program in (("flat", flat), ("folded", folded)):
        ok, lines, messages = run_rs274(write(tmp_path, f"{label}.ngc", program.text), timeout_s=300)
        assert ok, messages
        canon[label] = [line for line in lines if line.startswith("STRAIGHT")]
    assert len(canon["flat"]) > least_moves
    assert canon["folded"] == canon["flat"]


@pytest.mark.linuxcnc
def test_rs274_rotary_sign_turns_a_the_other_way(cam_paths, tmp_path):
    *_, roughing, _ = cam_paths["shifted_z12"]
    program = post_program(roughing, PostSettings(rotary_sign=-1), INFO)
    ok, canon, messages = run_rs274(write(tmp_path, "r.ngc", program.text))
    assert ok, messages
    assert_same_moves(canonical_moves(canon), roughing, 4, 4, rotary_sign=-1)


@pytest.mark.linuxcnc
def test_rs274_accepts_line_numbers_at_the_limit(cam_paths, tmp_path):
    *_, roughing, _ = cam_paths["shifted_z12"]
    program = post_program(roughing, PostSettings(folded=False, line_numbers=True, line_number_step=10,
                                                  max_line_number=99999), INFO)
    ok, canon, messages = run_rs274(write(tmp_path, "n.ngc", program.text))
    assert ok, messages
    assert_same_moves(canonical_moves(canon), roughing, 4, 4)


# --- every dialect, read back independently -------------------------------------------------------

@pytest.mark.parametrize("dialect", DIALECT_NAMES)
@pytest.mark.parametrize("name", sweep(["reference_z23_m4", "undercut_z8", "many_teeth_z120"],
                                      fast=["reference_z23_m4"]))
def test_every_dialect_reads_back_as_the_ir_with_its_invariants(dialect, name, cam_paths):
    spec, _, _, roughing, finishing = cam_paths[name]
    linear, rotary = DECIMALS[dialect]
    safe_radius = spec.tip_radius_mm + CLEARANCE
    for operation, path in (("roughing", roughing), ("finishing", finishing)):
        moves_by_mode = {}
        for folded in (False, True):
            settings = PostSettings(dialect=dialect, folded=folded, line_numbers=True, max_line_number=500)
            text = post_program(path, settings, INFO).text
            program = read_program(text, dialect)
            # The end code is reached (and "%" closes Fanuc/Haas files: the reader checks it).
            assert program.ended
            last = re.sub(r"^N\d+ ", "", text.rstrip().splitlines()[-1])
            expected_last = {"fanuc": "%", "haas": "%", "okuma": "RTS" if folded else "M30"}.get(dialect, "M30")
            assert last == expected_last
            # Block numbers: present, and never past the limit.
            assert program.block_numbers and max(program.block_numbers) <= 500
            for move in program.moves:
                if not move.rapid:  # every feed move has a feed in effect, G93 moves in their own block
                    assert move.feed is not None and move.feed > 0, move.words
                    if move.inverse_time:
                        assert move.feed_in_block, move.words
                if move.start[0] is not None and move.end[3] != move.start[3]:
                    low = min(move.start[2], move.end[2])
                    designed = operation == "finishing" and not move.rapid and (
                        move.inverse_time or dialect == "okuma")
                    assert low >= safe_radius - 1e-9 or designed, f"A moves at Z {low} outside finishing: {move.words}"
            moves = [(m.rapid, np.array(m.end)) for m in program.moves]
            assert_same_moves(moves, path, linear, rotary)
            moves_by_mode[folded] = moves
        assert_folded_moves_as_flat(moves_by_mode)


@pytest.mark.parametrize("dialect", DIALECT_NAMES)
def test_folding_divides_the_finishing_program_by_about_the_tooth_count(dialect, cam_paths):
    spec, *_, finishing = cam_paths["many_teeth_z120"]
    flat = post_program(finishing, PostSettings(dialect=dialect, folded=False), INFO)
    folded = post_program(finishing, PostSettings(dialect=dialect, folded=True), INFO)
    call_lines = {"haas": 3, "siemens": 2}.get(dialect, 1)  # Haas sets #101, #102 then M97; Siemens R1 R2, REPEAT
    assert flat.lines / folded.lines > 0.5 * spec.teeth / call_lines
    assert folded.subprograms >= 1


@pytest.mark.slow  # each dialect's feed mode over the whole program (8 s); the read-backs stay in the fast tier
def test_inverse_time_where_the_dialect_has_it_and_compensated_feed_where_it_has_not(cam_paths):
    spec, _, tool, _, finishing = cam_paths["reference_z23_m4"]
    machine = Machine()
    for dialect in DIALECT_NAMES:
        program = read_program(post_program(finishing, PostSettings(dialect=dialect), INFO).text, dialect)
        simultaneous = [m for m in program.moves if not m.rapid and m.start[0] is not None and m.end[3] != m.start[3]]
        assert simultaneous
        for move in simultaneous:
            start, end = np.array(move.start), np.array(move.end)
            intended = max(relative_path_length(start, end) / tool.feed_mm_min(machine),
                           abs(end[3] - start[3]) / machine.max_rotary_speed_deg_min)
            if dialect == "okuma":  # no G93: F is read along sqrt(dX^2 + dY^2 + dZ^2 + dA^2) (docs/post.md)
                assert not move.inverse_time
                minutes = float(np.linalg.norm(end - start)) / move.feed
            else:
                assert move.inverse_time
                minutes = 1.0 / move.feed
            # Rounded positions change the path by a few output units (A units at up to the tip radius).
            unit, unit_a = (10.0 ** -k for k in DECIMALS[dialect])
            slack_mm = 4 * unit + 2 * spec.tip_radius_mm * math.radians(unit_a)
            assert minutes == pytest.approx(intended, abs=slack_mm / tool.feed_mm_min(machine) + 2e-4 * intended), (
                dialect, move.words)
        # Back to feed per minute after the simultaneous moves.
        linear_after = [m for m in program.moves if not m.rapid and m.end[3] == m.start[3]]
        assert not any(m.inverse_time for m in linear_after)


# --- block numbers, wrapped A, settings ---------------------------------------------------------------

def test_block_numbers_wrap_or_stop_at_the_limit(cam_paths):
    *_, roughing, _ = cam_paths["shifted_z12"]
    wrap = post_program(roughing, PostSettings(folded=False, line_numbers=True, max_line_number=99,
                                               line_number_step=5), INFO).text
    numbers = [int(n) for n in re.findall(r"^N(\d+) ", wrap, flags=re.M)]
    assert max(numbers) <= 99 and numbers[:3] == [5, 10, 15] and numbers.count(5) > 10  # wrapped many times
    stop = post_program(roughing, PostSettings(folded=False, line_numbers=True, max_line_number=99,
                                               line_number_step=5, line_number_overflow="stop"), INFO).text
    numbers = [int(n) for n in re.findall(r"^N(\d+) ", stop, flags=re.M)]
    assert numbers == list(range(5, 100, 5))
    assert stop.rstrip().endswith("M30")


def test_block_numbers_off_by_default(cam_paths):
    *_, roughing, _ = cam_paths["shifted_z12"]
    assert not re.search(r"^N\d", post_program(roughing, PostSettings(), INFO).text, flags=re.M)


def test_haas_labels_stay_above_the_block_numbers(cam_paths):
    *_, finishing = cam_paths["shifted_z12"]
    text = post_program(finishing, PostSettings(dialect="haas", line_numbers=True, max_line_number=9999), INFO).text
    labels = [int(n) for n in re.findall(r"^N(\d+)$", text, flags=re.M)]
    numbers = [int(n) for n in re.findall(r"^N(\d+) ", text, flags=re.M)]
    assert labels and max(numbers) < min(labels) <= max(labels) <= 9999
    assert read_program(text, "haas").ended


def test_wrapped_a_stays_in_one_turn_and_okuma_states_the_direction(cam_paths):
    *_, finishing = cam_paths["shifted_z12"]
    text = post_program(finishing, PostSettings(dialect="okuma", folded=False, rotary_mode="wrapped"), INFO).text
    program = read_program(text, "okuma")
    a = np.array([m.end[3] for m in program.moves])
    assert a.min() >= 0.0 and a.max() < 360.0
    assert_same_moves([(m.rapid, np.array(m.end)) for m in program.moves], finishing, 3, 3, wrapped=True)
    # Each A move carries the direction of its motion: M15 positive, M16 negative.
    assert any(m.direction == "M15" for m in program.moves) and any(m.direction == "M16" for m in program.moves)
    for move in program.moves:
        if move.direction:
            turned = (move.end[3] - move.start[3]) % 360.0
            assert (move.direction == "M15") == (0.0 < turned < 180.0), move.words


def test_wrapped_a_without_direction_codes_needs_short_moves():
    from spur_cad.cam.ir import Operation, ToolpathBuilder

    builder = ToolpathBuilder(Operation.ROUGHING, 1, 1000.0)
    builder.move(MoveKind.RAPID, 0.0, 0.0, 60.0, 0.0)
    builder.move(MoveKind.RAPID, 0.0, 0.0, 60.0, -200.0)
    with pytest.raises(PostError, match="not the shortest way round"):
        post_program(builder.build(), PostSettings(dialect="fanuc", folded=False, rotary_mode="wrapped"), INFO)


@pytest.mark.parametrize(("values", "message"), [
    (dict(dialect="heidenhain"), "dialect = 'heidenhain' is not known"),
    (dict(rotary_sign=2), "rotary_sign must be 1 or -1"),
    (dict(rotary_mode="spin"), "rotary_mode must be 'unwound' or 'wrapped'"),
    (dict(max_line_number=0), "max_line_number must be in 1..99999999"),
    (dict(line_number_step=0), "line_number_step must be in 1..max_line_number"),
    (dict(line_number_overflow="alarm"), "line_number_overflow must be 'wrap' or 'stop'"),
    (dict(program_number=0), "program_number must be in 1..9999"),
    (dict(rotary_mode="wrapped"), "folded = true needs rotary_mode = 'unwound'"),
])
def test_bad_post_settings_are_named(values, message):
    """Refused when the settings are made (the posts trust them)."""
    with pytest.raises(PostError, match=re.escape(message)):
        PostSettings(**values)


def test_program_numbers_must_leave_room_for_the_subprograms(cam_paths):
    *_, finishing = cam_paths["shifted_z12"]
    with pytest.raises(PostError, match="numbered past 9999"):
        post_program(finishing, PostSettings(dialect="fanuc", program_number=9999), INFO)


def test_empty_toolpath_is_an_error():
    from spur_cad.cam.ir import Operation, ToolpathBuilder

    with pytest.raises(PostError, match="empty"):
        post_program(ToolpathBuilder(Operation.FINISHING, 1, 1.0).build(), PostSettings(), INFO)


def test_comments_cannot_break_the_program():
    from spur_cad.cam.ir import Operation, ToolpathBuilder

    builder = ToolpathBuilder(Operation.FINISHING, 1, 1000.0)
    builder.move(MoveKind.RAPID, 0.0, 0.0, 60.0, 0.0)
    info = ProgramInfo("job (with) parentheses; and semicolons", ("nested (a (b)) text",))
    for dialect in DIALECT_NAMES:
        text = post_program(builder.build(), PostSettings(dialect=dialect), info).text
        for line in text.splitlines():
            if dialect == "siemens":
                assert line.count(";") <= 1
            else:
                assert line.count("(") == line.count(")") <= 1, line
        assert read_program(text, dialect).ended


@pytest.mark.parametrize("folded", [False, True])
def test_rotary_clamp_codes_hold_the_table_while_roughing_cuts(folded, cam_paths):
    spec, tool, *_ = cam_paths["shifted_z12"]
    machine = Machine(rotary_clamp_code="M10", rotary_unclamp_code="M11")
    params = RoughingParams(flank_allowance_mm=0.1 * spec.module_mm, clamp_rotary=True, strategy="levels")
    path = roughing_toolpath(spec, tool, machine, params, spec.tip_radius_mm + 0.5)
    info = ProgramInfo("clamped", (), rotary_clamp_code="M10", rotary_unclamp_code="M11")
    text = post_program(path, PostSettings(folded=folded), info).text
    # Expand the program by its call order (independent reader for the moves; the M codes by text).
    program = read_program(text, "linuxcnc")
    assert_same_moves([(m.rapid, np.array(m.end)) for m in program.moves], path, 4, 4)
    assert "M10" in text and "M11" in text
    clamped, cuts = False, 0
    lines = inlined_lines(text)  # the subprogram's text at each call, in order
    for line in lines:
        if line == "M10":
            clamped = True
        elif line == "M11":
            clamped = False
        elif re.search(r"\bA", line):
            assert not clamped, f"A moves while the table is clamped: {line}"
        elif line.startswith("X"):  # a level pass along the face width
            assert clamped, f"cutting with the table unclamped: {line}"
            cuts += 1
    assert cuts > spec.teeth
