"""Restart after an alarm (issue 18): `spur-cad run ... --restart roughing:space=5` (or a level, a finishing
station, a space or a pass) writes a program whose moves after the safe approach are the full program's
tail, checked with LinuxCNC's own interpreter (rs274's canonical calls) and, for the other dialects, with
the project's reader; the approach is checked against what it must be (tool, spindle and coolant first, Z
alone to the clearance height, then X, Y and A of the first kept move at that height)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from spur_cad.cam.ir import MoveKind
from spur_cad.cam.restart import RestartError, parse_restart, restart_toolpath
from spur_cad.cli import main
from spur_cad.job import parse_job
from spur_cad.pipeline import build_programs, plan_cam, restart_program
from spur_cad.verify.reader import read_program
from tests.rs274_helper import canon_args, run_rs274
from tests.workbench_helper import small_job_text


@pytest.fixture(scope="module")
def generating():
    job = parse_job(small_job_text(), "small.toml")
    return job, plan_cam(job)


@pytest.fixture(scope="module")
def perimeter():
    text = small_job_text().replace("step_over_mm = 1.5", 'step_over_mm = 1.5\nstrategy = "perimeter"')
    job = parse_job(text, "perimeter.toml")
    return job, plan_cam(job)


def _clearance(job) -> float:
    return job.stock.blank_radius_mm(job.gear) + job.machine.clearance_mm


def _motions(canon: list[str]) -> list[tuple[str, tuple[float, ...], float | None]]:
    """(kind, (x, y, z, a), feed rate in effect) of every straight move rs274 makes."""
    feed, out = None, []
    for line in canon:
        if line.startswith("SET_FEED_RATE("):
            feed = canon_args(line)[0]
        elif line.startswith(("STRAIGHT_TRAVERSE(", "STRAIGHT_FEED(")):
            kind = "rapid" if line.startswith("STRAIGHT_TRAVERSE") else "feed"
            out.append((kind, tuple(round(v, 4) for v in canon_args(line)[:4]), None if kind == "rapid" else feed))
    return out


def _rs274(tmp_path, name: str, text: bytes) -> list[str]:
    path = tmp_path / name
    path.write_bytes(text)
    ok, canon, messages = run_rs274(path)
    assert ok, messages
    return canon


@pytest.mark.linuxcnc
@pytest.mark.parametrize("point", ["roughing:space=5", "roughing:space=0", "roughing:space=7,level=3",
                                   "finishing:space=3", "finishing:space=11,pass=4"])
def test_the_restarted_program_is_the_full_programs_tail_after_a_safe_approach(generating, point, tmp_path):
    job, plan = generating
    restart = parse_restart(point)
    full = _motions(_rs274(tmp_path, "full.ngc", build_programs(job, plan)[1][f"{restart.operation}.ngc"]))
    name, text = restart_program(job, plan, restart)
    canon = _rs274(tmp_path, name, text)
    restarted = _motions(canon)
    start = _expected_start(full, restart, job.gear.teeth)
    first = full[start][1]
    # the approach: tool, spindle and coolant before any move; Z alone to the clearance height, then across
    first_move = next(i for i, line in enumerate(canon) if line.startswith(("STRAIGHT_", "ARC_")))
    before = " ".join(canon[:first_move])
    assert "CHANGE_TOOL(" in before and "START_SPINDLE_CLOCKWISE(" in before and "FLOOD_ON(" in before
    (kind0, pose0, _), (kind1, pose1, _) = restarted[:2]
    assert kind0 == kind1 == "rapid"
    assert pose0[2] == pytest.approx(_clearance(job), abs=1e-4)
    assert pose1 == pytest.approx((first[0], first[1], _clearance(job), first[3]), abs=1e-4)
    # then the full program's moves from the restart point, move for move, feeds included
    assert restarted[2:] == full[start:]
    assert start > 0 or restart.at == (("space", 0),)


def _expected_start(full: list, point, teeth: int) -> int:
    """Where the restart point is in the full program's canonical moves, found from the moves alone: a roughing
    space is the first move at its A (-k 360/z, fixed while roughing a spur gear's space), level n the n-th
    plunge there (the feed moves at the space's lowest feed rate), after its retract and return when it has them;
    a generating space k's pass p is rapid number k x (rapids per space) + p (every pass starts with one)."""
    at = dict(point.at)
    if point.operation == "roughing":
        angle = round(-at["space"] * 360.0 / teeth, 4)
        in_space = [i for i, (_, pose, _) in enumerate(full) if pose[3] == angle]
        if "level" not in at:
            return in_space[0]
        plunge_feed = min(full[i][2] for i in in_space if full[i][0] == "feed")
        plunges = [i for i in in_space if full[i][0] == "feed" and full[i][2] == plunge_feed]
        i = plunges[at["level"]]
        return i - 2 if at["level"] > 0 and full[i - 1][0] == "rapid" else i
    rapids = [i for i, (kind, _, _) in enumerate(full) if kind == "rapid"]
    per_space = len(rapids) // teeth
    assert per_space * teeth == len(rapids)
    return rapids[at["space"] * per_space + at.get("pass", 0)]


@pytest.mark.linuxcnc
def test_a_perimeter_finishing_restarts_at_a_station_with_a_turned_the_same_way(perimeter, tmp_path):
    job, plan = perimeter
    restart = parse_restart("finishing:station=2")
    full = _motions(_rs274(tmp_path, "full.ngc", build_programs(job, plan)[1]["finishing.ngc"]))
    name, text = restart_program(job, plan, restart)
    restarted = _motions(_rs274(tmp_path, name, text))
    # a perimeter station keeps X: station 2 starts at the first move on the third X the program visits
    xs = list(dict.fromkeys(pose[0] for _, pose, _ in full))
    start = next(i for i, (_, pose, _) in enumerate(full) if pose[0] == xs[2])
    assert restarted[2:] == full[start:] and len(full) - start > 100
    # station 2 of a continuous table: A has turned twice round the gear before it, and the approach is there
    assert restarted[1][1] == pytest.approx(full[start][1][:2] + (_clearance(job), full[start][1][3]), abs=1e-4)
    assert restarted[1][1][3] == pytest.approx(-2 * 360.0, abs=360.0 / job.gear.teeth)


@pytest.mark.parametrize("dialect", ["fanuc", "haas", "siemens", "okuma"])
def test_every_dialects_restart_reads_back_as_the_full_programs_tail(generating, dialect):
    job, plan = generating
    job = dataclasses.replace(job, post=dataclasses.replace(job.post, dialect=dialect))
    restart = parse_restart("roughing:space=4,level=1")
    full_name, full_text = next(iter((n, t) for n, t in build_programs(job, plan)[1].items()
                                     if n.startswith("roughing")))
    full = read_program(full_text.decode(), dialect, full_name)
    name, text = restart_program(job, plan, restart)
    moves = read_program(text.decode(), dialect, name)
    poses = np.column_stack([moves.x, moves.y, moves.z, moves.a])
    full_poses = np.column_stack([full.x, full.y, full.z, full.a])
    tail = poses[1:]  # the Z-only move (X, Y, A unknown) is no move for the reader; then the approach
    assert len(tail) > 10
    np.testing.assert_allclose(tail, full_poses[-len(tail):], atol=2e-3)
    assert np.all(moves.tool == job.tools.roughing.tool_number) and np.all(moves.spindle_rpm > 0)
    assert poses[0][2] == pytest.approx(_clearance(job), abs=1e-3)


def test_a_clamped_table_is_unclamped_before_a_turns_and_clamped_again_where_the_full_program_has_it():
    job = parse_job(small_job_text().replace("[roughing]\n", "[roughing]\nclamp_rotary = true\n") +
                    '\n[machine]\nrotary_clamp_code = "M10"\nrotary_unclamp_code = "M11"\n', "clamped.toml")
    plan = plan_cam(job)
    path, start = restart_toolpath(plan.roughing.toolpath, parse_restart("roughing:space=3,level=2"), 30.0)
    kinds = list(path.kind[:4])
    assert kinds[:3] == [MoveKind.UNCLAMP_ROTARY, MoveKind.RAPID, MoveKind.CLAMP_ROTARY]
    full = plan.roughing.toolpath
    before = [k for k in full.kind[:start] if k in (MoveKind.CLAMP_ROTARY, MoveKind.UNCLAMP_ROTARY)]
    assert before[-1] == MoveKind.CLAMP_ROTARY  # mid-space the full program has A clamped
    _, text = restart_program(job, plan, parse_restart("roughing:space=3,level=2"))
    lines = text.decode().splitlines()
    approach = lines.index("M11")
    assert lines[approach + 2] == "M10" and lines[approach + 1].startswith("G0 ") and " A" in lines[approach + 1]


@pytest.mark.parametrize("text, message", [
    ("roughing:station=3", "expected roughing:space=K"),
    ("finishing:level=2", "expected"),
    ("roughing:space=-1", "expected"),
    ("roughing:space=5;M30", "expected"),
    ("drilling:space=1", "expected"),
])
def test_a_malformed_restart_point_is_refused(text, message):
    with pytest.raises(RestartError, match=message):
        parse_restart(text)


def test_a_restart_point_beyond_the_job_names_what_exists(generating):
    job, plan = generating
    with pytest.raises(RestartError, match=r"no space 12 \(spaces 0\.\.11\)"):
        restart_program(job, plan, parse_restart("roughing:space=12"))
    with pytest.raises(RestartError, match="no station 0"):
        restart_program(job, plan, parse_restart("finishing:station=0"))  # generating works space by space
    with pytest.raises(RestartError, match=r"space 2 has \d+ passes"):
        restart_program(job, plan, parse_restart("finishing:space=2,pass=100000"))


def test_the_cli_writes_the_restart_program_with_the_set_and_refuses_a_bad_point_writing_nothing(tmp_path, capsys):
    job_file = tmp_path / "small.toml"
    job_file.write_text(small_job_text() + "\n[simulation]\nenabled = false\n")
    out = tmp_path / "out"
    assert main(["run", str(job_file), "--out", str(out), "--quiet", "--restart", "roughing:space=2"]) == 0
    assert (out / "roughing_space2.ngc").is_file() and (out / "roughing.ngc").is_file()
    bad = tmp_path / "bad"
    assert main(["run", str(job_file), "--out", str(bad), "--restart", "roughing:space=99"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no space 99" in err[0] and not bad.exists()
