"""`spur-cad grade JOB probe.log` (issue 30.3, docs/probing.md "Reading the log"): the reference gear's cut is
simulated, "probed" along the G38.2 moves of its own probe.ngc (read from the program's text here, not from the
plan), and the log, in LinuxCNC's nine-number format, grades the same deviations as the CSV of the same contact
points within 0.5 um. A planted eccentricity shows in F_p by the value worked by hand, from the log and from the
CSV with `--datum axis`, and the default best fit of the CSV takes it out. Bad logs are one line naming the line.

Eccentricity by hand: the teeth translated by e in the transverse plane move a flank point along its normal n
by e . n. On the reference circle n makes the transverse pressure angle alpha_t with the circle's tangent, so
e . n = e_r sin(alpha_t) +- e_t cos(alpha_t) (radial and tangential parts of e), and the grade's flank position,
the arc (e . n) / cos(alpha_t) = e_r tan(alpha_t) +- e_t, runs round the gear as a sinusoid of amplitude
|e| / cos(alpha_t). F_p, the spread of the positions, is therefore 2 |e| / cos(alpha_t) sampled at z angles:
between that times cos(pi / z) and that.
"""

from __future__ import annotations

import dataclasses
import json
import math
import re

import numpy as np
import pytest

from spur_cad.cli import main
from spur_cad.geometry.frames import machine_to_part, part_to_machine
from spur_cad.job import parse_job
from spur_cad.pipeline import plan_cam, probe_program, simulate_stage
from tests.gears import REFERENCE_JOB

JOB_TEXT = REFERENCE_JOB.read_text() + "\n[probe]\nstylus_diameter_mm = 2.0\n"
BALL_MM = 1.0
ECCENTRICITY_MM = np.array([0.010, 0.006])  # the teeth's centre off the A axis (part frame), 11.7 um
WORD = re.compile(r"([XYZA])(-?[0-9.]+)")


@pytest.fixture(scope="module")
def cut():
    """The reference job with [probe], its simulated cut (5 um) and its probe.ngc text."""
    job = parse_job(JOB_TEXT, "ref.toml")
    assert job.simulation.resolution_mm <= 0.005
    result = simulate_stage(job, plan_cam(job))
    name, program = probe_program(job)
    assert name == "probe.ngc"
    return job, result, program.decode()


def probe_moves(program: str) -> list[tuple[np.ndarray, np.ndarray, float, float]]:
    """(start Y Z, end Y Z, X, A) of every G38.2 move, by modal X Y Z A words (comments left out)."""
    position = {"X": 0.0, "Y": 0.0, "Z": 0.0, "A": 0.0}
    moves = []
    for line in program.splitlines():
        line = re.sub(r"\(.*?\)", "", line)
        words = {name: float(value) for name, value in WORD.findall(line)}
        if line.startswith("G38.2"):
            end = {**position, **words}
            moves.append((np.array([position["Y"], position["Z"]]), np.array([end["Y"], end["Z"]]),
                          end["X"], end["A"]))
        position.update(words)
    return moves


def _crossing(q: np.ndarray, start: np.ndarray, direction: np.ndarray) -> tuple[int, float]:
    """Where the ray start + t direction (t > 0) first crosses the design polyline q (a move to the form circle
    may cross just inside the fillet, which continues the involute's tangent): segment index and fraction."""
    side = direction[0] * (q[:, 1] - start[1]) - direction[1] * (q[:, 0] - start[0])
    hits = np.nonzero(np.sign(side[:-1]) != np.sign(side[1:]))[0]
    distance = [np.dot(q[i] - start, direction) for i in hits]
    i = int(hits[int(np.argmin(np.where(np.array(distance) > 0, distance, np.inf)))])
    return i, float(side[i] / (side[i] - side[i + 1]))


