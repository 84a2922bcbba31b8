"""The report's "Job file" section: every key of every section of the job as the run used it, its value as the
job file writes it and its declared unit (spur_cad.job.Job.section_values, the same values as summary.json's
`job_file`), for a reader checking what the run took, defaults included.

Text from the file is data: the template escapes it (autoescape), and here control characters are written as
escapes and a long value is cut to JOB_FILE_TEXT_CHARS with its length said, as messages do (spur_cad.errors).
"""

from __future__ import annotations

from spur_cad.errors import escaped
from spur_cad.keys import Scalar, SectionValues, toml_literal
from spur_cad.report.sheet import MICRO, Table

JOB_FILE_TEXT_CHARS = 120
"""A text value is shown up to this many characters (a name, a file name); a longer one is cut, its length said."""

REPORT_UNITS = {"um": MICRO, "deg": "\u00b0", "deg/min": "\u00b0/min", "deg/s^2": "\u00b0/s\u00b2",
                "mm/s^2": "mm/s\u00b2", "kg/dm^3": "kg/dm\u00b3"}
"""A key's declared unit (spur_cad.keys.UNITS) as the rest of the report writes it; the others as declared."""


def job_file_value(value: Scalar) -> str:
    """A value as the job file writes it (20.0, 5, true, "linuxcnc"); text quoted, its backslashes and quotes
    escaped as TOML does, control and line-breaking characters as escapes, cut after JOB_FILE_TEXT_CHARS."""
    if not isinstance(value, str):
        return toml_literal(value)
    text = escaped(value[:JOB_FILE_TEXT_CHARS].replace("\\", "\\\\").replace('"', '\\"'))
    return f'"{text}"' if len(value) <= JOB_FILE_TEXT_CHARS else f'"{text}..." ({len(value):,} characters)'


def job_file_tables(sections: tuple[SectionValues, ...]) -> tuple[Table, ...]:
    """One table per section: head its name as the file writes it ('[tools.roughing]'), rows (key, value, unit)."""
    return tuple(Table((f"[{section.section}]",),
                       tuple((k.name, job_file_value(k.value), REPORT_UNITS.get(k.unit, k.unit)) for k in section.keys))
                 for section in sections)
