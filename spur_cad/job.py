"""Job files: one TOML file describes one gear job (gear, stock, tools, strategies, machine, post).

Every section is a small typed dataclass whose fields are the section's keys, each declared once
with `spur_cad.keys.key` (type, unit, default, range or choices, meaning, workbench label and
group). The loader rejects unknown sections and keys, wrong types, missing required values and
values outside the declared ranges with a JobFileError that names the key and, where the file
has it, the key's line, as it does what a section refuses when it is made (its `__post_init__`: keys
that contradict each other); then it builds the GearSpec and runs the checks that need it or a tool's
role (the sections' `validate(context)`). Units are in the key names (mm, deg, percent, m_min, ...).

spur_cad.keydocs writes docs/job-file.md from the same declarations
(`python -m spur_cad.keydocs > docs/job-file.md`).
"""

from __future__ import annotations

import dataclasses
import tomllib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

from spur_cad.cad.specs import StockSpec
from spur_cad.cam.calibration import CalibrationTable, parse_calibration_table
from spur_cad.cam.machine import Machine, RoughingParams, default_roughing_strategy
from spur_cad.cam.machine_limits import check_machine_limits
from spur_cad.cam.probing import ProbeSection
from spur_cad.cam.strategies import REGISTRY, FinishingParams, Strategies, finishing_section_type
from spur_cad.cam.three_axis_tabs import ThreeAxisSection
from spur_cad.cam.turning import LatheSection, check_lathe_blank, lathe_section_type
from spur_cad.dialects import DIALECTS, Dialects
from spur_cad.errors import (
    MAX_SHOWN_CHARS,
    GearSpecError,
    JobFileError,
    SpurCadError,
    StockError,
    escaped,
    shown_path,
)
from spur_cad.geometry.mate import GearPair
from spur_cad.geometry.modifications import SIDES, FlankModifications, flank_modification
from spur_cad.geometry.spec import GearSpec
from spur_cad.job_sections import (  # noqa: F401  (re-exported: the names callers know from here)
    MODIFICATION_SECTIONS,
    SECTIONS,
    ExportSection,
    GearSection,
    JobSection,
    ModificationsSection,
    SimulationSection,
    ToolsSection,
)
from spur_cad.job_toml import (  # noqa: F401  (re-exported)
    MAX_JOB_FILE_BYTES,
    blamed_key,
    deepest_value,
    load_section,
    longest_number,
    tables_of,
    toml_error,
    where_of,
)
from spur_cad.job_tools import (  # noqa: F401  (re-exported)
    AUTO,
    AUTO_KEYS,
    DEFAULT_BOTTOM_TOOL_NUMBER,
    DEFAULT_FINISHING_TOOL_NUMBER,
    DEFAULT_ROUGHING_TOP_TOOL_NUMBER,
    TOOL_ROLES,
    check_roughing_top,
    resolve_auto,
    tools_section,
    without_auto,
)
from spur_cad.keys import SectionValues, keys_of, section_values
from spur_cad.mate_section import MateSection, check_mate
from spur_cad.post.settings import PostSettings, post_settings_type


