"""Where a job file says what (spur_cad.job): the line of a key or a section's header for messages, the key a
cross-field error blames, one section's table read into its dataclass (keys, types, ranges, choices checked), the
tables of a file's sections, and tomllib's errors said with their line."""

from __future__ import annotations

import difflib
import re

from spur_cad.errors import (
    MAX_SHOWN_CHARS,
    JobFileError,
    SpurCadError,
    escaped,
    shown,
    shown_path,
)
from spur_cad.job_sections import SECTIONS
from spur_cad.keys import coerce, keys_of, section_problems, type_problem

MAX_JOB_FILE_BYTES = 1024 * 1024
"""Job files larger than this are refused before they are parsed."""


def line_of(text: str, table: str, key_name: str | None) -> int | None:
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


def where_of(source: str, text: str, table: str, key_name: str | None = None) -> str:
    """'file:line' of the key (its section's header when the file does not set it), or 'source'."""
    line = (line_of(text, table, key_name) if key_name else None) or line_of(text, table, None)
    return f"{source}:{line}" if line else source


def blamed_key(exc: SpurCadError, name: str, given: dict, sections: dict[str, type] = SECTIONS) -> str | None:
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


CONSTRUCTION_PREFIX = {"stock": "invalid [stock]: "}
"""What a refusal at a section's construction says before its message ([stock]'s do not name the section; the
other sections' messages start with it)."""


def load_section(table: object, name: str, source: str, text: str, sections: dict[str, type] = SECTIONS):
    """Build section `name`'s dataclass from its TOML table, checking keys, types, ranges and choices here (their
    messages name the table, e.g. [gear.modifications.left]); what the section's own `__post_init__` refuses when it
    is made (keys that contradict each other) is said the same way, at the line of the key it blames."""
    cls = sections[name]
    if not isinstance(table, dict):
        raise JobFileError(f"{where_of(source, text, name)}: [{name}] must be a table")
    known = {k.name: k for k in keys_of(cls)}
    for key_name in table:
        if key_name not in known:
            close = difflib.get_close_matches(key_name[:100], known, n=2)
            hint = (f"did you mean {' or '.join(close)}?" if close else f"known keys: {', '.join(sorted(known))}")
            raise JobFileError(f"{where_of(source, text, name, key_name)}: unknown key {shown(key_name)} in [{name}] "
                               f"({hint})", section=name)
    values = {}
    for k in known.values():
        if k.name not in table:
            if k.required:
                raise JobFileError(f"{where_of(source, text, name)}: [{name}] is missing the required key '{k.name}'",
                                   section=name, field=k.name)
            values[k.name] = k.default
            continue
        problem = type_problem(k, table[k.name])
        if problem:
            raise JobFileError(f"{where_of(source, text, name, k.name)}: [{name}] {k.name} {problem}", section=name,
                               field=k.name)
        values[k.name] = coerce(k, table[k.name])
    problems = section_problems(cls, values)
    if problems:
        key_name, problem = problems[0]
        raise JobFileError(f"{where_of(source, text, name, key_name)}: [{name}] {key_name} {problem}", section=name,
                           field=key_name)
    try:
        return cls(**values)
    except SpurCadError as exc:
        blamed = blamed_key(exc, name, table, sections)
        raise JobFileError(f"{where_of(source, text, name, blamed)}: {CONSTRUCTION_PREFIX.get(name, '')}{exc}",
                           section=name, field=blamed) from None


def deepest_value(text: str, source: str) -> str:
    """'file:line: key' of the most deeply nested value (for the one error tomllib gives no position for)."""
    best, where = 0, source
    for number, line in enumerate(text.splitlines(), start=1):
        name, sep, value = line.partition("=")
        depth = len(value) - len(value.lstrip("[{ "))
        if sep and depth > best:
            best, where = depth, f"{source}:{number}: {shown_path(name.strip(), MAX_SHOWN_CHARS)}"
    return where


def toml_error(source: str, message: str) -> str:
    """tomllib's 'Invalid value (at line 3, column 5)' as 'file:3: not valid TOML: invalid value (column 5)'."""
    found = re.fullmatch(r"(.*) \(at line (\d+), column (\d+)\)", message, re.DOTALL)
    if found is None:
        return f"{source}: not valid TOML: {escaped(message)}"
    what, line, column = found.groups()
    return f"{source}:{line}: not valid TOML: {escaped(what[:1].lower() + what[1:])} (column {column})"


def longest_number(text: str, source: str) -> str:
    """'file:line: key' of the longest run of digits (for the error tomllib gives no position for)."""
    best, where = 0, source
    for number, line in enumerate(text.splitlines(), start=1):
        digits = max((len(run) for run in re.findall(r"\d+", line)), default=0)
        if digits > best:
            key_name, equals, _ = line.partition("=")
            best, where = digits, f"{source}:{number}" + (f": {shown_path(key_name.strip(), MAX_SHOWN_CHARS)}"
                                                          if equals else "")
    return where


def tables_of(data: dict, source: str, text: str) -> dict[str, object]:
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
                raise JobFileError(f"{where_of(source, text, name)}: [{name}] must be a table")
            for child, child_table in table.items():
                if f"{name}.{child}" not in SECTIONS:
                    known = ", ".join(f"[{s}]" for s in children)
                    raise JobFileError(f"{where_of(source, text, name + '.' + child)}: unknown section "
                                       f"[{shown_path(name + '.' + child, MAX_SHOWN_CHARS)}] (known: {known})")
                tables[f"{name}.{child}"] = child_table
        else:
            raise JobFileError(f"{where_of(source, text, name)}: unknown section [{shown_path(name, MAX_SHOWN_CHARS)}] "
                               f"(known sections: {', '.join(top)})")
    if "gear" not in tables:
        raise JobFileError(f"{source}: the job file has no [gear] section")
    return tables
