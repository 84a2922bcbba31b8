"""Job files: one TOML file describes one gear job (gear, stock, tools, strategies, machine, post).

Every section is a small typed dataclass whose fields are the section's keys, each declared once
with `spur_cad.keys.key` (type, unit, default, range or choices, meaning, workbench label and
group). The loader rejects unknown sections and keys, wrong types, missing required values and
values outside the declared ranges with a JobFileError that names the key and, where the file
has it, the key's line; then it runs the sections' cross-field checks (`validate()`) and builds
the GearSpec. Units are in the key names (mm, deg, percent, m_min, ...).

spur_cad.keydocs writes docs/job-file.md from the same declarations
(`python -m spur_cad.keydocs > docs/job-file.md`).
"""

from __future__ import annotations

import dataclasses
import difflib
import re
import tomllib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

from spur_cad.cad.specs import BlankFeatures, StockSpec
from spur_cad.cam.calibration import CalibrationTable, parse_calibration_table
from spur_cad.cam.machine import Machine, RoughingParams, default_roughing_strategy
from spur_cad.cam.machine_limits import check_machine_limits
from spur_cad.cam.materials import DEFAULT_MATERIAL, MATERIALS
from spur_cad.cam.probing import ProbeSection
from spur_cad.cam.strategies import REGISTRY, FinishingParams, Strategies, finishing_section_type
from spur_cad.cam.three_axis_tabs import ThreeAxisSection
from spur_cad.cam.tools import Tool
from spur_cad.cam.turning import LatheSection, check_lathe_blank, lathe_section_type
from spur_cad.dialects import DIALECTS, Dialects
from spur_cad.errors import (
    MAX_SHOWN_CHARS,
    GearSpecError,
    JobFileError,
    SpurCadError,
    StockError,
    escaped,
    shown,
    shown_path,
)
from spur_cad.geometry.internal import InternalGearSpec
from spur_cad.geometry.mate import GearPair
from spur_cad.geometry.modifications import SIDES, FlankModifications, flank_modification
from spur_cad.geometry.spec import MAX_TEETH, MIN_TEETH, GearSpec
from spur_cad.keys import check_section, coerce, key, keys_of, section_problems, type_problem
from spur_cad.mate_section import MateSection, check_mate
from spur_cad.post.settings import PostSettings, post_settings_type


@dataclass(frozen=True)
class JobSection:
    """[job]: name and the chordal tolerance of sampled profiles."""

    name: str = key("gear job", label="JobName", group="Job", meaning="job name (summary, program headers)")
    profile_tolerance_mm: float = key(0.001, unit="mm", low=0.0001, high=0.1, label="ProfileTolerance", group="Job",
                                      meaning="chordal tolerance of sampled profiles (profile.csv)")
    report_template: str = key("", label="ReportTemplate", group="Job",
                               meaning="report.html's Jinja2 template, a file relative to the job file, in its "
                                       "folder or a --side-files folder (empty: spur_cad's own, "
                                       "spur_cad/report/templates/report.html.j2: copy it to start)")
    material: str = key(DEFAULT_MATERIAL, choices=tuple(MATERIALS), label="Material", group="Job",
                        meaning="the gear's material: its specific cutting force (Kienzle k_c1.1, m_c; "
                                "spur_cad/cam/materials.py) sets the finishing tool's deflection in the error budget")


