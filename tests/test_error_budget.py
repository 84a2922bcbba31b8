"""The machine's error budget in the simulated grade (issue 30, point 1): index errors from a calibration table
give the F_p worked by hand, runout and a tool-size error move the flanks by their size, the tool's deflection
is the cantilever's worked by hand, a zero budget is the ideal machine, and bad keys and bad table files are
refused with one line."""

from __future__ import annotations

import html
import json
import math
from types import SimpleNamespace

import numpy as np
import pytest

from spur_cad.cam.calibration import CalibrationTable
from spur_cad.cam.materials import MATERIALS
from spur_cad.errors import JobFileError
from spur_cad.grade.simulated import grade_simulation
from spur_cad.job import load_job, parse_job
from spur_cad.sim.budget import ErrorBudget, apply_budget, finishing_deflection
from spur_cad.sim.design import design_grid
from tests.workbench_helper import small_job_text

GEAR = parse_job(small_job_text(), "small.toml").gear  # z 12, m 3 (reference radius 18 mm), b 6
ARCSEC = math.pi / 648000.0  # one second of arc in radians, written out here on purpose

# A 30 arcsec table: 30 sin(A) every 30 deg. Space k is cut at A = -k 30 deg, so every space sits on a row:
# the errors of the 12 spaces are 30 sin(-30 k), from +30 (space 9, A = 90) to -30 (space 3, A = 270).
TABLE = "# A_deg  error_arcsec (a compensation table)\n" + "".join(
    f"{a}, {30.0 * math.sin(math.radians(a)):.6f}\n" for a in range(0, 361, 30))
# By hand: a turn of e moves a flank along the reference circle's arc by r e; F_p = r (e_max - e_min)
# = 18 mm x 60 arcsec = 18000 um x 60 x 4.8481e-6 = 5.236 um; f_pt = the largest step between neighbours,
# 30 sin 30 = 15 arcsec (from A = 0 to A = 330 or 30) -> 18000 x 15 x 4.8481e-6 = 1.309 um.
F_P_BY_HAND_UM = 5.236
F_PT_BY_HAND_UM = 1.309


def _job_file(tmp_path, machine: str, table: str | None = TABLE) -> str:
    if table is not None:
        (tmp_path / "rotary.txt").write_text(table)
    text = small_job_text() + "\n[simulation]\nresolution_mm = 0.02\n\n[machine]\n" + machine
    path = tmp_path / "job.toml"
    path.write_text(text)
    return str(path)


@pytest.fixture(scope="module")
def table_run(tmp_path_factory):
    from spur_cad.pipeline import run_job

    folder = tmp_path_factory.mktemp("budget")
    path = _job_file(folder, 'rotary_calibration_file = "rotary.txt"\nrotary_repeatability_arcsec = 0.0\n')
    files = run_job(load_job(path)).files
    return json.loads(files["summary.json"]), html.unescape(files["report.html"].decode())


def test_a_30_arcsec_table_gives_the_eccentric_gear_worked_by_hand(table_run):
    """The table's error acts at the A that cut each flank point (issue 46): 30 arcsec x sin(A) once per turn moves
    every flank point by c . n, |c| = r_b 30 arcsec, an eccentric gear, whose flank positions on the reference circle
    run round the gear as a sinusoid of amplitude r 30 arcsec: F_p = 2 r E sampled at the z spaces, between 5.236 x
    cos(pi / z) = 5.058 and 5.236 um, and f_pt at most 2 r E sin(pi / z) = 1.355 um."""
    summary, _ = table_run
    ideal, budget = summary["grading"], summary["error_budget"]
    expected = budget["grading"]["deviations_um"]
    noise = ideal["deviations_um"]["F_p"] + 0.1  # the ideal cut's own pitch (simulation resolution)
    assert F_P_BY_HAND_UM * math.cos(math.pi / 12) - noise <= expected["F_p"] <= F_P_BY_HAND_UM + noise
    assert expected["f_pt"] <= F_P_BY_HAND_UM * math.sin(math.pi / 12) + noise
    assert budget["index_error_arcsec"][9] == pytest.approx(30.0) and budget["index_error_arcsec"][3] == -30.0
    assert budget["index_source"].startswith("calibration table") and "rotary.txt" in budget["index_source"]
    assert budget["index_source"].endswith("at the A that cut each flank point")
    # the helix is the ideal's (a spur gear's flank is cut at one A along X); the profile changes by e(A)'s change
    # over the flank's A, a few tenths of a um here
    for name in ("f_Hb", "f_fb", "F_b"):
        assert expected[name] == pytest.approx(ideal["deviations_um"][name], abs=1e-3)
    assert budget["budget_share_um"]["F_p"] == pytest.approx(expected["F_p"] - ideal["deviations_um"]["F_p"],
                                                              abs=1e-3)
    # classes by hand for d = 36, m = 3, b = 6: F_pT class 5 = 0.072 + 3.3 + 2.1 + 12 = 17.47; class 1 = 17.47 / 4
    # = 4.37 -> 4.4 < 5.058, class 2 = 6.18 -> 6.0 >= 5.236: F_p is class 2
    assert budget["grading"]["classes"]["F_p"] == 2


