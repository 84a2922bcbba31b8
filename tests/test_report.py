"""report.html: self-contained (images embedded, nothing fetched), made from its Jinja2 template (a shop's copy
named in the job is used), showing summary.json's values labelled, with units and a sensible precision, no raw
key names; rendered and printed by headless Chromium: nothing wider than the page, A4 pages numbered, no table
split across pages."""

from __future__ import annotations

import base64
import dataclasses
import html as html_lib
import json
import re
import subprocess
from pathlib import Path

import pytest

from spur_cad.job import load_job
from spur_cad.pipeline import run_job
from spur_cad.report.html import default_template_text, render_report
from spur_cad.result import SimulationFacts
from tests.test_cli import run_cli

pytestmark = pytest.mark.slow  # make test-all

ROOT = Path(__file__).resolve().parents[1]
REFERENCE_JOB = ROOT / "resources" / "examples" / "reference_gear.toml"
PNG = b"\x89PNG\r\n\x1a\n"
MICRO = "\u00b5m"


def shown_duration(seconds: float) -> str:
    """How a time reads on the sheet: whole minutes, hours and minutes from an hour on."""
    minutes = round(seconds / 60.0)
    return f"{minutes // 60} h {minutes % 60:02d} min" if minutes >= 60 else f"{minutes} min"


def visible_text(page: str) -> str:
    """The page's text as a reader sees it (tags, the style sheet and image data left out), the folded "Job file"
    section folded: its line alone (unfolded it lists the job file's keys by their names, as the file writes them;
    its own test below)."""
    body = re.sub(r"<style>.*?</style>", " ", page, flags=re.DOTALL)
    body = re.sub(r"(<details class=\"job-file\">\s*<summary>.*?</summary>).*?</details>", r"\1", body,
                  flags=re.DOTALL)
    return html_lib.unescape(re.sub(r"<[^>]+>", " ", body))


@pytest.fixture(scope="module")
def outputs():
    result = run_job(load_job(REFERENCE_JOB))
    return result.files["report.html"].decode("utf-8"), json.loads(result.files["summary.json"]), result


def test_report_embeds_every_image_and_refers_to_nothing_outside(outputs):
    html, _, _ = outputs
    assert html.startswith("<!DOCTYPE html>")
    sources = re.findall(r'<img[^>]*\ssrc="([^"]*)"', html)
    assert len(sources) == 6  # profile, roughing levels, finishing passes, deviation map, engagement, K-chart
    for src in sources:
        assert src.startswith("data:image/png;base64,")
        assert base64.b64decode(src.split(",", 1)[1], validate=True)[:8] == PNG
    assert not re.search(r"https?://|<script|<link|<iframe|url\(", html, re.IGNORECASE)


def test_the_report_shows_the_measured_roughing_engagement_with_its_histogram(outputs):
    """The summary's engagement figures on the sheet, and the histogram: bars (the roughing's colour) and a red
    limit line in both panels (a_e / D, a_p / D). The figure goes to test-artifacts/ to be looked at."""
    import io

    import matplotlib.image
    import numpy as np

    html, summary, _ = outputs
    text = " ".join(visible_text(html).split())
    rough = summary["roughing"]
    ae = rough["max_radial_engagement_fraction"]
    assert f"largest radial engagement (width met / tool diameter) {ae:.2f} x D" in text
    assert f"largest axial depth met {rough['max_axial_depth_mm']:.3f} mm" in text
    assert f"mean material removal rate (while removing) {rough['mean_removal_rate_mm3_min']:.0f} mm³/min" in text
    src = re.search(r'<img alt="Roughing moves by the radial engagement[^"]*" src="data:image/png;base64,([^"]*)"',
                    html)
    png = base64.b64decode(src.group(1))
    artifacts = ROOT / "test-artifacts"
    artifacts.mkdir(exist_ok=True)
    (artifacts / "report_engagement.png").write_bytes(png)
    rgb = (matplotlib.image.imread(io.BytesIO(png))[:, :, :3] * 255).round().astype(int)
    half = rgb.shape[1] // 2
    bars = np.all(rgb == np.array((0x1F, 0x77, 0xB4)), axis=-1)  # tab:blue
    limit = (rgb[:, :, 0] > 150) & (rgb[:, :, 0] - rgb[:, :, 2] > 80)  # the dashed red line, antialiased
    assert bars[:, :half].sum() > 20 and bars[:, half:].sum() > 20
    for panel in (limit[:, :half], limit[:, half:]):  # a vertical dashed line: one column red over half its height
        assert panel.sum(axis=0).max() > 0.3 * rgb.shape[0]


