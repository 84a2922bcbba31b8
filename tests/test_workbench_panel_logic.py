"""The task panel's logic without FreeCAD: field titles, advice that names the field and what to change,
recommendations never derived from an invalid tool, notes on unusual machine values, the summary's figures
against the plan and the posted programs, the values' fingerprint, and the colour bar's geometry."""

from __future__ import annotations

import re
from types import SimpleNamespace

import numpy as np
import pytest

from spur_cad.cam.recommend import recommend_tools
from spur_cad.cam.strategies.generating import generating_tool_limits
from spur_cad.job import parse_job
from spur_cad.pipeline import build_programs, plan_cam
from tests.workbench_helper import ROOT, small_job_text


@pytest.fixture
def wb(monkeypatch):
    monkeypatch.syspath_prepend(str(ROOT / "workbench"))
    from spur_cad_workbench import colourbar, colours, schema, simulation, summary, validation

    return SimpleNamespace(schema=schema, validation=validation, summary=summary, simulation=simulation,
                           colourbar=colourbar, colours=colours)


def _values(wb, **job_changes):
    values = wb.schema.values_from_job(parse_job(small_job_text(), "small.toml"))
    values["job"].update(job_changes)
    return values


KEY_NAME = re.compile(r"\b[a-z]+(?:_[a-z0-9]+)+\b")  # a job-file key such as corner_radius_mm


def test_titles_are_words_unique_within_their_section(wb):
    seen: dict[str, set[str]] = {}
    for field in wb.schema.JOB_FIELDS + wb.schema.GEAR_FIELDS + wb.schema.STOCK_FIELDS:
        title = wb.schema.title(field)
        assert title and title[0].isupper() and not KEY_NAME.search(title) and not re.search(r"[a-z][A-Z]", title)
        assert title not in seen.setdefault(field.group, set()), (field.group, title)
        seen[field.group].add(title)
    by_prop = {f.prop: wb.schema.title(f) for f in wb.schema.JOB_FIELDS}
    assert by_prop["RoughingFeedPerTooth"] == "Feed per tooth" and by_prop["FinishingToolDiameter"] == "Diameter"
    assert by_prop["FinishingToolNumber"] == "Tool number" and by_prop["XMin"] == "X min"


# (property, bad value, the job-file key the command line blames, words the advice must hold)
BAD_VALUES = [
    ("RoughingToolDiameter", -1.0, "tools.roughing.diameter_mm", "Roughing tool: diameter must be in"),
    ("FinishingCornerRadius", 3.0, "tools.finishing.corner_radius_mm", "Finishing tool: corner radius below"),
    ("TargetScallop", 1.0, "finishing.target_scallop_mm", "Finishing strategy: target scallop must be in"),
    ("MaxFeed", 1.0, "machine.max_feed_mm_min", "Machine: max feed must be in"),
    ("FinishingToolNumber", 1, "tools.finishing.tool_number", "Finishing tool: tool number = 1 is also"),
    ("FinishStock", 0.5, "roughing.finish_stock_mm", "Roughing strategy: finish stock = 0.5 must be below flank "
                                                     "allowance = 0.1"),
    ("XMin", 2000.0, "machine.x_min_mm", "Machine: x min must be below x max"),
]


@pytest.mark.parametrize("prop, value, key, words", BAD_VALUES, ids=[b[0] for b in BAD_VALUES])
def test_advice_names_the_field_the_command_line_blames_in_the_panels_words(wb, prop, value, key, words):
    result = wb.validation.validate(_values(wb, **{prop: value}), "small.toml")
    assert not result.ok and len(result.problems) == 1
    problem = result.problems[0]
    section, key_name = key.rsplit(".", 1)
    field = wb.schema.field_by_prop(problem.prop)
    assert (field.section, field.key) == (section, key_name)
    assert problem.message.startswith(f"[{section}] ") and key_name in problem.message  # the CLI's message
    assert problem.advice.startswith(words), problem.advice
    assert not KEY_NAME.search(problem.advice.split("(")[0]), problem.advice


