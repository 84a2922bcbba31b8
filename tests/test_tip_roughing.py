"""Small gears on the default stock (0.5 mm above the tip circle) with the suggested ("auto") tools: roughing
takes the blank down to the tip circle + finish_stock_mm over every tip land, so the finishing tool's land
passes take that stock instead of the whole allowance (docs/cam.md, roughing). Full runs: simulated at a coarse
resolution for speed."""

from __future__ import annotations

import json

import pytest

from spur_cad.job import parse_job
from spur_cad.pipeline import run_job
from tests.rs274_helper import run_rs274

RESOLUTION_MM = 0.02

JOB = """
[job]
name = "module {module} z{teeth}"

[gear]
teeth = {teeth}
module_mm = {module}
rack_tip_radius_mm = {rho}
face_width_mm = 4.0

[tools.roughing]
diameter_mm = "auto"

[tools.finishing]
diameter_mm = "auto"
corner_radius_mm = "auto"

[simulation]
resolution_mm = {resolution}
"""

def small_job(module: float, teeth: int):
    """The default job for the gear: ISO 53 rack (tip radius 0.38 m), default stock, tools "auto"."""
    return parse_job(JOB.format(module=module, teeth=teeth, rho=round(0.38 * module, 6), resolution=RESOLUTION_MM),
                     f"m{module}.toml")


@pytest.mark.slow
@pytest.mark.parametrize("module, teeth", [(0.5, 40), (0.8, 30), (1.0, 20), (1.25, 20), (1.25, 40)])
def test_small_gear_on_the_default_stock_is_cut_to_the_design(module, teeth):
    job = small_job(module, teeth)
    blank = job.stock.blank_radius_mm(job.gear)
    finishing = job.tools.finishing
    assert blank - job.gear.tip_radius_mm == pytest.approx(0.5)
    result = run_job(job)
    summary = json.loads(result.files["summary.json"])
    tips = summary["roughing"]["tip_pass_heights_mm"]
    depth_limit = job.roughing.max_level_depth_fraction * job.tools.roughing.diameter_mm
    assert tips and blank - tips[0] <= depth_limit + 1e-9
    assert all(high - low <= depth_limit + 1e-9 for high, low in zip(tips, tips[1:]))
    # what roughing leaves on the tips is within the finishing tool's one pass (its land passes)
    assert tips[-1] == pytest.approx(job.gear.tip_radius_mm + job.roughing.finish_stock_mm)
    assert tips[-1] - job.gear.tip_radius_mm <= 0.5 * finishing.diameter_mm
    sim = summary["simulation"]
    assert sim["max_gouge_mm"] <= RESOLUTION_MM
    assert sim["uncut_points"] == 0
    assert sim["per_feature"]["tip"]["max_leftover_mm"] <= job.finishing.target_scallop_mm + RESOLUTION_MM


@pytest.mark.linuxcnc
def test_the_roughing_program_with_tip_passes_passes_rs274(tmp_path):
    job = parse_job(JOB.format(module=1.25, teeth=20, rho=0.475, resolution=RESOLUTION_MM).replace(
        "[simulation]\n", "[simulation]\nenabled = false\n"), "m125.toml")
    result = run_job(job)
    assert json.loads(result.files["summary.json"])["roughing"]["tip_pass_heights_mm"]
    path = tmp_path / "roughing.ngc"
    path.write_bytes(result.files["roughing.ngc"])
    ok, canon, messages = run_rs274(path)
    assert ok, messages
    # the interpreter moves along X at the tip circle + finish stock with A half a pitch (9 deg) beside each
    # space's A (k x 18 deg), across the whole face (tool radius + clearance + front margin beyond it)
    floor = job.gear.tip_radius_mm + job.roughing.finish_stock_mm
    feeds = [[float(v) for v in line[len("STRAIGHT_FEED("):-1].split(",")] for line in canon
             if line.startswith("STRAIGHT_FEED(")]
    over_tips = [(x, a) for x, _, z, a, *_ in feeds if abs(z - floor) < 1e-4]
    assert {round(a % 18.0, 4) for _, a in over_tips} == {9.0}
    assert {round(-(a + 9.0) / 18.0) % 20 for _, a in over_tips} == set(range(20))
    assert min(x for x, _ in over_tips) < -1.0 and max(x for x, _ in over_tips) > job.gear.face_width_mm
