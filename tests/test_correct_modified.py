"""`spur-cad correct` on a job with flank modifications (issue 31): the measured points are read from the modified
design, as the grader reads them, so a gear cut exactly to its design (tip reliefs, the left's parabolic, lead
crowning, a design profile and helix slope) identifies no correction, and the planted machine of tests/test_correct.py
(tool 8 um larger in radius, 25 arcsec index errors, slopes per side) is identified as on an unmodified gear; the
corrected programs, cut on that machine, give the modified design."""

from __future__ import annotations

import json

import numpy as np
import pytest

from spur_cad.correct.correct import corrected_plan_of, finishing_cut, ideal_flanks
from spur_cad.correct.identify import identify
from spur_cad.grade.measured import grade_measured, read_points_csv
from spur_cad.job import load_job
from spur_cad.pipeline import job_stock, plan_cam
from spur_cad.sim.contact import contact_angles
from tests.gears import REFERENCE_JOB
from tests.test_correct import ISSUE_MACHINE, TOOL_RADIUS_ERROR_UM, planted_cut, scan_csv
from tests.test_correct_slopes import HELIX_SLOPE_UM, PROFILE_SLOPE_UM, ROWS_MM, SLOPE_TOLERANCE_UM, slopes_mm

DESIGN_PROFILE_SLOPE_UM = 6.0  # f_Halpha designed on both flanks, beside the example's reliefs and crowning
DESIGN_HELIX_SLOPE_UM = -4.0  # f_Hbeta designed
PROBED_PROFILE_SLOPE_UM = 0.5  # a probe log's profile slope of a gear cut to its design, at most
CUT_TOLERANCE_UM = 1.0  # a modification as cut (fitted from the scan's valleys) against its designed amount


@pytest.fixture(scope="module")
def modified(tmp_path_factory):
    """(job file, job, plan, ideal cut) of resources/examples/modified_gear.toml with a design profile and helix
    slope added to its common table."""
    text = (REFERENCE_JOB.parent / "modified_gear.toml").read_text()
    anchor = "lead_crowning_um = 8.0"
    assert anchor in text
    text = text.replace(anchor, f"{anchor}\nprofile_slope_um = {DESIGN_PROFILE_SLOPE_UM}\n"
                                f"helix_slope_um = {DESIGN_HELIX_SLOPE_UM}")
    path = tmp_path_factory.mktemp("modified") / "job.toml"
    path.write_text(text)
    job = load_job(str(path))
    assert job.modifications.left.tip_relief_parabolic and not job.modifications.right.tip_relief_parabolic
    plan = plan_cam(job)
    return path, job, plan, ideal_flanks(job, plan)


@pytest.fixture(scope="module")
def exact_scan(modified):
    """The scan of the job's finishing cut on an ideal machine: the modified design and the program's scallops."""
    _, job, plan, _ = modified
    cut = finishing_cut(job.gear, plan.finishing.toolpath, plan.finishing.tool, job_stock(job),
                        (ROWS_MM[0], ROWS_MM[-1]))
    return scan_csv(cut, ROWS_MM)


def identified(job, plan, scan: str, ideal):
    """identify on the scan about the datum axis, the contacts from the plan's finishing."""
    contacts = contact_angles(job.gear, plan.finishing.toolpath, plan.finishing.tool)
    return identify(job.gear, read_points_csv(scan, "scan.csv"), contacts, ideal, job.modifications, "axis")


def assert_no_error(found, table_arcsec: float = 0.5, size_um: float = 0.5, slope_um: float = SLOPE_TOLERANCE_UM):
    """The identified errors are zero within the given bounds: size, every order of the table's error tested and
    each side's slopes."""
    assert abs(found.size_um) < size_um, found.size_um
    assert max(h.amplitude_arcsec for h in found.table.harmonics) < table_arcsec, found.table
    for side in ("right", "left"):
        assert abs(found.profile_slope_um[side]) < slope_um, found.profile_slope_um
        assert abs(found.helix_slope_um[side]) < slope_um, found.helix_slope_um


# plans and cuts the modified example (25 s); tests/test_correct.py identifies on the reference gear in the fast tier
@pytest.mark.slow
def test_a_gear_cut_to_its_modified_design_identifies_no_correction(modified, exact_scan):
    _, job, plan, ideal = modified
    assert_no_error(identified(job, plan, exact_scan, ideal))