@dataclass(frozen=True)
class GearSection:
    """[gear]: the gear as ISO 21771 names it, plus the blank's bore and keyway."""

    teeth: int = key(low=MIN_TEETH, high=MAX_TEETH, label="Teeth", group="Gear", meaning="number of teeth z")
    module_mm: float = key(unit="mm", low=0.05, high=100.0, label="Module", group="Gear", meaning="module m")
    face_width_mm: float = key(unit="mm", low=0.5, high=2000.0, label="FaceWidth", group="Gear",
                               meaning="face width b, along the rotary axis X")
    pressure_angle_deg: float = key(20.0, unit="deg", low=10.0, high=35.0, label="PressureAngle", group="Gear",
                                    meaning="pressure angle alpha")
    profile_shift_coefficient: float = key(0.0, low=-2.0, high=3.0, label="ProfileShift", group="Gear",
                                           meaning="profile shift coefficient x")
    addendum_coefficient: float = key(1.0, low=0.5, high=2.0, label="AddendumCoefficient", group="Rack",
                                      meaning="addendum coefficient h_a* of the generated gear")
    dedendum_coefficient: float = key(1.25, low=0.5, high=2.5, label="DedendumCoefficient", group="Rack",
                                      meaning="dedendum coefficient h_f* of the generated gear")
    rack_tip_radius_mm: float = key(0.0, unit="mm", low=0.0, high=60.0, label="RackTipRadius", group="Rack",
                                    meaning="tip corner radius rho of the generating rack (at most 0.6 x module)")
    thickness_allowance_percent: float = key(0.0, unit="%", low=0.0, high=20.0, label="ThicknessAllowancePercent",
                                             group="Allowance",
                                             meaning="nominal tooth thickness reduced by this percentage "
                                                     "(the reference process's profile clearance, 0-5 % typical)")
    thickness_allowance_mm: float = key(0.0, unit="mm", low=0.0, high=50.0, label="ThicknessAllowance",
                                        group="Allowance",
                                        meaning="further absolute tooth thickness reduction (at most 0.5 x module; "
                                                "normal section for helical gears)")
    helix_angle_deg: float = key(0.0, unit="deg", low=0.0, high=45.0, label="HelixAngle", group="Gear",
                                 meaning="helix angle beta on the reference cylinder, 0: spur gear (module, pressure "
                                         "angle, shift, coefficients and rack tip radius are then normal-section "
                                         "values)")
    hand: str = key("right", label="Hand", group="Gear", choices=("right", "left"),
                    meaning="hand of the helix (helical gears)")
    internal: bool = key(False, label="Internal", group="Gear",
                         meaning="internal spur gear (ring gear) cut by a pinion-type shaper cutter; its CAM needs the "
                                 "3-axis variant (docs/geometry.md, Internal gears)")
    shaper_cutter_teeth: int = key(20, low=MIN_TEETH, high=MAX_TEETH, label="ShaperCutterTeeth", group="Gear",
                                   meaning="internal gears: teeth z_0 of the shaper cutter (the external gear the rack "
                                           "generates, tip corners rounded by rack_tip_radius_mm)")
    shaper_cutter_profile_shift_coefficient: float = key(
        0.0, low=-1.0, high=1.5, label="ShaperCutterProfileShift", group="Gear",
        meaning="internal gears: profile shift coefficient x_0 of the shaper cutter")
    rim_outer_diameter_mm: float = key(0.0, unit="mm", low=0.0, high=4000.0, label="RimOuterDiameter", group="Gear",
                                       meaning="internal gears: outside diameter of the ring's rim (at least 2 modules "
                                               "below the root circle)")
    mating_pinion_teeth: int = key(0, low=0, high=MAX_TEETH, label="MatingPinionTeeth", group="Gear",
                                   meaning="internal gears: teeth of the mating pinion for the tip interference check, "
                                           "0: not checked")
    bore_diameter_mm: float = key(0.0, unit="mm", low=0.0, high=2000.0, label="BoreDiameter", group="Bore",
                                  meaning="through bore diameter, 0: none")
    keyway_width_mm: float = key(0.0, unit="mm", low=0.0, high=500.0, label="KeywayWidth", group="Bore",
                                 meaning="hub keyway width, 0: none")
    keyway_depth_mm: float = key(0.0, unit="mm", low=0.0, high=200.0, label="KeywayDepth", group="Bore",
                                 meaning="hub keyway depth from the bore surface, 0: none")

    def to_spec(self) -> GearSpec:
        """The GearSpec ([gear] internal = true: an InternalGearSpec, spur only)."""
        common: dict[str, Any] = dict(
            teeth=self.teeth, module_mm=self.module_mm, pressure_angle_deg=self.pressure_angle_deg,
            profile_shift_coefficient=self.profile_shift_coefficient,
            addendum_coefficient=self.addendum_coefficient, dedendum_coefficient=self.dedendum_coefficient,
            rack_tip_radius_mm=self.rack_tip_radius_mm,
            thickness_allowance_fraction=self.thickness_allowance_percent / 100.0,
            thickness_allowance_mm=self.thickness_allowance_mm, face_width_mm=self.face_width_mm,
            helix_angle_deg=self.helix_angle_deg, hand=self.hand,
        )
        if not self.internal:
            return GearSpec(**common)
        return InternalGearSpec(**common, shaper_cutter_teeth=self.shaper_cutter_teeth,
                                shaper_cutter_profile_shift_coefficient=self.shaper_cutter_profile_shift_coefficient,
                                rim_outer_diameter_mm=self.rim_outer_diameter_mm,
                                mating_pinion_teeth=self.mating_pinion_teeth)

    def blank_features(self) -> BlankFeatures:
        return BlankFeatures(self.bore_diameter_mm, self.keyway_width_mm, self.keyway_depth_mm)


def _amount(label: str, meaning: str, signed: bool = False):
    """A modification amount key (um): 0 = none; beyond 10 % of the module is refused with the gear."""
    return key(0.0, unit="um", low=-10000.0 if signed else 0.0, high=10000.0, label=label,
               group="Flank modifications", meaning=meaning)


