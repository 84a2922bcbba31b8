"""Issue 47, step 3: the checks that depend on where the flank must be exact use the mate's start of active
profile (SAP): the flat end mill's root lying flat, and grading's evaluation range (simulated, measured, probe)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.spatial import cKDTree

from spur_cad.cam.probing import ProbeSection, design_points
from spur_cad.cam.three_axis import check_three_axis
from spur_cad.cam.tools import ToolError
from spur_cad.grade.simulated import grade_simulation, profile_range_mm
from spur_cad.job import parse_job
from spur_cad.sim.design import design_grid
from tests.rs274_helper import run_rs274
from tests.test_three_axis import SCALLOP_TARGET_MM, exact_outline, flat, interpreted_path, three_axis_program

ISSUE_GEAR = ("[gear]\nteeth = 40\nmodule_mm = 1.0\nface_width_mm = 5.0\nrack_tip_radius_mm = 0.38\n"
              "thickness_allowance_percent = 2.0\n")


def _sap_diameter_mm(z1, z2, m, x1=0.0, x2=0.0, alpha_deg=20.0):
    """Textbook: the mate's tip meets the line of action at a sin(alpha_w) - sqrt(r_a2^2 - r_b2^2) from the gear's
    base tangent point; standard centre distance when the shifts are 0."""
    alpha = math.radians(alpha_deg)
    inv = math.tan(alpha) - alpha + 2 * math.tan(alpha) * (x1 + x2) / (z1 + z2)
    aw = 0.5  # Newton on inv(aw) = inv
    for _ in range(60):
        aw -= (math.tan(aw) - aw - inv) / math.tan(aw) ** 2
    a = m * (z1 + z2) / 2 * math.cos(alpha) / math.cos(aw)
    rb1, rb2, ra2 = m * z1 / 2 * math.cos(alpha), m * z2 / 2 * math.cos(alpha), m * z2 / 2 + (1 + x2) * m
    return 2 * math.hypot(rb1, a * math.sin(aw) - math.sqrt(ra2**2 - rb2**2))


def test_without_a_mate_the_message_names_the_basic_rack_and_what_would_let_a_tool_fit():
    job = parse_job(ISSUE_GEAR, "job.toml")
    with pytest.raises(ToolError) as caught:
        check_three_axis(job.gear, flat(1.0, 2), None)
    words = str(caught.value)
    assert "above the active profile's start at 38.395 mm (set by the basic rack: no [mate])" in words
    assert "D 0.00" not in words and "0.000 mm" not in words
    assert "no flat end mill fits; change: [mate] (a z40 mate: SAP 38.564 mm, D " in words
    assert "rack_tip_radius_mm 0.19 (D " in words and "protuberance rack" in words
    assert "\n" not in words and caught.value.field == "diameter_mm"


@pytest.mark.linuxcnc
def test_acceptance_a_z40_mate_lets_a_d1_end_mill_cut_without_gouge_its_root_below_the_sap(tmp_path):
    """The issue's acceptance: z40 m1, standard rack, 2 % thinner, lying flat, a z40 mate at the standard centre
    distance: D 1 mm accepted, its root (38.395 mm) below the SAP (38.564 mm), and the interpreted program cuts the
    exact outline without gouge and leaves the active involute (from the SAP) within the scallop target."""
    job = parse_job(ISSUE_GEAR + "[mate]\nteeth = 40\n", "job.toml")
    spec = job.gear
    sap = _sap_diameter_mm(40, 40, 1.0)
    assert spec.active_profile_start_diameter_mm == pytest.approx(sap, rel=1e-9) and round(sap, 3) == 38.564
    root = check_three_axis(spec, flat(1.0, 2), None)
    assert 2 * root.form_radius_mm == pytest.approx(38.395, abs=5e-4) and 2 * root.form_radius_mm < sap
    program, _, _ = three_axis_program(spec, flat(1.0, 2), tmp_path)
    ok, canon, messages = run_rs274(program)
    assert ok, messages
    centres, _ = interpreted_path(canon)
    outline, labels = exact_outline(spec)
    clearance, _ = cKDTree(centres).query(outline)
    assert (0.5 - clearance).max() <= 0.001  # no gouge (1 um)
    active = (labels == "involute") & (np.hypot(*outline.T) >= sap / 2)
    assert (clearance[active] - 0.5).max() <= SCALLOP_TARGET_MM


# A pair whose SAP lies more than 0.5 mm (diameter) above the form circle: z40 m2 with a z14 mate shifted +0.4.
WIDE_GEAR = ("[gear]\nteeth = 40\nmodule_mm = 2.0\nface_width_mm = 6.0\nrack_tip_radius_mm = 0.76\n"
             "thickness_allowance_percent = 2.0\n")
WIDE_MATE = "[mate]\nteeth = 14\nprofile_shift_coefficient = 0.4\n"


def test_the_evaluation_range_follows_the_mate_sap():
    plain, mated = parse_job(WIDE_GEAR, "a.toml").gear, parse_job(WIDE_GEAR + WIDE_MATE, "b.toml").gear
    sap = _sap_diameter_mm(40, 14, 2.0, 0.0, 0.4)
    assert sap - 2 * plain.form_radius_mm >= 0.5
    rb, ra = plain.base_radius_mm, plain.tip_radius_mm
    form_roll, sap_roll = math.sqrt(plain.form_radius_mm**2 - rb**2), math.sqrt((sap / 2) ** 2 - rb**2)
    tip_roll = math.sqrt(ra**2 - rb**2)
    assert profile_range_mm(plain) == pytest.approx((form_roll, form_roll + 0.95 * (tip_roll - form_roll)), abs=1e-9)
    assert profile_range_mm(mated) == pytest.approx((sap_roll, sap_roll + 0.95 * (tip_roll - sap_roll)), abs=1e-9)
    # the probe's profile trace: from the SAP, the same range
    rolls = [math.sqrt(p.radius_mm**2 - rb**2) for p in design_points(mated, ProbeSection(pitch=False))
             if p.kind == "profile" and p.space == 0 and p.side == "right"]
    assert (min(rolls), max(rolls)) == pytest.approx(profile_range_mm(mated), abs=1e-9)


@pytest.fixture(scope="module")
def wide():
    plain, mated = parse_job(WIDE_GEAR, "a.toml").gear, parse_job(WIDE_GEAR + WIDE_MATE, "b.toml").gear
    return plain, mated, design_grid(plain, 0.02, -1.0, plain.face_width_mm + 1.0, np.zeros(0))


def test_simulated_grading_ignores_a_bump_between_the_form_circle_and_the_mate_sap(wide):
    """A 12 um bump on space 3's right flank, all of it between the form circle and the SAP: graded from the form
    circle (no mate) it is the profile form deviation; from the mate's SAP the flank is perfect."""
    plain, mated, grid = wide
    names = grid.feature_names()
    right = np.array([n == "right involute" for n in names])
    radius = np.hypot(grid.points[:, 0], grid.points[:, 1])
    low, high = plain.form_radius_mm, mated.active_profile_start_diameter_mm / 2
    band = right & (radius > low + 0.05) & (radius < high - 0.05)
    assert band.sum() >= 3
    bump = np.zeros(len(grid.points))
    middle = 0.5 * (low + high)
    bump[band] = 12.0e-3 * np.cos(0.5 * math.pi * (radius[band] - middle) / (0.5 * (high - low))) ** 2
    deviation = np.zeros((plain.teeth, len(grid.points), len(grid.rows_x)))
    deviation[3] += bump[:, None]
    rows = (grid.rows_x >= -1e-9) & (grid.rows_x <= plain.face_width_mm + 1e-9)
    result = SimpleNamespace(grid=grid, deviation=deviation, gear_rows=rows)
    without, withmate = grade_simulation(plain, result), grade_simulation(mated, result)
    assert without.deviations_um["F_a"] >= 8.0 and without.where["F_a"].space == 3
    assert withmate.deviations_um["F_a"] == pytest.approx(0.0, abs=1e-6)
    starts = [t.evaluation[0] for t in withmate.traces if t.kind == "profile"]
    assert starts and all(start == pytest.approx(profile_range_mm(mated)[0], abs=1e-12) for start in starts)
