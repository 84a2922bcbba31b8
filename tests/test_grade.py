"""ISO 1328-1:2013 grading (issue 17, second part): the tolerance formulas against values worked out by hand
from the standard's formulas, trace evaluation, and synthetic gears with planted deviations of known size."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from spur_cad.geometry.spec import GearSpec
from spur_cad.grade.iso1328 import class_of, evaluate_trace, rounded_um, tolerance_um
from spur_cad.grade.simulated import grade_simulation, helix_range_mm, profile_range_mm
from spur_cad.job import parse_job
from spur_cad.sim.design import design_grid
from tests.workbench_helper import small_job_text

# Worked by hand (calculator) from the class-5 formulas, times sqrt(2)^(A-5), then rounded:
# reference gear d = 92, b = 20, m = 4 (METHOD's figures): class 5 f_pT 6.692 -> 6.5, F_pT 20.26 -> 20,
#   F_aT hypot(5.692, 7.2) = 9.178 -> 9, F_bT hypot(6.045, 6.684) = 9.012 -> 9; class 7 (x2): 13, 41, 18, 18.
# z 12 m 3 b 6 (d = 36): class 5 f_HaT 1.2 + 0.036 + 4 = 5.236 -> 5.0; f_faT 1.65 + 5 = 6.65 -> 6.5;
#   class 8 (x 2.828): f_HaT 14.81 -> 15, f_pT (0.036 + 1.2 + 5) = 6.236 x 2.828 = 17.64 -> 18.
# z 40 m 1.5 b 12 (d = 60): class 4 (/ 1.414): F_pT (0.12 + 4.260 + 1.05 + 12) = 17.43 / 1.414 = 12.33 -> 12;
#   f_fbT (0.542 + 1.559 + 4) = 6.101 / 1.414 = 4.314 -> 4.3; class 10 (x 5.657): f_HbT (0.387 + 1.212 + 4)
#   = 5.599 x 5.657 = 31.67 -> 32.
BY_HAND = [
    ((92.0, 20.0, 4.0), 5, {"f_pT": 6.5, "F_pT": 20.0, "F_aT": 9.0, "F_bT": 9.0}),
    ((92.0, 20.0, 4.0), 7, {"f_pT": 13.0, "F_pT": 41.0, "F_aT": 18.0, "F_bT": 18.0}),
    ((36.0, 6.0, 3.0), 5, {"f_HaT": 5.0, "f_faT": 6.5}),
    ((36.0, 6.0, 3.0), 8, {"f_HaT": 15.0, "f_pT": 18.0}),
    ((60.0, 12.0, 1.5), 4, {"F_pT": 12.0, "f_fbT": 4.3}),
    ((60.0, 12.0, 1.5), 10, {"f_HbT": 32.0}),
]


@pytest.mark.parametrize("gear, grade, expected", BY_HAND)
def test_tolerances_equal_values_worked_by_hand(gear, grade, expected):
    for kind, value in expected.items():
        assert tolerance_um(kind, grade, *gear) == value, kind


def test_rounding_steps():
    assert [rounded_um(v) for v in (4.26, 4.24, 7.3, 7.2, 12.5, 12.4)] == [4.3, 4.2, 7.5, 7.0, 13.0, 12.0]


def test_a_deviation_gets_the_finest_class_that_holds_it():
    gear = (36.0, 6.0, 3.0)
    assert class_of("f_HaT", 5.0, *gear) == 5 and class_of("f_HaT", 5.1, *gear) == 6
    assert class_of("f_HaT", 1e6, *gear) is None


def test_trace_evaluation_separates_slope_form_and_total():
    s = np.linspace(0.0, 10.0, 201)
    ripple = 1.5 * np.cos(2 * np.pi * s / 2.5)  # whole periods of a cosine: no share in the least-squares line
    values = evaluate_trace(s, 0.8 * s + ripple, 0.0, 10.0)
    assert values.slope_um == pytest.approx(8.0, abs=0.2) and values.form_um == pytest.approx(3.0, abs=0.1)
    assert values.total_um == pytest.approx(8.0 + 3.0, abs=1.0)


GEAR = parse_job(small_job_text(), "small.toml").gear  # z 12, m 3, b 6, rho 0.9, 2 % thinner teeth


@pytest.fixture(scope="module")
def grid():
    return design_grid(GEAR, 0.02, -1.0, GEAR.face_width_mm + 1.0, np.zeros(0))


def _result(grid, deviation):
    rows = (grid.rows_x >= -1e-9) & (grid.rows_x <= GEAR.face_width_mm + 1e-9)
    return SimpleNamespace(grid=grid, deviation=deviation, gear_rows=rows)


def _flank(grid, side):
    return np.array([name == f"{side} involute" for name in grid.feature_names()])


def _roll(grid, mask):
    radius = np.hypot(grid.points[mask, 0], grid.points[mask, 1])
    return np.sqrt(np.maximum(radius ** 2 - GEAR.base_radius_mm ** 2, 0.0))


def test_a_perfect_gear_is_class_1(grid):
    grading = grade_simulation(GEAR, _result(grid, np.zeros((12, len(grid.points), len(grid.rows_x)))))
    assert grading.overall_class == 1 and all(abs(v) < 1e-9 for v in grading.deviations_um.values())


def test_planted_deviations_are_found_with_their_size_and_class(grid):
    deviation = np.zeros((12, len(grid.points), len(grid.rows_x)))
    start, end = profile_range_mm(GEAR)
    right, left = _flank(grid, "right"), _flank(grid, "left")
    roll = _roll(grid, right)
    # space 2, right flank: profile slope +8 um over the evaluation range
    deviation[2][right] += (8.0e-3 * (roll - start) / (end - start))[:, None]
    # space 7, right flank: a sinusoidal form ripple of 3 um peak to peak (whole periods of a cosine over the
    # evaluation range, so that the least-squares line stays flat and the slope 0)
    period = (end - start) / 3.0
    deviation[7][right] += (1.5e-3 * np.cos(2.0 * np.pi * (roll - start) / period))[:, None]
    # space 4, left flank: the flank 10 um ahead on the reference circle (a normal deviation of 10 cos alpha)
    cos_alpha = GEAR.base_radius_mm / GEAR.reference_radius_mm
    deviation[4][left] += 10.0e-3 * cos_alpha
    # space 9, left flank: helix slope 6 um over the helix evaluation range
    lo, hi = helix_range_mm(GEAR.face_width_mm, GEAR.module_mm)
    deviation[9][left] += (6.0e-3 * (grid.rows_x - lo) / (hi - lo))[None, :]
    grading = grade_simulation(GEAR, _result(grid, deviation))
    found = grading.deviations_um
    assert found["f_Ha"] == pytest.approx(8.0, abs=0.5) and grading.where["f_Ha"].space == 2
    assert found["f_fa"] == pytest.approx(3.0, abs=0.5) and grading.where["f_fa"].space == 7
    assert found["f_pt"] == pytest.approx(10.0, abs=0.5) and found["F_p"] == pytest.approx(10.0, abs=0.5)
    assert grading.where["f_pt"].side == "left"
    assert found["f_Hb"] == pytest.approx(6.0, abs=0.5) and grading.where["f_Hb"].space == 9
    # classes by the hand-worked tolerances of this gear (d = 36, b = 6, m = 3):
    # f_HaT: class 6 = 5.236 x 1.414 = 7.40 -> 7.5 < 8, class 7 = 10.47 -> 10 >= 8: class 7
    # f_faT: class 1 = 6.65 / 4 = 1.66 -> 1.7 < 3, class 2 = 2.35 -> 2.4 < 3, class 3 = 3.33 -> 3.3: class 3
    # f_pT: class 7 = 6.236 x 2 = 12.47 -> 12 >= 10, class 6 = 8.82 -> 9.0 < 10: class 7
    # f_HbT: 0.05 x 6 + 0.35 x 2.449 + 4 = 5.157; class 6 = 7.29 -> 7.5 >= 6, class 5 = 5.157 -> 5.0 < 6: class 6
    classes = grading.classes
    assert classes["f_Ha"] == 7 and classes["f_fa"] == 3 and classes["f_pt"] == 7 and classes["f_Hb"] == 6
    assert grading.overall_class == max(c for c in classes.values())
    assert grading.validity == ()


def test_formulas_outside_their_range_are_flagged():
    tiny = GearSpec(teeth=12, module_mm=0.3, face_width_mm=2.0)
    from spur_cad.grade.iso1328 import validity_problems

    problems = validity_problems(tiny.teeth, 2 * tiny.reference_radius_mm, tiny.module_mm, tiny.face_width_mm, 0.0)
    assert any("module" in p for p in problems) and any("face width" in p for p in problems)
    assert math.isclose(2 * tiny.reference_radius_mm, 3.6)


def test_a_run_grades_the_simulated_gear_in_the_summary_and_the_report():
    import json

    from spur_cad.pipeline import run_job

    files = run_job(parse_job(small_job_text() + "\n[simulation]\nresolution_mm = 0.02\n", "small.toml")).files
    grading = json.loads(files["summary.json"])["grading"]
    assert grading["standard"] == "ISO 1328-1:2013" and grading["validity"] == []
    assert grading["class"] == max(grading["classes"].values())
    # 1.5 mm generating rolls with a 50 um target scallop: profile form is the scallop, far from class 5
    assert grading["deviations_um"]["f_fa"] > 10.0
    report = files["report.html"].decode()
    assert "Grade (ISO 1328-1:2013, from the simulated cut)" in report and 'alt="K-chart' in report


def _measured_csv(planted: bool, angle_deg: float = 3.0, centre=(0.05, -0.03), gear=GEAR) -> str:
    """Points on every flank of the small gear (a design grid sampled at another spacing than the grader's),
    in five transverse planes (each turned by the helix for a helical gear), turned and shifted as a scan would
    be; with planted deviations: profile slope +8 um (space 2 right), one flank 10 um ahead (space 4 left),
    helix slope 6 um (space 9 left)."""
    grid = design_grid(gear, 0.037, 0.0, 0.0, np.zeros(0))
    names = grid.feature_names()
    start, end = profile_range_mm(GEAR)
    lo, hi = helix_range_mm(gear.face_width_mm, gear.module_mm)
    cos_alpha = gear.base_radius_mm / gear.reference_radius_mm
    radius = np.hypot(grid.points[:, 0], grid.points[:, 1])
    roll = np.sqrt(np.maximum(radius ** 2 - gear.base_radius_mm ** 2, 0.0))
    lines = ["x_mm,y_mm,X_mm"]
    turn = math.radians(angle_deg)
    for k in range(gear.teeth):
        for x in np.linspace(lo, hi, 5):
            points, normals = grid.row_points(k, x)  # the section at X: turned by the helix
            dev = np.zeros(len(points))
            if planted:
                # a flank: its involute and its end on the form circle (sampled as the fillet's first point)
                form = radius >= gear.form_radius_mm - 1e-6
                right = np.array([n == "right involute" for n in names]) | (np.array(names) == "right fillet") & form
                left = np.array([n == "left involute" for n in names]) | (np.array(names) == "left fillet") & form
                if k == 2:
                    dev[right] += 8.0e-3 * (roll[right] - start) / (end - start)
                if k == 4:
                    dev[left] += 10.0e-3 * cos_alpha
                if k == 9:
                    dev[left] += 6.0e-3 * (x - lo) / (hi - lo)
            moved = points + dev[:, None] * normals
            y = math.cos(turn) * moved[:, 0] - math.sin(turn) * moved[:, 1] + centre[0]
            z = math.sin(turn) * moved[:, 0] + math.cos(turn) * moved[:, 1] + centre[1]
            lines += [f"{a:.6f},{c:.6f},{x:.4f}" for a, c in zip(y, z)]
    return "\n".join(lines) + "\n"


def _grade_cli(tmp_path, csv_text: str, *extra: str, job_text: str = small_job_text()) -> tuple[int, dict]:
    import json

    from spur_cad.cli import main

    tmp_path.mkdir(parents=True, exist_ok=True)
    (tmp_path / "job.toml").write_text(job_text)
    (tmp_path / "measured.csv").write_text(csv_text)
    code = main(["grade", str(tmp_path / "job.toml"), str(tmp_path / "measured.csv"), "--out",
                 str(tmp_path / "grade"), *extra])
    out = tmp_path / "grade" / "grade.json"
    return code, json.loads(out.read_text()) if out.exists() else {}


def test_measured_points_of_a_perfect_gear_fit_its_rotation_and_centre_and_grade_class_1(tmp_path):
    code, grading = _grade_cli(tmp_path, _measured_csv(planted=False), "--required-class", "1")
    fit = grading["fit"]
    assert code == 0 and grading["class"] == 1 and fit["rms_deviation_um"] < 0.2
    assert fit["rotation_deg"] == pytest.approx(3.0, abs=1e-3)  # the scan's turn (within half a pitch)
    assert fit["centre_mm"] == pytest.approx([0.05, -0.03], abs=1e-4) and grading["notes"] == []
    assert set(grading["deviations_um"]) == {"f_pt", "F_p", "f_Ha", "f_fa", "F_a", "f_Hb", "f_fb", "F_b"}


def test_measured_points_give_the_planted_deviations_and_their_classes(tmp_path):
    code, grading = _grade_cli(tmp_path, _measured_csv(planted=True), "--required-class", "6")
    found, where = grading["deviations_um"], grading["where"]
    assert found["f_Ha"] == pytest.approx(8.0, abs=0.5) and found["f_Hb"] == pytest.approx(6.0, abs=0.5)
    assert found["f_pt"] == pytest.approx(10.0, abs=0.5) and found["F_p"] == pytest.approx(10.0, abs=0.5)
    # a scan has no space 0: the fit may number the spaces from another one, but keeps their order
    assert where["f_Ha"]["side"] == "right" and where["f_Hb"]["side"] == "left"
    assert where["F_p"]["side"] in ("right", "left")  # the side of the largest F_p (one Grading type, issue 26)
    assert (where["f_Hb"]["space"] - where["f_Ha"]["space"]) % 12 == 7
    assert grading["classes"]["f_Ha"] == 7 and grading["classes"]["f_pt"] == 7 and grading["classes"]["f_Hb"] == 6
    assert code == 1 and grading["class"] == 7  # worse than the required class 6
    assert (tmp_path / "grade" / "k_chart.png").read_bytes()[:4] == b"\x89PNG"


HELICAL_JOB = small_job_text().replace("face_width_mm = 6.0", "face_width_mm = 6.0\nhelix_angle_deg = 15.0")
HELICAL = parse_job(HELICAL_JOB, "helical.toml").gear  # the small gear, 15 deg right hand: 4.9 deg over b


def test_a_helical_gears_sections_turn_with_x_and_give_the_planted_deviations(tmp_path):
    assert HELICAL.section_turn_rad(HELICAL.face_width_mm) > 0.08  # far more than the flank's 10 um over a pitch
    code, grading = _grade_cli(tmp_path, _measured_csv(planted=True, gear=HELICAL), job_text=HELICAL_JOB)
    found, where = grading["deviations_um"], grading["where"]
    assert grading["fit"]["rotation_deg"] == pytest.approx(3.0, abs=1e-3) and abs(found["f_fa"]) < 0.5
    assert found["f_Ha"] == pytest.approx(8.0, abs=0.5) and found["f_Hb"] == pytest.approx(6.0, abs=0.5)
    assert found["f_pt"] == pytest.approx(10.0, abs=0.5) and found["F_p"] == pytest.approx(10.0, abs=0.5)
    assert (where["f_Hb"]["space"] - where["f_Ha"]["space"]) % 12 == 7 and grading["class"] == 7


def test_only_what_was_measured_is_graded(tmp_path):
    # the planted file with X shifted by 50 mm: planes outside the face width give no helix trace in range
    shifted = "\n".join(line if line.startswith("x") else ",".join(line.split(",")[:2] + [
        f"{float(line.split(',')[2]) + 50.0:.4f}"]) for line in _measured_csv(planted=True).strip().splitlines())
    code, grading = _grade_cli(tmp_path, shifted + "\n")
    assert code == 0 and "f_Hb" not in grading["deviations_um"] and "f_Hb" not in grading["classes"]
    assert "outside the face width" in grading["notes"][0]
    # a single plane with a few flanks: profile only, no pitch (not every flank of a side) and no helix
    few = "\n".join(_measured_csv(planted=False).splitlines()[:800])
    _, grading = _grade_cli(tmp_path / "few", few + "\n")
    assert set(grading["deviations_um"]) <= {"f_Ha", "f_fa", "F_a"} and grading["deviations_um"]


@pytest.mark.parametrize("text, message", [
    ("x,y\n1,2\nthree,4\n", "measured.csv:3: not numbers"),
    ("1,2,3,4\n", "measured.csv:1: expected x_mm,y_mm[,X_mm], got 4 values"),
    ("1,nan\n", "measured.csv:1: a value is not a finite coordinate"),
    ("1,2\n", "measured.csv: 1 points; at least 10 are needed"),
])
def test_bad_measured_files_are_one_line(tmp_path, capsys, text, message):
    code, grading = _grade_cli(tmp_path, text)
    err = capsys.readouterr().err.strip()
    assert code == 2 and grading == {} and len(err.splitlines()) == 1 and message in err, err


def test_the_k_charts_tolerance_band_is_centred_on_the_design_not_on_the_traces_mean():
    from spur_cad.grade.grading import Grading, Trace
    from spur_cad.report.figures import k_chart_figure

    spec = parse_job(small_job_text(), "small.toml").gear
    grade = 8
    d, b, m = 2.0 * spec.reference_radius_mm, spec.face_width_mm, spec.module_mm
    half = {kind: 0.5 * tolerance_um(name, grade, d, b, m) for kind, name in (("profile", "F_aT"), ("helix", "F_bT"))}
    s = np.linspace(0.0, 4.0, 41)
    # every trace 0.7 of the half band above the design, rippling 0.2 of it: in class everywhere, its mean far from 0
    traces = tuple(Trace(kind, 3, side, 1.0 if kind == "profile" else None, s,
                         half[kind] * (0.7 + 0.2 * np.sin(3.0 * s)), (0.5, 3.5))
                   for kind in ("profile", "helix") for side in ("right", "left"))
    grading = Grading({}, {}, {}, grade, (), traces)
    fig = k_chart_figure(spec, grading)
    charts = [ax for ax in fig.axes if ax.get_lines()]
    assert len(charts) == 4
    for ax in charts:
        kind = "profile" if "profile" in ax.get_title() else "helix"
        trace = next(line.get_ydata() for line in ax.get_lines() if line.get_label().startswith("X =")
                     or line.get_label() == "reference circle")
        edges = sorted(float(line.get_ydata()[0]) for line in ax.get_lines() if line.get_gid() == "tolerance band")
        design, = [float(line.get_ydata()[0]) for line in ax.get_lines() if line.get_gid() == "design"]
        assert design == 0.0 and edges == pytest.approx([-half[kind], half[kind]], abs=1e-12)  # around the design
        assert abs(np.mean(trace)) > 0.6 * half[kind]  # far from the band's centre ...
        assert edges[0] <= trace.min() and trace.max() <= edges[1]  # ... and inside the band, as it is in class
        low, high = ax.get_ylim()
        assert low <= edges[0] and edges[1] <= high  # the band is in view


def test_a_k_chart_keeps_its_scale_on_the_evaluation_range_when_a_trace_spikes_beyond_it():
    """A ring's fillet or a tip corner beyond the evaluation range (a spike 40 bands high) must not squash the graded
    part of the trace to a line: the panel is clipped to the range's traces and the band, and says so."""
    from spur_cad.grade.grading import Grading, Trace
    from spur_cad.report.figures import k_chart_figure

    spec = parse_job(small_job_text(), "small.toml").gear
    grade = 8
    d, b, m = 2.0 * spec.reference_radius_mm, spec.face_width_mm, spec.module_mm
    half = {kind: 0.5 * tolerance_um(name, grade, d, b, m) for kind, name in (("profile", "F_aT"), ("helix", "F_bT"))}
    s = np.linspace(0.0, 4.0, 41)

    def deviation(kind: str) -> np.ndarray:
        values = half[kind] * 0.5 * np.sin(3.0 * s)
        values[s > 3.7] = 80.0 * half[kind] if kind == "profile" else values[s > 3.7]  # beyond the range (0.5, 3.5)
        return values

    traces = tuple(Trace(kind, 3, side, 1.0 if kind == "profile" else None, s, deviation(kind), (0.5, 3.5))
                   for kind in ("profile", "helix") for side in ("right", "left"))
    fig = k_chart_figure(spec, Grading({}, {}, {}, grade, (), traces))
    charts = [ax for ax in fig.axes if ax.get_lines()]
    for ax in charts:
        kind = "profile" if "profile" in ax.get_title() else "helix"
        low, high = ax.get_ylim()
        assert low <= -half[kind] and half[kind] <= high  # the band in view
        assert high - low < 4.0 * half[kind]  # the graded range fills the panel, the spike is clipped
        clipped = any("clipped" in text.get_text() for text in ax.texts)
        assert clipped == (kind == "profile")  # only the panel with a spike says so