def test_a_once_per_turn_error_at_the_generating_contacts_is_an_eccentric_gear(grid):
    """At generating's contacts (the right flank's normal turned onto -Y, A = 180 deg - angle(n); the left's onto +Y,
    A = -angle(n)), e(A) = E sin(A) moves every involute point by exactly c . n for one c with |c| = r_b E: the gear
    is perfect and round about a shifted centre, so a best fit of the centre would see nothing."""
    mask = np.array([name.endswith("involute") for name in grid.feature_names()])
    side = np.array([name.split()[0] for name in grid.feature_names()])[mask]
    a_deg = np.stack([np.where(side == "right", 180.0, 0.0)
                      - np.degrees(np.arctan2(*grid.space_normals(k)[mask][:, ::-1].T)) for k in range(GEAR.teeth)])
    moved, terms = apply_budget(grid, _ideal(grid), ErrorBudget(rotary_accuracy_arcsec=20.0), a_deg)
    normals = np.concatenate([grid.space_normals(k)[mask] for k in range(GEAR.teeth)])
    motion = np.concatenate([moved[k, mask, 0] for k in range(GEAR.teeth)])
    centre, *_ = np.linalg.lstsq(normals, motion, rcond=None)
    assert np.abs(normals @ centre - motion).max() < 1e-9
    assert np.hypot(*centre) * 1000.0 == pytest.approx(GEAR.base_radius_mm * 20.0 * ARCSEC * 1000.0, rel=1e-6)
    assert terms.eccentricity_um == pytest.approx(GEAR.base_radius_mm * 20.0 * ARCSEC * 1000.0, abs=1e-3)


def test_the_report_gives_the_ideal_and_the_expected_grade(table_run):
    _, report = table_run
    assert "ideal machine [µm]" in report and "with the budget [µm]" in report and "budget's share [µm]" in report
    assert "With the machine's error budget the gear is expected in class" in report
    assert "calibration table" in report
    assert "makes an eccentric gear" in report and "a best-fit measurement" in report and "will not show it" in report


@pytest.fixture(scope="module")
def grid():
    return design_grid(GEAR, 0.05, 0.0, GEAR.face_width_mm, np.zeros(0))


def _ideal(grid):
    return np.zeros((GEAR.teeth, len(grid.points), len(grid.rows_x)))


def _graded(grid, deviation):
    rows = (grid.rows_x >= -1e-9) & (grid.rows_x <= GEAR.face_width_mm + 1e-9)
    return grade_simulation(GEAR, SimpleNamespace(grid=grid, deviation=deviation, gear_rows=rows))


def _involute(grid, side: str) -> np.ndarray:
    return np.array([name == f"{side} involute" for name in grid.feature_names()])


def test_runout_and_tool_size_move_every_flank_into_the_material_by_their_size(grid):
    # runout 10 um total indicated: the longest edge cuts 5 um deeper; a tool 3 um larger in radius: 3 um more
    moved, terms = apply_budget(grid, _ideal(grid), ErrorBudget(runout_tir_um=10.0, tool_radius_error_um=3.0))
    for side in ("right", "left"):
        flank = moved[:, _involute(grid, side), :]
        assert flank.mean() * 1000 == pytest.approx(-8.0, abs=1e-9) and np.ptp(flank) < 1e-12
    assert np.all(moved[:, ~(_involute(grid, "right") | _involute(grid, "left")), :] == 0.0)  # fillets, root, tip
    graded = _graded(grid, moved)
    assert graded.deviations_um["F_p"] == pytest.approx(0.0, abs=1e-6)  # every space alike: no pitch
    assert graded.deviations_um["f_Ha"] == pytest.approx(0.0, abs=1e-6)  # the whole flank: no slope
    assert terms.flank_shift_um == {"runout": -5.0, "tool_radius": -3.0, "linear": 0.0, "deflection": 0.0,
                                    "total": -8.0}


