"""Corrected programs from a measured gear (issue 30, point 4): a planted machine (tool 8 um larger in radius than
the program assumes, rotary index error 25 arcsec x sin(A + 40 deg)) cuts the reference gear in simulation; its
flank points, written as a scan would (turned and shifted), give back the size error and every space's index
error; `spur-cad correct` writes the corrected programs."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from spur_cad.correct.correct import finishing_cut, ideal_flanks
from spur_cad.correct.identify import identify
from spur_cad.grade.measured import read_points_csv
from spur_cad.job import load_job
from spur_cad.pipeline import job_stock, plan_cam
from tests.gears import REFERENCE_JOB

TOOL_RADIUS_ERROR_UM = 8.0
INDEX_AMPLITUDE_ARCSEC = 25.0
INDEX_PHASE_DEG = 40.0
ARCSEC_DEG = 1.0 / 3600.0
SCAN_TURN_DEG = 2.7  # within half a pitch (7.8 deg) of the machine's frame: the scan's spaces keep their numbers
SCAN_CENTRE_MM = (0.04, -0.025)
SCAN_ROWS_MM = (8.0, 10.0, 12.0)


def planted_index_arcsec(teeth: int) -> np.ndarray:
    """The planted machine's index error of each space: 25 arcsec x sin(A + 40 deg) at the space's index angle
    A = -k 360 / z (in [0, 360))."""
    a_deg = np.mod(-360.0 * np.arange(teeth) / teeth, 360.0)
    return INDEX_AMPLITUDE_ARCSEC * np.sin(np.radians(a_deg + INDEX_PHASE_DEG))


def planted_cut(job, path, tool, rows_mm=SCAN_ROWS_MM):
    """The finishing toolpath cut on the planted machine over the rows' X range: every move of space k stands e_k
    further in A than its A word (an independent turn of the IR, not the correction's code), the tool 8 um larger in
    radius."""
    a = path.a.copy()
    spaces = path.space >= 0
    a[spaces] += planted_index_arcsec(job.gear.teeth)[path.space[spaces]] * ARCSEC_DEG
    bigger = dataclasses.replace(tool, diameter_mm=tool.diameter_mm + 2.0 * TOOL_RADIUS_ERROR_UM / 1000.0)
    return finishing_cut(job.gear, path.replace(a=a), bigger, job_stock(job), (rows_mm[0], rows_mm[-1]))


def scan_csv(result, rows_mm=SCAN_ROWS_MM, planted_mm=None) -> str:
    """The cut's involute points (the design point moved along its normal by the simulated deviation) in the rows
    at rows_mm, turned by SCAN_TURN_DEG and shifted by SCAN_CENTRE_MM as a scan's frame would be, in the
    `spur-cad grade` CSV format. planted_mm(side, radius_mm, x_mm): a deviation (mm, + material) added to each
    point of that side and radius in the row at x, e.g. a slope."""
    grid = result.grid
    names = np.array(grid.feature_names())
    flank = np.array([name.endswith("involute") for name in names])
    side = np.array([name.split()[0] for name in names[flank]])
    radius = np.hypot(grid.points[flank, 0], grid.points[flank, 1])
    turn = math.radians(SCAN_TURN_DEG)
    c, s = math.cos(turn), math.sin(turn)
    lines = ["x_mm,y_mm,X_mm"]
    for x in rows_mm:
        row = int(np.argmin(np.abs(grid.rows_x - x)))
        planted = np.zeros(len(radius)) if planted_mm is None else planted_mm(side, radius, grid.rows_x[row])
        for k in range(grid.teeth):
            points, normals = grid.space_points(k)[flank], grid.space_normals(k)[flank]
            moved = points + (result.deviation[k, flank, row] + planted)[:, None] * normals
            y = c * moved[:, 0] - s * moved[:, 1] + SCAN_CENTRE_MM[0]
            z = s * moved[:, 0] + c * moved[:, 1] + SCAN_CENTRE_MM[1]
            lines += [f"{a:.6f},{b:.6f},{grid.rows_x[row]:.4f}" for a, b in zip(y, z)]
    return "\n".join(lines) + "\n"


@pytest.fixture(scope="module")
def reference():
    job = load_job(str(REFERENCE_JOB))
    plan = plan_cam(job)
    return job, plan, ideal_flanks(job, plan)


@pytest.fixture(scope="module")
def planted_scan(reference):
    job, plan, _ = reference
    return scan_csv(planted_cut(job, plan.finishing.toolpath, plan.finishing.tool))


def test_the_planted_machines_size_and_index_errors_are_identified(reference, planted_scan):
    job, _, ideal = reference
    found = identify(job.gear, read_points_csv(planted_scan, "scan.csv"), ideal)
    assert found.size_um == pytest.approx(-TOOL_RADIUS_ERROR_UM, abs=1.0)  # a larger tool: less material
    planted = planted_index_arcsec(job.gear.teeth)
    assert np.all(np.isfinite(found.index_arcsec))
    assert np.abs(found.index_arcsec - (planted - planted.mean())).max() < 2.0  # relative to their mean
    assert found.scan_turn_deg == pytest.approx(SCAN_TURN_DEG, abs=0.01)
    assert found.size_uncertainty_um < 1.0 and found.index_uncertainty_arcsec < 2.0


@pytest.fixture(scope="module")
def corrected(tmp_path_factory, planted_scan):
    """`spur-cad correct` on the planted machine's scan: (exit code, output folder)."""
    from spur_cad.cli import main

    folder = tmp_path_factory.mktemp("correct")
    (folder / "scan.csv").write_text(planted_scan)
    code = main(["correct", str(REFERENCE_JOB), str(folder / "scan.csv"), "--out", str(folder / "out"), "--quiet"])
    return code, folder / "out"


def test_correct_writes_the_corrected_programs_and_correction_json(reference, corrected):
    import json

    job, _, _ = reference
    code, out = corrected
    assert code == 0
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == \
        ["correction.json", "finishing.ngc", "report.html", "roughing.ngc"]
    correction = json.loads((out / "correction.json").read_text())
    size = correction["size_error_um"]
    assert size["value"] == pytest.approx(-TOOL_RADIUS_ERROR_UM, abs=1.0) and 0.0 <= size["uncertainty"] < 1.0
    tool = correction["corrections"]["finishing_tool_diameter_mm"]
    assert tool["before"] == 2.0 and tool["programmed"] == pytest.approx(2.016, abs=0.002)  # the tool as it cuts
    planted = planted_index_arcsec(job.gear.teeth)
    index = np.array(correction["index_error_arcsec"]["values"])
    assert np.abs(index - (planted - planted.mean())).max() < 2.0
    a_correction = np.array(correction["corrections"]["a_correction_deg"]) * 3600.0
    assert np.abs(a_correction + index).max() < 0.01  # each space's A turned back by its error
    assert set(correction["not_corrected"]) >= {"slopes_off_the_involute", "form"}
    assert correction["profile_slope_um"]["corrected"] and correction["helix_slope_um"]["corrected"]
    header = (out / "finishing.ngc").read_text().split("\n", 40)[:40]
    assert any("corrected from" in line and "D 2.016" in line for line in header)


@pytest.mark.parametrize("text, message", [
    ("x,y\n1,2\nthree,4\n", "scan.csv:3: not numbers"),
    ("1,2\n", "scan.csv: 1 points; at least 10 are needed"),
])
def test_bad_measured_files_are_one_line_and_nothing_is_written(tmp_path, capsys, text, message):
    from spur_cad.cli import main

    (tmp_path / "scan.csv").write_text(text)
    code = main(["correct", str(REFERENCE_JOB), str(tmp_path / "scan.csv"), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and message in err, err
    assert not (tmp_path / "out").exists()


SECTION_X_MM = 10.0  # the transverse section of the 2-D cut (mid face)


def _sweeps(program_text: str) -> np.ndarray:
    """(Y, Z, A) of every cutting move of the program that sweeps along X through the section, as the independent
    reader (tests/gcode_reader.py) interprets the text, in the order they run."""
    from tests.gcode_reader import read_program

    moves = read_program(program_text, "linuxcnc").moves
    sweeps = [move.end[1:] for move in moves if not move.rapid and move.start[1:] == move.end[1:]
              and min(move.start[0], move.end[0]) < SECTION_X_MM < max(move.start[0], move.end[0])]
    return np.array(sweeps)


def cut_2d(spec, program_text: str, tool_diameter_mm: float, corner_radius_mm: float,
           index_arcsec: np.ndarray | None) -> dict[str, np.ndarray]:
    """The section at SECTION_X_MM cut by the program's sweeps on a machine whose table stands index_arcsec[k]
    further in A in space k (a program's spaces are its equal runs of sweeps, in order) with a tool of the given
    size: shapely silhouettes (tests/silhouette.py), and each flank's mean signed distance of the design's involute
    points in the profile evaluation range to the cut (um, + material), per side and space."""
    import shapely

    from spur_cad.grade.simulated import profile_range_mm
    from tests.silhouette import design_boundary, place_silhouettes

    sweeps = _sweeps(program_text)
    per_space, rest = divmod(len(sweeps), spec.teeth)
    assert rest == 0 and per_space > 10, len(sweeps)
    a_deg = sweeps[:, 2].copy()
    if index_arcsec is not None:
        a_deg += np.repeat(index_arcsec, per_space) * ARCSEC_DEG
    union = shapely.union_all(place_silhouettes(sweeps[:, 0], sweeps[:, 1], a_deg, tool_diameter_mm,
                                                corner_radius_mm, 12.0))
    points, _ = design_boundary(spec, range(spec.teeth), ("involute",))
    rings = shapely.get_rings(shapely.get_parts(union))
    segments = np.concatenate([np.stack([c[:-1], c[1:]], axis=1) for c in map(shapely.get_coordinates, rings)])
    tree = shapely.STRtree(shapely.linestrings(segments))
    (index, _), found = tree.query_nearest(shapely.points(points), return_distance=True, all_matches=False)
    distance = np.full(len(points), np.nan)
    distance[index] = found
    distance[shapely.contains_xy(union, points[:, 0], points[:, 1])] *= -1.0  # inside the tool's sweep: gouged
    angle = np.arctan2(points[:, 1], points[:, 0])
    space = np.mod(np.rint((angle - math.pi / 2.0) / (2.0 * math.pi / spec.teeth)), spec.teeth).astype(int)
    local = np.mod(angle - math.pi / 2.0 - space * 2.0 * math.pi / spec.teeth + math.pi, 2.0 * math.pi) - math.pi
    # (space 0's gap is centred on +Z; local < 0 and > 0 are its two flanks)
    roll = np.sqrt(np.maximum(np.hypot(points[:, 0], points[:, 1]) ** 2 - spec.base_radius_mm ** 2, 0.0))
    start, end = profile_range_mm(spec)
    in_range = (roll >= start) & (roll <= end)
    flanks = {}
    for name, on_side in (("minus", local < 0.0), ("plus", local > 0.0)):
        flanks[name] = np.array([distance[in_range & on_side & (space == k)].mean() for k in range(spec.teeth)])
        flanks[name] *= 1000.0
    return flanks


def pitch_total_um(spec, flank_um: np.ndarray) -> float:
    """F_p of one side: the spread of the flanks' positions as arcs on the reference circle (normal / cos alpha)."""
    return float(np.ptp(flank_um)) * spec.reference_radius_mm / spec.base_radius_mm


def test_the_corrected_programs_cut_on_the_planted_machine_give_the_design(reference, corrected, tmp_path):
    from spur_cad.cli import main

    job, _, _ = reference
    spec, tool = job.gear, job.tools.finishing
    planted = planted_index_arcsec(spec.teeth)
    real_diameter = tool.diameter_mm + 2.0 * TOOL_RADIUS_ERROR_UM / 1000.0
    assert main(["run", str(REFERENCE_JOB), "--out", str(tmp_path / "original"), "--quiet"]) == 0
    original = (tmp_path / "original" / "finishing.ngc").read_text()
    ideal = cut_2d(spec, original, tool.diameter_mm, tool.corner_radius_mm, None)
    before = cut_2d(spec, original, real_diameter, tool.corner_radius_mm, planted)
    after = cut_2d(spec, (corrected[1] / "finishing.ngc").read_text(), real_diameter, tool.corner_radius_mm, planted)
    for side in ("minus", "plus"):
        assert pitch_total_um(spec, ideal[side]) < 0.5 and np.abs(ideal[side]).max() < 2.0  # the program's scallops
        assert pitch_total_um(spec, before[side]) > 8.0 and np.abs(before[side]).max() > 5.0  # the planted machine
        assert pitch_total_um(spec, after[side]) < 2.0, after[side]
        assert np.abs(after[side]).max() < 2.0, after[side]
        assert np.abs(after[side] - ideal[side]).max() < 0.5  # what the program cuts on an ideal machine


def correction_section_rows(page: str) -> dict[str, list[str]]:
    """The rows of the table in report.html's Correction section (section id="correction"), by their first cell, as
    the page's text (HTML entities resolved)."""
    from html.parser import HTMLParser

    class Rows(HTMLParser):
        def __init__(self):
            super().__init__()
            self.depth, self.rows, self.cell = 0, [], None

        def handle_starttag(self, tag, attrs):
            if tag == "section" and ("id", "correction") in attrs:
                self.depth = 1
            elif self.depth and tag == "tr":
                self.rows.append([])
            elif self.depth and tag in ("td", "th"):
                self.cell = ""

        def handle_endtag(self, tag):
            if tag == "section":
                self.depth = 0
            elif self.depth and tag in ("td", "th") and self.cell is not None:
                self.rows[-1].append(self.cell.strip())
                self.cell = None

        def handle_data(self, data):
            if self.cell is not None:
                self.cell += data

    parser = Rows()
    parser.feed(page)
    return {row[0]: row[1:] for row in parser.rows}


def test_the_corrected_sets_report_has_a_correction_section_with_correction_json(corrected):
    """report.html of the corrected set: its Correction table holds correction.json's figures (to the 0.1 um and
    0.1 arcsec it prints): each error with its uncertainty, before and predicted after, and the reasons for what is
    not corrected."""
    import html
    import json

    out = corrected[1]
    correction = json.loads((out / "correction.json").read_text())
    page = (out / "report.html").read_text()
    rows = correction_section_rows(page)
    head = rows.pop("error")
    assert head == ["identified", "uncertainty (1 s.d.)", "corrected by", "before", "predicted after"]

    def near(cell: str, value: float) -> bool:
        return abs(float(cell.replace("\u2212", "-")) - value) <= 0.05 + 1e-9

    size, before, after = correction["size_error_um"], correction["before"], correction["predicted_after"]
    row = rows["flank position (tool size) [\u00b5m]"]
    assert near(row[0], size["value"]) and near(row[1], size["uncertainty"])
    assert "D 2.0160 mm" in row[2] and near(row[3], before["flank_position_um"]) and near(row[4], 0.0)
    index = [v for v in correction["index_error_arcsec"]["values"] if v is not None]
    low, high = rows["index error, range over the spaces [arcsec]"][0].split(" to ")
    assert near(low, min(index)) and near(high, max(index))
    for side in ("right", "left"):
        row = rows[f"F_p, {side} flanks [\u00b5m]"]
        assert near(row[3], before["F_p_um"][side]) and near(row[4], after["F_p_um"][side])
        assert before["F_p_um"][side] > 8.0 and after["F_p_um"][side] < 0.5  # the planted 25 arcsec table, removed
        for name, label in (("profile_slope_um", "profile slope f_H\u03b1"),
                            ("helix_slope_um", "helix slope f_H\u03b2")):
            found = correction[name]["by_side"][side]
            row = rows[f"{label}, {side} flanks [\u00b5m]"]
            assert near(row[0], found["value"]) and near(row[1], found["uncertainty"])
            assert near(row[3], before[name][side]) and near(row[4], after[name][side])
    text = html.unescape(page)
    assert all(reason in text for reason in correction["not_corrected"].values())