@dataclass(frozen=True)
class ModificationsSection:
    """[gear.modifications] / [gear.modifications.left] / [gear.modifications.right]: flank modifications
    (micro-geometry, ISO 21771 names; docs/geometry.md), amounts in um removed along the flank normal, lengths in mm.
    [gear.modifications] sets both flank sides; a .left or .right table overrides the keys it gives for that side.
    Amounts are at most 10 % of the module; reliefs start on the usable involute (form to tip diameter)."""

    tip_relief_um: float = _amount("TipRelief", "tip relief C_a: removed at the tip diameter")
    tip_relief_start_diameter_mm: float = key(0.0, unit="mm", low=0.0, high=5000.0, label="TipReliefStartDiameter",
                                              group="Flank modifications",
                                              meaning="diameter d_Ca where the tip relief starts (needed with it)")
    tip_relief_shape: str = key("linear", choices=("linear", "parabolic"), label="TipReliefShape",
                                group="Flank modifications",
                                meaning="tip relief along the roll length: linear or parabolic")
    root_relief_um: float = _amount("RootRelief", "root relief C_f: removed at the form diameter (start of the "
                                                  "usable involute)")
    root_relief_start_diameter_mm: float = key(0.0, unit="mm", low=0.0, high=5000.0, label="RootReliefStartDiameter",
                                               group="Flank modifications",
                                               meaning="diameter d_Cf where the root relief starts, toward the root "
                                                       "(needed with it)")
    root_relief_shape: str = key("linear", choices=("linear", "parabolic"), label="RootReliefShape",
                                 group="Flank modifications",
                                 meaning="root relief along the roll length: linear or parabolic")
    profile_crowning_um: float = _amount("ProfileCrowning", "profile crowning C_alpha: removed at both ends of the "
                                                            "usable involute, parabolic, none at its middle")
    profile_slope_um: float = _amount("ProfileSlope", "design profile slope f_Halpha: the material grows by this "
                                                      "from the form diameter to the tip (signed, none at "
                                                      "mid-profile)", signed=True)
    lead_crowning_um: float = _amount("LeadCrowning", "lead crowning C_beta: removed at both faces, parabolic, none "
                                                      "at mid-face")
    end_relief_um: float = _amount("EndRelief", "end relief C_I / C_II: removed at the face(s), linear")
    end_relief_length_mm: float = key(0.0, unit="mm", low=0.0, high=2000.0, label="EndReliefLength",
                                      group="Flank modifications",
                                      meaning="length L_I / L_II of the end relief from the face (needed with it)")
    end_relief_faces: str = key("both", choices=("both", "front", "back"), label="EndReliefFaces",
                                group="Flank modifications",
                                meaning="faces with end relief: both, front (X = 0) or back (X = b)")
    helix_slope_um: float = _amount("HelixSlope", "design helix slope f_Hbeta: the material grows by this from the "
                                                  "front face to the back face (signed, none at mid-face)",
                                    signed=True)


MODIFICATION_SECTIONS: dict[str, type] = {
    "gear.modifications": ModificationsSection,
    "gear.modifications.left": ModificationsSection,
    "gear.modifications.right": ModificationsSection,
}
"""The flank modification tables: read with [gear] (in the workbench, the gear's "Flank modifications" groups)."""


@dataclass(frozen=True)
class SimulationSection:
    """[simulation]: verification by simulated cutting (see docs/simulation.md)."""

    enabled: bool = key(True, label="SimulationEnabled", group="Simulation",
                        meaning="cut the stock with the roughing and finishing IR and measure it against the design "
                                "(summary simulation.*, deviation map in report.html)")
    # The simulator's blades reach 0.5 mm into the material, at least 10 x the resolution: 0.05 mm at most.
    resolution_mm: float = key(0.005, unit="mm", low=0.0005, high=0.05, label="SimulationResolution",
                               group="Simulation",
                               meaning="bound of the simulation's own error; finer is slower (about 4 x per halving)")

    def validate(self) -> None:
        """Raise SimulationError for a value outside its declared range (e.g. a resolution given to Simulate)."""
        from spur_cad.sim.simulate import SimulationError

        check_section(self, "simulation", SimulationError)


@dataclass(frozen=True)
class ExportSection:
    """[export]: the gear's transverse outline as 2-D drawings for wire EDM, laser and waterjet (docs/geometry.md):
    closed loops of arcs and lines within [job] profile_tolerance_mm, offset by offset_mm."""

    dxf: bool = key(False, label="ExportDxf", group="2-D export",
                    meaning="write gear.dxf: one closed LWPOLYLINE with arcs per loop, layers OUTLINE and BORE, mm "
                            "(spur gears only)")
    svg: bool = key(False, label="ExportSvg", group="2-D export",
                    meaning="write gear.svg: the same loops as SVG paths with arcs, in mm (spur gears only)")
    offset_mm: float = key(0.0, unit="mm", low=-10.0, high=10.0, label="ExportOffset", group="2-D export",
                           meaning="loops offset this far away from the material (outside the gear, inside the bore): "
                                   "wire radius plus spark gap for wire EDM, half the kerf for laser and waterjet, "
                                   "so the file is the path of the cut's centre; 0: the part's own outline")

    def validate(self) -> None:
        check_section(self, "export", JobFileError)