def test_tool_limit_advice_gives_the_limit_the_recommendations_compute(wb):
    job = parse_job(small_job_text(), "s")
    spec, blank = job.gear, job.stock.blank_radius_mm(job.gear)
    result = wb.validation.validate(_values(wb, RoughingToolDiameter=6.0))
    limit = recommend_tools(spec, blank, job.machine.clearance_mm, job.tools.finishing).roughing_max_diameter_mm
    assert result.problems[0].prop == "RoughingToolDiameter"
    assert result.problems[0].advice.startswith(f"Roughing tool: diameter at most {limit:.3g} mm for this gear")
    assert result.problems[0].advice.endswith("now 6 mm")

    generating = _values(wb, FinishingStrategy="generating", FinishingToolDiameter=9.0, FinishingCornerRadius=0.9)
    result = wb.validation.validate(generating)
    tip = generating_tool_limits(spec, 0.9, job.finishing.target_scallop_mm, blank).tip_mode_max_diameter_mm
    advice = result.problems[0].advice
    assert result.problems[0].prop == "FinishingToolDiameter"
    assert advice.startswith(f"Finishing tool: diameter at most {tip:.3g} mm for a corner radius of 0.9 mm")


def test_recommendations_never_derive_from_an_invalid_finishing_tool(wb):
    job = parse_job(small_job_text(), "s")
    spec, blank = job.gear, job.stock.blank_radius_mm(job.gear)
    result = wb.validation.validate(_values(wb, FinishingStrategy="generating", FinishingToolDiameter=9.0,
                                            FinishingCornerRadius=0.9))
    assert result.problems[0].group == "Finishing tool"
    without = recommend_tools(spec, blank, job.machine.clearance_mm)
    assert result.recommendations.roughing_max_diameter_mm == pytest.approx(without.roughing_max_diameter_mm)


def test_unusual_machine_values_get_notes_and_usual_ones_none(wb):
    usual = _values(wb)["job"]
    assert wb.validation.unusual_value_notes(usual) == {}
    notes = wb.validation.unusual_value_notes({**usual, "MaxSpindleRpm": 100.0, "RapidFeed": 1000.0})
    assert set(notes) == {"MaxSpindleRpm", "RapidFeed"} and "unusually low" in notes["MaxSpindleRpm"]
    assert wb.validation.validate({**_values(wb), "job": {**usual, "MaxSpindleRpm": 100.0}}).ok  # still valid


def test_summary_figures_are_the_plans_estimates_and_the_posted_programs_lines(wb):
    job = parse_job(small_job_text(), "s")
    plan = plan_cam(job)
    figures = wb.summary.plan_figures(job, plan)
    programs, files = build_programs(job, plan)
    for name in ("roughing", "finishing"):
        op, planned = getattr(figures, name), getattr(plan, name)
        assert op.moves == planned.estimate.moves and op.seconds == planned.estimate.time_s
        assert op.seconds_with_acceleration == planned.estimate.time_with_acceleration_s
        text = next(data for file, data in files.items() if file.startswith(name)).decode()
        assert op.program_lines == len(text.splitlines())
    text = wb.summary.figures_text(figures)
    total = plan.roughing.estimate.time_with_acceleration_s + plan.finishing.estimate.time_with_acceleration_s
    assert text.startswith(f"Cycle time {wb.summary.duration_text(total)} with the machine's accelerations")
    assert f"{plan.finishing.estimate.moves:,} moves" in text