@dataclass(frozen=True)
class Job:
    """A whole job file, validated. `gear` is the GearSpec built from [gear]."""

    source: str
    job: JobSection
    gear_section: GearSection
    gear: GearSpec
    mate: MateSection | None = None  # [mate]: the mating gear (None: the basic rack)
    pair: GearPair | None = None  # the gear and its [mate] as they mesh (spur_cad.geometry.mate)
    stock: StockSpec = field(default_factory=StockSpec)
    tools: ToolsSection = field(default_factory=ToolsSection)
    roughing: RoughingParams = field(default_factory=RoughingParams)
    finishing: FinishingParams = field(default_factory=FinishingParams)
    machine: Machine = field(default_factory=Machine)
    three_axis: ThreeAxisSection = field(default_factory=ThreeAxisSection)  # [machine] axes = 3: tabs, onion skin
    post: PostSettings = field(default_factory=PostSettings)
    simulation: SimulationSection = field(default_factory=SimulationSection)
    export: ExportSection = field(default_factory=ExportSection)
    lathe: LatheSection | None = None  # [lathe] present: the blank's lathe program is written too
    probe: ProbeSection | None = None  # [probe] present: the on-machine probing program is written too
    modifications: FlankModifications | None = None  # [gear.modifications]: None when it sets no amount
    # {table name: every key's value} of the [gear.modifications] tables the file gives, a side's with the common
    # table's values where it gives none (the workbench's properties hold them as given)
    modification_values: dict[str, dict] = field(default_factory=dict, repr=False, compare=False)
    text: str = field(default="", repr=False, compare=False)  # the file's text, to point at lines
    report_template_text: str | None = field(default=None, repr=False, compare=False)  # [job] report_template's
    rotary_calibration: CalibrationTable | None = field(default=None, repr=False, compare=False)  # [machine]'s file
    strategies: Strategies = field(default_factory=lambda: dict(REGISTRY), repr=False, compare=False)  # [finishing]'s
    dialects: Dialects = field(default_factory=lambda: dict(DIALECTS), repr=False, compare=False)  # [post], [lathe]'s
    # the file leaves [roughing] strategy out: the set-up's default, whose flank roughing falls back to levels where
    # it cannot take the gear or tools (cam.plan.plan_cam)
    roughing_strategy_left_out: bool = field(default=False, repr=False, compare=False)

    def located(self, error: SpurCadError) -> str:
        """An error raised after loading, prefixed with 'file:line' of the key it blames (its section's
        header when the file does not set the key, the file alone when the error names no key)."""
        where = where_of(self.source, self.text, error.section, error.field) if error.section else self.source
        return f"{where}: {error}"

    def section(self, name: str):
        """The dataclass of section `name` ('gear', 'tools.roughing', ...); None for an absent tool."""
        if name == "gear":
            return self.gear_section
        if name.startswith("tools."):
            return getattr(self.tools, name.removeprefix("tools."))
        return getattr(self, name)

    def section_values(self) -> tuple[SectionValues, ...]:
        """Every key of every section the job has, as the run uses it (defaults, the set-up's roughing strategy
        and the tools' resolved "auto" keys included), in the order of SECTIONS with the [gear.modifications]
        tables the file gives after [gear]; absent optional sections ([mate], a tool, [lathe], [probe]) left out.
        Read from the sections' own classes (spur_cad.keys.section_values), so a key declared on a section's class,
        a replacement's given as `sections=` included, is in summary.json's `job_file` and the report's "Job file"
        with no other code."""
        found = []
        for name in SECTIONS:
            section = self.section(name)
            if section is not None:
                found.append(section_values(name, section))
            if name == "gear":
                found.extend(section_values(table, ModificationsSection(**values))
                             for table, values in self.modification_values.items())
        return tuple(found)


def job_sections(strategies: Strategies = REGISTRY, dialects: Dialects = DIALECTS,
                 sections: Mapping[str, type] = MappingProxyType({})) -> dict[str, type]:
    """SECTIONS with the [finishing] section made from the keys of `strategies`' parameters (the same class
    as FinishingParams for the default registry's strategies), [post] and [lathe] taking the names of the
    registry `dialects` (PostSettings and LatheSection for the default registry), and the classes of `sections`
    in place of theirs: each a subclass of the section it replaces, with keys of its own (e.g. a key being added,
    declared in a test)."""
    types = {**SECTIONS, "finishing": finishing_section_type(strategies), "post": post_settings_type(dialects),
             "lathe": lathe_section_type(dialects)}
    for name, cls in sections.items():
        if name not in types or not (isinstance(cls, type) and issubclass(cls, types[name])):
            raise TypeError(f"sections: [{name}] must be a subclass of the section it replaces")
    return {**types, **sections}


