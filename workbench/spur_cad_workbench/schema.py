"""The document schema: which FreeCAD property holds which job-file key (plain Python, no FreeCAD).

Three document objects carry one job: the gear ([gear]), the stock ([stock]) and the job
([job], [tools.*], [roughing], [finishing], [machine], [simulation], [post]). Every key of the job file has
exactly one property, so a job file maps onto a document and back without loss, and every
property is a primitive FreeCAD type (saved as XML text, never pickled).

The input properties are derived from the job file's key declarations (spur_cad.keys.key
fields of the sections in spur_cad.job.SECTIONS): property name = the key's label, group = its
group, tooltip = its meaning, and the property type from the key's type, unit and range:

| key                                   | FreeCAD property            | value as the property holds it   |
| ------------------------------------- | --------------------------- | -------------------------------- |
| float, mm                             | App::PropertyDistance       | Quantity, .Value in mm (1)       |
| float, deg, range within [-360, 360]  | App::PropertyAngle          | Quantity, .Value in deg          |
| float, deg, range beyond +-360        | App::PropertyFloat          | number in deg (PropertyAngle     |
|                                       |                             | clamps to [-360, 360])           |
| float, mm/min                         | App::PropertySpeed          | Quantity in mm/s; set and read   |
|                                       |                             | in mm/min (15 significant digits)|
| float, um                             | App::PropertyDistance       | Quantity, set and read in um (15 |
|                                       |                             | significant digits; shown as um) |
| float, other units (m/min, 1/min,     | App::PropertyFloat          | number in the key's unit (named  |
| deg/min, s, %) or none                |                             | in the tooltip)                  |
| int                                   | App::PropertyInteger        | int                              |
| bool                                  | App::PropertyBool           | bool                             |
| str with choices or registry names    | App::PropertyEnumeration    | str                              |
| other str                             | App::PropertyString         | str                              |

(1) Also for keys that are never negative: PropertyLength clamps to >= 0, so a typed -3 mm would be
stored as 0 without a word; a PropertyDistance keeps it for spur_cad's check to refuse. Computed
lengths are PropertyLength.

Cutting speeds (m/min), spindle speeds (1/min) and rotary speeds (deg/min) stay PropertyFloat:
catalogues quote them in those units, and FreeCAD would show them as mm/s, Hz or deg/s.
The flank modifications ([gear.modifications], its .left and .right tables) are gear properties: the common
table in group "Flank modifications", each side's own values (`Left...`, `Right...`) in "Flank modifications:
left flank" / "...: right flank" behind a switch (LeftFlankOwnValues, RightFlankOwnValues). A side switched on
starts from the common values (the gear's onChanged copies them) and its table writes only the keys whose value
differs from the common one: the rest it inherits, key by key as a job file's side table does (which reads back as
the common values overridden by its keys). A job writes the tables only when some amount is set, so a gear without
modifications gives the job (and PlannedValues) it gave before.

`values_from_job` / `job_data` always hold plain numbers in the job file's units;
`plain_value` converts what FreeCAD returns (features.py converts when setting).

`SCHEMA_VERSION` is stored on each object; on reopening, features.py adds the properties a
document lacks, re-creates properties whose type changed (keeping their value) and updates
drop-down lists, so a new key needs no migration code. Version 2: MaxFeed and RapidFeed became
PropertySpeed (were PropertyFloat), AMin and AMax PropertyFloat (were PropertyAngle, which
clamped the default +-99999 deg to +-360). Version 3: the job's results gained the times with
accelerations, the program lines and PlannedValues; computed groups renamed "Values: ..." (sorted after
the inputs; reopening moves them). Version 4: every mm input became PropertyDistance (was PropertyLength
for keys that are never negative, which stored a typed -3 as 0 without a word); the gear gained its
length outputs as text to 0.1 um in the user's unit schema ("Values: precise"); the bottom tool's roughing
program (two-stage roughing) has its own results (BottomRoughingMoves, ...Time, ...TimeWithAcceleration,
...ProgramLines). Version 5: the um keys (the flank modifications, the machine's accuracy) became PropertyDistance
(were PropertyFloat): the property editor shows them with their unit.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

from spur_cad.job import MODIFICATION_SECTIONS, SECTIONS
from spur_cad.keys import keys_of

SCHEMA_VERSION = 5
TOOL_ROLES = ("roughing", "finishing")
OPERATION_TITLES = {"roughing": "Roughing", "roughing_bottom": "BottomRoughing", "finishing": "Finishing"}
"""The programs a job writes, in cutting order, and the prefix of their result properties on the job."""

# FreeCAD property type for each kind of value (the mapping above; outputs use the same kinds).
PROPERTY_TYPES = {
    "length": "App::PropertyLength",
    "distance": "App::PropertyDistance",
    "angle": "App::PropertyAngle",
    "speed": "App::PropertySpeed",
    "float": "App::PropertyFloat",
    "int": "App::PropertyInteger",
    "bool": "App::PropertyBool",
    "string": "App::PropertyString",
    "choice": "App::PropertyEnumeration",
    "strings": "App::PropertyStringList",
}
UNIT_CARRYING = {"length": "mm", "distance": "mm", "angle": "deg", "speed": "mm/min"}
SET_IN_KEY_UNIT = ("mm/min", "um")
"""Key units whose Quantity is set and read in the key's unit (FreeCAD's internal units are mm/s and mm)."""
ANGLE_PROPERTY_LIMIT_DEG = 360.0  # App::PropertyAngle clamps values to [-360, 360]


@dataclass(frozen=True)
class Field:
    """One FreeCAD property holding one job-file key (`section`, `key`), or a computed output (no key).

    `unit` is the job-file unit of the value (the key's); `choices` the drop-down list of a choice, or the values
    an int key takes (the panel offers them in a drop-down list; the property stays a PropertyInteger).
    """

    prop: str
    kind: str
    group: str
    section: str
    key: str
    doc: str
    choices: tuple[str, ...] = ()
    unit: str = ""

    @property
    def property_type(self) -> str:
        return PROPERTY_TYPES[self.kind]


def _f(prop, kind, group, section, key, doc, choices=()):
    return Field(prop, kind, group, section, key, doc, tuple(choices))


def property_kind(k) -> str:
    """The property kind of job-file key `k` (a spur_cad.keys.Key): the mapping in the module docstring."""
    if k.type is bool:
        return "bool"
    if k.type is int:
        return "int"
    if k.type is str:
        return "choice" if k.names else "string"
    numeric_low = k.low if not isinstance(k.low, str) else None
    numeric_high = k.high if not isinstance(k.high, str) else None
    if k.unit in ("mm", "um"):
        return "distance"
    if k.unit == "deg" and numeric_low is not None and numeric_high is not None and \
            -ANGLE_PROPERTY_LIMIT_DEG <= numeric_low and numeric_high <= ANGLE_PROPERTY_LIMIT_DEG:
        return "angle"
    if k.unit == "mm/min":
        return "speed"
    return "float"


def _key_field(section: str, k) -> Field:
    role = section.removeprefix("tools.").capitalize() if section.startswith("tools.") else ""
    kind = property_kind(k)
    doc = k.meaning if not k.unit or kind in UNIT_CARRYING else f"{k.meaning} ({k.unit})"
    return Field(k.label.format(Role=role), kind, k.group.format(Role=role), section, k.name, doc,
                 tuple(str(n) for n in k.names) if kind in ("choice", "int") else (), k.unit)


# The switch that says whether the job file has the [tools.<role>] section at all.
TOOL_SWITCHES = {"roughing": _f("UseRoughingTool", "bool", "Roughing tool", "tools.roughing", "",
                                "rough with this tool (without it the job has no roughing)"),
                 "finishing": _f("UseFinishingTool", "bool", "Finishing tool", "tools.finishing", "",
                                 "finish with this tool (without it the job has no finishing)"),
                 "bottom": _f("UseBottomTool", "bool", "Bottom tool", "tools.bottom", "",
                              "two-stage roughing: this smaller tool roughs the bottom of the spaces")}

# Every section the job file may leave out, and the switch (a job property) that says whether it is there.
SECTION_SWITCHES = {**{f"tools.{role}": switch for role, switch in TOOL_SWITCHES.items()},
                    "mate": _f("UseMate", "bool", "Mate", "mate", "",
                               "design against this mating gear ([mate]); off: the checks assume the basic rack"),
                    "lathe": _f("WriteLatheProgram", "bool", "Lathe", "lathe", "",
                                "write the blank's lathe program (blank.<ext>) with the job's files"),
                    "probe": _f("WriteProbeProgram", "bool", "Probe", "probe", "",
                                "write the on-machine probing program (probe.<ext>) with the job's files")}


def section_enabled(job_values: dict[str, object], section: str) -> bool:
    """Whether the job has `section` (a section without a switch always is there)."""
    switch = SECTION_SWITCHES.get(section)
    return switch is None or bool(job_values[switch.prop])


# Which document object holds each section (the job object holds every other section).
SECTION_OBJECTS = {"gear": "gear", "stock": "stock"}


MODIFICATIONS = "gear.modifications"
MODIFICATION_GROUP = "Flank modifications"
MODIFICATION_SIDES = ("left", "right")
MODIFICATION_SWITCHES = {
    f"{MODIFICATIONS}.{side}": _f(f"{side.capitalize()}FlankOwnValues", "bool", f"{MODIFICATION_GROUP}: {side} flank",
                                  f"{MODIFICATIONS}.{side}", "",
                                  f"the {side} flank has values of its own ([{MODIFICATIONS}.{side}]); off: the "
                                  f"common values")
    for side in MODIFICATION_SIDES}
"""The switch that says whether a flank side has its own modification table."""


def _modification_fields() -> list[Field]:
    """The common table's fields (group "Flank modifications"), then each side's switch and fields (its label
    prefixed Left / Right, in its own group)."""
    fields = [_key_field(MODIFICATIONS, k) for k in keys_of(MODIFICATION_SECTIONS[MODIFICATIONS])]
    for section, switch in MODIFICATION_SWITCHES.items():
        prefix = section.rsplit(".", 1)[1].capitalize()
        fields.append(switch)
        fields.extend(Field(prefix + f.prop, f.kind, switch.group, section, f.key, f.doc, f.choices, f.unit)
                      for f in fields[:len(keys_of(MODIFICATION_SECTIONS[MODIFICATIONS]))])
    return fields


JOB_FILE_ONLY = ("tools.roughing_top",)
"""Sections the panel leaves to the job file: [tools.roughing_top] is the pair of roughing tools the panel holds
as the roughing and bottom tools (values_from_job turns one into the other)."""


def _input_fields() -> dict[str, tuple[Field, ...]]:
    fields: dict[str, list[Field]] = {"gear": [], "stock": [], "job": []}
    for section, cls in SECTIONS.items():
        if section in JOB_FILE_ONLY:
            continue
        target = fields[SECTION_OBJECTS.get(section, "job")]
        if section in SECTION_SWITCHES:
            target.append(SECTION_SWITCHES[section])
        target.extend(_key_field(section, k) for k in keys_of(cls))
        if section == "gear":
            target.extend(_modification_fields())
    return {role: tuple(found) for role, found in fields.items()}


FIELDS = _input_fields()
GEAR_FIELDS, STOCK_FIELDS, JOB_FIELDS = FIELDS["gear"], FIELDS["stock"], FIELDS["job"]

# Computed properties (no job-file key). FreeCAD's property editor sorts groups by name: these all start with
# "Values", after every input group, so the inputs come first.
COMPUTED, INSPECTION, TOOL_LIMITS, RESULTS = "Values: computed", "Values: inspection", "Values: tool limits", \
    "Values: results"
PRECISE = "Values: precise"
STATUS_GROUP = "Values: status"
GEAR_OUTPUTS = (
    _f("ReferenceRadius", "length", COMPUTED, "", "", "reference radius r = m z / 2"),
    _f("BaseRadius", "length", COMPUTED, "", "", "base radius r_b"),
    _f("TipRadius", "length", COMPUTED, "", "", "tip radius r_a"),
    _f("RootRadius", "length", COMPUTED, "", "", "root radius r_f"),
    _f("FormRadius", "length", COMPUTED, "", "", "radius where the involute starts (fillet junction)"),
    _f("ToothThickness", "length", COMPUTED, "", "", "design tooth thickness on the reference circle (arc)"),
    _f("SpanTeeth", "int", INSPECTION, "", "", "teeth spanned k for the span measurement (0: none)"),
    _f("SpanMeasurement", "length", INSPECTION, "", "", "span measurement (base tangent length) W_k (0: none, an "
                                                         "internal gear has no span)"),
    _f("PinDiameter", "length", INSPECTION, "", "", "pin (ball) diameter for the dimension over pins"),
    _f("DimensionOverPins", "length", INSPECTION, "", "", "dimension over two pins M (an internal gear: between "
                                                          "two pins)"),
    _f("Undercut", "bool", INSPECTION, "", "", "the rack's tip corner undercuts the involute"),
    _f("UndercutDepth", "length", INSPECTION, "", "", "depth of the undercut (0 without undercut)"),
    _f("MinTeethWithoutUndercut", "int", INSPECTION, "", "", "fewest teeth generated without undercut"),
)
# The gear's lengths again as text to 0.1 um (the property editor shows a length with the user's global number
# of decimals, 2 by default, and FreeCAD 0.20 has no per-property precision), in the unit schema of the last
# recompute (units.py).
PRECISE_SUFFIX = "Precise"
GEAR_OUTPUTS += tuple(_f(f"{field.prop}{PRECISE_SUFFIX}", "string", PRECISE, "", "",
                         f"{field.doc}, to 0.1 um in the unit schema of the last recompute")
                      for field in GEAR_OUTPUTS if field.kind == "length")

STOCK_OUTPUTS = (
    _f("BlankRadius", "length", COMPUTED, "", "", "radius of the blank cylinder"),
)


JOB_OUTPUTS = (
    _f("FinishingMaxFlatWidth", "length", TOOL_LIMITS, "", "", "largest finishing flat width D - 2 r_t"),
    _f("FinishingMaxCornerRadius", "length", TOOL_LIMITS, "", "", "largest finishing corner radius r_t"),
    _f("PlungeAllowance", "length", TOOL_LIMITS, "", "",
       "what roughing may leave above the root: A_p = 0.5 x the finishing flat width (perimeter, along_x: it "
       "plunges), or one generating pass, 0.5 x D (generating)"),
    _f("RoughingMaxDiameter", "length", TOOL_LIMITS, "", "", "largest roughing diameter"),
    _f("RequiredFluteLength", "length", TOOL_LIMITS, "", "", "flute length the job needs"),
    _f("RequiredStickOut", "length", TOOL_LIMITS, "", "", "stick-out the job needs"),
    *(field for name, title in OPERATION_TITLES.items() for field in (
        _f(f"{title}Moves", "int", RESULTS, "", "", f"moves of the {name.replace('_', ' ')} program"),
        _f(f"{title}Time", "float", RESULTS, "", "", f"estimated {name.replace('_', ' ')} time (min)"),
        _f(f"{title}TimeWithAcceleration", "float", RESULTS, "", "",
           f"estimated {name.replace('_', ' ')} time with the machine's accelerations (min)"),
        _f(f"{title}ProgramLines", "int", RESULTS, "", "", f"lines of the {name.replace('_', ' ')} program as posted"),
    )),
    _f("PlannedValues", "string", RESULTS, "", "", "fingerprint of the values the results were planned for"),
    _f("Warnings", "strings", RESULTS, "", "", "warnings of the CAM stage"),
)

TOOLPATH_OUTPUTS = (
    _f("Operation", "string", "Toolpath", "", "", "roughing or finishing"),
    _f("Moves", "int", "Toolpath", "", "", "moves of the program (IR)"),
    _f("DisplayedMoves", "int", "Toolpath", "", "", "moves drawn in the 3D view (a subset of stations when large)"),
    _f("CuttingLength", "length", "Toolpath", "", "", "cutting path length relative to the part"),
    _f("EstimatedTime", "float", "Toolpath", "", "", "estimated machining time (min)"),
    _f("ToolNumber", "int", "Toolpath", "", "", "tool number"),
    _f("SpindleSpeed", "float", "Toolpath", "", "", "spindle speed (1/min)"),
)

OUTPUTS = {"gear": GEAR_OUTPUTS, "stock": STOCK_OUTPUTS, "job": JOB_OUTPUTS, "toolpath": TOOLPATH_OUTPUTS}
_BY_PROP = {field.prop: field for fields in (*FIELDS.values(), *OUTPUTS.values()) for field in fields}


def plain_value(field: Field, value):
    """A property's value as plain Python in the job file's unit (Quantity -> float in mm, deg or mm/min)."""
    if not hasattr(value, "Value"):
        return value
    if field.unit in SET_IN_KEY_UNIT:
        return float(format(float(value.getValueAs(field.unit)), ".15g"))
    return float(value.Value)


def _section_defaults() -> dict[str, dict[str, object]]:
    """The job file's defaults for every section; a required key without a value is 0 (a tool's
    diameter: 0 until chosen) until NEW_GEAR or the user gives one."""
    from spur_cad.job import DEFAULT_BOTTOM_TOOL_NUMBER, DEFAULT_FINISHING_TOOL_NUMBER

    zero = {float: 0.0, int: 0, str: "", bool: False}
    defaults = {section: {k.name: zero[k.type] if k.required else k.default for k in keys_of(cls)}
                for section, cls in {**SECTIONS, **MODIFICATION_SECTIONS}.items()}
    defaults["tools.finishing"]["tool_number"] = DEFAULT_FINISHING_TOOL_NUMBER  # T1 roughing, T2 finishing
    defaults["tools.bottom"]["tool_number"] = DEFAULT_BOTTOM_TOOL_NUMBER  # T3 the bottom roughing tool
    return defaults


# A new gear (no job file): ISO 53 basic rack profile A (tip radius 0.38 m) on the reference gear's size.
NEW_GEAR = {"teeth": 23, "module_mm": 4.0, "face_width_mm": 20.0, "rack_tip_radius_mm": 0.38 * 4.0}


NEW_STOCK_ALLOWANCE_MODULES = 0.125
"""A new stock's radial allowance is at most this many modules (the job file's 0.5 mm default is more than a
small gear's finishing tool takes off the tips in one pass: about 0.4 module)."""