def test_durations_and_long_job_advice(wb):
    s = wb.summary
    assert [s.duration_text(t) for t in (40.0, 14 * 60.0, 2 * 3600.0 + 5 * 60.0)] == ["40 s", "14 min", "2 h 05 min"]
    short = s.PlanFigures(s.OperationFigures(10, 3600.0, 3700.0, 5), s.OperationFigures(10, 3600.0, 3700.0, 5))
    assert s.long_job_advice(short, "generating") == ""
    long_finish = s.PlanFigures(s.OperationFigures(10, 3600.0, 3700.0, 5),
                                s.OperationFigures(10, 30 * 3600.0, 32 * 3600.0, 5))
    advice = s.long_job_advice(long_finish, "perimeter")
    assert advice.startswith("Long job: 33 h 02 min, of which finishing 32 h 00 min")
    assert "target scallop" in advice and "generating strategy" in advice
    long_rough = s.PlanFigures(s.OperationFigures(10, 9 * 3600.0, 9 * 3600.0, 5), None)
    assert "larger roughing tool" in s.long_job_advice(long_rough, "generating")


@pytest.mark.slow  # one job per value (7 s)
def test_values_fingerprint_changes_with_every_job_value(wb):
    values = _values(wb)
    base = wb.summary.values_signature(values)
    assert wb.summary.values_signature(_values(wb)) == base
    for field in wb.schema.JOB_FIELDS:
        if not field.key or not wb.schema.section_enabled(values["job"], field.section):
            continue
        value = values["job"][field.prop]
        changed = (not value if field.kind == "bool" else value + 1 if field.kind in ("int",) else
                   value + 0.5 if isinstance(value, float) else
                   next(c for c in field.choices if c != value) if field.kind == "choice" else value + "x")
        assert wb.summary.values_signature(_values(wb, **{field.prop: changed})) != base, field.prop


def test_colour_scale_and_colour_bar(wb):
    deviation = np.array([-0.002, 0.0, 0.0125])
    assert wb.simulation.colour_scale_mm(deviation, 0.005) == pytest.approx(0.0125)
    assert wb.simulation.colour_scale_mm(np.array([0.001]), 0.005) == 0.005  # below the resolution: noise
    vertices, fraction = wb.colourbar.bar_geometry(1.6, steps=10)
    assert vertices.shape == (22, 3) and fraction[0] == -1.0 and fraction[-1] == 1.0
    assert np.all(np.diff(vertices[::2, 1]) > 0) and vertices[:, 0].min() > -1.6 and vertices[:, 0].max() < -1.3
    colours = wb.colours.deviation_colours(fraction, 1.0)
    assert np.allclose(colours[0], (0, 0, 1)) and np.allclose(colours[-1], (1, 0, 0))


def _new_job(wb, **gear):
    """A new job as the workbench starts it: the default gear (changed by `gear`), a new stock, new job values."""
    values = wb.schema.default_values()
    values["gear"].update(gear)
    values["stock"] = wb.schema.new_stock_values(values["gear"])
    values["job"].update(wb.validation.new_job_values(values))
    return values


def test_the_default_new_job_is_valid_roughs_by_flanks_and_is_within_a_shift(wb):
    """Issues 28 and 29: a new job for the default gear (z23 m4, rho 0.38 m: the roughing tool that reaches the root
    is under 2 mm) starts from tools and a strategy that take a gear maker's time: roughing by flanks with the
    suggested tool (two-stage roughing by levels saves no tenth of that), within one shift; the panel's cycle time
    counts every program."""
    values = _new_job(wb)
    result = wb.validation.validate(values)
    assert result.ok, result.messages
    job = result.job
    assert job.roughing.strategy == "flank" and job.roughing.flank_allowance_mm == pytest.approx(0.3)
    # the job files' default, one constant (issue 48): a job file leaving the strategy out, the property's default
    from spur_cad.job import job_from_dict

    file_job = job_from_dict({"gear": {"teeth": 23, "module_mm": 4.0, "face_width_mm": 20.0}}, "default.toml")
    assert file_job.roughing.strategy == values["job"]["RoughingStrategy"] == "flank"
    assert wb.schema.default_values()["job"]["RoughingStrategy"] == "flank"
    plan = plan_cam(job)
    programs = [p for p in (plan.roughing, plan.roughing_bottom, plan.finishing) if p is not None]
    figures = wb.summary.plan_figures(job, plan)
    total_s = sum(p.estimate.time_with_acceleration_s for p in programs)
    assert figures.seconds_with_acceleration == pytest.approx(total_s)
    assert total_s < wb.summary.LONG_JOB_S  # today about 2 h 38 min (4 h 48 min by two-stage levels, issue 28)
    assert wb.summary.figures_text(figures).startswith(f"Cycle time {wb.summary.duration_text(total_s)}")
    # the same tool by levels takes far longer; two-stage roughing by levels would not save a tenth
    by_levels = plan_cam(wb.validation.validate({**values, "job": {**values["job"],
                                                                   "RoughingStrategy": "levels"}}).job)
    assert by_levels.roughing.estimate.time_s > 2.0 * plan.roughing.estimate.time_s
    from spur_cad.cam.plan import TWO_STAGE_PAYS_FRACTION, suggested_two_stage
    from spur_cad.pipeline import cam_inputs

    suggestion = suggested_two_stage(cam_inputs(job))
    assert job.tools.bottom is None and (suggestion is None or suggestion.two_stage_time_s
                                         > TWO_STAGE_PAYS_FRACTION * suggestion.bottom_tool_alone_time_s)