def test_an_index_error_moves_an_involute_by_the_base_radius_times_the_angle(grid):
    # a constant 20 arcsec error: every involute point moves r_b x 20 arcsec along its normal, one flank into
    # the material and the other out of it (the space turned as a whole)
    table = CalibrationTable("const.txt", (0.0, 360.0), (20.0, 20.0))
    moved, _ = apply_budget(grid, _ideal(grid), ErrorBudget(calibration=table))
    by_hand_um = GEAR.base_radius_mm * 1000 * 20 * ARCSEC  # 16.914 mm x 20" = 1.640 um
    right, left = moved[:, _involute(grid, "right"), :] * 1000, moved[:, _involute(grid, "left"), :] * 1000
    assert np.allclose(np.abs(right), by_hand_um, rtol=1e-6) and np.allclose(np.abs(left), by_hand_um, rtol=1e-6)
    assert np.sign(right).min() == np.sign(right).max() == -np.sign(left).min()


def test_the_deflection_is_the_cantilevers_worked_by_hand():
    # The reference job's finishing tool: bull nose D 2, r 0.5, stick-out 15, f_z 0.02, finish stock 0.02, C45.
    # h = f_z sqrt(a / D) = 0.02 x 0.1 = 0.002 mm; b = sqrt(2 r a) = sqrt(0.02) = 0.14142 mm;
    # F = 2220 x 0.002^0.86 x 0.14142: 0.002^0.86 = exp(0.86 x -6.2146) = exp(-5.3446) = 0.0047771 -> F = 1.4998 N;
    # I = pi (0.8 x 2)^4 / 64 = pi x 6.5536 / 64 = 0.32170 mm^4; k = 3 x 600000 x 0.32170 / 15^3 = 171.57 N/mm;
    # deflection = 1.4998 / 171.57 = 8.742 um.
    bent = finishing_deflection(2.0, 0.5, 15.0, 0.02, 0.02, MATERIALS["steel_c45"])
    assert bent.chip_thickness_mm == pytest.approx(0.002) and bent.chip_width_mm == pytest.approx(0.14142, rel=1e-4)
    assert bent.force_n == pytest.approx(1.4998, rel=2e-3) and bent.stiffness_n_mm == pytest.approx(171.57, rel=1e-4)
    assert bent.deflection_um == pytest.approx(8.742, rel=2e-3)
    # twice the stick-out: 8 x the deflection; AlMgSi: F = 830 x 0.002^0.77 x 0.14142, 0.002^0.77 = exp(-4.7852)
    # = 0.0083531 -> F = 0.98051 N, deflection 0.98051 / 171.57 = 5.715 um
    assert finishing_deflection(2.0, 0.5, 30.0, 0.02, 0.02, MATERIALS["steel_c45"]).deflection_um == \
        pytest.approx(8 * bent.deflection_um)
    assert finishing_deflection(2.0, 0.5, 15.0, 0.02, 0.02, MATERIALS["aluminium_almgsi"]).deflection_um == \
        pytest.approx(5.715, rel=2e-3)
    assert finishing_deflection(2.0, 0.5, 0.0, 0.02, 0.02, MATERIALS["steel_c45"]) is None  # no stick-out given


def test_the_deflection_moves_the_flanks_out_of_the_material(grid):
    bent = finishing_deflection(2.0, 0.5, 15.0, 0.02, 0.02, MATERIALS["steel_c45"])
    moved, _ = apply_budget(grid, _ideal(grid), ErrorBudget(deflection=bent))
    assert moved[:, _involute(grid, "left"), :].mean() * 1000 == pytest.approx(bent.deflection_um)