def new_stock_values(gear_values: dict[str, Any]) -> dict[str, object]:
    """The stock property values a new stock starts from for a gear with these property values."""
    stock: dict[str, Any] = dict(default_values()["stock"])
    module_mm = float(gear_values.get("Module", 0.0))
    if module_mm > 0.0:
        stock["RadialAllowance"] = min(float(stock["RadialAllowance"]), NEW_STOCK_ALLOWANCE_MODULES * module_mm)
    return stock


def default_values() -> dict[str, dict[str, object]]:
    """Property values of a new gear, stock and job: the job file's defaults, NEW_GEAR, no tools chosen."""
    defaults = _section_defaults()
    defaults["gear"].update(NEW_GEAR)
    values: dict[str, dict[str, object]] = {}
    for role, fields in FIELDS.items():
        values[role] = {field.prop: defaults[field.section][field.key] if field.key else False for field in fields}
    return values


def values_from_job(job) -> dict[str, dict[str, object]]:
    """Property values ({'gear': {...}, 'stock': {...}, 'job': {...}}) that hold a validated Job; a job's
    [tools.roughing_top] becomes the roughing tool and its [tools.roughing] the bottom tool (the same pair of
    tools: roughing plans the quicker of two-stage roughing and the smaller tool alone either way)."""
    import dataclasses

    if job.tools.roughing_top is not None:
        job = dataclasses.replace(job, tools=dataclasses.replace(job.tools, roughing=job.tools.roughing_top,
                                                                 bottom=job.tools.roughing, roughing_top=None))
    defaults = _section_defaults()
    values: dict[str, dict[str, object]] = {}
    given = job.modification_values  # {table: values} of the tables the job file gives
    for role, fields in FIELDS.items():
        values[role] = {}
        for field in fields:
            if field.section.startswith(MODIFICATIONS):
                table = given.get(field.section, given.get(MODIFICATIONS, defaults[MODIFICATIONS]))
                values[role][field.prop] = table[field.key] if field.key else field.section in given
                continue
            section = job.section(field.section)
            if not field.key:
                values[role][field.prop] = section is not None
            elif section is None:
                values[role][field.prop] = defaults[field.section][field.key]
            else:
                values[role][field.prop] = getattr(section, field.key)
    return values