def probed(job, result, program: str, eccentricity_mm=(0.0, 0.0)):
    """The simulated gear (its teeth moved by `eccentricity_mm`) probed along each G38.2 move: the ball trips
    where its surface meets the simulated flank, at the contact c = p + d n (p: the design flank point on the
    move's line, d: the simulated deviation there, interpolated along the flank and in X, plus e . n; n: the
    move's direction reversed); it logs the centre c + R n. Returns the log's text, the CSV of the contacts
    (part frame) and the number of trips."""
    grid, teeth, sign = result.grid, job.gear.teeth, job.post.rotary_sign
    log, csv = [], ["x_mm,y_mm,X_mm"]
    for start, end, x, a_word in probe_moves(program):
        a = sign * a_word
        s, e = (machine_to_part(np.array([yz[0]]), np.array([yz[1]]), a)[0] for yz in (start, end))
        direction = (e - s) / np.linalg.norm(e - s)
        k = round(-a * teeth / 360.0) % teeth
        q = grid.space_points(k)
        i, f = _crossing(q, s, direction)
        p = q[i] + f * (q[i + 1] - q[i])
        deviation = ((1.0 - f) * np.interp(x, grid.rows_x, result.deviation[k, i])
                     + f * np.interp(x, grid.rows_x, result.deviation[k, i + 1]))
        n = -direction
        contact = p + (deviation + float(np.dot(eccentricity_mm, n))) * n
        centre = part_to_machine((contact + BALL_MM * n)[None, :], a)[0]
        log.append(" ".join(f"{v:f}" for v in (x, *centre, a_word, 0.0, 0.0, 0.0, 0.0, 0.0)))
        csv.append(f"{contact[0]:.6f},{contact[1]:.6f},{x:.4f}")
    return "\n".join(log) + "\n", "\n".join(csv) + "\n", len(log)


def grade(tmp_path, name: str, text: str, *extra: str) -> tuple[int, dict]:
    work = tmp_path / name
    work.mkdir()
    (work / "job.toml").write_text(JOB_TEXT)
    (work / "measured").write_text(text)
    code = main(["grade", str(work / "job.toml"), str(work / "measured"), "--out", str(work / "grade"), *extra])
    out = work / "grade" / "grade.json"
    return code, json.loads(out.read_text()) if out.exists() else {}


@pytest.fixture(scope="module")
def eccentric(cut):
    return probed(*cut, eccentricity_mm=ECCENTRICITY_MM)


def test_the_probe_log_grades_as_the_csv_of_the_same_points_and_keeps_the_eccentricity(cut, eccentric, tmp_path):
    job, _, _ = cut
    log, csv, trips = eccentric
    assert trips == 23 * 2 + 4 * 2 * (10 + 5)
    _, from_log = grade(tmp_path, "log", log)
    _, axis = grade(tmp_path, "axis", csv, "--datum", "axis")
    _, best = grade(tmp_path, "best", csv)
    assert from_log["fit"]["datum"] == "probe log" and axis["fit"]["datum"] == "axis"
    assert from_log["points"] == trips and from_log["notes"] == []
    names = {"f_pt", "F_p", "f_Ha", "f_fa", "F_a", "f_Hb", "f_fb", "F_b"}
    assert set(from_log["deviations_um"]) == set(axis["deviations_um"]) == names
    for name in names:
        assert from_log["deviations_um"][name] == pytest.approx(axis["deviations_um"][name], abs=0.5), name
    # the eccentricity's F_p, worked by hand (module docstring); the simulated cut's own pitch is 0
    spec = job.gear
    cos_alpha = spec.base_radius_mm / spec.reference_radius_mm
    most = 2.0 * np.linalg.norm(ECCENTRICITY_MM) * 1000.0 / cos_alpha  # 24.9 um
    for found in (from_log, axis):
        assert most * math.cos(math.pi / 23) - 0.5 <= found["deviations_um"]["F_p"] <= most + 0.5
    # the default best fit finds the teeth's centre and takes the eccentricity out of F_p
    assert best["fit"]["centre_mm"] == pytest.approx(list(ECCENTRICITY_MM), abs=5e-4)
    assert best["deviations_um"]["F_p"] < 1.5


def test_without_eccentricity_the_log_and_csv_agree_and_f_p_is_the_cuts(cut, tmp_path):
    log, csv, _ = probed(*cut)
    _, from_log = grade(tmp_path, "log", log)
    _, axis = grade(tmp_path, "axis", csv, "--datum", "axis")
    _, best = grade(tmp_path, "best", csv)
    assert len(from_log["deviations_um"]) == 8
    for name, value in from_log["deviations_um"].items():
        assert value == pytest.approx(axis["deviations_um"][name], abs=0.5), name
        assert value == pytest.approx(best["deviations_um"][name], abs=0.5), name
    assert from_log["deviations_um"]["F_p"] < 1.0  # every space cut alike


