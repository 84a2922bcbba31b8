"""resources/examples/: every job file loads as `spur-cad run` loads it, and the figures docs/usage.md quotes from
the 3-axis and the flank modification examples are what they plan."""

from __future__ import annotations

from pathlib import Path

import pytest

from spur_cad.job import load_job
from spur_cad.pipeline import plan_cam

EXAMPLES = Path(__file__).resolve().parents[1] / "resources" / "examples"


@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.toml")), ids=lambda path: path.name)
def test_every_example_loads(path):
    assert load_job(path).job.name


def test_the_modified_example_has_the_modifications_the_readme_shows():
    mods = load_job(EXAMPLES / "modified_gear.toml").modifications
    assert (mods.right.tip_relief_mm, mods.left.tip_relief_mm) == (0.015, 0.02)
    assert mods.left.tip_relief_parabolic and not mods.right.tip_relief_parabolic
    assert mods.right.lead_crowning_mm == mods.left.lead_crowning_mm == 0.008


@pytest.mark.slow
def test_the_flat_example_plans_what_the_readme_quotes():
    job = load_job(EXAMPLES / "flat_gear.toml")
    assert job.machine.axes == 3 and job.three_axis.tabs == 3
    facts = plan_cam(job).finishing.result.facts
    assert facts.step_downs == 11 and facts.arcs_per_loop == 1013
    assert round(facts.form_diameter_mm, 3) == 86.614 and round(facts.active_start_diameter_mm, 3) == 86.828
    assert round(facts.root_fillet_radius_mm, 3) == 1.151


@pytest.mark.slow
def test_the_modified_example_cuts_and_grades_what_the_readme_quotes():
    """usage.md: against the modified design the cut gouges at most 0.2 um and leaves at most 5.6 um, and the grading
    reads the tip reliefs and the crowning within 0.4 um of designed, the profile slopes within 1.2 um."""
    from spur_cad.pipeline import run_job

    result = run_job(load_job(EXAMPLES / "modified_gear.toml"))
    simulation = result.simulation
    assert simulation.max_gouge_mm <= 0.0002 and simulation.max_leftover_mm <= 0.0056
    for cut in result.grading.modifications_cut:
        allowed = 1.2 if cut.symbol in ("f_Halpha", "f_Hbeta") else 0.4
        assert abs(cut.cut_um - cut.designed_um) <= allowed, (cut.side, cut.symbol, cut.cut_um)