@pytest.mark.parametrize("gear", [dict(Teeth=17, Module=2.0, RackTipRadius=0.5, FaceWidth=10.0, ProfileShift=0.3),
                                  dict(Teeth=40, Module=1.0, RackTipRadius=0.38, FaceWidth=8.0),
                                  dict(Teeth=31, Module=2.5, RackTipRadius=0.95, FaceWidth=15.0)])
def test_new_jobs_for_other_gears_are_valid_and_two_stage_only_when_it_pays(wb, gear):
    result = wb.validation.validate(_new_job(wb, **gear))
    assert result.ok, result.messages
    plan = plan_cam(result.job)
    if plan.two_stage is not None:
        assert plan.two_stage.two_stage_time_s <= 0.9 * plan.two_stage.bottom_tool_alone_time_s
    finishing_d = result.job.tools.finishing.diameter_mm
    assert result.job.roughing.flank_allowance_mm <= 0.15 * finishing_d + 1e-9


def test_long_roughing_advice_offers_two_stage_and_no_larger_tool_at_its_limit(wb):
    s = wb.summary
    long_rough = s.PlanFigures(s.OperationFigures(10, 9 * 3600.0, 9 * 3600.0, 5), None)
    at_limit = s.long_job_advice(long_rough, "generating", roughing_room_mm=0.05)
    assert "larger roughing tool" not in at_limit and "two-stage roughing" in at_limit
    two_stage = s.PlanFigures(s.OperationFigures(10, 9 * 3600.0, 9 * 3600.0, 5), None, (),
                              s.OperationFigures(10, 600.0, 600.0, 5))
    advice = s.long_job_advice(two_stage, "generating", roughing_room_mm=2.0)
    assert "two-stage" not in advice and "larger roughing tool" in advice
    assert advice.startswith("Long job: 9 h 10 min, of which roughing 9 h 00 min")


@pytest.mark.parametrize(("section", "key", "value", "title"), [
    ("gear", "module_mm", -3.0, "Module"), ("gear", "teeth", 2, "Teeth"),
    ("gear", "profile_shift_coefficient", 2.0, "Profile shift coefficient x"),
    ("gear", "rack_tip_radius_mm", 5.0, "Rack tip radius"), ("gear", "bore_diameter_mm", 200.0, "Bore diameter"),
    ("gear", "face_width_mm", float("nan"), "Face width"), ("stock", "radial_allowance_mm", -1.0, "Radial allowance"),
])
def test_an_object_s_error_is_one_sentence_with_the_field_s_title_and_unit(wb, section, key, value, title):
    from spur_cad.errors import SpurCadError
    from spur_cad.job import job_from_dict

    data = {"gear": {"teeth": 23, "module_mm": 4.0, "face_width_mm": 20.0, "rack_tip_radius_mm": 1.52}}
    data.setdefault(section, {})[key] = value
    with pytest.raises(SpurCadError) as caught:
        job_from_dict(data, "doc.FCStd")
    text = wb.validation.sentence(caught.value, "doc.FCStd")
    assert text.startswith(f"{title} ") or text.startswith(f"{title}:"), text
    assert text.endswith(".") and ". " not in text[:-1] and "\n" not in text, text
    assert not KEY_NAME.search(text) and "[" + section + "]" not in text and "doc.FCStd" not in text, text
    if key.endswith("_mm") and value == value:  # a length: its unit is said (NaN has none)
        assert " mm" in text, text