@pytest.mark.slow  # the command end to end (tests/test_correct.py runs it on the reference gear in the fast tier)
def test_correct_writes_no_correction_for_a_gear_cut_to_its_modified_design(modified, exact_scan, tmp_path):
    from spur_cad.cli import main

    path, job, _, _ = modified
    (tmp_path / "scan.csv").write_text(exact_scan)
    assert main(["correct", str(path), str(tmp_path / "scan.csv"), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    correction = json.loads((tmp_path / "out" / "correction.json").read_text())
    assert abs(correction["size_error_um"]["value"]) < 0.5
    assert correction["corrections"]["finishing_tool_diameter_mm"]["programmed"] == pytest.approx(
        job.tools.finishing.diameter_mm, abs=0.001)
    assert correction["table_error_arcsec"]["kept"] == [] and "a_words" not in correction["corrections"]
    for name in ("profile_slope_um", "helix_slope_um"):
        assert all(abs(found["value"]) < SLOPE_TOLERANCE_UM for found in correction[name]["by_side"].values())


@pytest.fixture(scope="module")
def planted(modified):
    """What the planted machine's scan of the modified gear, with the planted slopes, gives back."""
    _, job, plan, ideal = modified
    cut = planted_cut(job, plan.finishing.toolpath, plan.finishing.tool, ROWS_MM)
    return identified(job, plan, scan_csv(cut, ROWS_MM, slopes_mm(job.gear)), ideal)


# a planted cut of the modified example (15 s); tests/test_correct.py's planted machine stays in the fast tier
@pytest.mark.slow
def test_the_planted_machines_errors_are_identified_on_a_modified_gear(modified, planted):
    _, job, _, _ = modified
    assert planted.size_um == pytest.approx(-TOOL_RADIUS_ERROR_UM, abs=1.0)
    assert [h.order for h in planted.table.kept] == [1]
    assert planted.table.kept[0].amplitude_arcsec == pytest.approx(ISSUE_MACHINE.table[0].amplitude_arcsec, abs=1.0)
    for side in ("right", "left"):
        assert planted.profile_slope_um[side] == pytest.approx(PROFILE_SLOPE_UM[side], abs=SLOPE_TOLERANCE_UM)
        assert planted.helix_slope_um[side] == pytest.approx(HELIX_SLOPE_UM[side], abs=SLOPE_TOLERANCE_UM)


@pytest.mark.slow  # a second planted cut and grading; the identification above stays in the fast tier
def test_the_corrected_programs_cut_on_the_planted_machine_give_the_modified_design(modified, planted):
    """The corrected plan (tool as it cuts, passes moved for the slopes, every row's A moved by -e(A)) cut on the
    planted machine with its slopes: no error is left, and every modification is cut as designed (graded against the
    modified design, spur_cad.grade.design_trace)."""
    _, job, original, ideal = modified
    _, plan, applied = corrected_plan_of(job, planted)
    assert applied.slopes_not_corrected is None and applied.table_orders == (1,)
    cut = planted_cut(job, plan.finishing.toolpath, job.tools.finishing, ROWS_MM)  # the real tool: 8 um larger
    scan = scan_csv(cut, ROWS_MM, slopes_mm(job.gear))
    points = read_points_csv(scan, "cut.csv")
    assert_no_error(identified(job, original, scan, ideal), table_arcsec=2.0, size_um=1.0,
                    slope_um=2 * SLOPE_TOLERANCE_UM)
    grading = grade_measured(job.gear, points, modifications=job.modifications)
    named = {(found.side, found.symbol): found for found in grading.modifications_cut}
    for side in ("right", "left"):  # the profile's (a helix trace of five planes is too short to fit shapes to)
        for symbol in ("C_a", "f_Halpha"):
            found = named[side, symbol]
            assert found.designed_um != 0.0 and found.cut_um == pytest.approx(found.designed_um, abs=CUT_TOLERANCE_UM)
    helix = [trace for trace in grading.traces if trace.kind == "helix"]
    assert len(helix) == 2 * job.gear.teeth
    for trace in helix:  # lead crowning 8 um and helix slope -4 um cut as designed: flat against the design
        assert np.ptp(trace.deviation_um) < CUT_TOLERANCE_UM, (trace.side, trace.space, trace.deviation_um)


@pytest.mark.slow  # a full cut and probing; tests/test_probe_log.py reads probe logs in the fast tier
def test_correct_reads_a_modified_gears_probe_log_from_the_modified_design(modified, tmp_path):
    """`spur-cad correct JOB probe.log` on the modified gear cut exactly and probed 6 um larger (tests/test_probe_log's
    probing of the simulated cut along probe.ngc's moves): the size error is the 6 um (within 1 um, as
    there) and no slope is identified (read against the unmodified design: the design helix slope, -3.6 um)."""
    import dataclasses

    from spur_cad.cli import main
    from spur_cad.job import parse_job
    from spur_cad.pipeline import probe_program
    from tests.test_probe_log import probed

    path, _, plan, _ = modified
    text = path.read_text() + "\n[probe]\nstylus_diameter_mm = 2.0\n"
    job = parse_job(text, "job.toml")
    size_mm = 0.006
    cut = finishing_cut(job.gear, plan.finishing.toolpath, plan.finishing.tool, job_stock(job),
                        (0.0, job.gear.face_width_mm))
    log, _, _ = probed(job, dataclasses.replace(cut, deviation=cut.deviation + size_mm),
                       probe_program(job)[1].decode())
    (tmp_path / "job.toml").write_text(text)
    (tmp_path / "probe.log").write_text(log)
    assert main(["correct", str(tmp_path / "job.toml"), str(tmp_path / "probe.log"), "--out", str(tmp_path / "out"),
                 "--quiet"]) == 0
    correction = json.loads((tmp_path / "out" / "correction.json").read_text())
    assert correction["size_error_um"]["value"] == pytest.approx(1000.0 * size_mm, abs=1.0)  # as test_probe_log
    profile = [found["value"] for found in correction["profile_slope_um"]["by_side"].values()]
    helix = [found["value"] for found in correction["helix_slope_um"]["by_side"].values()]
    # the probe's eleven profile points sample the scallops: the unmodified reference's log reads 0.36 um there
    assert len(profile) == 2 and all(abs(value) < PROBED_PROFILE_SLOPE_UM for value in profile), profile
    assert len(helix) == 2 and all(abs(value) < SLOPE_TOLERANCE_UM for value in helix), helix