@dataclass(frozen=True)
class ToolsSection:
    """[tools]: the roughing and finishing tools (without them the job stops after the CAD stage)."""

    roughing: Tool | None = None
    finishing: Tool | None = None
    bottom: Tool | None = None  # two-stage roughing: a smaller tool for the bottom of the spaces
    roughing_top: Tool | None = None  # two-stage roughing offered: a larger tool for the upper part of the spaces


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
        where = _where(self.source, self.text, error.section, error.field) if error.section else self.source
        return f"{where}: {error}"

    def section(self, name: str):
        """The dataclass of section `name` ('gear', 'tools.roughing', ...); None for an absent tool."""
        if name == "gear":
            return self.gear_section
        if name.startswith("tools."):
            return getattr(self.tools, name.removeprefix("tools."))
        return getattr(self, name)


# Every section of the job file and its dataclass, in the order of the documentation and the workbench.
SECTIONS: dict[str, type] = {
    "job": JobSection,
    "gear": GearSection,
    "mate": MateSection,
    "stock": StockSpec,
    "tools.roughing": Tool,
    "tools.finishing": Tool,
    "tools.bottom": Tool,
    "tools.roughing_top": Tool,
    "roughing": RoughingParams,
    "finishing": FinishingParams,
    "machine": Machine,
    "three_axis": ThreeAxisSection,
    "simulation": SimulationSection,
    "export": ExportSection,
    "post": PostSettings,
    "lathe": LatheSection,
    "probe": ProbeSection,
}


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


_TOOL_ROLES = ("roughing", "finishing", "bottom", "roughing_top")
MAX_JOB_FILE_BYTES = 1024 * 1024
"""Job files larger than this are refused before they are parsed."""


def _line_of(text: str, table: str, key_name: str | None) -> int | None:
    """1-based line where `key_name` is set inside `[table]` (or the table header if key_name is None)."""
    current = ""
    header = re.compile(r"^\s*\[\s*([A-Za-z0-9_.\- ]+?)\s*\]\s*(#.*)?$")
    for number, line in enumerate(text.splitlines(), start=1):
        m = header.match(line)
        if m:
            current = re.sub(r"\s+", "", m.group(1))
            if key_name is None and current == table:
                return number
            continue
        if key_name is not None and current == table and re.match(rf"^\s*[\"']?{re.escape(key_name)}[\"']?\s*=",
                                                                 line):
            return number
    return None


def _where(source: str, text: str, table: str, key_name: str | None = None) -> str:
    """'file:line' of the key (its section's header when the file does not set it), or 'source'."""
    line = (_line_of(text, table, key_name) if key_name else None) or _line_of(text, table, None)
    return f"{source}:{line}" if line else source


def _blamed_key(exc: SpurCadError, name: str, given: dict, sections: dict[str, type] = SECTIONS) -> str | None:
    """The key of section `name` a cross-field error is about, for its line: the error's `field` when the
    file sets it, else the first key the message names that the file sets, else the `field` (not set)."""
    names = [k.name for k in keys_of(sections[name])]
    if exc.field in names and exc.field in given:
        return exc.field
    message = str(exc)
    positions = {k: m.start() for k in names if (m := re.search(rf"\b{re.escape(k)}\b", message))}
    for k in sorted(positions, key=lambda name: positions[name]):
        if k in given:
            return k
    return exc.field if exc.field in names else None


def _load_section(table: object, name: str, source: str, text: str, sections: dict[str, type] = SECTIONS):
    """Build section `name`'s dataclass from its TOML table, checking keys, types, ranges and choices."""
    cls = sections[name]
    if not isinstance(table, dict):
        raise JobFileError(f"{_where(source, text, name)}: [{name}] must be a table")
    known = {k.name: k for k in keys_of(cls)}
    for key_name in table:
        if key_name not in known:
            close = difflib.get_close_matches(key_name[:100], known, n=2)
            hint = (f"did you mean {' or '.join(close)}?" if close else f"known keys: {', '.join(sorted(known))}")
            raise JobFileError(f"{_where(source, text, name, key_name)}: unknown key {shown(key_name)} in [{name}] "
                               f"({hint})", section=name)
    values = {}
    for k in known.values():
        if k.name not in table:
            if k.required:
                raise JobFileError(f"{_where(source, text, name)}: [{name}] is missing the required key '{k.name}'",
                                   section=name, field=k.name)
            values[k.name] = k.default
            continue
        problem = type_problem(k, table[k.name])
        if problem:
            raise JobFileError(f"{_where(source, text, name, k.name)}: [{name}] {k.name} {problem}", section=name,
                               field=k.name)
        values[k.name] = coerce(k, table[k.name])
    problems = section_problems(cls, values)
    if problems:
        key_name, problem = problems[0]
        raise JobFileError(f"{_where(source, text, name, key_name)}: [{name}] {key_name} {problem}", section=name,
                           field=key_name)
    return cls(**values)