def test_three_axes_are_checked_as_the_3_axis_plan_checks_them(wb):
    """axes = 3: the flat end mill's rules (at the finishing tool's kind), not the rotary table's tool limits (a
    roughing tool wider than the space at the root is fine: it roughs around the gear)."""
    values = wb.schema.values_from_job(parse_job(small_job_text(), "small.toml"))
    values["gear"].update(Teeth=23, Module=4.0, FaceWidth=20.0, RackTipRadius=0.8)
    values["job"].update(MachineAxes=3, FinishingToolKind="bull_nose", FinishingCornerRadius=0.3,
                         FinishingToolDiameter=2.0, RoughingToolDiameter=6.0)
    result = wb.validation.validate(values, "flat")
    assert [(p.prop, p.group) for p in result.problems] == [("FinishingToolKind", "Finishing tool")]
    assert "flat end mill" in result.problems[0].advice
    values["job"].update(FinishingToolKind="flat", FinishingCornerRadius=0.0)
    assert wb.validation.validate(values, "flat").ok
    values["job"]["MachineAxes"] = 4  # the same 6 mm roughing tool on the rotary table: too wide for the space
    assert not wb.validation.validate(values, "table").ok


def test_the_modification_summary_names_the_amounts_of_each_table(wb):
    gear = wb.schema.default_values()["gear"]
    assert wb.summary.modification_summary(gear) == "none"
    gear.update(TipRelief=15.0, TipReliefStartDiameter=96.0, LeftFlankOwnValues=True, LeftEndRelief=4.0,
                LeftEndReliefLength=2.0)
    assert wb.summary.modification_summary(gear) == "tip relief 15 \u00b5m; left flank: end relief 4 \u00b5m"
    assert wb.summary.group_summary("3-axis", {"MachineAxes": 4}) == ""  # its fields are off
    assert wb.summary.group_summary("Machine", {"MachineName": "VMC", "MachineAxes": 3}) == "VMC, 3 axes"
    assert wb.summary.group_summary("3-axis", {"MachineAxes": 3, "HoldingTabs": 3}) == "3 holding tabs"
    # the mate only when the job designs against one (off: the basic rack, as the switch's own text says)
    assert wb.summary.group_summary("Mate", {"UseMate": False, "MateTeeth": 40}) == "none: basic rack"
    assert wb.summary.group_summary("Mate", {"UseMate": True, "MateTeeth": 40}) == "z 40"
    assert wb.summary.group_summary("Mate", {"UseMate": True, "MateTeeth": 60, "MateInternal": True,
                                             "MateCentreDistance": 40.0}) == "z 60 ring, a 40 mm"


@pytest.mark.parametrize("resolution_mm", [0.0001, 0.2, float("nan")])
def test_simulate_refuses_a_resolution_out_of_range_when_its_settings_are_made(wb, resolution_mm):
    """The resolution the Simulate command asks for is checked when the [simulation] section is made (its
    __post_init__), naming the key, before anything is simulated (the plan is not looked at)."""
    from spur_cad.errors import SimulationError

    job = parse_job(small_job_text(), "small.toml")
    with pytest.raises(SimulationError, match=r"\[simulation\] resolution_mm must") as raised:
        wb.simulation.simulate_job(job, None, resolution_mm)
    assert raised.value.field == "resolution_mm"
