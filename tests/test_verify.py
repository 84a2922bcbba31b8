"""`spur-cad verify` (issue 17, first part): programs from anywhere read as a controller would, simulated with
the job's tools, judged per tooth space.

References independent of the reader: the toolpath IR the posts wrote from (every dialect, flat and folded),
LinuxCNC's own interpreter rs274, and planted faults of known place and size."""

from __future__ import annotations

import dataclasses
import json
import math
import re

import numpy as np
import pytest

from spur_cad.cam.ir import Feature, MoveKind
from spur_cad.cli import main
from spur_cad.dialects import DIALECTS
from spur_cad.job import parse_job
from spur_cad.pipeline import build_programs, plan_cam
from spur_cad.post import ProgramInfo, post_program
from spur_cad.verify.reader import ProgramReadError, read_program
from tests.workbench_helper import small_job_text

SIM = "\n[simulation]\nresolution_mm = 0.02\n"
RESOLUTION = 0.02


def _job_text(strategy: str = "generating", resolution_mm: float = RESOLUTION) -> str:
    text = small_job_text() + SIM.replace(str(RESOLUTION), str(resolution_mm))
    return text if strategy == "generating" else text.replace("step_over_mm = 1.5", "step_over_mm = 1.5\n"
                                                              f"strategy = \"{strategy}\"")


@pytest.fixture(scope="module")
def small():
    job = parse_job(_job_text(), "small.toml")
    return job, plan_cam(job)


def _programs(job, plan, dialect: str, folded: bool) -> dict[str, bytes]:
    posted = dataclasses.replace(job, post=dataclasses.replace(job.post, dialect=dialect, folded=folded))
    return build_programs(posted, plan)[1]


def _distinct_motion(path) -> np.ndarray:
    poses = path.poses()[path.motion_mask]
    keep = np.concatenate([[True], np.any(np.abs(np.diff(poses, axis=0)) > 1e-9, axis=1)])
    return poses[keep], path.inverse_time[path.motion_mask][keep], path.kind[path.motion_mask][keep]


@pytest.mark.parametrize("folded", [True, False], ids=["folded", "flat"])
@pytest.mark.parametrize("dialect", list(DIALECTS))
def test_the_reader_reproduces_the_toolpath_the_post_wrote(small, dialect, folded):
    job, plan = small
    for name, data in _programs(job, plan, dialect, folded).items():
        planned = getattr(plan, name.split(".")[0])
        moves = read_program(data.decode(), dialect, name)
        poses, inverse, kind = _distinct_motion(planned.toolpath)
        read = np.column_stack([moves.x, moves.y, moves.z, moves.a])
        assert read.shape == poses.shape, name
        assert np.abs(read - poses).max() <= 0.0006  # the dialects write 3 or 4 decimals
        assert np.array_equal(moves.rapid, kind == MoveKind.RAPID)
        assert np.array_equal(moves.inverse_time, inverse & (kind != MoveKind.RAPID))
        assert set(moves.tool.tolist()) == {planned.toolpath.tool_number}
        feeds = planned.toolpath.feed[planned.toolpath.motion_mask][np.concatenate(
            [[True], np.any(np.abs(np.diff(planned.toolpath.poses()[planned.toolpath.motion_mask], axis=0)) > 1e-9,
                            axis=1)])]
        cutting = ~moves.rapid
        assert np.allclose(moves.feed[cutting], feeds[cutting], rtol=1e-3)  # mm/min, or 1/min under G93


@pytest.mark.linuxcnc
def test_the_reader_agrees_with_linuxcncs_interpreter(small, rs274, tmp_path):
    from tests.rs274_helper import canon_args, run_rs274

    job, plan = small
    for name, data in _programs(job, plan, "linuxcnc", True).items():
        program = tmp_path / name
        program.write_bytes(data)
        ok, canon, messages = run_rs274(program)
        assert ok, messages
        ends = np.array([canon_args(line)[:4] for line in canon if line.startswith(("STRAIGHT_FEED",
                                                                                      "STRAIGHT_TRAVERSE"))])
        moves = read_program(data.decode(), "linuxcnc", name)
        read = np.column_stack([moves.x, moves.y, moves.z, moves.a])
        assert len(ends) == len(read) and np.abs(ends - read).max() < 1e-9