def _deepest_value(text: str, source: str) -> str:
    """'file:line: key' of the most deeply nested value (for the one error tomllib gives no position for)."""
    best, where = 0, source
    for number, line in enumerate(text.splitlines(), start=1):
        name, sep, value = line.partition("=")
        depth = len(value) - len(value.lstrip("[{ "))
        if sep and depth > best:
            best, where = depth, f"{source}:{number}: {shown_path(name.strip(), MAX_SHOWN_CHARS)}"
    return where


def _toml_error(source: str, message: str) -> str:
    """tomllib's 'Invalid value (at line 3, column 5)' as 'file:3: not valid TOML: invalid value (column 5)'."""
    found = re.fullmatch(r"(.*) \(at line (\d+), column (\d+)\)", message, re.DOTALL)
    if found is None:
        return f"{source}: not valid TOML: {escaped(message)}"
    what, line, column = found.groups()
    return f"{source}:{line}: not valid TOML: {escaped(what[:1].lower() + what[1:])} (column {column})"


def _longest_number(text: str, source: str) -> str:
    """'file:line: key' of the longest run of digits (for the error tomllib gives no position for)."""
    best, where = 0, source
    for number, line in enumerate(text.splitlines(), start=1):
        digits = max((len(run) for run in re.findall(r"\d+", line)), default=0)
        if digits > best:
            key_name, equals, _ = line.partition("=")
            best, where = digits, f"{source}:{number}" + (f": {shown_path(key_name.strip(), MAX_SHOWN_CHARS)}"
                                                          if equals else "")
    return where


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
        raise JobFileError(_toml_error(source, str(exc))) from None
    except ValueError as exc:  # an integer of thousands of digits (Python refuses to convert it)
        raise JobFileError(f"{_longest_number(text, source)}: a number of thousands of digits (no key takes one: "
                           f"{escaped(str(exc).split(':')[0])})") from None
    except RecursionError:
        raise JobFileError(f"{_deepest_value(text, source)}: arrays or tables nested too deeply for a job file") \
            from None
    return _job_from_data(data, source, text, strategies, dialects, sections)


def job_from_dict(data: dict, source: str, strategies: Strategies = REGISTRY, dialects: Dialects = DIALECTS,
                  sections: Mapping[str, type] = MappingProxyType({})) -> Job:
    """Validate a job given as nested dicts (the TOML structure), e.g. built by the FreeCAD workbench.

    Same checks and messages as parse_job, without line numbers (`source` names the origin).
    """
    return _job_from_data(data, source, "", strategies, dialects, sections)


def _tables(data: dict, source: str, text: str) -> dict[str, object]:
    """{section name: its table} of the sections `data` has; unknown sections are errors."""
    if not isinstance(data, dict):
        raise JobFileError(f"{source}: a job must be a table of sections")
    top = sorted({name.split(".")[0] for name in SECTIONS})
    tables: dict[str, object] = {}
    for name, table in data.items():
        children = [s for s in SECTIONS if s.startswith(name + ".")]
        if name in SECTIONS:
            tables[name] = table
        elif children:
            if not isinstance(table, dict):
                raise JobFileError(f"{_where(source, text, name)}: [{name}] must be a table")
            for child, child_table in table.items():
                if f"{name}.{child}" not in SECTIONS:
                    known = ", ".join(f"[{s}]" for s in children)
                    raise JobFileError(f"{_where(source, text, name + '.' + child)}: unknown section "
                                       f"[{shown_path(name + '.' + child, MAX_SHOWN_CHARS)}] (known: {known})")
                tables[f"{name}.{child}"] = child_table
        else:
            raise JobFileError(f"{_where(source, text, name)}: unknown section [{shown_path(name, MAX_SHOWN_CHARS)}] "
                               f"(known sections: {', '.join(top)})")
    if "gear" not in tables:
        raise JobFileError(f"{source}: the job file has no [gear] section")
    return tables


DEFAULT_FINISHING_TOOL_NUMBER = 2
"""The finishing tool's number when its section gives none (the roughing tool's default is 1)."""
DEFAULT_BOTTOM_TOOL_NUMBER = 3
"""The bottom roughing tool's number when its section gives none."""
DEFAULT_ROUGHING_TOP_TOOL_NUMBER = 4
"""The larger roughing tool's number ([tools.roughing_top]) when its section gives none."""


def _tool_label(tool: Tool) -> str:
    corner = f" r {tool.effective_corner_radius_mm:g} mm" if tool.effective_corner_radius_mm else ""
    return f"{tool.kind} D {tool.diameter_mm:g} mm{corner}, {tool.flutes} flutes"


