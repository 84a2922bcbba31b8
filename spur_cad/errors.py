"""Exception types: every error a user can cause is a SpurCadError with a specific message."""

from __future__ import annotations

import os
import re


class SpurCadError(Exception):
    """Base class for errors caused by user input; the CLI and GUI show the message only.

    `field` names the offending input (a job-file key of the section the error is about) when
    one input is to blame; the job loader then points at that key's line. Errors raised after
    the job file was read (CAM limits, simulation bounds) also name the `section`, so front ends
    can still point at the key's line.
    """

    def __init__(self, *args: object, field: str | None = None, section: str | None = None):
        super().__init__(*args)
        self.field = field
        self.section = section

    @property
    def key(self) -> str | None:
        """"section.field" when both are known (e.g. "finishing.target_scallop_mm"), else None."""
        return f"{self.section}.{self.field}" if self.section and self.field else None


class GearSpecError(SpurCadError, ValueError):
    """A gear specification that cannot be made (or cut) as given.

    `field` names the offending input (a GearSpec field name) when one input is to blame.
    """

    def __init__(self, message: str, field: str | None = None, section: str | None = None):
        super().__init__(message, field=field, section=section)


class StockError(SpurCadError, ValueError):
    """A stock (blank, margins, holding stub) that cannot be made; `field` names the StockSpec field."""

    def __init__(self, message: str, field: str | None = None):
        super().__init__(message, field=field, section="stock")


class SimulationError(SpurCadError, ValueError):
    """Simulation settings that cannot work (the message names the setting and its value).

    Here (spur_cad.sim.simulate re-exports it) so that the job's [simulation] section refuses a bad value when it
    is made without importing the simulator."""


class WorkLimitError(SpurCadError, ValueError):
    """Input that would need more work (moves, points, memory) than spur_cad's limits allow; raised
    before the work is done, naming the quantity, the limit and what to change."""


class ArgumentError(SpurCadError, TypeError):
    """A public function called with an argument of the wrong kind; the message names the argument."""


def require_instance(value: object, expected: type | tuple[type, ...], argument: str) -> None:
    """Raise ArgumentError naming `argument` unless `value` is an instance of `expected`."""
    if not isinstance(value, expected):
        names = " or ".join(t.__name__ for t in (expected if isinstance(expected, tuple) else (expected,)))
        raise ArgumentError(f"{argument} must be a {names}, got {type(value).__name__}")


class JobFileError(SpurCadError, ValueError):
    """A job file that cannot be read: bad TOML, unknown key, wrong type, missing value."""


class PostError(SpurCadError, ValueError):
    """A post setting or a toolpath the chosen controller cannot take; the message names it.

    Here (not in spur_cad.post.settings) so that the dialect table and the settings both import it
    and neither imports the other."""


MAX_SHOWN_CHARS = 60
"""User text a message echoes (a value, a key, a name) is cut to about this many characters."""
MAX_SHOWN_PATH_CHARS = 160
MAX_MESSAGE_CHARS = 380
"""A message is cut to this many characters (its start, which names the file and key, kept): with the
command line's `spur-cad: error: ` a line stays below 400."""
_UNPRINTABLE = re.compile(r"[^\S ]|[\x00-\x1f\x7f-\x9f\u2028\u2029\u200b-\u200f\u202a-\u202e\u2066-\u2069"
                          r"\ud800-\udfff]")  # controls, line and paragraph breaks, direction marks, lone surrogates


def escaped(text: str) -> str:
    """`text` with every control or line-breaking character written as an escape (\\n, \\x1b, \\u2028): one
    line that no terminal interprets, and that cannot start a forged `spur-cad:` line."""
    return _UNPRINTABLE.sub(lambda match: repr(match.group(0))[1:-1], text)


def _cut(text: str, limit: int, keep_end: bool = False) -> str:
    if len(text) <= limit:
        return text
    if keep_end:  # a path: its start and its end (the file's name) both say something
        head = limit // 3
        return f"{text[:head]}...{text[-(limit - head - 3):]}"
    suffix = f"... ({len(text):,} characters)"
    return text[:max(0, limit - len(suffix))] + suffix


def shown(value: object, limit: int = MAX_SHOWN_CHARS) -> str:
    """A value as a message echoes it: quoted text with control characters escaped, cut to `limit`
    characters; no 5000-digit integer is written out (Python refuses to, and nobody reads it)."""
    if isinstance(value, bool):
        return repr(value)
    if isinstance(value, int):
        digits = int(abs(value).bit_length() * 0.30103) + 1
        return repr(value) if digits <= 20 else f"a {digits}-digit number"
    if isinstance(value, str):
        text = escaped(value[:limit].replace("'", "\\'"))
        return f"'{text}'" if len(value) <= limit else f"'{text}...' ({len(value):,} characters)"
    try:
        text = repr(value)
    except ValueError:  # e.g. a list holding a huge integer
        return f"a {type(value).__name__}"
    return _cut(escaped(text), limit)


def shown_path(path: object, limit: int = MAX_SHOWN_PATH_CHARS) -> str:
    """A file or folder name as a message names it: unquoted, control characters escaped, long names cut in
    the middle."""
    text = os.fsdecode(path) if isinstance(path, (str, bytes, os.PathLike)) else str(path)
    return _cut(escaped(text), limit, keep_end=True)


def one_line(message: str, limit: int = MAX_MESSAGE_CHARS) -> str:
    """A message as the command line prints it: one line (control characters escaped), at most `limit`."""
    return _cut(escaped(message), limit)
