"""report.html: one self-contained page (images as base64 data URIs, inline CSS, no scripts, no links out), made
from a Jinja2 template: spur_cad's own (report/templates/report.html.j2) or a shop's copy named in the job file
([job] report_template). The template receives every value already labelled and formatted with its unit
(spur_cad.report.sheet) and the typed result itself; it runs in Jinja2's sandbox with HTML escaping on.
Sections a job does not have (no tools, no simulation, no post) are left out or say so.
"""

from __future__ import annotations

import base64
from importlib import resources
from typing import TYPE_CHECKING

from spur_cad.cam.plan import REFERENCE_CONTACT_SPACING_MM, REFERENCE_STATION_STEP_MM
from spur_cad.cam.strategies import COMPARISON_STRATEGY, get_strategy
from spur_cad.cam.three_axis import ThreeAxisFinishingFacts
from spur_cad.dependencies import require_jinja2
from spur_cad.errors import SpurCadError, one_line
from spur_cad.report import sheet
from spur_cad.report.job_file import job_file_tables
from spur_cad.report.pair import NO_MATE_NOTE, pair_rows
from spur_cad.report.sheet import Table, duration, number

if TYPE_CHECKING:
    from spur_cad.report.template_bounds import TemplateLimits
    from spur_cad.result import FinishingFacts, JobResult, RoughingFacts

TEMPLATE_NAME = "report.html.j2"


class ReportTemplateError(SpurCadError, ValueError):
    """A report template that cannot be compiled or rendered (the message names the template and the line)."""


def default_template_text() -> str:
    """spur_cad's own report template (a file a shop can copy and adapt)."""
    return resources.files("spur_cad.report").joinpath("templates", TEMPLATE_NAME).read_text(encoding="utf-8")


def compile_template(text: str, source: str = TEMPLATE_NAME, limits: TemplateLimits | None = None):
    """The template compiled in Jinja2's sandbox, bounded (spur_cad.report.template_bounds: autoescaped, undefined
    names are errors, its loops, calls, values and output counted when it renders); a syntax error (or a template
    nested too deeply to compile) is a ReportTemplateError naming `source` and the template's line. Without Jinja2
    installed: what to install."""
    require_jinja2()
    import jinja2

    from spur_cad.report.template_bounds import BoundedSandbox, TemplateLimits, TemplateTooDeepError

    environment = BoundedSandbox(limits or TemplateLimits())
    try:
        return environment.bounded_template(text)
    except jinja2.TemplateSyntaxError as exc:
        raise ReportTemplateError(one_line(f"{source}:{exc.lineno}: not a valid report template: {exc.message}"),
                                  field="report_template", section="job") from None
    except TemplateTooDeepError as exc:  # nested past what Jinja2's parser or Python's compiler takes
        raise ReportTemplateError(one_line(f"{source}{f':{exc.line}' if exc.line else ''}: not a valid report "
                                           f"template: {exc}"), field="report_template", section="job") from None
    except (SyntaxError, ValueError, OverflowError) as exc:  # e.g. a number literal of thousands of digits
        raise ReportTemplateError(one_line(f"{source}: not a valid report template: {type(exc).__name__}: {exc}"),
                                  field="report_template", section="job") from None


NOT_ESTIMATED = ("not estimated (too large to build for comparison, the tool does not fit that strategy, or the "
                 "strategy is for spur gears only)")


def finishing_comparison(finish: FinishingFacts) -> Table:
    """This job's finishing beside perimeter finishing and the reference process's strategy (same tool)."""
    reference = (f"reference process's strategy (perimeter, {number(REFERENCE_CONTACT_SPACING_MM, 2)} mm contacts, "
                 f"{number(REFERENCE_STATION_STEP_MM, 2)} mm X step)")
    own = finish.estimate
    rows = [(f"this job's finishing ({finish.strategy})", f"{own.moves:,}", duration(own.time_s),
             duration(own.time_with_acceleration_s))]
    others = [(finish.perimeter, "perimeter finishing at this job's target scallop")] \
        if finish.strategy != COMPARISON_STRATEGY else []
    others.append((finish.reference_strategy, reference))
    for other, label in others:
        if other is None:
            rows.append((label, "-", NOT_ESTIMATED, "-"))
        else:
            rows.append((label, f"{other.moves:,}", duration(other.time_s), duration(other.time_with_acceleration_s)))
    return Table(("finishing (same tool)", "moves", "time at feed", "with acceleration"), tuple(rows))


