"""The shipped examples run without a warning (issue 48), while every warning they no longer give still fires on a
job it concerns: the end mills' sizes for a gear with no tools that is not cut by an outline's 2-D process, roughing
by levels (suggested by flanks), the 3-axis machine's error budget applied (tests/test_three_axis.py)."""

from __future__ import annotations

from pathlib import Path

import pytest

from spur_cad.job import load_job, parse_job
from spur_cad.pipeline import plan_cam, run_job
from spur_cad.report.sheet import warning_lines

EXAMPLES = Path(__file__).resolve().parents[1] / "resources" / "examples"
WIRE_EDM = EXAMPLES / "wire_edm_gear.toml"
SMALL_FLAT_END_MILL = "this gear's largest flat end mill for finishing by generation"


@pytest.mark.slow
@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.toml")), ids=lambda path: path.name)
def test_every_shipped_example_runs_without_a_warning(path):
    result = run_job(load_job(path))
    assert result.warnings == ()  # what spur-cad run prints as "warning:" and summary.json's warnings
    assert warning_lines(result) == ()  # the report's, with the simulation's own


def test_the_wire_edm_example_is_not_told_about_end_mills_but_a_job_that_may_mill_that_gear_is():
    """The wire EDM example writes the outline and gives no tools: nothing is milled. The same gear without [export]
    (a job asking for the recommendations to choose tools) is told that its flat end mill for generation (0.297 mm)
    is below the smallest end mill; so is one that writes the outline and also gives a tool to mill it."""
    text = WIRE_EDM.read_text()
    assert not [w for w in plan_cam(load_job(WIRE_EDM)).warnings if SMALL_FLAT_END_MILL in w]
    without_export = text.split("[export]")[0]
    assert [w for w in plan_cam(parse_job(without_export, "no_export.toml")).warnings if SMALL_FLAT_END_MILL in w]
    milled = text + "\n[tools.roughing]\ndiameter_mm = 1.5\nflutes = 3\n"
    assert [w for w in plan_cam(parse_job(milled, "milled.toml")).warnings if SMALL_FLAT_END_MILL in w]
