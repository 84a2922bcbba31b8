"""Job files: one TOML file describes one gear job (gear, stock, tools, strategies, machine, post).

Every section is a small typed dataclass; the loader rejects unknown sections and keys, wrong
types and missing required values with a JobFileError that names the key and, where the
file has it, the line. Units are in the key names (mm, deg, percent, m_min, ...).
Sections beyond [job] and [gear] are validated now and consumed by the CAD/CAM/post layers.
"""

from __future__ import annotations

import dataclasses
import re
import tomllib
import typing
from dataclasses import dataclass, field
from pathlib import Path

from spur_cad.cad.specs import BlankFeatures, StockSpec
from spur_cad.cam.machine import FinishingParams, Machine, RoughingParams
from spur_cad.cam.tools import Tool
from spur_cad.errors import GearSpecError, JobFileError, SpurCadError, StockError
from spur_cad.geometry.spec import GearSpec
from spur_cad.post.settings import PostSettings

REQUIRED = object()  # marker default for keys the file must give


@dataclass(frozen=True)
class JobSection:
    """[job]: name and the chordal tolerance of sampled profiles."""

    name: str = "gear job"
    profile_tolerance_mm: float = 0.001


@dataclass(frozen=True)
class GearSection:
    """[gear]: the gear as ISO 21771 names it, plus the blank's bore and keyway."""

    teeth: int = REQUIRED  # type: ignore[assignment]
    module_mm: float = REQUIRED  # type: ignore[assignment]
    face_width_mm: float = REQUIRED  # type: ignore[assignment]
    pressure_angle_deg: float = 20.0
    profile_shift_coefficient: float = 0.0
    addendum_coefficient: float = 1.0
    dedendum_coefficient: float = 1.25
    rack_tip_radius_mm: float = 0.0
    thickness_allowance_percent: float = 0.0
    thickness_allowance_mm: float = 0.0
    bore_diameter_mm: float = 0.0
    keyway_width_mm: float = 0.0
    keyway_depth_mm: float = 0.0

    def to_spec(self) -> GearSpec:
        return GearSpec(
            teeth=self.teeth, module_mm=self.module_mm, pressure_angle_deg=self.pressure_angle_deg,
            profile_shift_coefficient=self.profile_shift_coefficient,
            addendum_coefficient=self.addendum_coefficient, dedendum_coefficient=self.dedendum_coefficient,
            rack_tip_radius_mm=self.rack_tip_radius_mm,
            thickness_allowance_fraction=self.thickness_allowance_percent / 100.0,
            thickness_allowance_mm=self.thickness_allowance_mm, face_width_mm=self.face_width_mm,
        )

    def blank_features(self) -> BlankFeatures:
        return BlankFeatures(self.bore_diameter_mm, self.keyway_width_mm, self.keyway_depth_mm)


@dataclass(frozen=True)
class SimulationSection:
    """[simulation]: verification by simulated cutting (spur_cad.sim) and its resolution."""

    enabled: bool = True
    resolution_mm: float = 0.005

    def validate(self) -> None:
        """Raise SimulationError for a resolution the simulator does not accept."""
        from spur_cad.sim.simulate import SimSettings

        SimSettings(resolution_mm=self.resolution_mm).validate()


@dataclass(frozen=True)
class ToolsSection:
    """[tools]: the roughing and finishing tools (without them the job stops after the CAD stage)."""

    roughing: Tool | None = None
    finishing: Tool | None = None


@dataclass(frozen=True)
class Job:
    """A whole job file, validated. `gear` is the GearSpec built from [gear]."""

    source: str
    job: JobSection
    gear_section: GearSection
    gear: GearSpec
    stock: StockSpec = field(default_factory=StockSpec)
    tools: ToolsSection = field(default_factory=ToolsSection)
    roughing: RoughingParams = field(default_factory=RoughingParams)
    finishing: FinishingParams = field(default_factory=FinishingParams)
    machine: Machine = field(default_factory=Machine)
    post: PostSettings = field(default_factory=PostSettings)
    simulation: SimulationSection = field(default_factory=SimulationSection)


_SECTIONS: dict[str, type] = {
    "job": JobSection,
    "gear": GearSection,
    "stock": StockSpec,
    "roughing": RoughingParams,
    "finishing": FinishingParams,
    "machine": Machine,
    "post": PostSettings,
    "simulation": SimulationSection,
}
_TOOL_SECTIONS = ("roughing", "finishing")


def _line_of(text: str, table: str, key: str | None) -> int | None:
    """1-based line where `key` is set inside `[table]` (or the table header if key is None)."""
    current = ""
    header = re.compile(r"^\s*\[\s*([A-Za-z0-9_.\- ]+?)\s*\]\s*(#.*)?$")
    for number, line in enumerate(text.splitlines(), start=1):
        m = header.match(line)
        if m:
            current = re.sub(r"\s+", "", m.group(1))
            if key is None and current == table:
                return number
            continue
        if key is not None and current == table and re.match(rf"^\s*{re.escape(key)}\s*=", line):
            return number
    return None


def _where(source: str, text: str, table: str, key: str | None = None) -> str:
    line = _line_of(text, table, key)
    return f"{source}:{line}" if line else source


def _check_value(value: object, expected: object) -> bool:
    """Whether a TOML value fits a field annotation (int is accepted for float, bool is not a number)."""
    if expected is float:
        return isinstance(value, (int, float)) and not isinstance(value, bool)
    if expected is int:
        return isinstance(value, int) and not isinstance(value, bool)
    if expected is bool:
        return isinstance(value, bool)
    if expected is str:
        return isinstance(value, str)
    return False