def test_the_finishing_figure_has_no_empty_band_and_draws_every_tool_inside_it(outputs):
    """Issue 28: the passes figure's height follows its data (it had about 200 px of empty space) and the land
    passes' tool outlines stay inside the plot (they ran off its top): no all-white row band above the title or
    below the axis labels, and no coloured pass pixel in the top row of the plot frame's inside."""
    import io

    import matplotlib.image
    import numpy as np

    html, _, _ = outputs
    sources = re.findall(r'<img[^>]*\ssrc="data:image/png;base64,([^"]*)"', html)
    image = matplotlib.image.imread(io.BytesIO(base64.b64decode(sources[2])), format="png")[..., :3]
    white_rows = np.all(image > 0.98, axis=(1, 2))
    leading = int(np.argmax(~white_rows))
    trailing = int(np.argmax(~white_rows[::-1]))
    assert (leading + trailing) / len(image) < 0.15, (leading, trailing, len(image))  # 9 %; was 40 %
    # the plot frame: the longest dark horizontal line is its top or bottom edge; inside its top edge no
    # land-pass colour (matplotlib's tab:purple) meets the frame
    dark = np.all(image < 0.25, axis=2)
    frame_rows = np.flatnonzero(dark.sum(axis=1) > 0.6 * image.shape[1])
    top_edge = int(frame_rows.min())
    purple = np.all(np.abs(image - np.array([0x94, 0x67, 0xBD]) / 255.0) < 0.12, axis=2)
    assert purple.any() and not purple[top_edge + 1: top_edge + 3].any()


def test_report_shows_the_summarys_values_labelled_with_units(outputs):
    html, summary, _ = outputs
    text = visible_text(html)
    ins = summary["inspection"]
    for key in ("span_measurement_mm", "dimension_over_pins_mm", "pin_diameter_mm", "chordal_thickness_mm",
                "tooth_thickness_mm"):
        assert f"{ins[key]:.4f}" in text, key  # inspection dimensions to the tenth of a micrometre
    assert f"{-ins['thickness_reduction_mm']:.4f}" in text  # the thickness allowance
    assert f"over k = {ins['span_teeth_k']} teeth" in text
    sim = summary["simulation"]
    assert re.search(rf"largest gouge \(material cut below the design\)\s+{1000 * sim['max_gouge_mm']:.1f}\s+{MICRO}",
                     text)
    assert re.search(rf"largest leftover \(material left above the design\)\s+{1000 * sim['max_leftover_mm']:.1f}"
                     rf"\s+{MICRO}", text)
    assert f"{sim['removed_volume_mm3']:.0f}" in text
    finishing, roughing = summary["finishing"], summary["roughing"]
    for seconds in (finishing["estimated_time_s"], finishing["estimated_time_with_acceleration_s"],
                    finishing["reference_strategy_time_s"], roughing["estimated_time_with_acceleration_s"]):
        assert shown_duration(seconds) in text
    total = finishing["estimated_time_with_acceleration_s"] + roughing["estimated_time_with_acceleration_s"]
    assert re.search(rf"estimated machine time \(with acceleration\)\s+{shown_duration(total)}", text)
    for role, number in (("roughing", "T1"), ("finishing", "T2")):
        tool = summary["tools"][role]
        assert re.search(rf"{number}\s+{role}\s+\S+(-nose)? end mill\s+{tool['diameter_mm']:.3f}\s+"
                         rf"{tool['corner_radius_mm']:.3f}", text), role
        assert f"{tool['spindle_rpm']:.0f}" in text and "7000.0000" not in text
    assert f"{summary['post']['finishing_lines']:,}" in text
    assert "um" not in re.findall(r"\b[a-z]+\b", text)  # micrometres are µm
    assert not re.search(r"-0\.0+\b", text)  # no negative zero


def test_no_job_file_key_name_is_a_label(outputs):
    """A gear maker reads labels, not the job file's or summary.json's keys (only file names and the ISO
    deviation symbols have underscores)."""
    html, summary, _ = outputs
    text = visible_text(html)
    keys = set(summary["gear"]) | set(summary["inspection"]) | set(summary["tools"]) \
        | set(summary["tools"]["generating_advice"]) | set(summary["simulation"])
    shown = {name for name in keys if "_" in name and re.search(rf"\b{re.escape(name)}\b", text)}
    assert shown == set()
    assert not re.search(r"\b[a-z]+(_[a-z0-9]+)*_(mm|deg|um|rpm|mm3|fraction|percent|coefficient)\b", text)