def _verify(tmp_path, job_text: str, programs: dict[str, bytes], *extra: str) -> tuple[int, dict]:
    tmp_path.mkdir(parents=True, exist_ok=True)
    job_file = tmp_path / "job.toml"
    job_file.write_text(job_text)
    names = []
    for name, data in programs.items():
        (tmp_path / name).write_bytes(data)
        names.append(str(tmp_path / name))
    out = tmp_path / "verify_out"
    code = main(["verify", str(job_file), *names, "--out", str(out), "--quiet", *extra])
    return code, json.loads((out / "verify.json").read_text()) if (out / "verify.json").exists() else {}


@pytest.mark.parametrize("dialect", ["linuxcnc", "okuma"])
def test_spur_cads_own_programs_verify_clean(small, tmp_path, dialect, capsys):
    job, plan = small
    code, result = _verify(tmp_path, _job_text().replace("[job]", f"[post]\ndialect = \"{dialect}\"\n\n[job]"),
                           _programs(job, plan, dialect, True))
    assert code == 0 and result["passed"], result
    assert result["max_gouge_mm"] <= RESOLUTION and len(result["spaces"]) == 12
    assert capsys.readouterr().out.strip().splitlines()[0].startswith("PASS: ")


@pytest.mark.slow
@pytest.mark.parametrize("folded", [True, False], ids=["folded", "flat"])
@pytest.mark.parametrize("dialect", list(DIALECTS))
def test_spur_cads_own_programs_verify_clean_in_every_dialect(small, tmp_path, dialect, folded):
    job, plan = small
    code, result = _verify(tmp_path, _job_text(), _programs(job, plan, dialect, folded), "--dialect", dialect)
    assert code == 0 and result["passed"], result


def _post(path, dialect: str = "linuxcnc") -> bytes:
    from spur_cad.post.settings import PostSettings

    return post_program(path, PostSettings(dialect=dialect, folded=False), ProgramInfo("test", ())).text.encode()


def test_a_block_moved_20_um_into_a_flank_is_found_at_its_space_and_size(small, tmp_path):
    job, plan = small
    path = plan.finishing.toolpath
    # finishing by generation: a flank pass runs with the rack flank's plane vertical, so its normal is Y
    target = (path.space == 3) & (path.feature == Feature.RIGHT_FLANK)
    first_pass = np.nonzero(target)[0]
    assert len(first_pass)
    found = []
    fine = 0.005  # the simulation's resolution here: a 20 um fault measured within 5 um
    for shift in (-0.02, 0.02):
        moved = path.replace(y=np.where(target, path.y + shift, path.y))
        code, result = _verify(tmp_path / f"s{shift}", _job_text(resolution_mm=fine),
                               {"roughing.ngc": _post(plan.roughing.toolpath), "finishing.ngc": _post(moved)})
        found.append((code, result))
    code, result = max(found, key=lambda item: item[1]["max_gouge_mm"])
    assert code == 1 and not result["passed"]
    worst = max(result["spaces"], key=lambda s: s["max_gouge_mm"])
    # the pass's side gouges the right involute, its corner the right fillet below it: both 20 um deep
    assert worst["space"] == 3 and worst["worst_gouge"]["feature"] in ("right involute", "right fillet")
    assert abs(worst["max_gouge_mm"] - 0.02) <= fine
    others = [s["max_gouge_mm"] for s in result["spaces"] if s["space"] != 3]
    assert max(others) <= fine