def parse_job(text: str, source: str = "<job>", strategies: Strategies = REGISTRY,
              dialects: Dialects = DIALECTS, sections: Mapping[str, type] = MappingProxyType({})) -> Job:
    """Validate a job file's text; raises JobFileError (or GearSpecError wrapped into it). `strategies`: the
    finishing strategies [finishing] strategy names and whose keys it takes; `dialects`: the controllers
    [post] dialect and [lathe] dialect name; `sections`: section classes in place of the standard ones
    (job_sections)."""
    if len(text) > MAX_JOB_FILE_BYTES:
        raise JobFileError(f"{source}: the job file is larger than {MAX_JOB_FILE_BYTES // 1024} KiB; a job file is "
                           "a few kilobytes of TOML")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise JobFileError(toml_error(source, str(exc))) from None
    except ValueError as exc:  # an integer of thousands of digits (Python refuses to convert it)
        raise JobFileError(f"{longest_number(text, source)}: a number of thousands of digits (no key takes one: "
                           f"{escaped(str(exc).split(':')[0])})") from None
    except RecursionError:
        raise JobFileError(f"{deepest_value(text, source)}: arrays or tables nested too deeply for a job file") \
            from None
    return _job_from_data(data, source, text, strategies, dialects, sections)


def job_from_dict(data: dict, source: str, strategies: Strategies = REGISTRY, dialects: Dialects = DIALECTS,
                  sections: Mapping[str, type] = MappingProxyType({})) -> Job:
    """Validate a job given as nested dicts (the TOML structure), e.g. built by the FreeCAD workbench.

    Same checks and messages as parse_job, without line numbers (`source` names the origin).
    """
    return _job_from_data(data, source, "", strategies, dialects, sections)


def _validate_sections(sections: dict, tables: dict, types: dict, autos: dict[str, set[str]], spec: GearSpec,
                       strategies: Strategies, where: Callable[[str, str | None], str]) -> None:
    """The checks of a section that need more than its own keys (its own ran when it was made, load_section):
    [three_axis]'s heights against the face width, and each tool's, which its role names, the tools last: their
    "auto" keys are resolved once the sections the suggestion depends on (machine, roughing, finishing) are made.
    A tool checks itself here, not when made: suggestions and the plan make tools beyond the job file's ranges
    (bisection probes) that are never cut."""
    for name in ("three_axis", *(f"tools.{role}" for role in TOOL_ROLES)):
        if name not in sections:
            continue
        is_tool = name.startswith("tools.")
        if is_tool and autos:
            resolve_auto(sections, tables, autos, spec, strategies, where)
            autos = {}
        try:
            if is_tool:
                sections[name].validate(name.removeprefix("tools."))
            else:  # [three_axis]: its heights are checked against the face width
                sections[name].validate(spec.face_width_mm)
        except SpurCadError as exc:
            prefix = f"[{name}] " if is_tool else ""
            blamed = blamed_key(exc, name, tables[name], types)
            raise JobFileError(f"{where(name, blamed)}: {prefix}{exc}", section=name, field=blamed) from None


def _split_modifications(data: dict, source: str, text: str) -> tuple[dict, dict[str, dict]]:
    """`data` without [gear.modifications], and {table name: table} of its common, .left and .right tables."""
    if not isinstance(data, dict) or not isinstance(data.get("gear"), dict) or "modifications" not in data["gear"]:
        return data, {}
    gear = dict(data["gear"])
    common = gear.pop("modifications")
    name = "gear.modifications"
    if not isinstance(common, dict):
        raise JobFileError(f"{where_of(source, text, name)}: [{name}] must be a table")
    common = dict(common)
    tables = {name: common}
    for child, value in common.items():
        if isinstance(value, dict) and child not in SIDES:
            raise JobFileError(f"{where_of(source, text, f'{name}.{child}')}: unknown section "
                               f"[{shown_path(f'{name}.{child}', MAX_SHOWN_CHARS)}] (known: [{name}.left], "
                               f"[{name}.right])")
    for side in SIDES:
        if side in common:
            side_table = common.pop(side)
            if not isinstance(side_table, dict):
                raise JobFileError(f"{where_of(source, text, f'{name}.{side}')}: [{name}.{side}] must be a table")
            tables[f"{name}.{side}"] = side_table
    return {**data, "gear": gear}, tables