def program_notes(result: JobResult) -> tuple[str, ...]:
    """Sentences on the roughing levels, two-stage roughing and the finishing strategy's own facts."""
    rough, finish = result.roughing, result.finishing
    notes = []
    if rough is not None:
        tips = (f"; {len(rough.tip_heights_mm)} over each tip land, down to "
                f"{number(rough.tip_heights_mm[-1], 3)} mm from the axis" if rough.tip_heights_mm else "")
        if rough.passes_per_space is not None:
            turns = ", ".join(number(abs(turn), 1) for turn in rough.flank_turns_deg)
            notes.append(f"Roughing by flanks: {rough.passes_per_space} passes per space, A turned by +-({turns}) "
                         f"deg to the flank segments, down to {number(rough.lowest_level_height_mm, 3)} mm above "
                         f"the root circle{tips}.")
        else:  # by levels, in the set-up's words
            notes.append(sheet.machine_setup(result).levels_roughing_note.format(
                levels=rough.levels_per_space, lowest_above_root_mm=number(rough.lowest_level_height_mm, 3),
                lowest_z_mm=number(min(rough.level_heights_mm), 3) if rough.level_heights_mm else "-", tips=tips))
        stage = rough.two_stage
        if stage is not None and stage.bottom.passes_per_space is not None:
            larger = result.tools.roughing
            if larger is None:  # never: two-stage roughing is planned with the job's roughing tool
                raise ValueError("two-stage roughing without a roughing tool")
            notes.append(f"Two-stage roughing by flanks: the larger tool (T{larger.tool_number}, D "
                         f"{number(larger.diameter_mm, 3)} mm) down to {number(stage.split_height_above_root_mm, 3)} "
                         f"mm above the root circle, then the smaller (T{stage.bottom_tool.tool_number}, D "
                         f"{number(stage.bottom_tool.diameter_mm, 3)} mm) takes what it leaves, "
                         f"{stage.bottom.passes_per_space} passes per space: {duration(stage.two_stage_time_s)} in "
                         f"all, {duration(stage.time_saved_s)} less than the smaller tool alone "
                         f"({duration(stage.bottom_tool_alone_time_s)}).")
        elif stage is not None:
            notes.append(f"Two-stage roughing: the bottom tool (T{stage.bottom_tool.tool_number}, D "
                         f"{number(stage.bottom_tool.diameter_mm, 3)} mm) roughs {stage.bottom.levels_per_space} "
                         f"levels per space below {number(stage.split_height_above_root_mm, 3)} mm above the root "
                         "circle "
                         f"(split chosen by {stage.split_chosen_by}): {duration(stage.two_stage_time_s)} in all, "
                         f"{duration(stage.time_saved_s)} less than the bottom tool alone "
                         f"({duration(stage.bottom_tool_alone_time_s)}).")
        declined = rough.two_stage_declined
        if declined is not None:
            notes.append(f"Two-stage roughing with the larger tool (T{declined.roughing_tool.tool_number}, D "
                         f"{number(declined.roughing_tool.diameter_mm, 3)} mm) over the upper part would take "
                         f"{duration(declined.two_stage_time_s)}, "
                         f"{duration(declined.two_stage_time_s - declined.bottom_tool_alone_time_s)} more than the "
                         f"smaller tool alone ({duration(declined.bottom_tool_alone_time_s)}): roughing uses the "
                         "smaller tool alone, the quicker of the two.")
        suggested = rough.two_stage_suggested
        if suggested is not None:
            notes.append(f"A D {number(suggested.top_tool_diameter_mm, 3)} mm top tool would save "
                         f"{duration(suggested.roughing_tool_alone_time_s - suggested.two_stage_time_s)} of roughing "
                         f"({duration(suggested.roughing_tool_alone_time_s)} -> "
                         f"{duration(suggested.two_stage_time_s)}): name it [tools.roughing_top] (two-stage "
                         "roughing by flanks, the same cutting data).")
        notes.extend(strategy_notes(rough))
    if finish is not None:
        notes.append(finish.report_text)
    return tuple(notes)


