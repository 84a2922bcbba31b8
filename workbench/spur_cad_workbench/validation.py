"""Checks of a job's property values for the task panel, and tool suggestions (plain Python, no FreeCAD).

`validate` runs the same checks as the command line (spur_cad.job.job_from_dict, then the
tool limits and the roughing reach of spur_cad.cam.recommend) and files each SpurCadError
message under the panel group it is about, so the panel shows it beside the fields. What people read
(`sentence`, `advice`, the notes) names fields by their titles, never by job-file keys, and gives lengths and
feeds in the user's unit schema (units.py; `units` is FreeCAD.Units, None: the job file's mm).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import TYPE_CHECKING

from spur_cad.errors import SpurCadError
from spur_cad_workbench import units as unit_text
from spur_cad_workbench.schema import TOOL_SWITCHES, job_data

if TYPE_CHECKING:
    from spur_cad.job import Job

# Panel groups (the property groups of schema.JOB_FIELDS, plus the gear and stock objects).
SECTION_GROUPS = {"tools.roughing": "Roughing tool", "tools.finishing": "Finishing tool", "tools.bottom": "Bottom tool",
                  "roughing": "Roughing strategy", "finishing": "Finishing strategy", "machine": "Machine",
                  "post": "Post", "job": "Job", "gear": "Gear", "stock": "Stock", "simulation": "Simulation"}
_SECTION_RE = re.compile(
    r"\[(tools\.roughing|tools\.finishing|tools\.bottom|roughing|finishing|machine|post|job|gear|stock|simulation)\]")


@dataclass(frozen=True)
class Problem:
    """One invalid input: the panel group and property it is about (None: no single property), the command
    line's message (without the job's source) and the same as advice for people (what to change)."""

    group: str
    prop: str | None
    message: str
    advice: str


@dataclass(frozen=True)
class Validation:
    """Outcome of checking a job: the Job when valid, the problems (at most one: the first the command line
    finds), recommendations when known."""

    job: Job | None
    problems: tuple[Problem, ...]
    recommendations: object | None

    @property
    def ok(self) -> bool:
        return self.job is not None and not self.problems

    @property
    def messages(self) -> dict[str, str]:
        """{panel group: the command line's message}."""
        return {problem.group: problem.message for problem in self.problems}


def group_of(message: str) -> str:
    """Panel group a job_from_dict or tool-check message is about."""
    found = _SECTION_RE.search(message)
    if found:
        return SECTION_GROUPS[found.group(1)]
    if "invalid gear" in message:
        return "Gear"
    for role in ("roughing", "finishing"):
        if message.startswith(f"{role} "):
            return SECTION_GROUPS[f"tools.{role}"]
    return "Job"


def _strip_source(message: str, source: str) -> str:
    prefix = f"{source}: "
    return message.removeprefix(prefix)


def field_of(section: str | None, key: str | None):
    """The schema Field holding job-file key `key` of `section` (None when either is unknown)."""
    from spur_cad_workbench.schema import FIELDS

    if not section or not key:
        return None
    return next((field for fields in FIELDS.values() for field in fields
                 if field.section == section and field.key == key), None)


def _with_titles(text: str, section: str) -> str:
    """`text` with the job-file key names of `section` replaced by the panel's titles."""
    from spur_cad_workbench.schema import FIELDS, title

    for fields in FIELDS.values():
        for field in fields:
            if field.section == section and field.key:
                text = re.sub(rf"\b{re.escape(field.key)}\b", title(field).lower(), text)
    return text


_ROUGHING_LIMIT = re.compile(r"roughing tool diameter ([\d.]+) mm exceeds roughing_max_diameter_mm = ([\d.]+) mm")
_CORNER_LIMIT = re.compile(r"corner_radius_mm = ([\d.]+) must be in \(0, ([\d.]+)\)")
_TIP_MODE_LIMIT = re.compile(r"largest diameter for tip mode with this corner radius: ([\d.]+) mm")


_GOT_NUMBER = re.compile(r"got (-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?)$")
_UNITS_IN_MESSAGES = ("mm", "mm/min", "mm/rev", "mm/s^2")


def _with_unit(body: str, field) -> str:
    """'... got -3' -> '... got -3 mm' when the field's unit is a length or feed (converted with the others)."""
    if field is None or field.unit not in _UNITS_IN_MESSAGES:
        return body
    return _GOT_NUMBER.sub(lambda found: f"got {found.group(1)} {field.unit}", body)


def advice(message: str, section: str | None, key: str | None, values: dict | None = None, units=None) -> str:
    """The message as the panel says it: the group, then what to change ("Finishing tool: diameter at most
    3.55 mm for a corner radius of 1.52 mm ..."), with key names replaced by the field titles and lengths in
    the user's unit schema."""
    return unit_text.message(_advice(message, section, key, values), units)


def _advice(message: str, section: str | None, key: str | None, values: dict | None) -> str:
    from spur_cad_workbench.schema import title

    group = SECTION_GROUPS.get(section or "", group_of(message))
    field = field_of(section, key)
    body = _with_unit(re.sub(r"^\[[a-z.]+\] ", "", message), field)
    found = _ROUGHING_LIMIT.search(message)
    if found:
        return (f"{group}: diameter at most {float(found.group(2)):.3g} mm for this gear (the tooth space's width "
                f"at the root plus the plunge allowance); now {float(found.group(1)):g} mm")
    found = _CORNER_LIMIT.search(message)
    if found:
        return (f"{group}: corner radius below {float(found.group(2)):g} mm (half the diameter); "
                f"now {float(found.group(1)):g} mm")
    found = _TIP_MODE_LIMIT.search(message)
    if found:
        corner = (values or {}).get("job", {}).get("FinishingCornerRadius")
        radius = f" for a corner radius of {corner:g} mm" if isinstance(corner, float) else ""
        reason = _with_titles(message.split(";")[0], section or "").removeprefix("finishing strategy generating: ")
        return f"{group}: diameter at most {float(found.group(1)):.3g} mm{radius} ({reason})"
    if field is not None and key is not None and body.startswith(f"{key} "):
        return f"{group}: {title(field).lower()} {_with_titles(body[len(key) + 1:], section or '')}"
    if field is not None:
        return f"{group}, {title(field).lower()}: {_with_titles(body, section or '')}"
    return f"{group}: {_with_titles(body, section or '')}"


_INVALID_PREFIX = re.compile(r"^(?:\[[a-z.]+\] |invalid (?:gear|\[[a-z.]+\]): )")


def sentence(exc: SpurCadError, source: str, units=None) -> str:
    """One sentence about a SpurCadError as an object's Status and the report view state it: a gear or stock
    field's title first ("Module must be in [0.05 mm, 100 mm], got -3 mm."), a job's as the panel says it
    (its group first: "Finishing tool: diameter at most ..."); titles for key names, lengths in the user's schema."""
    from spur_cad_workbench.schema import SECTION_OBJECTS, title

    message = _strip_source(str(exc), source).strip()
    field = field_of(exc.section, exc.field)
    if exc.section not in SECTION_OBJECTS and (field is not None or exc.section in SECTION_GROUPS):
        body = advice(message, exc.section, exc.field, None, units)
        return body if body.endswith(".") else f"{body}."
    body = _INVALID_PREFIX.sub("", message)
    if field is not None and exc.field is not None:
        body = _with_unit(body, field)
        rest = body[len(exc.field) + 1:] if body.startswith(f"{exc.field} ") else None
        body = title(field) + (f" {_with_titles(rest, exc.section or '')}" if rest is not None
                               else f": {_with_titles(body, exc.section or '')}")
    else:
        body = _with_titles(body, exc.section or "")
        body = body[:1].upper() + body[1:]
    body = unit_text.message(body, units)
    return body if body.endswith(".") else f"{body}."


def _problem(exc: SpurCadError, source: str, values: dict, units=None) -> Problem:
    message = _strip_source(str(exc), source)
    field = field_of(exc.section, exc.field)
    group = SECTION_GROUPS.get(exc.section or "") or (field.group if field is not None else group_of(message))
    return Problem(group, field.prop if field is not None else None, message,
                   advice(message, exc.section, exc.field, values, units))


def validate(values: dict[str, dict[str, object]], source: str = "job", units=None) -> Validation:
    """Check gear, stock and job values as the command line would; never raises for a SpurCadError.

    Recommendations never use an invalid tool: with the finishing tool in error they are the gear's alone.
    """
    from spur_cad.cam.plan import SETUP_CHECKS
    from spur_cad.cam.recommend import recommend_tools
    from spur_cad.cam.strategies import get_strategy
    from spur_cad.job import job_from_dict
    from spur_cad.pipeline import cam_inputs

    data = job_data(values)
    base = {name: section for name, section in data.items() if name != "tools"}
    try:
        without_tools = job_from_dict(base, source)
    except SpurCadError as exc:
        return Validation(None, (_problem(exc, source, values, units),), None)
    spec, blank = without_tools.gear, without_tools.stock.blank_radius_mm(without_tools.gear)
    clearance = without_tools.machine.clearance_mm
    strategy = get_strategy(without_tools.finishing.strategy, without_tools.strategies)  # its bottom allowance
    try:
        job = job_from_dict(data, source)
    except SpurCadError as exc:
        return Validation(None, (_problem(exc, source, values, units),),
                          recommend_tools(spec, blank, clearance, strategy=strategy))
    check = SETUP_CHECKS[job.machine.setup]  # the blank on the table, or lying flat
    try:
        rec, _ = check(cam_inputs(job))
    except SpurCadError as exc:
        problem = _problem(exc, source, values, units)
        finishing = None if problem.group == SECTION_GROUPS["tools.finishing"] else job.tools.finishing
        return Validation(None, (problem,), recommend_tools(spec, blank, clearance, finishing, strategy=strategy))
    return Validation(job, (), rec)


def recommendation_notes(rec, two_stage: bool = False, units=None) -> dict[str, str]:
    """Text shown beside the tool fields (property name -> note) for ToolRecommendations `rec`, lengths in the
    user's unit schema; with `two_stage` (a bottom tool in use) the roughing tool's limit is the bottom tool's
    and the roughing tool only fits the space."""
    if rec is None:
        return {}

    def length(value_mm: float) -> str:
        return unit_text.text(value_mm, "mm", units)

    notes = {
        "RoughingToolDiameter": f"at most {length(rec.roughing_max_diameter_mm)} (space width at root + what the "
                                f"finishing strategy lets roughing leave, {length(rec.plunge_allowance_mm)})",
        "FinishingToolDiameter": f"perimeter, along_x: flat width D - 2 r_t at most "
                                 f"{length(rec.finishing_max_flat_width_mm)} (root arc length); generating: within "
                                 "the rack's tip flat and the flank limit",
        "FinishingCornerRadius": f"at most {length(rec.finishing_max_corner_radius_mm)} (smallest fillet radius)",
    }
    if two_stage:
        notes["BottomToolDiameter"] = notes.pop("RoughingToolDiameter")
        notes["RoughingToolDiameter"] = "two-stage roughing: larger than the bottom tool (it roughs the upper levels)"
    for role in ("Roughing", "Finishing", "Bottom"):
        notes[f"{role}FluteLength"] = f"at least {length(rec.required_flute_length_mm)} (or 0: not checked)"
        notes[f"{role}StickOut"] = f"at least {length(rec.required_stick_out_mm)} (or 0: not checked)"
    return notes


# Machine values a machining centre rarely has: (property, test, note). Notes only: the job stays valid.
_UNUSUAL = (
    ("MaxSpindleRpm", lambda v: v < 2000.0, "unusually low for a machining centre (usual: 6,000 to 40,000 1/min); "
                                            "small end mills will run far below their cutting speed"),
    ("MaxFeed", lambda v: v < 500.0, "unusually low (usual: 2000 mm/min to 30000 mm/min); every feed is capped by it"),
    ("MaxRotarySpeed", lambda v: v < 360.0, "unusually low for a rotary table (usual: 1,800 to 30,000 deg/min)"),
    ("BlockTime", lambda v: v > 0.05, "unusually long (usual: 0.5 to 8 ms); short moves will be slow"),
)


def unusual_value_notes(job_values: dict[str, object], units=None) -> dict[str, str]:
    """Notes for machine values that are valid but unlike any machining centre (property name -> note)."""
    notes = {prop: unit_text.message(note, units) for prop, unusual, note in _UNUSUAL
             if isinstance(job_values.get(prop), float) and unusual(job_values[prop])}
    rapid, feed = job_values.get("RapidFeed"), job_values.get("MaxFeed")
    if isinstance(rapid, float) and isinstance(feed, float) and rapid < feed:
        notes["RapidFeed"] = "below the max feed: rapids would be slower than cutting moves"
    return notes


NEW_JOB_FLANK_ALLOWANCE_MM = 0.3
"""A new job's roughing flank allowance: the reference shop's proven 0.3 mm (the job file's default, 0.1 mm, is a
fine staircase that takes three times the roughing levels)..."""
NEW_JOB_FLANK_ALLOWANCE_FRACTION = 0.15
"""... at most this fraction of the finishing tool's diameter, so that a small finishing tool's radial engagement
on the staircase stays light."""


def new_job_values(values: dict[str, dict[str, object]]) -> dict[str, object]:
    """A new job's starting values for the gear and stock in `values`: the suggested tools (suggest_tools), the
    flank allowance a gear maker starts from (NEW_JOB_FLANK_ALLOWANCE_MM, within the finishing tool's share) and
    the job files' default roughing strategy (spur_cad.cam.machine.default_roughing_strategy: by flanks on the rotary
    table, about three times faster than levels with the same tool; two-stage roughing by levels is suggested only
    where it still saves a tenth of that time); {} if no tool fits."""
    from spur_cad.cam.machine import default_roughing_strategy
    from spur_cad.cam.strategies import get_strategy
    from spur_cad.cam.suggest import suggested_finishing

    check = _without_tools(values)
    if check.job is None:
        return {}
    job = check.job
    finishing = suggested_finishing(job.gear, get_strategy(job.finishing.strategy, job.strategies),
                                    job.finishing.target_scallop_mm, job.stock.blank_radius_mm(job.gear),
                                    job.machine.clearance_mm)
    if finishing is None:
        return {}
    allowance = round(min(NEW_JOB_FLANK_ALLOWANCE_MM, NEW_JOB_FLANK_ALLOWANCE_FRACTION * finishing.diameter_mm), 3)
    # the roughing reach and the two-stage split depend on the allowance and the strategy: suggest the tools
    # with them
    chosen = {"FlankAllowance": allowance, "RoughingStrategy": default_roughing_strategy(job.machine.setup)}
    tools = suggest_tools({**values, "job": {**values["job"], **chosen}})
    return {**tools, **chosen}


def _without_tools(values: dict[str, dict[str, object]]) -> Validation:
    """The values checked with every tool switched off (what the gear, stock and job sections alone allow)."""
    return validate({**values, "job": {**values["job"], TOOL_SWITCHES["roughing"].prop: False,
                                       TOOL_SWITCHES["finishing"].prop: False, "UseBottomTool": False}})


def suggest_tools(values: dict[str, dict[str, object]]) -> dict[str, object]:
    """Job property values choosing tools within the recommendations (for a new job); {} if none fits.

    The tools are spur_cad's suggestion for the gear (spur_cad.cam.suggest, as a job file's "auto" sizes):
    finishing, the tool the job's strategy suggests (by generation, the default: r_t = rho and 95 % of the
    largest diameter that fits); roughing, the largest 0.1 mm diameter that passes the tool limits and the
    roughing-reach rule, and below it the largest with which the whole job passes this panel's checks. When
    a larger tool for the upper levels saves at least a tenth of the roughing time (spur_cad.cam.plan
    suggested_two_stage), that tool roughs and the suggested one becomes the bottom tool (two-stage roughing).
    """
    from spur_cad.cam.plan import suggested_two_stage
    from spur_cad.cam.strategies import get_strategy
    from spur_cad.cam.suggest import ROUGHING_STEP_MM, SMALLEST_SUGGESTED_MM, suggested_tools
    from spur_cad.pipeline import cam_inputs

    check = _without_tools(values)
    if check.job is None:
        return {}
    job = check.job
    strategy = get_strategy(job.finishing.strategy, job.strategies)
    suggested = suggested_tools(job.gear, strategy, job.finishing.target_scallop_mm, job.roughing, job.stock,
                                job.machine.clearance_mm)
    if suggested.finishing is None:
        return {}
    finishing = suggested.finishing
    chosen = {"UseFinishingTool": True, "FinishingToolKind": finishing.kind,
              "FinishingToolDiameter": finishing.diameter_mm, "FinishingCornerRadius": finishing.corner_radius_mm,
              "UseBottomTool": False}
    diameter = suggested.roughing.diameter_mm if suggested.roughing is not None else 0.0
    while diameter >= SMALLEST_SUGGESTED_MM - 1e-9:
        candidate = {**chosen, "UseRoughingTool": True, "RoughingToolKind": "flat",
                     "RoughingToolDiameter": round(diameter, 6), "RoughingCornerRadius": 0.0}
        single = validate({**values, "job": {**values["job"], **candidate}})
        if single.ok and single.job is not None:
            return _with_two_stage(values, candidate, suggested_two_stage(cam_inputs(single.job)))
        diameter -= ROUGHING_STEP_MM
    return chosen


def _with_two_stage(values: dict[str, dict[str, object]], single: dict[str, object], stage) -> dict[str, object]:
    """The single roughing tool of `single` as the bottom tool below the suggested larger one (`stage`, a
    TwoStageSuggestion or None), when the whole job then passes the checks; else `single`."""
    if stage is None:
        return single
    two_stage = {**single, "RoughingToolDiameter": stage.top_diameter_mm, "UseBottomTool": True,
                 "BottomToolKind": "flat", "BottomToolDiameter": single["RoughingToolDiameter"],
                 "BottomCornerRadius": 0.0}
    for role in ("CuttingSpeed", "FeedPerTooth", "Flutes"):  # the bottom tool cuts with the roughing tool's data
        two_stage[f"Bottom{role}"] = values["job"][f"Roughing{role}"]
    return two_stage if validate({**values, "job": {**values["job"], **two_stage}}).ok else single