def _modifications(tables: dict[str, dict], spec: GearSpec, source: str,
                   text: str) -> tuple[FlankModifications | None, dict[str, dict]]:
    """Both flank sides' modifications from the [gear.modifications] tables (a side's table overrides the keys it
    gives), checked against the gear (None when no amount is set), and {table name: its keys' values} of the tables
    given (a side's resolved). Errors name the key's line in the table that gives it."""
    if not tables:
        return None, {}
    common = load_section(tables["gear.modifications"], "gear.modifications", source, text, MODIFICATION_SECTIONS)
    given_values = {"gear.modifications": dataclasses.asdict(common)}
    sides = {}
    for side in SIDES:
        name = f"gear.modifications.{side}"
        given = tables.get(name, {})
        own = load_section(given, name, source, text, MODIFICATION_SECTIONS)
        values = {k.name: getattr(own if k.name in given else common, k.name) for k in keys_of(ModificationsSection)}
        if name in tables:
            given_values[name] = values
        try:
            sides[side] = flank_modification(values, spec.base_radius_mm, spec.form_radius_mm, spec.tip_radius_mm,
                                             spec.module_mm, spec.face_width_mm)
        except GearSpecError as exc:
            table = name if exc.field in given else "gear.modifications"
            if table not in tables:
                table = "gear.modifications"
            raise JobFileError(f"{where_of(source, text, table, exc.field)}: [{table}] {exc}", section=table,
                               field=exc.field) from None
    modifications = FlankModifications(**sides)
    return (None if modifications.is_zero else modifications), given_values


def _check_added_material(mods: FlankModifications | None, finish_stock_mm: float, tables: dict[str, dict], source: str,
                          text: str) -> None:
    """JobFileError at the slope key when the signed slopes of `mods` (None: no modification, or no finishing) add
    more material to a flank (negative removal, at the worst roll length and face position) than roughing leaves
    for finishing ([roughing] finish_stock_mm): the finishing tool would find nothing to cut there."""
    import numpy as np

    if mods is None:
        return
    for side in SIDES:
        flank = mods.side(side)
        rolls = np.linspace(flank.form_roll_mm, flank.tip_roll_mm, 2001)
        faces = np.linspace(0.0, flank.face_width_mm, 2001)
        added = -(float(flank.profile_offset_mm(rolls).min()) + float(flank.lead_offset_mm(faces).min()))
        if added <= finish_stock_mm + 1e-9:  # as much as roughing leaves: the finishing just touches it
            continue
        key = "profile_slope_um" if abs(flank.profile_slope_mm) >= abs(flank.helix_slope_mm) else "helix_slope_um"
        table = f"gear.modifications.{side}" if key in tables.get(f"gear.modifications.{side}", {}) \
            else "gear.modifications"
        raise JobFileError(f"{where_of(source, text, table, key)}: [{table}] the {side} flank's modifications add "
                           f"{1000 * added:.1f} um of material (the signed slopes), more than roughing leaves for "
                           f"finishing ([roughing] finish_stock_mm = {finish_stock_mm:g} mm)", section=table, field=key)