def _map(folder, column: int = 4) -> dict[tuple[int, str, float], float]:
    """deviation_map.csv as {(space, feature, x): largest (column 4) or smallest (3) deviation (um)}."""
    lines = (folder / "verify_out" / "deviation_map.csv").read_text().splitlines()[1:]
    return {(int(parts[0]), parts[1], float(parts[2])): float(parts[column]) for parts in
            (line.split(",") for line in lines)}


def test_z_programmed_at_the_corner_centre_read_as_the_tip_gouges_the_root_by_the_corner_radius(tmp_path):
    # a finishing tool with r_t = 0.3 mm (below the simulator's 0.5 mm gouge range, so the depth is measured)
    text = _job_text("perimeter").replace("diameter_mm = 1.5", "diameter_mm = 1.2").replace(
        "corner_radius_mm = 0.5", "corner_radius_mm = 0.3")
    job = parse_job(text, "p.toml")
    plan = plan_cam(job)
    programs = {"roughing.ngc": _post(plan.roughing.toolpath), "finishing.ngc": _post(plan.finishing.toolpath)}
    _, right = _verify(tmp_path / "tip", text, programs)
    code, wrong = _verify(tmp_path / "centre", text, programs, "--point", "corner-centre")
    assert code == 1 and wrong["max_gouge_mm"] > right["max_gouge_mm"] + 0.2
    lowest = _map(tmp_path / "centre", column=3)
    root = [value for (k, feature, x), value in lowest.items() if feature == "root"]
    assert abs(-float(np.median(root)) / 1000.0 - 0.3) <= RESOLUTION  # the tool tip r_t below the root