def strategy_notes(rough: RoughingFacts) -> list[str]:
    """Sentences on the roughing strategy not used: the other strategy when it would save a tenth of the time (by
    flanks for a job by levels, by levels for one by flanks), and why a job file's default flank roughing fell back
    to levels."""
    notes = []
    by_flanks = rough.flank_suggested
    if by_flanks is not None:
        notes.append(f"Roughing by flanks ([roughing] strategy = \"flank\", the same tool and cutting data, "
                     f"{by_flanks.passes_per_space} passes per space) would take "
                     f"{duration(by_flanks.flank_time_s)} instead of {duration(by_flanks.levels_time_s)} "
                     "by levels, "
                     f"{duration(by_flanks.levels_time_s - by_flanks.flank_time_s)} less.")
    by_levels = rough.levels_suggested
    if by_levels is not None:
        notes.append(f"Roughing by levels ([roughing] strategy = \"levels\", the same tool and cutting data, "
                     f"{by_levels.levels_per_space} levels per space) would take "
                     f"{duration(by_levels.levels_time_s)} instead of {duration(by_levels.flank_time_s)} "
                     f"by flanks, {duration(by_levels.flank_time_s - by_levels.levels_time_s)} less.")
    if rough.flank_fallback is not None:
        notes.append("Roughing by levels: the job leaves [roughing] strategy to its default, roughing by flanks, "
                     f"which cannot take this gear with these tools ({rough.flank_fallback}).")
    return notes


def _image_uri(png: bytes | None) -> str:
    return f"data:image/png;base64,{base64.b64encode(png).decode('ascii')}" if png else ""


def _tool_reach_note(result: JobResult) -> str:
    """A 3-axis finish whose flat end mill cannot follow the generated fillet: the root's leftover is the tool's
    reach (expected, the design's fillet being tighter than the tool), not a flank error; '' otherwise."""
    finish = result.finishing
    facts = finish.strategy_facts if finish is not None else None
    if not isinstance(facts, ThreeAxisFinishingFacts) or \
            abs(facts.form_diameter_mm - facts.rack_form_diameter_mm) < 1e-6:
        return ""
    root = [f.max_leftover_mm for f in result.simulation.per_feature if f.feature.endswith(("fillet", "root"))]
    generated = f"{facts.generated_by}-generated"
    graded = (f"the involute it cuts is graded from diameter {number(facts.form_diameter_mm, 3)} mm")
    if result.mate is not None:  # the mate's SAP nearer the tip than the tool's form diameter: graded from there
        sap, ring = result.mate.start_of_active_profile_diameter_mm, result.kind.has_rim
        if (sap < facts.form_diameter_mm) if ring else (sap > facts.form_diameter_mm):
            graded = (f"the involute is graded from the mate's start of active profile, diameter {number(sap, 3)} mm "
                      f"({'outside' if ring else 'below'} it the flank need not be exact)")
    return (f" The leftover in the root ({number(1000 * max(root, default=0.0), 1)} {sheet.MICRO} at most) and on "
            f"the involute between diameters {number(facts.form_diameter_mm, 3)} and "
            f"{number(facts.rack_form_diameter_mm, 3)} mm is where the D {number(2 * facts.tool_radius_mm, 3)} mm "
            f"flat end mill cannot reach (the {generated} fillet is tighter than its radius), as planned: expected, "
            f"not a flank error; {graded}.")