def _check_tool_numbers(first_role: str, first: Tool, role: str, tool: Tool, where: str, blamed: str) -> None:
    """Two different end mills under one tool number would make the machine load the wrong one for one of the
    programs: refuse (the same end mill may serve both, with its own cutting data)."""
    def shape(tool: Tool) -> tuple:
        return (tool.kind, tool.diameter_mm, tool.effective_corner_radius_mm, tool.flutes, tool.flute_length_mm,
                tool.stick_out_mm, tool.gauge_length_mm)

    if first.tool_number == tool.tool_number and shape(first) != shape(tool):
        raise JobFileError(f"{where}: [tools.{role}] tool_number = {tool.tool_number} is also the {first_role} "
                           f"tool's number, but the tools differ ({first_role} {_tool_label(first)}; {role} "
                           f"{_tool_label(tool)}): the machine would load the wrong end mill; give each tool "
                           "its own number", section=f"tools.{blamed}", field="tool_number")


def _tools_section(sections: dict, tables: dict, where: Callable[[str, str | None], str]) -> ToolsSection:
    """The tools, with the default numbers of tools whose sections give none (T2 finishing, T3 bottom, T4
    roughing_top), and no two different tools under one number."""
    for role, number in (("finishing", DEFAULT_FINISHING_TOOL_NUMBER), ("bottom", DEFAULT_BOTTOM_TOOL_NUMBER),
                         ("roughing_top", DEFAULT_ROUGHING_TOP_TOOL_NUMBER)):
        if f"tools.{role}" in sections and "tool_number" not in tables[f"tools.{role}"]:
            sections[f"tools.{role}"] = dataclasses.replace(sections[f"tools.{role}"], tool_number=number)
    tools = ToolsSection(**{role: sections.get(f"tools.{role}") for role in _TOOL_ROLES})
    present = [role for role in _TOOL_ROLES if getattr(tools, role) is not None]
    for i, first_role in enumerate(present):
        for role in present[i + 1:]:
            given = "tool_number" in tables[f"tools.{role}"]  # else blame the other tool's number (the default given)
            blamed = role if given else first_role
            _check_tool_numbers(first_role, getattr(tools, first_role), role, getattr(tools, role),
                                where(f"tools.{blamed}", "tool_number"), blamed)
    return tools


def _check_roughing_top(tools: ToolsSection, where: Callable[[str, str | None], str]) -> None:
    """[tools.roughing_top] offers two-stage roughing with a larger flat end mill above [tools.roughing]: it needs
    that section, not [tools.bottom] as well (each makes a pair of roughing tools), and a larger diameter."""
    top, roughing = tools.roughing_top, tools.roughing
    if top is None:
        return
    name = "tools.roughing_top"
    if roughing is None:
        problem, key = ("needs [tools.roughing]: the larger tool roughs the upper part of the spaces, the roughing "
                        "tool what it leaves"), "diameter_mm"
    elif tools.bottom is not None:
        problem, key = ("and [tools.bottom] both make two-stage roughing: give one of them (roughing_top: a larger "
                        "tool above [tools.roughing]; bottom: a smaller one below it)"), "diameter_mm"
    elif top.kind != "flat":
        problem, key = f"kind = {shown(top.kind)}: roughing uses a flat end mill", "kind"
    elif top.diameter_mm <= roughing.diameter_mm:
        problem, key = (f"diameter_mm = {top.diameter_mm:g} must be larger than the roughing tool's "
                        f"{roughing.diameter_mm:g} mm (it roughs the upper part of the spaces)"), "diameter_mm"
    else:
        return
    raise JobFileError(f"{where(name, key)}: [{name}] {problem}", section=name, field=key)


AUTO = "auto"
AUTO_KEYS = ("diameter_mm", "corner_radius_mm")
"""Tool keys a job may give as "auto": the suggestion for the gear (spur_cad.cam.suggest) takes their place."""
_AUTO_ROLES = ("roughing", "finishing")
_PROVISIONAL = {"diameter_mm": 1.0, "corner_radius_mm": 0.0}  # stand-ins until the suggestion is known


def _without_auto(tables: dict, where: Callable[[str, str | None], str]) -> tuple[dict, dict[str, set[str]]]:
    """The tables with every "auto" tool key replaced by a stand-in, and {role: its "auto" keys}; "auto"
    anywhere else is refused with one line."""
    autos: dict[str, set[str]] = {}
    tables = dict(tables)
    for name, table in list(tables.items()):
        if not isinstance(table, dict):
            continue
        for key_name, value in table.items():
            if value != AUTO:
                continue
            role = name.removeprefix("tools.")
            if not name.startswith("tools.") or role not in _AUTO_ROLES or key_name not in AUTO_KEYS:
                allowed = " and ".join(f"[tools.{r}]" for r in _AUTO_ROLES)
                raise JobFileError(f"{where(name, key_name)}: [{name}] {key_name} = \"auto\": only "
                                   f"{' and '.join(AUTO_KEYS)} of {allowed} may be \"auto\"",
                                   section=name, field=key_name)
            autos.setdefault(role, set()).add(key_name)
            tables[name] = {**tables[name], key_name: _PROVISIONAL[key_name]}
    return tables, autos