def test_the_folded_job_file_section_lists_every_key_as_the_file_writes_it(outputs):
    """The report's "Job file": one table per section of summary.json's `job_file`, in its order, each key of it in
    order (every key its section's class declares: test_registry_job_key), a value the job file gives as its own
    line writes it (read here from the file's text, comments cut), each _mm key in mm."""
    html, summary, _ = outputs
    folded = re.search(r'<details class="job-file">\s*<summary>Job file: [^<]*</summary>(.*?)</details>', html,
                       re.DOTALL)
    assert folded and folded[1].count("<table") == len(summary["job_file"])
    tables = re.split(r"<caption>", folded[1])[1:]
    assert [re.match(r"\[([a-z_.]+)\]</caption>", t)[1] for t in tables] == list(summary["job_file"])
    lines = {}  # (section, key) -> the value as the file's line writes it
    section = ""
    for line in REFERENCE_JOB.read_text().splitlines():
        line = line.split("#")[0].strip()
        if line.startswith("["):
            section = line.strip("[]")
        elif "=" in line:
            key, value = (part.strip() for part in line.split("=", 1))
            lines[(section, key)] = value
    given = 0
    for name, table in zip(summary["job_file"], tables):
        rows = re.findall(r'<tr><th>([a-z0-9_]+)</th><td class="(?:num|text)">([^<]*)</td>'
                          r'<td class="unit">([^<]*)</td>', table)
        assert [key for key, _, _ in rows] == list(summary["job_file"][name]), name
        for key, value, unit in rows:
            if (name, key) in lines:
                assert html_lib.unescape(value) == lines[(name, key)], (name, key)
                given += 1
            assert unit == "mm" or not key.endswith("_mm"), (name, key)
    assert given == len(lines) > 40  # every line of the file found


def test_report_without_toolpaths_simulation_or_grade_still_renders(outputs):
    _, summary, result = outputs
    bare = dataclasses.replace(result, roughing=None, finishing=None, grading=None,
                               simulation=SimulationFacts(enabled=False, resolution_mm=0.005))
    html = render_report(bare, {}).decode("utf-8")
    assert "Inspection sheet" in html and "Not simulated" in html and "<img" not in html
    assert "Programs and cycle time" not in html and "Grade (ISO" not in html
    assert f"{summary['inspection']['span_measurement_mm']:.4f}" in html


def test_report_shows_the_generating_passes_advice_and_all_three_cycle_times(outputs):
    html, summary, _ = outputs
    text = visible_text(html)
    finishing, advice = summary["finishing"], summary["tools"]["generating_advice"]
    assert finishing["strategy"] == "generating"
    assert f"{finishing['passes_per_space']} straight passes per tooth space" in text
    assert f"generating flat height {1000 * finishing['flat_height_mm']:.2f} {MICRO}" in text
    assert f"{finishing['land_passes_per_space']} on the tip land" in text
    for prefix in ("estimated", "perimeter", "reference_strategy"):
        for suffix in ("time_s", "time_with_acceleration_s"):
            assert shown_duration(finishing[f"{prefix}_{suffix}"]) in text, (prefix, suffix)
    assert "Advice for finishing strategy generating" in text
    for key, label in (("recommended_diameter_mm", "recommended diameter"),
                       ("tip_mode_max_diameter_mm", "tip mode max diameter"),
                       ("required_flute_length_mm", "required flute length")):
        assert re.search(rf"{label}\s+{advice[key]:.3f}\s+mm", text), key
    assert len(re.findall(r'<img alt="Finishing passes[^"]*" src="data:image/png;base64,', html)) == 1


def test_a_copied_and_edited_template_named_in_the_job_is_used(tmp_path):
    """A shop copies spur_cad's template, changes it and names it in [job] report_template: its page is the one
    written (with the values filled in); a broken template is one line at the key's line, nothing written."""
    template = default_template_text().replace("<h2>Set-up sheet</h2>", "<h2>Einrichteblatt, Werkstatt Nord</h2>")
    assert template != default_template_text()
    template = template.replace("</body>", "<p id='shop'>{{ result.gear.teeth }} teeth, checked by ____</p></body>")
    (tmp_path / "templates").mkdir()
    (tmp_path / "templates" / "shop.html.j2").write_text(template)
    text = REFERENCE_JOB.read_text().replace("[job]\n", '[job]\nreport_template = "templates/shop.html.j2"\n', 1)
    text = text.replace("[post]", "[simulation]\nenabled = false\n\n[post]", 1)
    job = tmp_path / "job.toml"
    job.write_text(text)
    out = tmp_path / "out"
    result = run_cli("run", str(job), "--out", str(out), "--quiet")
    assert result.returncode == 0, result.stderr
    page = (out / "report.html").read_text()
    assert "Einrichteblatt, Werkstatt Nord" in page and "<p id='shop'>23 teeth, checked by ____</p>" in page
    assert "Set-up sheet" not in page and "Inspection sheet" in page
    line = text[:text.index("report_template")].count("\n") + 1
    for broken, says in (("{% if %}", "not a valid report template"), ("{{ no_such_value }}", "failed")):
        (tmp_path / "templates" / "shop.html.j2").write_text(template.replace("</body>", broken + "</body>"))
        refused = run_cli("run", str(job), "--out", str(tmp_path / "out2"))
        assert refused.returncode == 2 and not (tmp_path / "out2").exists()
        assert len(refused.stderr.strip().splitlines()) == 1
        assert refused.stderr.startswith(f"spur-cad: error: {job}:{line}:") and says in refused.stderr, refused.stderr
    (tmp_path / "templates" / "shop.html.j2").write_text("x" * (300 * 1024))  # larger than a template is read
    refused = run_cli("run", str(job), "--out", str(tmp_path / "out4"))
    assert refused.returncode == 2 and not (tmp_path / "out4").exists()
    assert refused.stderr.startswith(f"spur-cad: error: {job}:{line}: [job] report_template: ")
    assert "at most 262,144 are read" in refused.stderr
    (tmp_path / "templates" / "shop.html.j2").unlink()
    (tmp_path / "templates" / "shop.html.j2").mkdir()  # not a regular file
    refused = run_cli("run", str(job), "--out", str(tmp_path / "out3"))
    assert refused.returncode == 2 and "report_template" in refused.stderr


