"""The flank modification chart (issue 31.6): the design's removal as a measuring machine charts it (+ material),
profile against roll length with the diameter on top, lead against the face position, both flanks; in the report
beside the inspection sheet (rendered by headless Chromium: nothing wider than the page) and in the task panel
(tests/test_workbench_panel_gui.py)."""

from __future__ import annotations

import html as html_lib
import json
import re

import numpy as np
import pytest

from spur_cad.job import parse_job
from spur_cad.pipeline import run_job
from spur_cad.report.figures import modification_chart_figure
from tests.workbench_helper import ARTIFACTS

GEAR = """[job]
name = "modified z23 m4"

[gear]
teeth = 23
module_mm = 4
face_width_mm = 20
rack_tip_radius_mm = 1.52
"""

MODIFICATIONS = """
[gear.modifications]
tip_relief_um = 15
tip_relief_start_diameter_mm = 96
lead_crowning_um = 8
end_relief_um = 5
end_relief_length_mm = 3

[gear.modifications.right]
tip_relief_um = 20
tip_relief_shape = "parabolic"
"""


def _lines(ax) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    return {line.get_label(): (np.asarray(line.get_xdata()), np.asarray(line.get_ydata())) for line in ax.get_lines()
            if not line.get_label().startswith("_")}


@pytest.mark.parametrize("stacked", [False, True])
def test_the_chart_draws_each_flanks_design_removal_as_material_below_the_design(stacked):
    job = parse_job(GEAR + MODIFICATIONS, "mods.toml")
    fig = modification_chart_figure(job.modifications, job.gear.base_radius_mm, 2.6 if stacked else 9.0, stacked)
    profile_ax, lead_ax = fig.axes[:2]
    profile, lead = _lines(profile_ax), _lines(lead_ax)
    assert set(profile) == set(lead) == {"right flank", "left flank"}
    tip_roll = np.sqrt(job.gear.tip_radius_mm ** 2 - job.gear.base_radius_mm ** 2)
    start_roll = np.sqrt(48.0 ** 2 - job.gear.base_radius_mm ** 2)
    for side, tip_um in (("right", -20.0), ("left", -15.0)):
        rolls, material = profile[f"{side} flank"]
        assert rolls[-1] == pytest.approx(tip_roll, abs=1e-9) and material[-1] == pytest.approx(tip_um, abs=1e-9)
        assert np.all(material[rolls <= start_roll] == 0.0)  # no removal below the relief's start
        assert start_roll in rolls  # the linear relief's corner is a breakpoint
        faces, along = lead[f"{side} flank"]
        assert along[0] == pytest.approx(-13.0) and along[-1] == pytest.approx(-13.0)  # crowning + end relief
        assert along[np.argmin(np.abs(faces - 10.0))] == pytest.approx(0.0, abs=1e-3)
    rolls, right = profile["right flank"]
    middle = (rolls > start_roll) & (rolls < tip_roll)
    s = (rolls[middle] - start_roll) / (tip_roll - start_roll)
    assert right[middle] == pytest.approx(-20.0 * s * s)  # parabolic on the right
    diameter_axis = next(child for child in profile_ax.child_axes)  # the secondary axis: diameter on top
    assert diameter_axis.get_xlabel() == "diameter [mm]"
    assert profile_ax.get_ylabel().startswith("profile [\u00b5m]") and "(+ material)" in profile_ax.get_ylabel()


@pytest.fixture(scope="module")
def reports():
    """report.html of a gear with modifications and of the same gear without (no tools: the CAD stage only)."""
    modified = run_job(parse_job(GEAR + MODIFICATIONS.replace("lead_crowning_um = 8\nend_relief_um = 5\n"
                                                              "end_relief_length_mm = 3\n", ""), "mods.toml"))
    plain = run_job(parse_job(GEAR, "plain.toml"))
    return modified.files["report.html"].decode("utf-8"), plain.files["report.html"].decode("utf-8")


def test_the_report_charts_the_modifications_after_the_inspection_sheet(reports):
    modified, plain = reports
    headings = re.findall(r"<h2>([^<]*)</h2>", modified)
    assert headings[headings.index("Inspection sheet") + 1] == "Flank modifications"
    section = modified.split("<h2>Flank modifications</h2>", 1)[1].split("</section>", 1)[0]
    assert re.search(r'<img alt="[^"]+" src="data:image/png;base64,', section)
    assert "Flank modifications" not in plain and plain.count("<img") == modified.count("<img") - 1


@pytest.mark.browser
def test_the_modification_chart_fits_the_page_in_chromium(reports, browser, tmp_path):
    """At a narrow window nothing reaches past the body; a screenshot of the section goes to test-artifacts/."""
    import subprocess

    from tests.test_report import MEASURE

    modified, _ = reports
    page = tmp_path / "measured.html"
    page.write_text(modified.replace("</body>", MEASURE + "</body>"))
    chromium = [browser[0], "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars"]
    result = subprocess.run([*chromium, "--window-size=800,2000", "--virtual-time-budget=5000", "--dump-dom",
                             page.as_uri()], capture_output=True, text=True, timeout=120, check=False)
    found = re.search(r'<pre id="measured">(.*?)</pre>', result.stdout, re.DOTALL)
    assert found, result.stderr[-2000:]
    assert json.loads(html_lib.unescape(found[1])) == []
    # the section alone, for people to look at
    section = modified.split("<section class=\"keep\">\n<h2>Inspection sheet</h2>", 1)[1]
    head = modified.split("<body>", 1)[0]
    shot = tmp_path / "section.html"
    shot.write_text(f"{head}<body><section class=\"keep\">\n<h2>Inspection sheet</h2>"
                    f"{section.split('<section>', 1)[0]}</body></html>")
    ARTIFACTS.mkdir(exist_ok=True)
    subprocess.run([*chromium, "--window-size=900,1500", f"--screenshot={ARTIFACTS / 'report_modifications.png'}",
                    shot.as_uri()], capture_output=True, timeout=120, check=True)
    assert (ARTIFACTS / "report_modifications.png").stat().st_size > 0
