"""The document schema: which FreeCAD property holds which job-file key (plain Python, no FreeCAD).

Three document objects carry one job: the gear ([gear]), the stock ([stock]) and the job
([job], [tools.*], [roughing], [finishing], [machine], [simulation], [post]). Every key of the job file has
exactly one property, so a job file maps onto a document and back without loss, and every
property is a primitive FreeCAD type (saved as XML text, never pickled). `SCHEMA_VERSION` is
stored on each object so later versions can migrate old documents.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from spur_cad.cam.strategies import strategy_names
from spur_cad.cam.tools import TOOL_KINDS
from spur_cad.post.settings import DIALECT_NAMES

SCHEMA_VERSION = 1
TOOL_ROLES = ("roughing", "finishing")

# FreeCAD property type for each kind of value. Lengths are >= 0; distances may be negative.
PROPERTY_TYPES = {
    "length": "App::PropertyLength",
    "distance": "App::PropertyDistance",
    "angle": "App::PropertyAngle",
    "float": "App::PropertyFloat",
    "int": "App::PropertyInteger",
    "bool": "App::PropertyBool",
    "string": "App::PropertyString",
    "choice": "App::PropertyEnumeration",
    "strings": "App::PropertyStringList",
}


@dataclass(frozen=True)
class Field:
    """One FreeCAD property holding one job-file key (`section`, `key`), or a computed output (no key)."""

    prop: str
    kind: str
    group: str
    section: str
    key: str
    doc: str
    choices: tuple[str, ...] = ()

    @property
    def property_type(self) -> str:
        return PROPERTY_TYPES[self.kind]


def _f(prop, kind, group, section, key, doc, choices=()):
    return Field(prop, kind, group, section, key, doc, tuple(choices))


GEAR_FIELDS = (
    _f("Teeth", "int", "Gear", "gear", "teeth", "number of teeth z"),
    _f("Module", "length", "Gear", "gear", "module_mm", "module m (mm)"),
    _f("PressureAngle", "angle", "Gear", "gear", "pressure_angle_deg", "pressure angle alpha (deg)"),
    _f("ProfileShift", "float", "Gear", "gear", "profile_shift_coefficient", "profile shift coefficient x"),
    _f("FaceWidth", "length", "Gear", "gear", "face_width_mm", "face width b (mm), along the rotary axis X"),
    _f("AddendumCoefficient", "float", "Rack", "gear", "addendum_coefficient", "addendum coefficient h_a*"),
    _f("DedendumCoefficient", "float", "Rack", "gear", "dedendum_coefficient", "dedendum coefficient h_f*"),
    _f("RackTipRadius", "length", "Rack", "gear", "rack_tip_radius_mm",
       "tip corner radius rho of the generating rack (mm)"),
    _f("ThicknessAllowancePercent", "float", "Allowance", "gear", "thickness_allowance_percent",
       "nominal tooth thickness reduced by this percentage (0-5 % typical)"),
    _f("ThicknessAllowance", "length", "Allowance", "gear", "thickness_allowance_mm",
       "further absolute tooth thickness reduction (mm)"),
    _f("BoreDiameter", "length", "Bore", "gear", "bore_diameter_mm", "through bore diameter (mm), 0: none"),
    _f("KeywayWidth", "length", "Bore", "gear", "keyway_width_mm", "hub keyway width (mm), 0: none"),
    _f("KeywayDepth", "length", "Bore", "gear", "keyway_depth_mm", "hub keyway depth from the bore surface (mm)"),
)

GEAR_OUTPUTS = (
    _f("ReferenceRadius", "length", "Computed", "", "", "reference radius r = m z / 2"),
    _f("BaseRadius", "length", "Computed", "", "", "base radius r_b"),
    _f("TipRadius", "length", "Computed", "", "", "tip radius r_a"),
    _f("RootRadius", "length", "Computed", "", "", "root radius r_f"),
    _f("FormRadius", "length", "Computed", "", "", "radius where the involute starts (fillet junction)"),
    _f("ToothThickness", "length", "Computed", "", "", "design tooth thickness on the reference circle (arc)"),
    _f("SpanTeeth", "int", "Inspection", "", "", "teeth spanned k for the span measurement"),
    _f("SpanMeasurement", "length", "Inspection", "", "", "span measurement (base tangent length) W_k"),
    _f("PinDiameter", "length", "Inspection", "", "", "pin (ball) diameter for the dimension over pins"),
    _f("DimensionOverPins", "length", "Inspection", "", "", "dimension over two pins M"),
    _f("Undercut", "bool", "Inspection", "", "", "the rack's tip corner undercuts the involute"),
    _f("UndercutDepth", "length", "Inspection", "", "", "depth of the undercut (0 without undercut)"),
    _f("MinTeethWithoutUndercut", "int", "Inspection", "", "", "fewest teeth generated without undercut"),
)

STOCK_FIELDS = (
    _f("RadialAllowance", "length", "Stock", "stock", "radial_allowance_mm",
       "blank radius = tip radius + this allowance (mm)"),
    _f("FrontMargin", "length", "Stock", "stock", "front_margin_mm", "blank beyond the front face X = 0 (mm)"),
    _f("BackMargin", "length", "Stock", "stock", "back_margin_mm", "blank beyond the back face X = b (mm)"),
    _f("StubDiameter", "length", "Holding stub", "stock", "stub_diameter_mm",
       "holding stub toward the chuck (+X) diameter (mm), 0: none"),
    _f("StubLength", "length", "Holding stub", "stock", "stub_length_mm", "holding stub length (mm)"),
)

STOCK_OUTPUTS = (
    _f("BlankRadius", "length", "Computed", "", "", "radius of the blank cylinder"),
)


def _tool_fields(role: str) -> tuple[Field, ...]:
    title = role.capitalize()
    group, section = f"{title} tool", f"tools.{role}"
    return (
        _f(f"{title}ToolKind", "choice", group, section, "kind", f"{role} end mill: flat, bull_nose or ball",
           TOOL_KINDS),
        _f(f"{title}ToolDiameter", "length", group, section, "diameter_mm", "tool diameter D (mm)"),
        _f(f"{title}CornerRadius", "length", group, section, "corner_radius_mm",
           "corner radius r_t (0 flat, D/2 ball) (mm)"),
        _f(f"{title}Flutes", "int", group, section, "flutes", "number of flutes"),
        _f(f"{title}FluteLength", "length", group, section, "flute_length_mm", "flute length (mm), 0: not given"),
        _f(f"{title}StickOut", "length", group, section, "stick_out_mm", "stick-out from the holder (mm), 0: not given"),
        _f(f"{title}ToolNumber", "int", group, section, "tool_number", "tool number in the machine's magazine"),
        _f(f"{title}CuttingSpeed", "float", group, section, "cutting_speed_m_min", "cutting speed V_c (m/min)"),
        _f(f"{title}FeedPerTooth", "length", group, section, "feed_per_tooth_mm", "feed per tooth f_z (mm)"),
    )


# The switch that says whether the job file has the [tools.<role>] section at all.
TOOL_SWITCHES = {"roughing": _f("UseRoughingTool", "bool", "Roughing tool", "tools.roughing", "",
                                "rough with this tool (without it the job has no roughing)"),
                 "finishing": _f("UseFinishingTool", "bool", "Finishing tool", "tools.finishing", "",
                                 "finish with this tool (without it the job has no finishing)")}

JOB_FIELDS = (
    _f("JobName", "string", "Job", "job", "name", "job name (summary, programs)"),
    _f("ProfileTolerance", "length", "Job", "job", "profile_tolerance_mm", "chordal tolerance of sampled profiles (mm)"),
    TOOL_SWITCHES["roughing"],
    *_tool_fields("roughing"),
    TOOL_SWITCHES["finishing"],
    *_tool_fields("finishing"),
    _f("FlankAllowance", "length", "Roughing strategy", "roughing", "flank_allowance_mm",
       "largest staircase roughing leaves on the flanks (mm)"),
    _f("FinishStock", "length", "Roughing strategy", "roughing", "finish_stock_mm",
       "roughing never comes closer than this to the design (mm)"),
    _f("StepOverFraction", "float", "Roughing strategy", "roughing", "step_over_fraction",
       "Y step between passes of a level, x D"),
    _f("MaxLevelDepthFraction", "float", "Roughing strategy", "roughing", "max_level_depth_fraction",
       "slotting depth limit per level, x D"),
    _f("ClampRotary", "bool", "Roughing strategy", "roughing", "clamp_rotary",
       "clamp A around each tooth space (needs the machine's codes)"),
    _f("FinishingStrategy", "choice", "Finishing strategy", "finishing", "strategy",
       "perimeter (stations along X), along_x or generating (the tool as the rack, A clamped per pass)",
       strategy_names()),
    _f("TargetScallop", "length", "Finishing strategy", "finishing", "target_scallop_mm", "target scallop height (mm)"),
    _f("FinishingStepOver", "length", "Finishing strategy", "finishing", "step_over_mm",
       "X step between stations (mm), 0: from the target scallop"),
    _f("CuttingDirection", "choice", "Finishing strategy", "finishing", "cutting_direction",
       "generating: climb or conventional milling (spindle clockwise, M3)", ("climb", "conventional")),
    _f("FlankToolEnd", "choice", "Finishing strategy", "finishing", "flank_tool_end",
       "generating: tool end on the rack's tip round (rack) or raised per pass (raised)", ("rack", "raised")),
    _f("MachineName", "string", "Machine", "machine", "name", "machine name"),
    _f("MaxSpindleRpm", "float", "Machine", "machine", "max_spindle_rpm", "spindle speed limit (1/min)"),
    _f("MaxFeed", "float", "Machine", "machine", "max_feed_mm_min", "linear feed limit (mm/min)"),
    _f("RapidFeed", "float", "Machine", "machine", "rapid_feed_mm_min", "rapid traverse rate (mm/min)"),
    _f("MaxRotarySpeed", "float", "Machine", "machine", "max_rotary_speed_deg_min", "rotary axis speed limit (deg/min)"),
    _f("Clearance", "length", "Machine", "machine", "clearance_mm", "clearance of non-cutting moves from the stock (mm)"),
    _f("BlockTime", "float", "Machine", "machine", "block_time_s", "control's block processing time (s)"),
    _f("RotaryContinuous", "bool", "Machine", "machine", "rotary_continuous", "A turns without limits"),
    _f("AMin", "angle", "Machine", "machine", "a_min_deg", "A travel limit, low (deg)"),
    _f("AMax", "angle", "Machine", "machine", "a_max_deg", "A travel limit, high (deg)"),
    _f("XMin", "distance", "Machine", "machine", "x_min_mm", "X travel limit, low (mm)"),
    _f("XMax", "distance", "Machine", "machine", "x_max_mm", "X travel limit, high (mm)"),
    _f("YMin", "distance", "Machine", "machine", "y_min_mm", "Y travel limit, low (mm)"),
    _f("YMax", "distance", "Machine", "machine", "y_max_mm", "Y travel limit, high (mm)"),
    _f("ZMin", "distance", "Machine", "machine", "z_min_mm", "Z travel limit, low (mm)"),
    _f("ZMax", "distance", "Machine", "machine", "z_max_mm", "Z travel limit, high (mm)"),
    _f("RotaryClampCode", "string", "Machine", "machine", "rotary_clamp_code", "M code clamping A"),
    _f("RotaryUnclampCode", "string", "Machine", "machine", "rotary_unclamp_code", "M code unclamping A"),
    _f("SimulationEnabled", "bool", "Simulation", "simulation", "enabled",
       "simulate the cutting when exporting (summary and report)"),
    _f("SimulationResolution", "length", "Simulation", "simulation", "resolution_mm",
       "resolution of the simulation (mm); finer is slower"),
    _f("PostDialect", "choice", "Post", "post", "dialect", "G-code dialect", DIALECT_NAMES),
    _f("LineNumbers", "bool", "Post", "post", "line_numbers", "write N block numbers"),
    _f("LineNumberStep", "int", "Post", "post", "line_number_step", "step between block numbers"),
    _f("MaxLineNumber", "int", "Post", "post", "max_line_number", "largest block number the control accepts"),
    _f("LineNumberOverflow", "choice", "Post", "post", "line_number_overflow",
       "past the largest block number: wrap (restart) or stop numbering", ("wrap", "stop")),
    _f("Folded", "bool", "Post", "post", "folded", "repeat a tooth space's moves as a subprogram"),
    _f("RotarySign", "int", "Post", "post", "rotary_sign", "+1, or -1 for a table turning the other way"),
    _f("RotaryMode", "choice", "Post", "post", "rotary_mode",
       "unwound (A as the toolpath has it) or wrapped into [0, 360)", ("unwound", "wrapped")),
    _f("ProgramNumber", "int", "Post", "post", "program_number", "program number (O word)"),
    _f("Coolant", "bool", "Post", "post", "coolant", "coolant on while cutting"),
)

JOB_OUTPUTS = (
    _f("FinishingMaxFlatWidth", "length", "Recommendations", "", "", "largest finishing flat width D - 2 r_t"),
    _f("FinishingMaxCornerRadius", "length", "Recommendations", "", "", "largest finishing corner radius r_t"),
    _f("PlungeAllowance", "length", "Recommendations", "", "", "A_p: what the finishing tool takes by plunging"),
    _f("RoughingMaxDiameter", "length", "Recommendations", "", "", "largest roughing diameter"),
    _f("RequiredFluteLength", "length", "Recommendations", "", "", "flute length the job needs"),
    _f("RequiredStickOut", "length", "Recommendations", "", "", "stick-out the job needs"),
    _f("RoughingMoves", "int", "Results", "", "", "moves of the roughing program"),
    _f("RoughingTime", "float", "Results", "", "", "estimated roughing time (min)"),
    _f("FinishingMoves", "int", "Results", "", "", "moves of the finishing program"),
    _f("FinishingTime", "float", "Results", "", "", "estimated finishing time (min)"),
    _f("Warnings", "strings", "Results", "", "", "warnings of the CAM stage"),
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

FIELDS = {"gear": GEAR_FIELDS, "stock": STOCK_FIELDS, "job": JOB_FIELDS}
OUTPUTS = {"gear": GEAR_OUTPUTS, "stock": STOCK_OUTPUTS, "job": JOB_OUTPUTS, "toolpath": TOOLPATH_OUTPUTS}


def _section_objects(job) -> dict[str, object | None]:
    """The dataclass behind each job-file section of a spur_cad.job.Job."""
    return {"job": job.job, "gear": job.gear_section, "stock": job.stock, "tools.roughing": job.tools.roughing,
            "tools.finishing": job.tools.finishing, "roughing": job.roughing, "finishing": job.finishing,
            "machine": job.machine, "post": job.post, "simulation": job.simulation}


def _section_defaults() -> dict[str, dict[str, object]]:
    """The job file's defaults for every section (tool diameter has none: 0 until chosen)."""
    from spur_cad.cad.specs import StockSpec
    from spur_cad.cam.machine import FinishingParams, Machine, RoughingParams
    from spur_cad.cam.tools import Tool
    from spur_cad.job import GearSection, JobSection, SimulationSection
    from spur_cad.post.settings import PostSettings

    tool = dataclasses.asdict(Tool(diameter_mm=0.0))
    return {"job": dataclasses.asdict(JobSection()), "gear": {f.name: f.default for f in dataclasses.fields(GearSection)},
            "stock": dataclasses.asdict(StockSpec()), "tools.roughing": tool, "tools.finishing": dict(tool),
            "roughing": dataclasses.asdict(RoughingParams()), "finishing": dataclasses.asdict(FinishingParams()),
            "machine": dataclasses.asdict(Machine()), "post": dataclasses.asdict(PostSettings()),
            "simulation": dataclasses.asdict(SimulationSection())}