def job_data(values: dict[str, dict[str, object]]) -> dict[str, dict]:
    """The job as nested dicts in the job file's structure (input of spur_cad.job.job_from_dict).

    `values` may hold only some objects (e.g. {'gear': ...}): their sections are returned.
    """
    data: dict[str, dict] = {}
    for role, fields in FIELDS.items():
        if role not in values:
            continue
        for field in fields:
            if not field.key:
                continue
            if role == "job" and not section_enabled(values["job"], field.section):
                continue
            if field.section.startswith(MODIFICATIONS) and (field.section not in modification_tables(values[role])
                                                            or field.prop in inherited_side_props(values[role])):
                continue
            target: dict = data
            for part in field.section.split("."):
                target = target.setdefault(part, {})
            target[field.key] = values[role][field.prop]
    mate = data.get("mate")
    if mate and mate.get("centre_distance_mm", 0.0) > 0.0 and mate.get("profile_shift_coefficient") == 0.0:
        del mate["profile_shift_coefficient"]  # a document always holds a shift: 0 lets the centre distance set it
    return data


def modification_tables(gear_values: dict[str, object]) -> tuple[str, ...]:
    """The [gear.modifications] tables the gear's values write: none without an amount (the job of a gear without
    modifications stays as it was), else the common table and the sides switched on."""
    tables = (MODIFICATIONS, *(section for section, switch in MODIFICATION_SWITCHES.items()
                               if gear_values[switch.prop]))
    amounts = [field for field in FIELDS["gear"] if field.section in tables and field.key.endswith("_um")]
    return tables if any(gear_values[field.prop] for field in amounts) else ()