def _resolve_auto(sections: dict, tables: dict, autos: dict[str, set[str]], spec: GearSpec, strategies: Strategies,
                  where: Callable[[str, str | None], str]) -> None:
    """Put the suggested tools' sizes (and kinds, where the table gives none) in place of the "auto" keys: the
    finishing tool first (the roughing limit depends on it and the finishing strategy), then the roughing tool."""
    from spur_cad.cam.strategies import get_strategy
    from spur_cad.cam.suggest import suggested_finishing, suggested_roughing

    stock, machine = sections.get("stock", StockSpec()), sections.get("machine", Machine())
    blank = stock.blank_radius_mm(spec)
    finishing_section = sections.get("finishing") or finishing_section_type(strategies)()
    for role in ("finishing", "roughing"):
        if role not in autos:
            continue
        name = f"tools.{role}"
        strategy = get_strategy(finishing_section.strategy, strategies)
        if role == "finishing":
            shape = suggested_finishing(spec, strategy, finishing_section.target_scallop_mm, blank,
                                        machine.clearance_mm)
        else:
            shape = suggested_roughing(spec, strategy, sections.get("tools.finishing"),
                                       sections.get("roughing", RoughingParams()), stock, machine.clearance_mm)
        first = sorted(autos[role])[0]
        if shape is None:
            raise JobFileError(f"{where(name, first)}: [{name}] {first} = \"auto\": no {role} tool fits this gear "
                               "within its limits; give the tool's size", section=name, field=first)
        chosen = {key_name: getattr(shape, key_name) for key_name in autos[role]}
        if "kind" not in tables[name]:
            chosen["kind"] = shape.kind
        sections[name] = dataclasses.replace(sections[name], **chosen)


def _validate_sections(sections: dict, tables: dict, types: dict, autos: dict[str, set[str]], spec: GearSpec,
                       strategies: Strategies, where: Callable[[str, str | None], str]) -> None:
    """Every section's own checks, the tools last: their "auto" keys are resolved once the sections the
    suggestion depends on (machine, roughing, finishing) have passed theirs."""
    for name in ("machine", "three_axis", "roughing", "finishing", "post", "export", "lathe", "probe",
                 *(f"tools.{role}" for role in _TOOL_ROLES)):
        if name not in sections:
            continue
        is_tool = name.startswith("tools.")
        if is_tool and autos:
            _resolve_auto(sections, tables, autos, spec, strategies, where)
            autos = {}
        try:
            if is_tool:
                sections[name].validate(name.removeprefix("tools."))
            elif name == "three_axis":  # its heights are checked against the face width
                sections[name].validate(spec.face_width_mm)
            else:
                sections[name].validate()
        except SpurCadError as exc:
            prefix = f"[{name}] " if is_tool else ""
            blamed = _blamed_key(exc, name, tables[name], types)
            raise JobFileError(f"{where(name, blamed)}: {prefix}{exc}", section=name, field=blamed) from None


def _split_modifications(data: dict, source: str, text: str) -> tuple[dict, dict[str, dict]]:
    """`data` without [gear.modifications], and {table name: table} of its common, .left and .right tables."""
    if not isinstance(data, dict) or not isinstance(data.get("gear"), dict) or "modifications" not in data["gear"]:
        return data, {}
    gear = dict(data["gear"])
    common = gear.pop("modifications")
    name = "gear.modifications"
    if not isinstance(common, dict):
        raise JobFileError(f"{_where(source, text, name)}: [{name}] must be a table")
    common = dict(common)
    tables = {name: common}
    for child, value in common.items():
        if isinstance(value, dict) and child not in SIDES:
            raise JobFileError(f"{_where(source, text, f'{name}.{child}')}: unknown section "
                               f"[{shown_path(f'{name}.{child}', MAX_SHOWN_CHARS)}] (known: [{name}.left], "
                               f"[{name}.right])")
    for side in SIDES:
        if side in common:
            side_table = common.pop(side)
            if not isinstance(side_table, dict):
                raise JobFileError(f"{_where(source, text, f'{name}.{side}')}: [{name}.{side}] must be a table")
            tables[f"{name}.{side}"] = side_table
    return {**data, "gear": gear}, tables