def test_a_trip_off_its_probe_line_is_refused_naming_its_line(eccentric, tmp_path, capsys):
    lines = eccentric[0].splitlines()
    x, y, z, *rest = lines[40].split()
    lines[40] = " ".join([x, f"{float(y) + 0.02:f}", z, *rest])  # 20 um across the move
    code, grading = grade(tmp_path, "off", "\n".join(lines) + "\n")
    err = capsys.readouterr().err.strip()
    assert code == 2 and grading == {} and len(err.splitlines()) == 1
    assert "measured:41: trip 41: the ball centre is" in err and "off the probe line" in err, err


def test_a_short_log_is_graded_on_its_trips_with_a_note(eccentric, tmp_path, capsys):
    lines = eccentric[0].splitlines()[:46]  # the program stopped after the last pitch point of space 5 ...
    code, grading = grade(tmp_path, "short", "\n".join(lines) + "\n")
    assert code == 0 and "46 of the probing program's 166 trips" in grading["notes"][0]
    # ... so: space 0's profile and helix traces, no pitch (not every flank of a side)
    assert set(grading["deviations_um"]) == {"f_Ha", "f_fa", "F_a", "f_Hb", "f_fb", "F_b"}
    assert "note: the probe log holds 46" in capsys.readouterr().out


@pytest.mark.parametrize("change, message", [
    (lambda lines: lines + [lines[0]], "measured:167: trip 167, but the job's probing program has 166 points"),
    (lambda lines: lines[:3] + ["1 2 3 4 5 6 7 8"] + lines[3:], "measured:4: a probe log line is nine numbers"),
    (lambda lines: lines[:3] + ["# a comment"] + lines[3:], "measured:4: a probe log line is nine numbers"),
    (lambda lines: lines[:1] + [lines[2]] + lines[2:], "measured:2: trip 2: "),  # a trip out of order
    (lambda lines: [" ".join(lines[0].split()[:3] + ["90.0"] + lines[0].split()[4:])] + lines[1:],
     "measured:1: trip 1: A = 90, but its point (P1, space 0) is probed at A = 0"),
])
def test_bad_logs_are_one_line(eccentric, tmp_path, capsys, change, message):
    text = "\n".join(change(eccentric[0].splitlines())) + "\n"
    code, grading = grade(tmp_path, "bad", text)
    err = capsys.readouterr().err.strip()
    assert code == 2 and grading == {} and len(err.splitlines()) == 1 and message in err, err


def test_a_probe_log_needs_the_jobs_probe_section_and_the_axis_datum(eccentric, tmp_path, capsys):
    work = tmp_path / "noprobe"
    work.mkdir()
    (work / "job.toml").write_text(REFERENCE_JOB.read_text())
    (work / "probe.log").write_text(eccentric[0])
    assert main(["grade", str(work / "job.toml"), str(work / "probe.log")]) == 2
    assert "probe.log: a probe log, but the job has no [probe] section" in capsys.readouterr().err
    code, _ = grade(tmp_path, "bestfit", eccentric[0], "--datum", "best-fit")
    assert code == 2 and "--datum best-fit is for CSV scans" in capsys.readouterr().err