def test_a_missing_station_is_found_at_its_space_and_x(tmp_path):
    job = parse_job(_job_text("perimeter"), "p.toml")
    plan = plan_cam(job)
    path = plan.finishing.toolpath
    stations = np.unique(path.station[path.station >= 0])
    missing = int(stations[len(stations) // 2])
    drop = (path.station == missing) & (path.space == 5)
    kept = dataclasses.replace(path, **{name: getattr(path, name)[~drop] for name in
                                        ("kind", "x", "y", "z", "a", "feed", "inverse_time", "space", "station",
                                         "feature")})
    station_x = float(np.median(path.x[drop & (path.feature != Feature.NONE)]))
    roughing = _post(plan.roughing.toolpath)
    _verify(tmp_path / "intact", _job_text("perimeter"), {"roughing.ngc": roughing, "finishing.ngc": _post(path)})
    code, result = _verify(tmp_path / "missing", _job_text("perimeter"), {"roughing.ngc": roughing,
                                                                          "finishing.ngc": _post(kept)})
    assert code == 1
    intact, faulty = _map(tmp_path / "intact"), _map(tmp_path / "missing")
    # the space's own surfaces (its tip lands belong to the teeth it shares with spaces 4 and 6 too)
    grown = {key: faulty[key] - intact[key] for key in intact if "tip" not in key[1]}
    (space, feature, x), growth = max(grown.items(), key=lambda item: item[1])
    assert space == 5 and abs(x - station_x) <= 0.75 + 1e-9 and growth > 2 * RESOLUTION * 1000
    assert max(value for (k, _, _), value in grown.items() if k != 5) <= 1e-6  # nothing else changed


def _legacy_program(path, corner_radius_mm: float, swap_direction: bool = False) -> str:
    """An old shop program written from a toolpath: bare modal axis words (a G-word only when the motion
    changes), only the axes that change, A in [0, 360) with M15/M16 giving the way round, Z programmed at the
    corner-radius centre."""
    lines = ["O1000", "G90 G94 G17", f"T{path.tool_number} M6", f"S{path.spindle_rpm:.0f} M3"]
    motion, previous, feed, inverse = None, [None] * 4, None, False
    for i in np.nonzero(path.motion_mask)[0]:
        pose = [path.x[i], path.y[i], path.z[i] + corner_radius_mm, path.a[i]]
        words = []
        code = "G0" if path.kind[i] == MoveKind.RAPID else "G1"
        if code == "G1" and bool(path.inverse_time[i]) != inverse:
            inverse = bool(path.inverse_time[i])
            words.append("G93" if inverse else "G94")
            feed = None
        if code != motion:
            words.append(code)
            motion = code
        for axis, value, old in zip("XYZ", pose[:3], previous[:3]):
            if old is None or abs(value - old) > 1e-9:
                words.append(f"{axis}{value:.4f}")
        if previous[3] is None or abs(pose[3] - previous[3]) > 1e-9:
            positive = previous[3] is None or pose[3] > previous[3]
            words += [f"A{pose[3] % 360.0:.4f}", "M15" if positive != swap_direction else "M16"]
        if code == "G1" and (path.feed[i] != feed or inverse):  # G93: every feed block carries its own F
            words.append(f"F{path.feed[i]:.1f}")
            feed = path.feed[i]
        if any(word[0] in "XYZA" for word in words):
            lines.append(" ".join(words))
        previous = pose
    return "\n".join(lines + ["M30"]) + "\n"


@pytest.mark.slow  # two whole verifications (7 s)
def test_a_legacy_program_verifies_as_the_original_and_the_wrong_rotary_direction_fails(tmp_path):
    # perimeter finishing turns A while it cuts: the way round matters there
    job = parse_job(_job_text("perimeter"), "p.toml")
    plan = plan_cam(job)
    path = plan.finishing.toolpath
    corner = plan.finishing.tool.effective_corner_radius_mm
    roughing = _post(plan.roughing.toolpath, "okuma")
    _, original = _verify(tmp_path / "original", _job_text("perimeter"),
                          {"roughing.min": roughing, "finishing.min": _post(path, "okuma")}, "--dialect", "okuma")
    legacy = _legacy_program(path, corner)
    assert "M15" in legacy and "M16" in legacy and re.search(r"\n[XYZ]-?\d", legacy)  # bare modal words
    assert max(float(word[1:]) for word in re.findall(r"A-?\d+\.\d+", legacy)) < 360.0
    _, result = _verify(tmp_path / "legacy", _job_text("perimeter"),
                        {"roughing.min": roughing, "finishing.min": legacy.encode()},
                        "--dialect", "okuma", "--point", "corner-centre")
    assert abs(result["max_gouge_mm"] - original["max_gouge_mm"]) <= 0.001
    assert abs(result["max_leftover_mm"] - original["max_leftover_mm"]) <= 0.001
    assert [s["max_gouge_mm"] <= RESOLUTION for s in result["spaces"]] == [True] * 12
    code, at_tip = _verify(tmp_path / "tip", _job_text("perimeter"),
                           {"roughing.min": roughing, "finishing.min": legacy.encode()}, "--dialect", "okuma")
    _, roughed = _verify(tmp_path / "roughed", _job_text("perimeter"), {"roughing.min": roughing}, "--dialect",
                         "okuma")
    # read at the tip, the tool is r_t too high everywhere: every space keeps the worst of what roughing left
    # (its lowest level's leftover above the root, far beyond the tolerance)
    assert code == 1 and min(s["max_leftover_mm"] for s in roughed["spaces"]) > 2 * at_tip["leftover_tolerance_mm"]
    assert [s["max_leftover_mm"] for s in at_tip["spaces"]] == pytest.approx(
        [s["max_leftover_mm"] for s in roughed["spaces"]], abs=RESOLUTION)
    swapped = _legacy_program(path, corner, swap_direction=True)
    code, result = _verify(tmp_path / "swap", _job_text("perimeter"),
                           {"roughing.min": roughing, "finishing.min": swapped.encode()},
                           "--dialect", "okuma", "--point", "corner-centre")
    assert code == 1 and result["max_gouge_mm"] > 0.1  # the long way round cuts through the teeth


@pytest.mark.parametrize("program, message", [
    ("G90\nG2 X1 Y1 I1 J0\nM30\n", ":2: G2 (an arc) is not read"),
    ("G91\nG0 X1 Y0 Z30 A0\nM30\n", ":1: G91 is not supported"),
    ("T1 M6\nG0 X1 Y0 Z30 A0\nT7 M6\nG1 X2 F100\nM30\n", ":4: moves with tool T7, which the job does not have"),
    ("G0 X1 Y0 Z30 A0\nM30\n", ":1: a move before any tool is loaded"),
    ("G0 X1 Y0 Z30\nG1 X2 F100\nM30\n", ":2: a feed move before every axis is known (A unknown"),
    ("G0 X1 Y0 Z30 A0\nG1 X2\nM30\n", ":2: a feed move without a positive F"),
    ("T1 M6\nG0 X1 Y0 Z30 A0\n", ": no end of program (M30 or M2)"),
    ("o100 call\nM30\n", ":1: calls subprogram 100, which the program does not define"),
    ("G0 X1 Y0 Z30 A[#5+1]\nM30\n", ":1: variable #5 is used before it is set"),
    ("G0 X1 Y0 Z30 A0\nM123\nM30\n", ":2: M123 is not supported"),
])
def test_unsupported_or_bad_programs_are_one_line_naming_the_line(tmp_path, capsys, program, message):
    code, result = _verify(tmp_path, _job_text(), {"bad.ngc": program.encode()}, "--dialect", "linuxcnc")
    err = capsys.readouterr().err.strip()
    assert code == 2 and result == {} and not (tmp_path / "verify_out").exists()
    assert len(err.splitlines()) == 1 and err.startswith("spur-cad: error: ") and message in err, err


def test_direction_codes_turn_the_way_they_say():
    text = "G0 X0 Y0 Z30 A350\nA10 M15\nA350 M16\nA10 M16\nM30\n"
    moves = read_program(text, "okuma", "p")
    assert np.allclose(moves.a, [350.0, 370.0, 350.0, 10.0])  # +20, -20, -340: each the way its code says
    with pytest.raises(ProgramReadError, match=r"p:2: with M15, A must be an angle in \[0, 360\], got 400"):
        read_program("G0 X0 Y0 Z30 A0\nA400 M15\nM30\n", "okuma", "p")
    with pytest.raises(ProgramReadError, match=r"p:2: with M16, A must be an angle in \[0, 360\], got -10"):
        read_program("G0 X0 Y0 Z30 A0\nA-10 M16\nM30\n", "okuma", "p")
    assert math.isclose(read_program("G0 X0 Y0 Z30 A0\nA10 M16\nM30\n", "okuma", "p").a[-1], -350.0)


def test_a_directed_move_to_the_angle_already_reached_past_a_turn_is_no_move():
    # 3.6 -> 1.4 turning positively unwinds to 361.4, computed 361.40000000000003: (1.4 - that) % 360 is
    # 359.99999999999994, which read as a step turned A a full turn more (M15) or one less (M16)
    text = "G0 X0 Y0 Z30 A3.6\nA1.4 M15\nG1 X5 A1.4 M15 F100\nA1.4 M16\nX6 M15\nA3.6 M16\nM30\n"
    assert np.allclose(read_program(text, "okuma", "p").a, [3.6, 361.4, 361.4, 361.4, 361.4, 3.6], atol=1e-9)
    # A360 in a directed block is the angle 0 (legacy Okuma programs write it); 360 + 1e-3 is still refused
    moves = read_program("G0 X0 Y0 Z30 A10\nA360.000 M16\nA360 M15\nA90 M15\nA360.000 M16\nM30\n", "okuma", "p")
    assert np.allclose(moves.a, [10.0, 0.0, 0.0, 90.0, 0.0], atol=1e-9)
    with pytest.raises(ProgramReadError, match=r"p:2: with M15, A must be an angle in \[0, 360\], got 360.001"):
        read_program("G0 X0 Y0 Z30 A0\nA360.001 M15\nM30\n", "okuma", "p")
    assert read_program("G0 X0 Y0 Z30 A360\nG0 A720\nM30\n", "okuma", "p").a.tolist() == [360.0, 720.0]  # absolute A


def _hand_written(path, dialect: str) -> str:
    """A program written by hand from a toolpath in the grammar of `dialect`, as old shop programs are: every block
    gives every axis; A is written to 3 decimals, unwound on LinuxCNC, on Okuma as an angle with 0 written 360.000
    and M15 or M16 in every block (where A does not change, the angle already reached, the code of the last turn)."""
    okuma = dialect == "okuma"
    lines = (["O1000"] if okuma else []) + ["G90 G94 G17", f"T{path.tool_number} M6", f"S{path.spindle_rpm:.0f} M3"]
    previous, inverse, direction = None, False, "M15"
    for i in np.nonzero(path.motion_mask)[0]:
        a = round(float(path.a[i]), 3)
        words = ["G0" if path.kind[i] == MoveKind.RAPID else "G1"]
        if words[0] == "G1" and bool(path.inverse_time[i]) != inverse:
            inverse = bool(path.inverse_time[i])
            words.insert(0, "G93" if inverse else "G94")
        words += [f"X{path.x[i]:.4f}", f"Y{path.y[i]:.4f}", f"Z{path.z[i]:.4f}"]
        if okuma:
            angle = f"{a % 360.0:.3f}"
            if previous is not None and a != previous:
                direction = "M15" if a > previous else "M16"
            words += [f"A{'360.000' if angle == '0.000' else angle}", direction]
        else:
            words.append(f"A{a:.3f}")
        if words[-1 if not okuma else -2][0] == "A" and path.kind[i] != MoveKind.RAPID:
            words.append(f"F{path.feed[i]:.1f}")
        lines.append(" ".join(words))
        previous = a
    return "\n".join(lines + ["M30"]) + "\n"


def test_an_okuma_program_unwound_past_a_turn_reads_and_verifies_as_its_linuxcnc_twin(small, tmp_path):
    job, plan = small
    # finishing by generation turns A from about +49 deg to -379 deg: past a full turn, and back
    programs = {dialect: {f"{name}.{ext}": _hand_written(getattr(plan, name).toolpath, dialect).encode()
                          for name in ("roughing", "finishing")} for dialect, ext in (("okuma", "min"),
                                                                                      ("linuxcnc", "ngc"))}
    finishing = programs["okuma"]["finishing.min"].decode()
    assert re.search(r"A360\.000 M1[56]", programs["okuma"]["roughing.min"].decode())  # legacy A360 words
    okuma_a = read_program(finishing, "okuma", "o").a
    linuxcnc = read_program(programs["linuxcnc"]["finishing.ngc"].decode(), "linuxcnc", "l")
    assert okuma_a.min() < -360.0 and len(okuma_a) == len(linuxcnc)
    assert np.abs(okuma_a - linuxcnc.a).max() <= 1e-9  # the same moves: no extra turn anywhere
    results = {dialect: _verify(tmp_path / dialect, _job_text(), programs[dialect], "--dialect", dialect)[1]
               for dialect in programs}
    okuma, twin = results["okuma"], results["linuxcnc"]
    assert twin["passed"] and twin["max_gouge_mm"] <= RESOLUTION
    for key in ("max_gouge_mm", "max_leftover_mm", "moves"):
        assert okuma[key] == pytest.approx(twin[key], abs=1e-9), key
    assert [s["max_gouge_mm"] for s in okuma["spaces"]] == pytest.approx([s["max_gouge_mm"] for s in twin["spaces"]],
                                                                         abs=1e-9)


@pytest.mark.linuxcnc
def test_linuxcncs_interpreter_as_the_reader_gives_the_same_verdict(small, rs274, tmp_path):
    job, plan = small
    programs = _programs(job, plan, "linuxcnc", True)
    _, own = _verify(tmp_path / "own", _job_text(), programs, "--dialect", "linuxcnc")
    code, by_rs274 = _verify(tmp_path / "rs274", _job_text(), programs, "--dialect", "linuxcnc", "--reader", "rs274")
    assert code == 0 and by_rs274["passed"] and by_rs274["moves"] == own["moves"]
    assert by_rs274["max_gouge_mm"] == pytest.approx(own["max_gouge_mm"], abs=1e-9)
    assert by_rs274["max_leftover_mm"] == pytest.approx(own["max_leftover_mm"], abs=1e-9)


def _read(text: str, dialect: str):
    moves = read_program(text, dialect, "p")
    return np.column_stack([moves.x, moves.y, moves.z, moves.a]), moves


HAND_WRITTEN = [  # the same three moves written as shops write them by hand, one dialect each
    ("fanuc", "%\nO0001\nG90 G94\nT2 M6\nG65P0100 X1.0 A5.0 L2\nM30\nO0100\nG0 X#24 Y0 Z30 A#1\nG1 Z20 F100\nM99\n%\n"),
    ("haas", "%\nO01000\nT2M06\nM97P200L2\nM30\nN200\nG00X1.Y0Z30.A5.\nG01Z20.F100.\nM99\n%\n"),
    ("siemens", "T2 D1\nM6\nR1=1 R2=5\nA1:\nG0 X=R1 Y0 Z30 A=R2\nG1 Z20 F100\nA1_END:\nREPEAT A1 A1_END P=1\nM30\n"),
    ("okuma", "O1000\nT2 M6\nCALL O100 XS=1 AS=5\nCALL O100 XS=1 AS=5\nM30\nO100\nG0 X=XS Y0 Z30 A=AS\n"
              "G1 Z20 F100\nRTS\n"),
    ("linuxcnc", "#1 = 7\nT2 M6\no100 call [1] [5]\no100 call [1] [5]\nG0 X#1 Y0 Z30 A0\nM30\n"
                 "o100 sub\nG0 X#1 Y0 Z30 A#2\nG1 Z20 F100\no100 endsub\n"),
]


@pytest.mark.parametrize("dialect, text", HAND_WRITTEN, ids=[d for d, _ in HAND_WRITTEN])
def test_hand_written_forms(dialect, text):
    poses, moves = _read(text, dialect)
    assert np.allclose(poses[:4], [[1, 0, 30, 5], [1, 0, 20, 5], [1, 0, 30, 5], [1, 0, 20, 5]])
    assert set(moves.tool.tolist()) == {2}
    if dialect == "linuxcnc":  # the call's arguments are local: #1 is 7 again after it
        assert np.allclose(poses[4], [7, 0, 30, 0])


def test_tool_change_words_in_any_order_and_inverse_time_needs_f_in_each_block():
    _, moves = _read("M6 T2\nG0 X0 Y0 Z30 A0\nM30\n", "linuxcnc")
    assert moves.tool.tolist() == [2]
    with pytest.raises(ProgramReadError, match=r"p:4: an inverse-time \(G93\) feed move needs its own F"):
        _read("T2 M6\nG0 X0 Y0 Z30 A0\nG93 G1 X1 A5 F20\nX2\nM30\n", "linuxcnc")
    with pytest.raises(ProgramReadError, match=r"p:4: a feed move without a positive F"):  # G94 resets F
        _read("T2 M6\nG0 X0 Y0 Z30 A0\nG93 G1 X1 A5 F20\nG94 X2\nM30\n", "linuxcnc")


@pytest.mark.parametrize("dialect, text, message", [
    ("linuxcnc", "T2 M6\nG0 X0 Y0 Z30 A10 M15\nM30\n", ":2: M15 is not supported"),
    ("fanuc", "T2 M6\nG71\nM30\n", ":2: G71 is not supported"),
    ("linuxcnc", "T2 M6\nG0 X[1 2] Y0 Z30 A0\nM30\n", ":2: cannot evaluate '1 2': terms need + or -"),
    ("haas", "%\nT2 M6\nM97 P5\nM30\nO5\nG0 X0 Y0 Z30 A0\nM99\n%\n", ":3: calls subprogram 5, which the program"),
])
def test_forms_that_mean_something_else_are_refused(dialect, text, message):
    with pytest.raises(ProgramReadError, match=re.escape(message)):
        _read(text, dialect)


def test_endless_loops_are_refused_before_they_run_for_hours(monkeypatch):
    import spur_cad.verify.reader as reader

    monkeypatch.setattr(reader, "MAX_BLOCKS", 300_000)  # the limit scaled down: the same check, seconds not minutes
    text = "o1 repeat [100000]\no2 repeat [100000]\n#1 = 1\no2 endrepeat\no1 endrepeat\nM30\n"
    with pytest.raises(ProgramReadError, match="executes more than 300,000 blocks"):
        _read(text, "linuxcnc")
    monkeypatch.setattr(reader, "CHECK_EVERY_BLOCKS", 1000)
    calls = []  # a long read offers the CLI a checkpoint (where it stops on Ctrl-C) every CHECK_EVERY_BLOCKS
    read_program("#1 = 0\no1 repeat [3000]\n#1 = 1\no1 endrepeat\nM30\n", "linuxcnc", "p", lambda: calls.append(1))
    assert len(calls) == 3


def test_point_applies_to_the_tools_named(small, tmp_path):
    job, plan = small
    programs = _programs(job, plan, "linuxcnc", True)
    _, everywhere = _verify(tmp_path / "all", _job_text(), programs, "--point", "corner-centre")
    _, finishing_only = _verify(tmp_path / "t1", _job_text(), programs, "--point", "corner-centre",
                                "--point-tools", "1")
    assert everywhere["max_gouge_mm"] > 0.1  # the finishing tool (r 0.5) goes r_t deep
    assert finishing_only["max_gouge_mm"] <= RESOLUTION  # only the flat roughing tool named: nothing changes


def test_the_a_offset_adds_to_every_a_word_of_programs_written_with_another_a_zero(small, tmp_path):
    from spur_cad.verify.verify import toolpaths

    job, plan = small
    zero_deg = 7.5  # a quarter pitch: read at the wrong zero, every flank is cut 7.5 deg off
    programs = {f"{name}.ngc": _hand_written(getattr(plan, name).toolpath, "linuxcnc") for name in ("roughing",
                                                                                                   "finishing")}
    shifted = {name: re.sub(r"A(-?\d+\.\d+)", lambda m: f"A{float(m.group(1)) - zero_deg:.3f}", text).encode()
               for name, text in programs.items()}
    moves = read_program(shifted["finishing.ngc"].decode(), "linuxcnc", "f")
    tools = {job.tools.finishing.tool_number: job.tools.finishing}
    cut, = toolpaths(moves, tools, None, "tip", a_offset_deg=zero_deg)
    assert np.array_equal(cut.path.a, moves.a + zero_deg) and np.array_equal(cut.path.x, moves.x)
    original = read_program(programs["finishing.ngc"], "linuxcnc", "o").a
    assert np.abs(cut.path.a - original).max() <= 1e-9  # the program's own A zero is back at the job's
    code, result = _verify(tmp_path / "offset", _job_text(), shifted, "--dialect", "linuxcnc", "--a-offset-deg",
                           str(zero_deg))
    assert code == 0 and result["max_gouge_mm"] <= RESOLUTION
    code, result = _verify(tmp_path / "none", _job_text(), shifted, "--dialect", "linuxcnc")
    assert code == 1 and result["max_gouge_mm"] > 0.1
    code, result = _verify(tmp_path / "bad", _job_text(), shifted, "--a-offset-deg", "nan")
    assert code == 2 and result == {}