def report_context(result: JobResult, images: dict[str, bytes]) -> dict:
    """What the template receives: labelled, formatted values (spur_cad.report.sheet), the images as data URIs,
    and the typed result itself (`result`)."""
    sim, grading = result.simulation, result.grading
    verdict = ""
    worst = sim.worst_leftover
    if sim.enabled and worst is not None:  # a simulation's largest leftover has its place
        within = sim.max_gouge_mm <= sim.resolution_mm
        verdict = (f"Largest gouge {number(1000 * sim.max_gouge_mm, 1)} {sheet.MICRO} "
                   f"({'within' if within else 'beyond'} the resolution). Largest leftover "
                   f"{number(1000 * sim.max_leftover_mm, 1)} {sheet.MICRO} at tooth space {worst.space}, "
                   f"{worst.feature}, X = {number(worst.x_mm, 3)} mm.") + _tool_reach_note(result)
    return {
        "title": f"spur_cad report: {result.job.name}", "job": result.job, "version": result.version,
        "dialect": result.post.dialect, "folded": result.post.folded, "result": result,
        "warnings": sheet.warning_lines(result), "setup_rows": sheet.setup_rows(result),
        "totals_rows": sheet.totals_rows(result), "operation_table": sheet.operation_table(result),
        "tool_table": sheet.tool_table(result), "gear_rows": sheet.gear_rows(result),
        "pair_rows": pair_rows(result), "no_mate_note": NO_MATE_NOTE if result.pair is None else "",
        "helical": result.kind.measured_in == "normal", "inspection_rows": sheet.inspection_rows(result),
        "expected_tolerance": sheet.expected_tolerance(result), "limit_rows": sheet.limit_rows(result),
        "advice_rows": sheet.advice_rows(result), "advice_strategy": result.tools.advice_strategy,
        "program_table": sheet.program_table(result),
        # the comparison strategy is a rotary-table strategy: none for a gear lying flat
        "finishing_comparison": finishing_comparison(result.finishing) if result.finishing is not None
        and sheet.machine_setup(result).accepts_strategy(get_strategy(COMPARISON_STRATEGY)) else None,
        "program_notes": program_notes(result), "simulation_rows": sheet.simulation_rows(result),
        "gouge_within_resolution": (not sim.enabled) or sim.max_gouge_mm <= sim.resolution_mm,
        "simulation_verdict": verdict, "feature_table": sheet.feature_table(result),
        "grading_table": sheet.grading_table(result),
        "modifications_cut_table": sheet.modifications_cut_table(result),
        "correction": result.correction, "correction_table": sheet.correction_table(result.correction),
        "correction_notes": sheet.correction_notes(result.correction),
        "error_budget_text": sheet.error_budget_text(result),
        "overall_class": (grading.overall_class or "beyond 11") if grading is not None else "",
        "grading_validity": "; ".join(grading.validity) if grading is not None and grading.validity else "",
        "job_file": job_file_tables(result.job_file),
        "images": {name: _image_uri(images.get(name)) for name in ("profile", "modifications", "roughing", "finishing",
                                                                  "deviation", "engagement", "kchart")},
    }


def render_report(result: JobResult, images: dict[str, bytes], template_text: str | None = None,
                  template_source: str = TEMPLATE_NAME, limits: TemplateLimits | None = None) -> bytes:
    """The whole report as UTF-8 HTML bytes, from `template_text` (default: spur_cad's own template). `images`:
    'profile', 'roughing', 'finishing', 'deviation', 'kchart' PNGs. A template that fails while rendering (an
    unknown name, a division by zero) or passes one of its `limits` (TemplateLimits: time, size of the page and of
    its values, loops, recursion) is a ReportTemplateError naming it and its line. A job with flank modifications
    adds 'modifications' (their chart)."""
    import jinja2

    template = compile_template(default_template_text() if template_text is None else template_text,
                                template_source, limits)
    try:
        text = template.environment.bounded_render(template, report_context(result, images))
    except (jinja2.TemplateError, TypeError, ValueError, AttributeError, LookupError, ArithmeticError,
            RecursionError, MemoryError) as exc:
        from spur_cad.report.template_bounds import TemplateBoundError

        line = _template_line(exc)
        if isinstance(exc, TemplateBoundError):
            reason = f"passed its bounds (docs/report.md): {exc}"
        elif isinstance(exc, MemoryError):  # no bound should let it happen; its own text is empty
            reason = ("failed: it ran out of memory (MemoryError) making a value; a value is bounded at "
                      f"{template.environment.limits.value_size:,} characters or elements (docs/report.md)")
        else:
            named = isinstance(exc, (RecursionError, MemoryError, ArithmeticError))  # their text alone says little
            reason = f"failed: {type(exc).__name__ + ': ' if named else ''}{exc}"
        raise ReportTemplateError(one_line(f"[job] report_template: {template_source}{f':{line}' if line else ''}: "
                                           f"the report template {reason}"), field="report_template",
                                  section="job") from None
    return text.encode("utf-8")


def _template_line(exc: BaseException) -> int | None:
    """The template line an error was raised at (Jinja2 compiles templates to code named <template>)."""
    tb = exc.__traceback__
    line = None
    while tb is not None:
        if tb.tb_frame.f_code.co_filename == "<template>":
            line = tb.tb_lineno
        tb = tb.tb_next
    return line