def _job_from_data(data: dict, source: str, text: str, strategies: Strategies = REGISTRY,
                   dialects: Dialects = DIALECTS, sections: Mapping[str, type] = MappingProxyType({})) -> Job:
    """Validate parsed job data; `text` (the file's text, or "") only locates keys for messages."""
    data, modification_tables = _split_modifications(data, source, text)
    tables, autos = without_auto(tables_of(data, source, text), lambda name, key_name: where_of(source, text, name,
                                                                                              key_name))
    types = job_sections(strategies, dialects, sections)
    loaded: dict[str, Any] = {name: load_section(tables[name], name, source, text, types)
                              for name in types if name in tables}  # each section's dataclass, by its name
    loaded["roughing"], strategy_left_out = _roughing_section(loaded, tables)

    def where(name: str, key_name: str | None) -> str:
        return where_of(source, text, name, key_name)

    gear_section: GearSection = loaded["gear"]
    try:
        spec = gear_section.to_spec()
    except GearSpecError as exc:
        blamed = blamed_key(exc, 'gear', tables['gear'])
        raise JobFileError(f"{where('gear', blamed)}: invalid gear: {exc}", section="gear", field=blamed) from None
    setup = loaded.get("machine", Machine()).setup
    if spec.kind.has_rim and any(name.startswith("tools") for name in tables) and not setup.cuts(spec.kind):
        raise JobFileError(f"{where('gear', 'internal')}: internal = true: the rotary table cannot cut an internal "
                           "gear (its tool cannot reach inside the ring along the rotary axis); cut it with [machine] "
                           "axes = 3 or leave out [tools]", section="gear", field="internal")
    if modification_tables and not (spec.kind.follows_modifications and setup.follows_modifications):
        table = next(iter(modification_tables))
        what = ("the 3-axis variant ([machine] axes = 3)" if spec.kind.follows_modifications
                else "an internal gear's ring")
        raise JobFileError(f"{where_of(source, text, table)}: [{table}] flank modifications are cut by generating or "
                           f"perimeter finishing on the rotary table only; {what} does not follow them: leave them "
                           "out",
                           section=table, field=None)
    modifications, modification_values = _modifications(modification_tables, spec, source, text)
    spec, pair = _mated(spec, loaded.get("mate"), tables.get("mate", {}), where)
    for check, name in ((lambda: gear_section.blank_features().validate(spec), "gear"),
                        (lambda: loaded.get("stock", StockSpec()).validate(spec), "stock")):
        try:
            check()
        except (GearSpecError, StockError) as exc:
            blamed = blamed_key(exc, name, tables.get(name, {}))
            raise JobFileError(f"{where(name, blamed)}: invalid [{name}]: {exc}", section=name, field=blamed) from None
    _validate_sections(loaded, tables, types, autos, spec, strategies, where)
    tools = tools_section(loaded, tables, where)
    _check_added_material(modifications if tools.finishing is not None else None,
                          loaded.get("roughing", RoughingParams()).finish_stock_mm, modification_tables, source, text)
    check_roughing_top(tools, where)
    try:
        check_machine_limits(spec, loaded.get("stock", StockSpec()), loaded.get("machine", Machine()),
                             {role: tool for role in TOOL_ROLES if (tool := getattr(tools, role)) is not None})
    except SpurCadError as exc:
        raise JobFileError(f"{where('machine', exc.field)}: {exc}", section="machine", field=exc.field) from None
    if "lathe" in loaded:
        try:
            check_lathe_blank(spec, loaded.get("stock", StockSpec()), loaded["lathe"])
        except SpurCadError as exc:
            name = exc.section if exc.section in ("stock", "lathe") else "lathe"
            blamed = blamed_key(exc, name, tables.get(name, {}))
            raise JobFileError(f"{where(name, blamed)}: {exc}", section=name, field=blamed) from None
    if "probe" in loaded:
        _check_probe(spec, loaded, tools, tables, where, dialects)
    if "export" in loaded:
        _check_export(spec, gear_section, loaded["export"], tables, where)
    optional = {name: loaded[name] for name in ("mate", "stock", "roughing", "machine", "three_axis",
                                                "simulation", "export", "lathe", "probe") if name in loaded}
    finishing = loaded["finishing"] if "finishing" in loaded else types["finishing"]()  # the registry's default
    post = loaded["post"] if "post" in loaded else types["post"]()  # the registry's default dialect
    return Job(source=source, job=loaded.get("job", JobSection()), gear_section=gear_section, gear=spec,
               tools=tools, finishing=finishing, post=post, **optional, text=text, strategies=dict(strategies),
               dialects=dict(dialects), modifications=modifications, modification_values=modification_values,
               pair=pair, roughing_strategy_left_out=strategy_left_out)


def _mated(spec: GearSpec, mate: MateSection | None, given: dict,
           where: Callable[[str, str | None], str]) -> tuple[GearSpec, GearPair | None]:
    """The gear with the start of its active profile in mesh with [mate], and the pair (None: no [mate], the gear
    as it is), if the pair runs (spur_cad.mate_section.check_mate); else one line at the [mate] key to blame."""
    if mate is None:
        return spec, None
    try:
        pair, facts = check_mate(spec, mate, given)
    except SpurCadError as exc:
        blamed = blamed_key(exc, "mate", given)
        raise JobFileError(f"{where('mate', blamed)}: [mate] {exc}", section="mate", field=blamed) from None
    return dataclasses.replace(spec, active_profile_start_diameter_mm=facts.start_of_active_profile_diameter_mm), pair