# A new gear (no job file): ISO 53 basic rack profile A (tip radius 0.38 m) on the reference gear's size.
NEW_GEAR = {"teeth": 23, "module_mm": 4.0, "face_width_mm": 20.0, "rack_tip_radius_mm": 0.38 * 4.0}


def default_values() -> dict[str, dict[str, object]]:
    """Property values of a new gear, stock and job: the job file's defaults, NEW_GEAR, no tools chosen."""
    defaults = _section_defaults()
    defaults["gear"].update(NEW_GEAR)
    values: dict[str, dict[str, object]] = {}
    for role, fields in FIELDS.items():
        values[role] = {field.prop: defaults[field.section][field.key] if field.key else False for field in fields}
    return values


def values_from_job(job) -> dict[str, dict[str, object]]:
    """Property values ({'gear': {...}, 'stock': {...}, 'job': {...}}) that hold a validated Job."""
    sections = _section_objects(job)
    defaults = _section_defaults()
    values: dict[str, dict[str, object]] = {}
    for role, fields in FIELDS.items():
        values[role] = {}
        for field in fields:
            section = sections[field.section]
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
            if field.section.startswith("tools.") and not values["job"][TOOL_SWITCHES[field.section[6:]].prop]:
                continue
            target = data
            for part in field.section.split("."):
                target = target.setdefault(part, {})
            target[field.key] = values[role][field.prop]
    return data


def field_by_prop(prop: str) -> Field:
    """The Field of a property name (inputs and outputs of every object)."""
    for fields in (*FIELDS.values(), *OUTPUTS.values()):
        for field in fields:
            if field.prop == prop:
                return field
    raise KeyError(prop)