def test_a_zero_budget_is_the_ideal_machine(grid):
    ideal = _ideal(grid)
    ideal[:, _involute(grid, "right"), :] += 0.002 * np.sin(np.arange(GEAR.teeth))[:, None, None]  # some pitch
    moved, terms = apply_budget(grid, ideal, ErrorBudget())
    assert np.array_equal(moved, ideal) and set(terms.index_error_arcsec) == {0.0}
    assert _graded(grid, moved).deviations_um == _graded(grid, ideal).deviations_um


def test_the_repeatability_is_the_same_draw_on_every_run_within_half_of_it_each_way(grid):
    budget = ErrorBudget(rotary_repeatability_arcsec=8.0)
    first, terms = apply_budget(grid, _ideal(grid), budget)
    again, _ = apply_budget(grid, _ideal(grid), budget)
    assert np.array_equal(first, again)
    assert max(abs(e) for e in terms.random_index_arcsec) <= 4.0 and len(set(terms.random_index_arcsec)) == 12


@pytest.mark.parametrize("machine, message", [
    ("rotary_accuracy_arcsec = nan\n", "rotary_accuracy_arcsec must be a finite number, got nan"),
    ("tool_runout_um = inf\n", "tool_runout_um must be a finite number, got inf"),
    ("linear_accuracy_um = -1.0\n", "linear_accuracy_um must be in [0, 500] um, got -1"),
    ("rotary_repeatability_arcsec = 1e9\n", "rotary_repeatability_arcsec must be in [0, 3600] arcsec"),
])
def test_bad_budget_keys_are_one_line_naming_file_line_and_key(machine, message):
    text = small_job_text() + "\n[machine]\n" + machine
    with pytest.raises(JobFileError) as raised:
        parse_job(text, "job.toml")
    line = text.splitlines().index(machine.strip()) + 1
    assert str(raised.value).startswith(f"job.toml:{line}: [machine] ") and message in str(raised.value)
    assert "\n" not in str(raised.value)


def test_an_unknown_material_is_refused_with_the_known_ones():
    text = small_job_text().replace("[job]\n", '[job]\nmaterial = "unobtainium"\n')
    with pytest.raises(JobFileError, match=r"^small.toml:\d+: \[job\] material must be one of 'steel_s235'"):
        parse_job(text, "small.toml")


@pytest.mark.parametrize("table, message", [
    ("0 0\n90 12 13\n", r"rotary.txt:2: expected two finite numbers 'A_deg error_arcsec', got '90 12 13'"),
    ("0 0\n90 nan\n", r"rotary.txt:2: expected two finite numbers"),
    ("0 0\n90 5\n45 3\n", r"rotary.txt:3: A = 45 deg must be in \[0, 360\] and above the line before's"),
    ("0 0\n90 5000\n", r"rotary.txt:2: error 5000 arcsec is beyond \+-3600"),
    ("# nothing\n", r"needs at least two rows"),
    ("0 1\n360 2\n", r"A = 0 and A = 360 deg are the same place but have different errors"),
])
def test_a_malformed_table_is_one_line_naming_the_key_and_the_tables_line(tmp_path, table, message):
    path = _job_file(tmp_path, 'rotary_calibration_file = "rotary.txt"\n', table)
    line = len(open(path).read().splitlines())
    with pytest.raises(JobFileError, match=rf"^.*job.toml:{line}: \[machine\] rotary_calibration_file: .*{message}"):
        load_job(path)


def test_a_table_that_is_not_a_regular_file_or_too_big_is_refused_before_it_is_read(tmp_path):
    path = _job_file(tmp_path, 'rotary_calibration_file = "tables"\n', None)
    (tmp_path / "tables").mkdir()
    with pytest.raises(JobFileError, match=r"rotary_calibration_file: .*tables: the calibration table is a folder"):
        load_job(path)
    path = _job_file(tmp_path, 'rotary_calibration_file = "big.txt"\n', None)
    (tmp_path / "big.txt").write_text("0 0\n" * 300_000)
    with pytest.raises(JobFileError, match=r"the calibration table has 1,200,000 bytes; at most 1,048,576"):
        load_job(path)
    path = _job_file(tmp_path, 'rotary_calibration_file = "missing.txt"\n', None)
    with pytest.raises(JobFileError, match=r"job.toml:\d+: \[machine\] rotary_calibration_file: .*missing.txt: "
                                           "calibration table not found"):
        load_job(path)