def _roughing_section(sections: dict, tables: dict) -> tuple[RoughingParams, bool]:
    """[roughing] as the file gives it, its strategy the set-up's default where the file leaves it out
    (default_roughing_strategy), and whether it does."""
    roughing = sections.get("roughing", RoughingParams())
    if "strategy" in tables.get("roughing", {}):
        return roughing, False
    setup = sections.get("machine", Machine()).setup
    return dataclasses.replace(roughing, strategy=default_roughing_strategy(setup)), True


def _check_probe(spec: GearSpec, sections: dict, tools: ToolsSection, tables: dict,
                 where: Callable[[str, str | None], str], dialects: Dialects) -> None:
    """[probe] needs a dialect with probing words, a tool number of its own, a spur gear and a ball that reaches
    every point (spur_cad.cam.probing.plan_probe): one line at the key to blame."""
    from spur_cad.cam.probing import ProbeError, plan_probe
    from spur_cad.post.probe import probing_dialect

    probe: ProbeSection = sections["probe"]
    try:
        probing_dialect(sections.get("post", PostSettings()).dialect, dialects)
        for role in TOOL_ROLES:
            tool = getattr(tools, role)
            if tool is not None and tool.tool_number == probe.tool_number:
                raise ProbeError(f"[probe] tool_number = {probe.tool_number} is the {role} tool's number too; the "
                                 "probe needs a tool number of its own", field="tool_number")
        plan_probe(spec, sections.get("stock", StockSpec()), sections.get("machine", Machine()), probe)
    except SpurCadError as exc:
        name = exc.section if exc.section in ("post", "probe") else "probe"
        blamed = blamed_key(exc, name, tables.get(name, {}))
        raise JobFileError(f"{where(name, blamed)}: {exc}", section=name, field=blamed) from None


def _check_export(spec: GearSpec, gear_section: GearSection, export: ExportSection, tables: dict,
                  where: Callable[[str, str | None], str]) -> None:
    """[export] with dxf or svg: a spur gear (a wire, laser or waterjet cuts straight teeth only), and an offset
    that leaves the root fillet and every loop intact (computed here, before the run): one line at the key."""
    from spur_cad.outline_export import ExportError, gear_layers

    if not (export.dxf or export.svg):
        return
    blamed = "dxf" if export.dxf else "svg"
    if not spec.kind.cut_straight:
        raise JobFileError(f"{where('export', blamed)}: [export] {blamed} = true: a helical gear's teeth are not "
                           "straight, and a wire, laser or waterjet cuts straight (spur) teeth only",
                           section="export", field=blamed)
    fillet_radius = spec.tooth_space_profile().min_fillet_curvature_radius_mm
    if export.offset_mm >= fillet_radius:
        raise JobFileError(f"{where('export', 'offset_mm')}: [export] offset_mm = {export.offset_mm:g} mm is too big "
                           f"for the root: it must stay below the root fillet's smallest curvature radius "
                           f"{fillet_radius:.4f} mm, or the cut rounds the fillet off", section="export",
                           field="offset_mm")
    try:
        gear_layers(spec, 0.01, export.offset_mm, gear_section.bore_diameter_mm, gear_section.keyway_width_mm,
                    gear_section.keyway_depth_mm)
    except ExportError as exc:
        raise JobFileError(f"{where('export', 'offset_mm')}: {exc}", section="export", field="offset_mm") from None


MAX_TEMPLATE_BYTES = 256 * 1024
"""Largest report template read (spur_cad's own is about 9 kB)."""


