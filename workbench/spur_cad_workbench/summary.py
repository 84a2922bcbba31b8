"""What the task panel's summary says (plain Python, no FreeCAD): cycle times by both estimators, moves,
program lines, the tool limits, and advice when a job is long.

The figures need a plan (seconds for a large gear), so the panel shows them from the job's last
recompute while the panel's values equal the job's (`values_signature`), and plans the panel's
values only when the user asks (Plan) or on OK; the tool limits come from the cheap checks.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from spur_cad.cam.setups import ROTARY_TABLE, SETUPS, MachineSetup
from spur_cad_workbench.schema import OPERATION_TITLES, job_data

OPERATION_NAMES = {"roughing": "Roughing", "roughing_bottom": "Roughing the bottom (bottom tool)",
                   "finishing": "Finishing"}
LONG_JOB_S = 8 * 3600.0  # a shift: longer jobs get advice on what would shorten them
ROUGHING_ROOM_MM = 0.1  # a roughing tool within this of its limit is at its limit (tools come in 0.1 mm steps)


@dataclass(frozen=True)
class OperationFigures:
    """One program's figures: moves, estimated seconds (programmed feeds; with the machine's accelerations)
    and program lines as posted."""

    moves: int
    seconds: float
    seconds_with_acceleration: float
    program_lines: int


@dataclass(frozen=True)
class PlanFigures:
    """The figures of a planned job, by program (None: the job has no such program; `roughing_bottom`: the
    bottom tool's program of two-stage roughing), and its warnings."""

    roughing: OperationFigures | None
    finishing: OperationFigures | None
    warnings: tuple[str, ...] = ()
    roughing_bottom: OperationFigures | None = None

    def operations(self) -> list[tuple[str, OperationFigures]]:
        """(program name, figures) in cutting order, the programs the job has."""
        return [(name, figures) for name in OPERATION_TITLES if (figures := getattr(self, name)) is not None]

    @property
    def seconds(self) -> float:
        return sum(figures.seconds for _, figures in self.operations())

    @property
    def seconds_with_acceleration(self) -> float:
        return sum(figures.seconds_with_acceleration for _, figures in self.operations())


def values_signature(values: dict[str, dict[str, object]]) -> str:
    """A fingerprint of the job the values describe (the job file's data): equal values, equal signature."""
    text = json.dumps(job_data(values), sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def plan_figures(job, plan) -> PlanFigures:
    """Figures of a spur_cad CamPlan for `job`; posts the programs to count their lines."""
    from spur_cad.pipeline import build_programs

    programs, _ = build_programs(job, plan)
    found = {}
    for name in OPERATION_TITLES:
        planned = getattr(plan, name)
        if planned is not None:
            found[name] = OperationFigures(int(planned.estimate.moves), float(planned.estimate.time_s),
                                           float(planned.estimate.time_with_acceleration_s),
                                           int(programs[name].lines))
    return PlanFigures(found.get("roughing"), found.get("finishing"), tuple(plan.warnings),
                       found.get("roughing_bottom"))


def duration_text(seconds: float) -> str:
    """'2 h 05 min', '14 min', '40 s'."""
    if seconds < 60.0:
        return f"{seconds:.0f} s"
    minutes = round(seconds / 60.0)
    hours, minutes = divmod(minutes, 60)
    return f"{hours} h {minutes:02d} min" if hours else f"{minutes} min"


def figures_text(figures: PlanFigures) -> str:
    """Cycle time (with accelerations, and at the programmed feeds), then per operation: time, moves, lines."""
    if not figures.operations():
        return "No program: choose a roughing or finishing tool."
    lines = [f"Cycle time {duration_text(figures.seconds_with_acceleration)} with the machine's accelerations "
             f"({duration_text(figures.seconds)} at the programmed feeds)"]
    for name, op in figures.operations():
        lines.append(f"{OPERATION_NAMES[name]}: {duration_text(op.seconds_with_acceleration)}, {op.moves:,} moves, "
                     f"{op.program_lines:,} program lines")
    return "\n".join(lines)


def limits_text(rec, with_roughing_limit: bool = True, two_stage: bool = False, units=None) -> str:
    """The tool limits of the gear (spur_cad.cam.recommend.ToolRecommendations), one line each, lengths in the
    user's unit schema (units.py); without the roughing diameter when it would derive from an invalid finishing
    tool (its plunge allowance); with `two_stage` that limit is the bottom tool's."""
    from spur_cad_workbench.units import text

    if rec is None:
        return ""

    def length(value_mm: float) -> str:
        return text(value_mm, "mm", units)

    deepest = "Bottom tool" if two_stage else "Roughing tool"
    roughing = f"{deepest}: D at most {length(rec.roughing_max_diameter_mm)}\n" if with_roughing_limit else ""
    return (f"{roughing}"
            f"Finishing tool: corner radius at most {length(rec.finishing_max_corner_radius_mm)}, flat D - 2 r at "
            f"most {length(rec.finishing_max_flat_width_mm)} (perimeter, along X)\n"
            f"Both: flute length at least {length(rec.required_flute_length_mm)}, stick-out at least "
            f"{length(rec.required_stick_out_mm)}")


def long_job_advice(figures: PlanFigures, strategy: str, roughing_room_mm: float | None = None) -> str:
    """Empty for a job within LONG_JOB_S; else which operation takes the time and what would shorten it.
    `roughing_room_mm`: how much larger the roughing tool may be (its limit minus its diameter; None unknown):
    a tool at its limit is not advised to grow."""
    total = figures.seconds_with_acceleration
    if total <= LONG_JOB_S or not figures.operations():
        return ""
    name, op = max(figures.operations(), key=lambda item: item[1].seconds_with_acceleration)
    if name == "finishing":
        from spur_cad.cam.strategies import DEFAULT_STRATEGY, get_strategy

        ways = "a larger target scallop, a larger finishing tool (within its limits)"
        if strategy != DEFAULT_STRATEGY:  # the default is the fastest strategy the registry has
            ways += f", or the {DEFAULT_STRATEGY} strategy ({get_strategy(DEFAULT_STRATEGY).description})"
    else:
        options = []
        if roughing_room_mm is None or roughing_room_mm >= ROUGHING_ROOM_MM:
            options.append("a larger roughing tool (within its limit)")
        if figures.roughing_bottom is None:
            options.append("two-stage roughing (a larger tool for the upper levels, this one as the bottom tool)")
        ways = ", ".join(options + ["a larger level depth or step-over, a higher feed per tooth"])
    return (f"Long job: {duration_text(total)}, of which {OPERATION_NAMES[name].lower()} "
            f"{duration_text(op.seconds_with_acceleration)}. Shorter with {ways}.")


GROUP_SUMMARY_CHARS = 60
"""A folded group's header shows its state in at most this many characters (it fits the default task dock)."""


def _tool_summary(job: dict, role: str, units) -> str:
    """'T1 flat D 4 mm', 'T2 bull-nose D 3.35 mm' (lengths in the user's unit schema) or 'not used'."""
    from spur_cad_workbench.units import text

    if not job.get(f"Use{role}Tool"):
        return "not used"
    diameter = text(float(job.get(f"{role}ToolDiameter", 0.0)), "mm", units)
    kind = str(job.get(f"{role}ToolKind", "")).replace("_", "-")
    return f"T{job.get(f'{role}ToolNumber', '')} {kind} D {diameter}"


def modification_summary(gear: dict[str, object]) -> str:
    """The gear's flank modification amounts in a few words ('tip relief 15 um, lead crowning 8 um; right flank:
    tip relief 20 um'); 'none' without an amount. `gear`: the gear's property values."""
    from spur_cad_workbench.schema import FIELDS, MODIFICATION_SWITCHES, MODIFICATIONS, modification_tables, title

    parts = []
    for table in modification_tables(gear):
        amounts = [f"{title(field).lower().removeprefix(table.rsplit('.', 1)[1] + ' ')} {gear[field.prop]:g} \u00b5m"
                   for field in FIELDS["gear"] if field.section == table and field.key.endswith("_um")
                   and gear[field.prop]]
        side = "" if table == MODIFICATIONS else f"{MODIFICATION_SWITCHES[table].group.split(': ')[1]}: "
        parts.append(side + (", ".join(amounts) or "none"))
    return "; ".join(parts) or "none"


def machine_setup(job: dict[str, Any]) -> MachineSetup:
    """The set-up the panel's MachineAxes chooses (spur_cad.cam.setups; the rotary table for a value none has, as
    the job file's loader would refuse it)."""
    return SETUPS.get(int(job.get("MachineAxes", ROTARY_TABLE.axes)), ROTARY_TABLE)


def _three_axis_summary(job: dict[str, Any], units=None) -> str:
    """The folded "3-axis" group: how a through-cut gear is held; nothing on the rotary table (its fields are off)."""
    from spur_cad_workbench.units import text as length_text

    if not machine_setup(job).reads_section("three_axis"):
        return ""
    if int(job.get("HoldingTabs", 0)):
        return f"{job['HoldingTabs']} holding tabs"
    if float(job.get("OnionSkin", 0.0)):
        return f"onion skin {length_text(float(job['OnionSkin']), 'mm', units)}"
    return "cut through, no tabs"


def _mate_summary(job: dict[str, Any], units=None) -> str:
    """The folded "Mate" group: the mating gear when the job designs against one ("z 40", "z 60 ring, a 40 mm");
    "none: basic rack" when it does not (the checks then assume the basic rack, as the report says)."""
    from spur_cad_workbench.units import text as length_text

    if not job.get("UseMate"):
        return "none: basic rack"
    text = f"z {int(job.get('MateTeeth', 0))}" + (" ring" if job.get("MateInternal") else "")
    centre_mm = float(job.get("MateCentreDistance", 0.0))
    return text + (f", a {length_text(centre_mm, 'mm', units)}" if centre_mm > 0.0 else "")


# The groups whose summary is one property's value or state
_SWITCH_SUMMARIES: dict[str, Callable[[dict[str, Any]], str]] = {
    "Job": lambda job: str(job.get("JobName", "")),
    "Post": lambda job: str(job.get("PostDialect", "")),
    "Simulation": lambda job: "on" if job.get("SimulationEnabled") else "off",
    "Lathe": lambda job: "program written" if job.get("WriteLatheProgram") else "no program",
    "Probe": lambda job: "program written" if job.get("WriteProbeProgram") else "no program",
}


def group_summary(group: str, job: dict[str, Any], units=None) -> str:
    """What a folded group of the job panel holds, in a few words ('T1 flat D 4 mm', 'generating, scallop
    5 um'; lengths in the user's unit schema, `units` = FreeCAD.Units, None for mm); '' for groups without one.
    Cut at GROUP_SUMMARY_CHARS with an ellipsis."""
    from spur_cad_workbench.units import text as length_text

    tools = {"Roughing tool": "Roughing", "Finishing tool": "Finishing", "Bottom tool": "Bottom"}
    if group in tools:
        text = _tool_summary(job, tools[group], units)
    elif group == "Finishing strategy":
        scallop = length_text(float(job.get("TargetScallop", 0.0)), "mm", units)
        text = f"{job.get('FinishingStrategy', '')}, scallop {scallop}"
    elif group == "Roughing strategy":
        text = (f"{job.get('RoughingStrategy', '')}, flank allowance "
                f"{length_text(float(job.get('FlankAllowance', 0.0)), 'mm', units)}")
    elif group == "Machine":
        text = str(job.get("MachineName", "")) + machine_setup(job).machine_summary
    elif group == "3-axis":
        text = _three_axis_summary(job, units)
    elif group in _SWITCH_SUMMARIES:
        text = _SWITCH_SUMMARIES[group](job)
    elif group == "2-D export":
        formats = [name for name, prop in (("DXF", "ExportDxf"), ("SVG", "ExportSvg")) if job.get(prop)]
        offset = length_text(float(job.get("ExportOffset", 0.0)), "mm", units)
        text = f"{' + '.join(formats)}, offset {offset}" if formats else "not written"
    elif group == "Mate":
        text = _mate_summary(job, units)
    else:
        return ""
    return text if len(text) <= GROUP_SUMMARY_CHARS else text[:GROUP_SUMMARY_CHARS - 1].rstrip() + "\u2026"
