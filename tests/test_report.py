"""report.html: self-contained (images embedded, nothing fetched) and showing summary.json's values."""

from __future__ import annotations

import base64
import dataclasses
import json
import re
from pathlib import Path

import pytest

from spur_cad.job import load_job
from spur_cad.pipeline import run_job
from spur_cad.report.html import render_report
from spur_cad.result import SimulationFacts

pytestmark = pytest.mark.slow  # make test-all

ROOT = Path(__file__).resolve().parents[1]
REFERENCE_JOB = ROOT / "resources" / "examples" / "reference_gear.toml"
PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def outputs():
    result = run_job(load_job(REFERENCE_JOB))
    return result.files["report.html"].decode("utf-8"), json.loads(result.files["summary.json"]), result


def test_report_embeds_every_image_and_refers_to_nothing_outside(outputs):
    html, _, _ = outputs
    assert html.startswith("<!DOCTYPE html>")
    sources = re.findall(r'<img[^>]*\ssrc="([^"]*)"', html)
    assert len(sources) == 5  # profile, roughing levels, finishing poses, deviation map, K-chart
    for src in sources:
        assert src.startswith("data:image/png;base64,")
        assert base64.b64decode(src.split(",", 1)[1], validate=True)[:8] == PNG
    assert not re.search(r"https?://|<script|<link|<iframe|url\(", html, re.IGNORECASE)


def test_report_shows_the_inspection_sheet_and_simulation_values_of_the_summary(outputs):
    html, summary, _ = outputs
    ins = summary["inspection"]
    for key in ("span_measurement_mm", "dimension_over_pins_mm", "pin_diameter_mm", "chordal_thickness_mm",
                "tooth_thickness_mm"):
        assert f"{ins[key]:.4f}" in html, key
    assert f"{-ins['thickness_reduction_mm']:.4f}" in html  # the thickness tolerance (allowance)
    assert f"over k = {ins['span_teeth_k']} teeth" in html
    sim = summary["simulation"]
    assert f"{sim['max_gouge_mm']:.4f}" in html and f"{sim['max_leftover_mm']:.4f}" in html
    assert f"{sim['removed_volume_mm3']:.1f}" in html
    finishing = summary["finishing"]
    for seconds in (finishing["estimated_time_s"], finishing["reference_strategy_time_s"]):
        assert f"{seconds / 3600:.2f} h" in html
    for role in ("roughing", "finishing"):
        assert f"{summary['tools'][role]['diameter_mm']:.4f}" in html
    assert str(summary["post"]["finishing_lines"]) in html


def test_report_without_toolpaths_simulation_or_grade_still_renders(outputs):
    _, summary, result = outputs
    bare = dataclasses.replace(result, roughing=None, finishing=None, grading=None,
                               simulation=SimulationFacts(enabled=False, resolution_mm=0.005))
    html = render_report(bare, {}).decode("utf-8")
    assert "Inspection sheet" in html and "Simulation disabled" in html and "<img" not in html
    assert "Programs and cycle time" not in html and "Grade (ISO" not in html
    assert f"{summary['inspection']['span_measurement_mm']:.4f}" in html


def test_report_shows_the_generating_passes_advice_and_all_three_cycle_times(outputs):
    html, summary, _ = outputs
    finishing, advice = summary["finishing"], summary["tools"]["generating_advice"]
    assert finishing["strategy"] == "generating"
    assert f"{finishing['passes_per_space']} straight passes per tooth space" in html
    assert f"generating flat height {1000 * finishing['flat_height_mm']:.2f} um" in html
    assert f"{finishing['land_passes_per_space']} on the tip land" in html
    for prefix in ("estimated", "perimeter", "reference_strategy"):
        for suffix in ("time_s", "time_with_acceleration_s"):
            key = f"{prefix}_{suffix}" if prefix != "estimated" else f"estimated_{suffix}"
            assert f"{finishing[key] / 3600:.2f} h" in html, key
    assert "For finishing strategy generating" in html
    for key in ("recommended_diameter_mm", "tip_mode_max_diameter_mm", "required_flute_length_mm"):
        assert key in html and f"{advice[key]:.4f}" in html, key
    assert len(re.findall(r'<img alt="finishing poses" src="data:image/png;base64,', html)) == 1