def with_report_template(job: Job, folder: Path, side_folders: Sequence[Path] = ()) -> Job:
    """The job with its [job] report_template read (found as `_named_file` finds it) and compiled: a name that
    leads outside the allowed folders, a missing or unreadable file, one that is not a regular file or larger
    than MAX_TEMPLATE_BYTES, or a template syntax error is one JobFileError at the key's line."""
    from spur_cad.report.html import compile_template

    def compiled(text: str, source: str) -> str:
        compile_template(text, shown_path(job.job.report_template))  # a syntax error is refused now, before any work
        return text

    text = _named_file(job, folder, side_folders, "job", "report_template", "report template", MAX_TEMPLATE_BYTES,
                       compiled)
    return job if text is None else dataclasses.replace(job, report_template_text=text)


MAX_CALIBRATION_BYTES = 1024 * 1024
"""Largest rotary calibration table read (a table of every 0.1 deg is about 60 kB)."""


def with_rotary_calibration(job: Job, folder: Path, side_folders: Sequence[Path] = ()) -> Job:
    """The job with its [machine] rotary_calibration_file read (found as `_named_file` finds it): a name that
    leads outside the allowed folders, a missing file, one that is not a regular file, larger than
    MAX_CALIBRATION_BYTES, not UTF-8 or with a line that is not 'A_deg error_arcsec' is one JobFileError at the
    key's line."""
    table = _named_file(job, folder, side_folders, "machine", "rotary_calibration_file", "calibration table",
                        MAX_CALIBRATION_BYTES, parse_calibration_table)
    return job if table is None else dataclasses.replace(job, rotary_calibration=table)


def _named_file(job: Job, folder: Path, side_folders: Sequence[Path], section: str, field_name: str, what: str,
                max_bytes: int, read):
    """`read(text, shown path)` of the UTF-8 file [section] field_name names; None when the key is empty. The
    name is relative and the file must lie in `folder` (the job file's) or one of `side_folders` (the user's
    --side-files), links and `..` resolved: spur_cad.inputs.side_file_path. Every failure (where the name leads,
    the file, its encoding, what `read` raises: ValueError or a SpurCadError) is one JobFileError at the key's
    line."""
    from spur_cad.inputs import read_regular_file, side_file_path
    from spur_cad.report.html import ReportTemplateError

    name = getattr(job.section(section), field_name)
    if not name:
        return None
    where = f"{where_of(job.source, job.text, section, field_name)}: [{section}] {field_name}"
    try:
        path = side_file_path(name, (folder, *side_folders), what, JobFileError)
        data = read_regular_file(path, what, max_bytes, JobFileError, shown_path(name))  # as the job names it
        return read(data.decode("utf-8"), shown_path(path))
    except UnicodeDecodeError:
        raise JobFileError(f"{where}: {shown_path(name)} is not UTF-8 text", section=section,
                           field=field_name) from None
    except (JobFileError, ReportTemplateError, ValueError) as exc:
        raise JobFileError(f"{where}: {exc}", section=section, field=field_name) from None


def with_files(job: Job, folder: Path, side_folders: Sequence[Path] = ()) -> Job:
    """The job with the files it names read: the report template and the rotary calibration table, each found
    in `folder` (the job file's, or in the workbench the saved document's) or in one of `side_folders` (folders
    the user named), never outside them."""
    return with_rotary_calibration(with_report_template(job, folder, side_folders), folder, side_folders)


def load_job(path: str | Path, strategies: Strategies = REGISTRY, side_folders: Sequence[Path] = (),
             dialects: Dialects = DIALECTS) -> Job:
    """Read and validate a job file from disk (a regular file of at most MAX_JOB_FILE_BYTES: a FIFO or a device
    is refused before it is read); the files it names ([job] report_template, [machine] rotary_calibration_file) are
    read from the job file's folder or one of `side_folders` (`--side-files`), never from elsewhere."""
    from spur_cad.inputs import read_regular_file

    source = shown_path(path)  # messages name the file with its control characters escaped
    raw = read_regular_file(path, "job file", MAX_JOB_FILE_BYTES, JobFileError)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise JobFileError(f"{source}: the job file is not UTF-8 text") from None
    if "\x00" in text:
        raise JobFileError(f"{source}: the job file contains NUL characters (not a text file)")
    return with_files(parse_job(text, source, strategies, dialects), Path(path).parent, side_folders)