def common_prop(side_field: Field) -> str:
    """The common [gear.modifications] property a side's field overrides (LeftTipRelief: TipRelief)."""
    return side_field.prop.removeprefix(side_field.section.rsplit(".", 1)[1].capitalize())


def inherited_side_props(gear_values: dict[str, object]) -> set[str]:
    """The side properties whose value is the common one: their side table leaves them out and inherits them, as a
    job file's side table does (it overrides key by key), so that a side switched on with one amount changed writes
    that one key."""
    return {field.prop for field in FIELDS["gear"]
            if field.key and field.section in MODIFICATION_SWITCHES
            and gear_values[field.prop] == gear_values[common_prop(field)]}


def side_start_values(gear_values: dict[str, object], section: str) -> dict[str, object]:
    """{side property: the common value} of a side's table (`section`: 'gear.modifications.left'): what a side
    switched on starts from (the common modifications; the user then changes what differs)."""
    return {field.prop: gear_values[common_prop(field)] for field in FIELDS["gear"]
            if field.key and field.section == section}


def field_by_prop(prop: str) -> Field:
    """The Field of a property name (inputs and outputs of every object)."""
    return _BY_PROP[prop]


# Titles that splitting the property name would not give (after dropping the tool role's word).
_TITLES = {"UseRoughingTool": "Rough with this tool", "UseFinishingTool": "Finish with this tool",
           "UseBottomTool": "Rough the bottom with this tool", "WriteLatheProgram": "Write the lathe program",
           "WriteProbeProgram": "Write the probing program", "UseMate": "Design against a mate",
           "StickOut": "Stick-out", "StepOverFraction": "Step-over (fraction of D)",
           "MaxLevelDepthFraction": "Level depth (fraction of D)", "FinishingStrategy": "Strategy",
           "RoughingStrategy": "Strategy", "MaxRadialEngagementFraction": "Radial engagement (fraction of D)",
           "MaxAxialDepth": "Axial depth (0: flute length)", "MaxFeedFactor": "Feed raise (times)",
           "FinishingStepOver": "Step-over", "MaxSpindleRpm": "Max spindle speed", "SimulationEnabled": "Simulate",
           "SimulationResolution": "Resolution", "PostDialect": "Dialect", "JobName": "Name",
           "MachineName": "Name", "ThicknessAllowancePercent": "Thickness allowance (%)",
           "ProfileShift": "Profile shift coefficient x", "LeftFlankOwnValues": "Own values for the left flank",
           "RightFlankOwnValues": "Own values for the right flank", "MachineAxes": "Axes (4: rotary table, 3: flat)",
           "ExportDxf": "Write gear.dxf", "ExportSvg": "Write gear.svg",
           "ExportOffset": "Offset (wire radius + gap, half kerf)"}


def title(field: Field) -> str:
    """A field's label for people: "RoughingFeedPerTooth" in group "Roughing tool" -> "Feed per tooth"."""
    words = re.findall(r"[A-Z][a-z0-9]*|[a-z0-9]+", field.prop)
    role = field.section.removeprefix("tools.").capitalize() if field.section.startswith("tools.") else ""
    if role and words and words[0] == role:
        words = words[1:]
    if len(words) > 1 and words[0] == "Tool" and words[1] != "Number":
        words = words[1:]
    key = "".join(words)
    if field.prop in _TITLES or key in _TITLES:
        return _TITLES[field.prop] if field.prop in _TITLES else _TITLES[key]
    text = " ".join(word if len(word) == 1 else word.lower() for word in words)
    return text[:1].upper() + text[1:]
