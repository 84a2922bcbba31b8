"""The default roughing strategy (issue 48): a job file that leaves [roughing] strategy out roughs by flanks on the
rotary table and by levels on 3 axes, the workbench's new job starts from the same default, and where flank roughing
cannot take the gear or tools the default falls back to levels with a note, so that such a job is refused only
where levels are refused too (a strategy the file gives is planned or refused as given); where levels would be
quicker than flanks, the plan and the report say so."""

from __future__ import annotations

import numpy as np
import pytest

from spur_cad.cam.machine import DEFAULT_ROUGHING_STRATEGY, Machine, MachineError, RoughingParams
from spur_cad.job import parse_job
from spur_cad.pipeline import plan_cam, run_job
from spur_cad.report.html import program_notes, strategy_notes
from spur_cad.summary import roughing_facts, roughing_json
from tests.gears import REFERENCE_JOB, with_roughing_strategy

# The reference gear's roughing alone, on a table whose A travels only from -360 to 0 deg (not continuous): its
# levels index A from 0 down to -352.2 deg, while its flank passes turn A up to +-31.1 deg beyond the spaces' own.
LIMITED_TABLE = """
[job]
name = "reference gear, roughing on a table of one turn"

[gear]
teeth = 23
module_mm = 4.0
rack_tip_radius_mm = 0.8
thickness_allowance_percent = 5.0
face_width_mm = 20.0

[stock]
radial_allowance_mm = 0.5
front_margin_mm = 1.0
back_margin_mm = 2.0

[tools.roughing]
diameter_mm = 3.5
flutes = 3
cutting_speed_m_min = 80.0
feed_per_tooth_mm = 0.015

[roughing]
flank_allowance_mm = 0.3
{strategy}
[machine]
rotary_continuous = false
a_min_deg = -360.0
a_max_deg = {a_max}

[simulation]
enabled = false
"""


def limited_table(strategy: str | None, a_max_deg: float = 0.0):
    text = LIMITED_TABLE.format(strategy=f'strategy = "{strategy}"\n' if strategy else "", a_max=a_max_deg)
    return parse_job(text, "limited_table.toml")


def test_a_job_file_without_a_strategy_roughs_by_flanks_on_the_table_and_by_levels_on_three_axes():
    text = REFERENCE_JOB.read_text()
    assert "strategy = \"" not in text.split("[roughing]")[1].split("[")[0]  # the example leaves it out
    job = parse_job(text, "reference.toml")
    assert job.roughing.strategy == DEFAULT_ROUGHING_STRATEGY == "flank" and job.roughing_strategy_left_out
    assert RoughingParams().strategy == "flank"
    given = parse_job(text.replace("[roughing]\n", "[roughing]\nstrategy = \"flank\"\n"), "given.toml")
    assert given.roughing.strategy == "flank" and not given.roughing_strategy_left_out
    flat = parse_job(text.replace("[machine]\n", "[machine]\naxes = 3\n"), "flat.toml")
    assert flat.roughing.strategy == "levels" and flat.roughing_strategy_left_out
    without_section = parse_job(text.split("[roughing]")[0] + "[finishing]" + text.split("[finishing]")[1], "r.toml")
    assert without_section.roughing.strategy == "flank" and without_section.roughing_strategy_left_out


def test_where_flank_roughing_is_refused_the_default_falls_back_to_the_levels_plan_with_a_note():
    by_default = limited_table(None)
    with pytest.raises(MachineError, match="roughing needs A = "):  # the same job asking for flanks is refused
        plan_cam(limited_table("flank"))
    plan = plan_cam(by_default)
    levels = plan_cam(limited_table("levels"))
    assert plan.roughing.flank is None and plan.flank_fallback is not None
    assert "outside the machine's travel" in plan.flank_fallback and levels.flank_fallback is None
    for axis in ("x", "y", "z", "a", "feed"):  # exactly the levels' program
        assert np.array_equal(getattr(plan.roughing.toolpath, axis), getattr(levels.roughing.toolpath, axis),
                              equal_nan=True), axis
    assert plan.roughing.toolpath.a.max() <= 0.0 and plan.roughing.toolpath.a.min() >= -360.0
    facts = roughing_facts(plan, by_default.machine)
    assert roughing_json(facts, measured=False)["flank_fallback"] == plan.flank_fallback
    assert "flank_fallback" not in roughing_json(roughing_facts(levels, by_default.machine), measured=False)


def test_the_fallback_is_noted_in_the_report():
    result = run_job(limited_table(None))
    notes = program_notes(result)
    assert any(note.startswith("Roughing by levels: the job leaves [roughing] strategy to its default")
               and "outside the machine's travel" in note for note in notes), notes


def test_where_levels_are_refused_too_the_default_gets_the_levels_refusal():
    # A ends at -10 deg: the levels' first space (A = 0) is beyond it as well
    with pytest.raises(MachineError, match=r"roughing needs A = 0\.000 deg"):
        plan_cam(limited_table(None, a_max_deg=-10.0))
    with pytest.raises(MachineError, match=r"roughing needs A = 0\.000 deg"):
        plan_cam(limited_table("levels", a_max_deg=-10.0))


# Flank passes held to a light engagement and a short axial depth, with a coarse staircase allowed: by levels quicker
CAUTIOUS_FLANKS = {"flank_allowance_mm": "1.0", "max_radial_engagement_fraction": "0.05", "max_axial_depth_mm": "2.0"}


def _reference_with(values: dict[str, str], strategy: str | None = None):
    text = REFERENCE_JOB.read_text()
    for name, value in values.items():
        line = next((line for line in text.splitlines() if line.startswith(f"{name} = ")), None)
        text = (text.replace(line, f"{name} = {value}") if line is not None
                else text.replace("[roughing]\n", f"[roughing]\n{name} = {value}\n", 1))
    return parse_job(with_roughing_strategy(text, strategy) if strategy else text, "reference_variant.toml")


def test_where_levels_would_be_quicker_than_the_default_flanks_the_plan_says_so_with_the_levels_plan_s_time():
    plan = plan_cam(_reference_with(CAUTIOUS_FLANKS))
    levels = plan_cam(_reference_with(CAUTIOUS_FLANKS, "levels"))
    suggestion = plan.levels_suggested
    assert plan.roughing.flank is not None and suggestion is not None and levels.levels_suggested is None
    assert suggestion.levels_time_s == levels.roughing.estimate.time_with_acceleration_s  # the job planned so
    assert suggestion.flank_time_s == plan.roughing.estimate.time_with_acceleration_s
    assert suggestion.levels_per_space == len(levels.roughing.levels.heights_mm)
    assert suggestion.levels_time_s <= 0.9 * suggestion.flank_time_s
    facts = roughing_facts(plan, Machine())
    saved = roughing_json(facts, measured=False)["levels_suggested"]["time_saved_s"]
    assert saved == pytest.approx(suggestion.flank_time_s - suggestion.levels_time_s)
    (note,) = strategy_notes(facts)
    assert note.startswith("Roughing by levels ([roughing] strategy = \"levels\", the same tool and cutting data, ")
    # the shipped reference job roughs quicker by flanks (38.6 min against 2 h 26 min): nothing to say
    shipped = plan_cam(parse_job(REFERENCE_JOB.read_text(), "reference.toml"))
    assert shipped.roughing.flank is not None and shipped.levels_suggested is None
    assert strategy_notes(roughing_facts(shipped, Machine())) == []