def _modifications(tables: dict[str, dict], spec: GearSpec, source: str,
                   text: str) -> tuple[FlankModifications | None, dict[str, dict]]:
    """Both flank sides' modifications from the [gear.modifications] tables (a side's table overrides the keys it
    gives), checked against the gear (None when no amount is set), and {table name: its keys' values} of the tables
    given (a side's resolved). Errors name the key's line in the table that gives it."""
    if not tables:
        return None, {}
    common = _load_section(tables["gear.modifications"], "gear.modifications", source, text, MODIFICATION_SECTIONS)
    given_values = {"gear.modifications": dataclasses.asdict(common)}
    sides = {}
    for side in SIDES:
        name = f"gear.modifications.{side}"
        given = tables.get(name, {})
        own = _load_section(given, name, source, text, MODIFICATION_SECTIONS)
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
            raise JobFileError(f"{_where(source, text, table, exc.field)}: [{table}] {exc}", section=table,
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
        raise JobFileError(f"{_where(source, text, table, key)}: [{table}] the {side} flank's modifications add "
                           f"{1000 * added:.1f} um of material (the signed slopes), more than roughing leaves for "
                           f"finishing ([roughing] finish_stock_mm = {finish_stock_mm:g} mm)", section=table, field=key)


def _job_from_data(data: dict, source: str, text: str, strategies: Strategies = REGISTRY,
                   dialects: Dialects = DIALECTS, sections: Mapping[str, type] = MappingProxyType({})) -> Job:
    """Validate parsed job data; `text` (the file's text, or "") only locates keys for messages."""
    data, modification_tables = _split_modifications(data, source, text)
    tables, autos = _without_auto(_tables(data, source, text), lambda name, key_name: _where(source, text, name,
                                                                                              key_name))
    types = job_sections(strategies, dialects, sections)
    loaded: dict[str, Any] = {name: _load_section(tables[name], name, source, text, types)
                              for name in types if name in tables}  # each section's dataclass, by its name
    loaded["roughing"], strategy_left_out = _roughing_section(loaded, tables)

    def where(name: str, key_name: str | None) -> str:
        return _where(source, text, name, key_name)

    gear_section: GearSection = loaded["gear"]
    try:
        spec = gear_section.to_spec()
    except GearSpecError as exc:
        blamed = _blamed_key(exc, 'gear', tables['gear'])
        raise JobFileError(f"{where('gear', blamed)}: invalid gear: {exc}", section="gear", field=blamed) from None
    setup = loaded.get("machine", Machine()).setup
    if spec.kind.teeth_inward and any(name.startswith("tools") for name in tables) and not setup.cuts(spec.kind):
        raise JobFileError(f"{where('gear', 'internal')}: internal = true: the rotary table cannot cut an internal "
                           "gear (its tool cannot reach inside the ring along the rotary axis); cut it with [machine] "
                           "axes = 3 or leave out [tools]", section="gear", field="internal")
    if modification_tables and not (spec.kind.follows_modifications and setup.follows_modifications):
        table = next(iter(modification_tables))
        what = ("the 3-axis variant ([machine] axes = 3)" if spec.kind.follows_modifications
                else "an internal gear's ring")
        raise JobFileError(f"{_where(source, text, table)}: [{table}] flank modifications are cut by generating or "
                           f"perimeter finishing on the rotary table only; {what} does not follow them: leave them "
                           "out",
                           section=table, field=None)
    modifications, modification_values = _modifications(modification_tables, spec, source, text)
    spec, pair = _mated(spec, loaded.get("mate"), tables.get("mate", {}), where)
    for check, name in ((gear_section.blank_features().validate, "gear"),
                        (loaded.get("stock", StockSpec()).validate, "stock")):
        try:
            check(spec)
        except (GearSpecError, StockError) as exc:
            blamed = _blamed_key(exc, name, tables.get(name, {}))
            raise JobFileError(f"{where(name, blamed)}: invalid [{name}]: {exc}", section=name, field=blamed) from None
    _validate_sections(loaded, tables, types, autos, spec, strategies, where)
    tools = _tools_section(loaded, tables, where)
    _check_added_material(modifications if tools.finishing is not None else None,
                          loaded.get("roughing", RoughingParams()).finish_stock_mm, modification_tables, source, text)
    _check_roughing_top(tools, where)
    try:
        check_machine_limits(spec, loaded.get("stock", StockSpec()), loaded.get("machine", Machine()),
                             {role: tool for role in _TOOL_ROLES if (tool := getattr(tools, role)) is not None})
    except SpurCadError as exc:
        raise JobFileError(f"{where('machine', exc.field)}: {exc}", section="machine", field=exc.field) from None
    if "lathe" in loaded:
        try:
            check_lathe_blank(spec, loaded.get("stock", StockSpec()), loaded["lathe"])
        except SpurCadError as exc:
            name = exc.section if exc.section in ("stock", "lathe") else "lathe"
            blamed = _blamed_key(exc, name, tables.get(name, {}))
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
        blamed = _blamed_key(exc, "mate", given)
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
        for role in _TOOL_ROLES:
            tool = getattr(tools, role)
            if tool is not None and tool.tool_number == probe.tool_number:
                raise ProbeError(f"[probe] tool_number = {probe.tool_number} is the {role} tool's number too; the "
                                 "probe needs a tool number of its own", field="tool_number")
        plan_probe(spec, sections.get("stock", StockSpec()), sections.get("machine", Machine()), probe)
    except SpurCadError as exc:
        name = exc.section if exc.section in ("post", "probe") else "probe"
        blamed = _blamed_key(exc, name, tables.get(name, {}))
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
    where = f"{_where(job.source, job.text, section, field_name)}: [{section}] {field_name}"
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