_TYPE_NAMES = {float: "a number", int: "a whole number", bool: "true or false", str: "a string"}


def _load_section(table: object, cls: type, name: str, source: str, text: str):
    """Build section dataclass `cls` from a TOML table, checking keys and types."""
    if not isinstance(table, dict):
        raise JobFileError(f"{_where(source, text, name)}: [{name}] must be a table")
    hints = typing.get_type_hints(cls)
    known = {f.name: f for f in dataclasses.fields(cls)}
    for key in table:
        if key not in known:
            allowed = ", ".join(sorted(known))
            raise JobFileError(f"{_where(source, text, name, key)}: unknown key '{key}' in [{name}] "
                               f"(known keys: {allowed})")
    values = {}
    for key, f in known.items():
        if key not in table:
            if f.default is REQUIRED or (f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING):
                raise JobFileError(f"{_where(source, text, name)}: [{name}] is missing the required key '{key}'")
            continue
        expected = hints[key]
        if not _check_value(table[key], expected):
            raise JobFileError(f"{_where(source, text, name, key)}: [{name}] {key} must be "
                               f"{_TYPE_NAMES.get(expected, expected)}, got {table[key]!r}")
        values[key] = float(table[key]) if expected is float else table[key]
    return cls(**values)


def parse_job(text: str, source: str = "<job>") -> Job:
    """Validate a job file's text; raises JobFileError (or GearSpecError wrapped into it)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise JobFileError(f"{source}: not valid TOML: {exc}") from None
    return _job_from_data(data, source, text)


def job_from_dict(data: dict, source: str) -> Job:
    """Validate a job given as nested dicts (the TOML structure), e.g. built by the FreeCAD workbench.

    Same checks and messages as parse_job, without line numbers (`source` names the origin).
    """
    return _job_from_data(data, source, "")


def _job_from_data(data: dict, source: str, text: str) -> Job:
    """Validate parsed job data; `text` (the file's text, or "") only locates keys for messages."""
    if not isinstance(data, dict):
        raise JobFileError(f"{source}: a job must be a table of sections")
    allowed = sorted(list(_SECTIONS) + ["tools"])
    for name in data:
        if name not in _SECTIONS and name != "tools":
            raise JobFileError(f"{_where(source, text, name)}: unknown section [{name}] "
                               f"(known sections: {', '.join(allowed)})")
    if "gear" not in data:
        raise JobFileError(f"{source}: the job file has no [gear] section")
    sections = {name: _load_section(data[name], cls, name, source, text)
                for name, cls in _SECTIONS.items() if name in data}
    tools_table = data.get("tools", {})
    if not isinstance(tools_table, dict):
        raise JobFileError(f"{_where(source, text, 'tools')}: [tools] must be a table")
    for name in tools_table:
        if name not in _TOOL_SECTIONS:
            raise JobFileError(f"{_where(source, text, 'tools.' + name)}: unknown section [tools.{name}] "
                               "(known: [tools.roughing], [tools.finishing])")
    tools = ToolsSection(**{name: _load_section(tools_table[name], Tool, f"tools.{name}", source, text)
                            for name in _TOOL_SECTIONS if name in tools_table})
    gear_section: GearSection = sections["gear"]
    try:
        spec = gear_section.to_spec()
    except GearSpecError as exc:
        key = {"thickness_allowance_fraction": "thickness_allowance_percent"}.get(exc.field or "", exc.field)
        where = _where(source, text, "gear", key) if key in {f.name for f in dataclasses.fields(GearSection)} \
            else source
        message = str(exc).replace("thickness_allowance_fraction", "thickness_allowance_percent / 100")
        raise JobFileError(f"{where}: invalid gear: {message}") from None
    for check, table in ((gear_section.blank_features().validate, "gear"),
                         (sections.get("stock", StockSpec()).validate, "stock")):
        try:
            check(spec)
        except (GearSpecError, StockError) as exc:
            raise JobFileError(f"{_where(source, text, table, exc.field)}: invalid [{table}]: {exc}") from None
    for name, check in (("machine", lambda m: m.validate()), ("roughing", lambda r: r.validate()),
                        ("finishing", lambda f: f.validate()), ("post", lambda p: p.validate()),
                        ("simulation", lambda s: s.validate())):
        if name in sections:
            try:
                check(sections[name])
            except SpurCadError as exc:
                raise JobFileError(f"{_where(source, text, name)}: {exc}") from None
    for role in _TOOL_SECTIONS:
        tool = getattr(tools, role)
        if tool is not None:
            try:
                tool.validate(role)
            except SpurCadError as exc:
                raise JobFileError(f"{_where(source, text, 'tools.' + role)}: [tools.{role}] {exc}") from None
    job_section: JobSection = sections.get("job", JobSection())
    if not job_section.profile_tolerance_mm > 0.0 or job_section.profile_tolerance_mm > 0.1:
        raise JobFileError(f"{_where(source, text, 'job', 'profile_tolerance_mm')}: [job] profile_tolerance_mm "
                           f"must be in (0, 0.1] mm, got {job_section.profile_tolerance_mm:g}")
    optional = {name: sections[name] for name in ("stock", "roughing", "finishing", "machine", "post", "simulation")
                if name in sections}
    return Job(source=source, job=job_section, gear_section=gear_section, gear=spec, tools=tools, **optional)


def load_job(path: str | Path) -> Job:
    """Read and validate a job file from disk."""
    path = Path(path)
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise JobFileError(f"{path}: job file not found") from None
    except OSError as exc:
        raise JobFileError(f"{path}: cannot read the job file: {exc.strerror}") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise JobFileError(f"{path}: the job file is not UTF-8 text") from None
    return parse_job(text, str(path))