def test_the_template_runs_sandboxed(outputs, tmp_path):
    """A template cannot reach Python's internals (a shop's file is input, not code)."""
    _, _, result = outputs
    hostile = "{{ result.__class__.__mro__[1].__subclasses__() }}"
    with pytest.raises(Exception, match="report template failed"):
        render_report(result, {}, hostile, "hostile.j2")


MEASURE = """
<script>
addEventListener("load", () => {
  const page = document.body.getBoundingClientRect();
  const wide = [...document.querySelectorAll("table, figure, img, p, h1, h2")]
    .filter(e => e.getBoundingClientRect().right > page.right + 1 || e.scrollWidth > e.clientWidth + 1)
    .map(e => e.tagName + ": " + e.textContent.slice(0, 60));
  const out = document.createElement("pre"); out.id = "measured"; out.textContent = JSON.stringify(wide);
  document.body.appendChild(out);
});
</script>
"""


def _chromium(browser, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([browser[0], "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars", *args],
                          capture_output=True, text=True, timeout=120, check=False)


@pytest.mark.browser
@pytest.mark.parametrize("width", [1280, 800])
def test_nothing_is_wider_than_the_page_in_chromium(outputs, browser, tmp_path, width):
    """Headless Chromium lays the page out (a copy with a measuring script: the report itself has none) at a
    desktop and a narrow window: no table, figure or paragraph reaches past the body."""
    html, _, _ = outputs
    page = tmp_path / "measured.html"
    page.write_text(html.replace("</body>", MEASURE + "</body>"))
    result = _chromium(browser, f"--window-size={width},2000", "--virtual-time-budget=5000", "--dump-dom",
                       page.as_uri())
    found = re.search(r'<pre id="measured">(.*?)</pre>', result.stdout, re.DOTALL)
    assert found, result.stderr[-2000:]
    assert json.loads(html_lib.unescape(found[1])) == []


@pytest.mark.browser
def test_chromium_prints_the_report_on_numbered_a4_pages_without_splitting_a_table(outputs, browser, tmp_path):
    html, summary, _ = outputs
    page = tmp_path / "report.html"
    page.write_text(html)
    pdf = tmp_path / "report.pdf"
    result = _chromium(browser, "--no-pdf-header-footer", f"--print-to-pdf={pdf}", page.as_uri())
    assert pdf.is_file(), result.stderr[-2000:]
    info = subprocess.run([browser[1], str(pdf)], capture_output=True, text=True, check=True).stdout
    size = re.search(r"Page size:\s+([\d.]+) x ([\d.]+) pts", info)
    assert size and abs(float(size[1]) - 595.28) < 1.0 and abs(float(size[2]) - 841.89) < 1.0, info  # A4
    pages = int(re.search(r"Pages:\s+(\d+)", info)[1])
    assert pages >= 3
    texts = [subprocess.run([browser[2], "-layout", "-f", str(n), "-l", str(n), str(pdf), "-"], capture_output=True,
                            text=True, check=True).stdout for n in range(1, pages + 1)]
    for n, text in enumerate(texts, 1):
        assert f"page {n} of {pages}" in text, n

    def page_of(label: str) -> int:
        found = [n for n, text in enumerate(texts, 1) if label in " ".join(text.split())]
        assert found, label
        return found[0]

    # Each table's first and last rows are printed on one page.
    for first, last in (("number of teeth z", "undercut"), ("span measurement W_k", "fewest teeth without"),
                        ("largest roughing end mill", "stick-out the tools need"),
                        ("single pitch f_pt", "total helix F_b"), ("blank diameter", "clearance above the")):
        assert page_of(first) == page_of(last), (first, last)
    assert summary["inspection"]["span_teeth_k"] == 3