@pytest.mark.slow  # the correct command end to end (6 s); tests/test_correct.py runs it in the fast tier
def test_correct_reads_the_probe_log_for_the_tool_size_and_says_it_cannot_see_the_table(cut, tmp_path):
    """`spur-cad correct JOB probe.log`: a gear probed 6 um larger than cut (material left: the tool as it cut was
    smaller, or worn) gives a size error of +6 um (within 1 um: the ideal cut's scallops are simulated apart, at
    2 um) and a finishing tool programmed 12 um smaller; the table's error is not identified and not corrected,
    and correction.json and the report say why (the probe turns on the table that cut the gear)."""
    from spur_cad.cli import main

    job, result, program = cut
    size_mm = 0.006
    shifted = dataclasses.replace(result, deviation=result.deviation + size_mm)
    log, _, _ = probed(job, shifted, program)
    work = tmp_path / "correct"
    work.mkdir()
    (work / "job.toml").write_text(JOB_TEXT)
    (work / "probe.log").write_text(log)
    assert main(["correct", str(work / "job.toml"), str(work / "probe.log"), "--out", str(work / "out"),
                 "--quiet"]) == 0
    correction = json.loads((work / "out" / "correction.json").read_text())
    assert correction["size_error_um"]["value"] == pytest.approx(1000.0 * size_mm, abs=1.0)
    programmed = correction["corrections"]["finishing_tool_diameter_mm"]
    assert programmed["before"] - programmed["programmed"] == pytest.approx(2.0 * correction["size_error_um"]["value"]
                                                                           / 1000.0, abs=1e-9)
    assert correction["table_error_arcsec"] == {"seen": False, "why": correction["not_corrected"]["table_error"]}
    assert "a_words" not in correction["corrections"] and "y_z_words" not in correction["corrections"]
    assert not correction["once_per_turn"]["visible"]
    assert "never e itself" in correction["not_corrected"]["table_error"]
    report = (work / "out" / "report.html").read_text()
    assert "not seen" in report and "turns on the table that cut the gear" in report


@pytest.mark.slow  # a planted cut and the correct command (6 s)
def test_a_probe_log_of_a_machine_with_a_table_error_still_corrects_the_size_and_cannot_see_the_table(cut, tmp_path,
                                                                                                      capsys):
    """Issue 46: the reference gear cut on the planted machine of tests/test_correct.py (tool 8 um larger, the table
    standing 25 arcsec x sin(A + 40 deg) further at each row's A; spur_cad's simulator) and probed on the same table:
    each space probed at its index angle A_k, where the table stands e(A_k) further, so the probe sees the space
    turned by +e(A_k) (a point's deviation + e(A_k) (p x n)). The log still gives the size (-8 um within 1 um) and
    slopes of a few tenths of a um (the table's difference between the cutting and the probing A, averaged over the
    four trace spaces), and correction.json says why it cannot see e(A); no A word is moved."""
    from tests.test_correct import ISSUE_MACHINE, TOOL_RADIUS_ERROR_UM, planted_cut

    job, _, program = cut
    plan = plan_cam(job)
    result = planted_cut(job, plan.finishing.toolpath, plan.finishing.tool, (0.0, job.gear.face_width_mm))
    grid, teeth = result.grid, job.gear.teeth
    probe_a_deg = -360.0 * np.arange(teeth) / teeth * job.post.rotary_sign
    turn_rad = np.radians(ISSUE_MACHINE.table_error_arcsec(probe_a_deg) / 3600.0)
    deviation = result.deviation.copy()
    for k in range(teeth):
        points, normals = grid.space_points(k), grid.space_normals(k)
        lever = points[:, 0] * normals[:, 1] - points[:, 1] * normals[:, 0]
        deviation[k] += (turn_rad[k] * lever)[:, None]
    log, _, _ = probed(job, dataclasses.replace(result, deviation=deviation), program)
    work = tmp_path / "table"
    work.mkdir()
    (work / "job.toml").write_text(JOB_TEXT)
    (work / "probe.log").write_text(log)
    assert main(["correct", str(work / "job.toml"), str(work / "probe.log"), "--out", str(work / "out"),
                 "--quiet"]) == 0
    correction = json.loads((work / "out" / "correction.json").read_text())
    assert correction["size_error_um"]["value"] == pytest.approx(-TOOL_RADIUS_ERROR_UM, abs=1.0)
    for name in ("profile_slope_um", "helix_slope_um"):
        assert all(abs(found["value"]) < 1.0 for found in correction[name]["by_side"].values()), correction[name]
    assert not correction["table_error_arcsec"]["seen"] and "never e itself" in correction["not_corrected"][
        "table_error"]
    assert "a_words" not in correction["corrections"] and "unfolded" not in correction["corrections"]
    # a probe log has its own datum, the A axis: --datum best-fit is refused in one line and nothing is written
    capsys.readouterr()
    assert main(["correct", str(work / "job.toml"), str(work / "probe.log"), "--datum", "best-fit", "--out",
                 str(work / "other")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--datum is for CSV scans" in err and not (work / "other").exists()
