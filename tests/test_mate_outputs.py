"""Issue 47, outputs: summary.json's `mate`, the report's "Gear pair" section (or the no-mate sentence) and the
SAP on profile.png, against the textbook pair formulas (written out in tests/test_mate.py)."""

from __future__ import annotations

import dataclasses
import json
from html import unescape

import pytest

from spur_cad.geometry.sampling import sample_profile
from spur_cad.job import parse_job
from spur_cad.pipeline import run_job
from spur_cad.report.plots import tooth_space_png
from tests.test_mate import _external_textbook

GEAR = ("[gear]\nteeth = 40\nmodule_mm = 1.0\nface_width_mm = 5.0\nrack_tip_radius_mm = 0.38\n"
        "thickness_allowance_mm = 0.03\n[simulation]\nenabled = false\n")
MATE = "[mate]\nteeth = 25\nprofile_shift_coefficient = 0.3\nthickness_allowance_mm = 0.02\n"


@pytest.fixture(scope="module")
def mated():
    return run_job(parse_job(GEAR + MATE, "pair.toml"))


def test_summary_mate_agrees_with_the_textbook(mated):
    summary = json.loads(mated.files["summary.json"])["mate"]
    book = _external_textbook(1.0, 20.0, 40, 25, 0.0, 0.3, ds1=0.03, ds2=0.02)
    expected = {"working_pressure_angle_deg": book["aw"], "centre_distance_mm": book["a"],
                "transverse_contact_ratio": book["eps"], "start_of_active_profile_diameter_mm": book["sap1"],
                "mate_start_of_active_profile_diameter_mm": book["sap2"],
                "circumferential_backlash_mm": book["backlash"], "tip_clearance_mm": book["c1"]}
    for name, value in expected.items():
        assert summary[name] == pytest.approx(value, rel=1e-6), name
    assert summary["teeth"] == 25 and summary["profile_shift_coefficient"] == 0.3 and summary["internal"] is False


def test_the_report_has_a_gear_pair_section_and_says_when_there_is_no_mate(mated):
    html = mated.files["report.html"].decode()
    facts = mated.mate
    assert "<h2>Gear pair</h2>" in html and "No [mate] given" not in html
    assert f"{facts.start_of_active_profile_diameter_mm:.4f}" in html
    assert f"{facts.transverse_contact_ratio:.4f}" in html and f"{facts.centre_distance_mm:.4f}" in html
    alone = run_job(parse_job(GEAR, "gear.toml"))
    text = alone.files["report.html"].decode()
    assert "<h2>Gear pair</h2>" not in text and "No [mate] given" in text and "basic rack" in text
    assert "mate" not in json.loads(alone.files["summary.json"])


def test_profile_png_marks_the_sap_only_with_a_mate():
    job = parse_job(GEAR + MATE, "pair.toml")
    samples = sample_profile(job.gear.tooth_space_profile(), 0.001)
    plain = dataclasses.replace(job.gear, active_profile_start_diameter_mm=0.0)
    assert tooth_space_png(job.gear, samples) != tooth_space_png(plain, samples)
    assert tooth_space_png(plain, samples) == tooth_space_png(plain, samples)


@pytest.mark.slow
def test_a_flat_finish_that_leaves_the_rack_fillet_is_graded_from_the_mate_sap():
    """Lying flat, a D 1.14 mm flat end mill on the issue's z40 gear with a z40 mate: its root climbs above the rack's
    form circle but stays below the SAP; the report says the involute is graded from the SAP, and the grade's
    profile traces start there."""
    text = ("[gear]\nteeth = 40\nmodule_mm = 1.0\nface_width_mm = 3.0\nrack_tip_radius_mm = 0.38\n"
            "thickness_allowance_percent = 2.0\n[machine]\naxes = 3\n[tools.finishing]\nkind = \"flat\"\n"
            "diameter_mm = 1.14\n[tools.roughing]\nkind = \"flat\"\ndiameter_mm = 1.0\n[mate]\nteeth = 40\n")
    result = run_job(parse_job(text, "flat.toml"))
    sap = result.mate.start_of_active_profile_diameter_mm
    facts = result.finishing.strategy_facts
    assert facts.rack_form_diameter_mm < facts.form_diameter_mm < sap
    html = unescape(result.files["report.html"].decode())
    assert f"graded from the mate's start of active profile, diameter {sap:.3f} mm" in html
    rb = result.gear.base_radius_mm
    starts = {round(t.evaluation[0], 9) for t in result.grading.traces if t.kind == "profile"}
    assert starts == {round(((sap / 2) ** 2 - rb**2) ** 0.5, 9)}
