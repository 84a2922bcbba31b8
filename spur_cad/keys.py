"""Job-file keys, each declared once: a dataclass field made by `key(...)` carries its metadata.

A section of the job file ([gear], [machine], ...) is a frozen dataclass; each field is one key.
The field's annotation is the key's type (float, int, bool or str), its default the key's default
(none: the file must give it), and `key(...)` adds the unit, the accepted range or choices, a
one-line meaning, and the FreeCAD workbench's property label and group:

    @dataclass(frozen=True)
    class Machine:
        clearance_mm: float = key(1.0, unit="mm", low=0.0, high=100.0,
                                  meaning="clearance of non-cutting moves from the stock",
                                  label="Clearance", group="Machine")

Everything else derives from these declarations: the job loader's type, range and choice
checks and their messages (spur_cad.job), the sections' own `__post_init__` (which runs
`check_section` before its cross-field checks, so an invalid section cannot be made), the workbench's properties
(workbench/spur_cad_workbench/schema.py) and docs/job-file.md. Adding a key is one field.

Lowest layer: imports only the standard library.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import typing
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from spur_cad.errors import shown

METADATA_KEY = "spur_cad.key"
REQUIRED = dataclasses.MISSING  # the default of a key the file must give

# Units a key may have (the job file spells them in the key's name: _mm, _deg, _mm_min, ...).
UNITS = {
    "": "dimensionless (a count, a coefficient, a name or a flag)",
    "mm": "millimetre",
    "um": "micrometre",
    "deg": "degree",
    "arcsec": "second of arc (1/3600 degree)",
    "%": "percent",
    "s": "second",
    "mm/min": "millimetres per minute (feeds)",
    "m/min": "metres per minute (cutting speed)",
    "deg/min": "degrees per minute (rotary speed)",
    "1/min": "revolutions per minute (spindle speed)",
    "mm/s^2": "millimetres per second squared (linear axis acceleration)",
    "deg/s^2": "degrees per second squared (rotary axis acceleration)",
    "mm/rev": "millimetres per spindle revolution (lathe feeds)",
    "kg": "kilogram",
    "kg/dm^3": "kilograms per cubic decimetre (density)",
}

_TYPE_NAMES = {float: "a number", int: "a whole number", bool: "true or false", str: "a string"}
Bound = float | int | str | None  # a number, or the name of another key of the same section


@dataclass(frozen=True)
class Key:
    """Metadata of one job-file key. `name`, `type`, `default` and `required` are filled in by `keys_of`.

    Range: `low` / `high` (inclusive unless `low_open` / `high_open`), each a number or the name
    of another key of the same section (e.g. line_number_step <= max_line_number).
    `choices`: the closed set of values the key takes (checked here).
    `names_from`: a callable giving the names a registry in the code offers (dialects, finishing
    strategies, tool kinds); the section's `__post_init__` checks them with the registry's message,
    the workbench offers them in a drop-down list and the documentation lists them.
    """

    unit: str
    meaning: str
    label: str
    group: str
    low: Bound = None
    high: Bound = None
    low_open: bool = False
    high_open: bool = False
    choices: tuple = ()
    names_from: Callable[[], Sequence[str]] | None = None
    name: str = ""
    type: type = object
    default: object = None  # None for a required key
    required: bool = False

    @property
    def names(self) -> tuple:
        """The values the key may take when it is a choice (its choices, or its registry's names)."""
        if self.choices:
            return self.choices
        return tuple(self.names_from()) if self.names_from is not None else ()

    def interval(self, values: dict | None = None) -> str:
        """The accepted range as text: '[0, 100] mm', '(0, 0.1] mm', '5..1000', '1..max_line_number'."""
        if self.low is None and self.high is None:
            return ""
        low, high = (_bound_text(b, values) for b in (self.low, self.high))
        if self.type is int and not self.low_open and not self.high_open:
            text = f"{low}..{high}"
        else:
            text = f"{'(' if self.low_open else '['}{low}, {high}{')' if self.high_open else ']'}"
        return f"{text} {self.unit}" if self.unit else text


def key(default: object = REQUIRED, *, unit: str = "", meaning: str, label: str, group: str, low: Bound = None,
        high: Bound = None, low_open: bool = False, high_open: bool = False, choices: Sequence = (),
        names_from: Callable[[], Sequence[str]] | None = None):
    """A dataclass field declaring one job-file key (see the module docstring and `Key`).

    `label` is the workbench property's name (for the two tool sections, `{Role}` stands for
    Roughing / Finishing), `group` its property group.
    """
    if unit not in UNITS:
        raise ValueError(f"unknown unit {unit!r} (known: {', '.join(repr(u) for u in UNITS)})")
    if (low is None) != (high is None):
        raise ValueError("a range needs both ends: give low and high")
    meta = Key(unit=unit, meaning=meaning, label=label, group=group, low=low, high=high, low_open=low_open,
               high_open=high_open, choices=tuple(choices), names_from=names_from)
    return dataclasses.field(default=default, metadata={METADATA_KEY: meta})


@functools.cache
def keys_of(cls: type) -> tuple[Key, ...]:
    """The keys of section dataclass `cls`, in declaration order (fields without `key()` metadata are
    not job-file keys)."""
    hints = typing.get_type_hints(cls)
    found = []
    for f in dataclasses.fields(cls):
        meta = f.metadata.get(METADATA_KEY)
        if meta is None:
            continue
        kind = hints[f.name]
        if kind not in _TYPE_NAMES:
            raise TypeError(f"{cls.__name__}.{f.name}: a job-file key is float, int, bool or str, not {kind}")
        required = f.default is REQUIRED
        found.append(dataclasses.replace(meta, name=f.name, type=kind, default=None if required else f.default,
                                         required=required))
    return tuple(found)


def with_key(cls: type, name: str, field: dataclasses.Field) -> type:
    """A subclass of section dataclass `cls`, of the same name and checks, whose key `name` is `field` (a
    `key(...)` declared anew): how a section takes the names of a registry other than the default one (another
    set of dialects: spur_cad.post.settings.post_settings_type, spur_cad.cam.turning.lathe_section_type)."""
    hints = typing.get_type_hints(cls)
    if name not in {f.name for f in dataclasses.fields(cls)} or METADATA_KEY not in field.metadata:
        raise TypeError(f"{cls.__name__}: {name!r} is not one of its keys, or {field!r} is not a key(...)")
    section = dataclasses.make_dataclass(cls.__name__, [(name, hints[name], field)], bases=(cls,), frozen=True)
    section.__module__, section.__qualname__, section.__doc__ = cls.__module__, cls.__qualname__, cls.__doc__
    return section


def key_of(cls: type, name: str) -> Key:
    for k in keys_of(cls):
        if k.name == name:
            return k
    raise KeyError(f"{cls.__name__} has no job-file key {name!r}")


def defaults_of(cls: type) -> dict[str, object]:
    """{key: default} of the keys that have one."""
    return {k.name: k.default for k in keys_of(cls) if not k.required}


Scalar = bool | int | float | str
"""A job-file key's value (`keys_of` admits these four types only): JSON and the report take it as it is."""


@dataclass(frozen=True)
class KeyValue:
    """One key of a section as a run used it: its name, its value (the file's, the default, or what "auto"
    resolved to) and its declared unit ('' for none)."""

    name: str
    value: Scalar
    unit: str

    def __post_init__(self) -> None:
        if not isinstance(self.value, (bool, int, float, str)):
            raise TypeError(f"key {self.name}: a job-file value is a number, a string or a flag, not "
                            f"{type(self.value).__name__}")
        if self.unit not in UNITS:
            raise ValueError(f"key {self.name}: unknown unit {self.unit!r}")


@dataclass(frozen=True)
class SectionValues:
    """Every key of one section of a job as the run used it, in declaration order (summary.json's `job_file`,
    the report's "Job file")."""

    section: str
    keys: tuple[KeyValue, ...]


def section_values(section: str, obj: object) -> SectionValues:
    """The keys of section dataclass instance `obj` (named `section`: 'gear', 'tools.roughing', ...) with their
    values: every key its class declares, so a key added to the class is here with no other code."""
    cls: type = type(obj)
    return SectionValues(section, tuple(KeyValue(k.name, getattr(obj, k.name), k.unit) for k in keys_of(cls)))


# --- checks ---------------------------------------------------------------------------------------------


def type_problem(k: Key, value: object) -> str | None:
    """'must be a number, got ...' when `value` (as TOML or JSON gives it) does not fit the key's type.

    An int is accepted for a float; a bool is never a number.
    """
    if k.type is float:
        ok = isinstance(value, (int, float)) and not isinstance(value, bool)
    elif k.type is int:
        ok = isinstance(value, int) and not isinstance(value, bool)
    else:
        ok = isinstance(value, k.type)
    if ok and isinstance(value, int) and not isinstance(value, bool) and abs(value) > MAX_INTEGER:
        return f"must be a number of sensible size, got {_shown(value)}"
    return None if ok else f"must be {_TYPE_NAMES[k.type]}, got {_shown(value)}"


def coerce(k: Key, value: Any) -> Any:
    """A value that passed `type_problem` as the key's type (int -> float for float keys)."""
    return float(value) if k.type is float else value


def value_problem(k: Key, value: Any, values: dict) -> str | None:
    """What is wrong with a well-typed `value` of key `k` ('must be in [0, 100] mm, got -1'), or None.

    `values` holds the section's other values (for bounds naming another key).
    """
    if k.type is float and not math.isfinite(value):
        return f"must be a finite number, got {_number(value)}"
    if k.choices and value not in k.choices:
        listed = [repr(c) if isinstance(c, str) else _number(c) for c in k.choices]
        options = f"{listed[0]} or {listed[1]}" if len(listed) == 2 else "one of " + ", ".join(listed)
        return f"must be {options}, got {shown(value)}"
    if k.low is None or k.type not in (float, int):
        return None
    low, high = (_bound_value(b, values) for b in (k.low, k.high))
    too_low = value <= low if k.low_open else value < low
    too_high = value >= high if k.high_open else value > high
    if too_low or too_high:
        return f"must be in {k.interval(values)}, got {_number(value)}"
    return None


def section_problems(cls: type, values: dict) -> list[tuple[str, str]]:
    """[(key, problem)] of the well-typed `values` ({key: value}, defaults filled in) of section `cls`.

    Bounds that are numbers are checked first, then bounds naming another key (so the named key
    has been checked before it bounds another).
    """
    named_last = sorted(keys_of(cls), key=lambda k: isinstance(k.low, str) or isinstance(k.high, str))
    problems = []
    for k in named_last:
        problem = value_problem(k, values[k.name], values) if k.name in values else None
        if problem:
            problems.append((k.name, problem))
    return problems


def check_section(obj: Any, section: str, error: Callable[..., Exception]) -> None:
    """Raise `error(f"[{section}] {key} {problem}", field=key)` for the first key of dataclass
    instance `obj` outside its declared range or choices (the sections' __post_init__ call this first)."""
    cls: type = type(obj)
    values = {k.name: getattr(obj, k.name) for k in keys_of(cls)}
    for k in keys_of(cls):
        problem = type_problem(k, values[k.name])
        if problem:
            raise error(f"[{section}] {k.name} {problem}", field=k.name)
    problems = section_problems(cls, values)
    if problems:
        name, problem = problems[0]
        raise error(f"[{section}] {name} {problem}", field=name)


# --- formatting --------------------------------------------------------------------------------------------


MAX_INTEGER = 10**15
"""Integers beyond this are refused for every key (beyond a float's exact range; no key means them)."""


def _shown(value: object, limit: int = 40) -> str:
    """A value as a message shows it: no 400-digit integers, long text shortened, control characters escaped."""
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) > MAX_INTEGER:
        return shown(value)
    return shown(value, limit)


def _number(value: object) -> str:
    """A number as short as it stays exact: 100, 0.0005, 100000.5, nan."""
    if isinstance(value, float):
        short = format(value, "g")
        return short if not math.isfinite(value) or float(short) == value else repr(value)
    return str(value)


def _bound_value(bound: Bound, values: dict):
    return values[bound] if isinstance(bound, str) else bound


def _bound_text(bound: Bound, values: dict | None) -> str:
    if isinstance(bound, str):
        return f"{bound} (= {_number(values[bound])})" if values and bound in values else bound
    return _number(bound)


def toml_literal(value: object) -> str:
    """A default as the job file writes it: 20.0, 5, true, "linuxcnc"."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    return repr(value)
