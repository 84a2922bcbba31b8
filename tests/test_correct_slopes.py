"""Profile and helix slopes in `spur-cad correct` (issue 30, point 4): slopes planted per flank side in the planted
machine's scan (tests/test_correct.py) are identified within 0.3 um, and the corrected generating finishing, cut in
the simulator, carries the opposite slopes (so the machine's add up to the design's)."""

from __future__ import annotations

import numpy as np
import pytest

from spur_cad.correct.correct import finishing_cut, slope_corrected_finishing
from spur_cad.correct.identify import identify
from spur_cad.correct.summary import pressure_angle_change_deg
from spur_cad.grade.measured import read_points_csv
from spur_cad.grade.simulated import helix_range_mm, profile_range_mm
from spur_cad.pipeline import job_stock
from spur_cad.sim.contact import contact_angles
from tests.test_correct import (
    ISSUE_MACHINE,
    TOOL_RADIUS_ERROR_UM,
    planted_cut,
    reference,  # noqa: F401  (the module's fixture)
    scan_csv,
)

PROFILE_SLOPE_UM = {"right": 6.0, "left": -4.0}  # f_Halpha: + material rising toward the tip
HELIX_SLOPE_UM = {"right": 5.0, "left": -3.0}  # f_Hbeta: + material rising toward +X
ROWS_MM = (2.0, 6.0, 10.0, 14.0, 18.0)  # planes spread over the face: helix traces of five points
SLOPE_TOLERANCE_UM = 0.3


def slopes_mm(spec):
    """The planted deviation (mm, + material) of a side's points at radius and X: each side's profile slope linear in
    roll length over the profile evaluation range and helix slope linear in X over the helix range, 0 at their
    middles."""
    start, end = profile_range_mm(spec)
    front, back = helix_range_mm(spec.face_width_mm, spec.module_mm)

    def planted(side, radius_mm, x_mm):
        roll = np.sqrt(np.maximum(radius_mm ** 2 - spec.base_radius_mm ** 2, 0.0))
        profile = np.array([PROFILE_SLOPE_UM[s] for s in side]) * (roll - 0.5 * (start + end)) / (end - start)
        helix = np.array([HELIX_SLOPE_UM[s] for s in side]) * (x_mm - 0.5 * (front + back)) / (back - front)
        return (profile + helix) / 1000.0

    return planted


@pytest.fixture(scope="module")
def sloped(reference):  # noqa: F811
    """What the planted machine's scan with the slopes added gives back."""
    job, plan, ideal = reference
    cut = planted_cut(job, plan.finishing.toolpath, plan.finishing.tool, ROWS_MM)
    scan = scan_csv(cut, ROWS_MM, slopes_mm(job.gear))
    contacts = contact_angles(job.gear, plan.finishing.toolpath, plan.finishing.tool)
    return identify(job.gear, read_points_csv(scan, "scan.csv"), contacts, ideal, datum="axis")


def test_planted_slopes_are_identified_per_side_with_the_size_and_index(reference, sloped):  # noqa: F811
    job, _, _ = reference
    for side in ("right", "left"):
        assert sloped.profile_slope_um[side] == pytest.approx(PROFILE_SLOPE_UM[side], abs=SLOPE_TOLERANCE_UM)
        assert sloped.helix_slope_um[side] == pytest.approx(HELIX_SLOPE_UM[side], abs=SLOPE_TOLERANCE_UM)
        assert 0.0 < sloped.profile_slope_uncertainty_um[side] < SLOPE_TOLERANCE_UM
        assert 0.0 < sloped.helix_slope_uncertainty_um[side] < SLOPE_TOLERANCE_UM
    # slopes centred on their ranges leave the flanks' means, so the size and the table's error come back as before
    assert sloped.size_um == pytest.approx(-TOOL_RADIUS_ERROR_UM, abs=1.0)
    assert [h.order for h in sloped.table.kept] == [1]
    assert sloped.table.kept[0].amplitude_arcsec == pytest.approx(ISSUE_MACHINE.table[0].amplitude_arcsec, abs=1.0)


def test_the_pressure_angle_change_of_a_profile_slope_worked_by_hand(reference):  # noqa: F811
    spec = reference[0].gear
    # z 23, m 4, alpha 20 deg: r_b = 46 cos 20 = 43.226 mm; the form circle (43.307 mm) at roll 2.653 mm, the tip
    # (50 mm) at sqrt(50^2 - r_b^2) = 25.132 mm, the range's end at 95 % of the way: 24.006 mm, so L_alpha = 21.353 mm.
    # 6 um more material at the tip end is a base circle larger by 6 um / L_alpha of itself, a pressure angle
    # smaller by that / tan 20: 0.006 / 21.353 / 0.36397 = 7.720e-4 rad = 0.04423 deg.
    assert pressure_angle_change_deg(spec, 6.0) == pytest.approx(-0.04423, abs=2e-5)


@pytest.mark.slow  # a second planted cut (15 s); the identification above stays in the fast tier
def test_the_corrected_finishing_cuts_the_opposite_slopes(reference, sloped):  # noqa: F811
    """The moved passes cut on an ideal machine (the simulator, ideal cut subtracted by identify) give back minus the
    planted slopes: on the sloped machine they would cut the design's."""
    job, plan, ideal = reference
    finishing, not_corrected = slope_corrected_finishing(job, plan.finishing, sloped)
    assert not_corrected is None
    cut = finishing_cut(job.gear, finishing.toolpath, finishing.tool, job_stock(job), (ROWS_MM[0], ROWS_MM[-1]))
    contacts = contact_angles(job.gear, plan.finishing.toolpath, plan.finishing.tool)
    found = identify(job.gear, read_points_csv(scan_csv(cut, ROWS_MM), "cut.csv"), contacts, ideal, datum="axis")
    for side in ("right", "left"):
        assert found.profile_slope_um[side] == pytest.approx(-PROFILE_SLOPE_UM[side], abs=2 * SLOPE_TOLERANCE_UM)
        assert found.helix_slope_um[side] == pytest.approx(-HELIX_SLOPE_UM[side], abs=2 * SLOPE_TOLERANCE_UM)
    assert abs(found.size_um) < 0.5  # the flanks' mean position stays the size correction's
