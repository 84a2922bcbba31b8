"""Exception types: every error a user can cause is a SpurCadError with a specific message."""

from __future__ import annotations


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
