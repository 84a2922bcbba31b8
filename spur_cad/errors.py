"""Exception types: every error a user can cause is a SpurCadError with a specific message."""

from __future__ import annotations


class SpurCadError(Exception):
    """Base class for errors caused by user input; the CLI and GUI show the message only.

    `field` names the offending input (a job-file key of the section the error is about) when
    one input is to blame; the job loader then points at that key's line.
    """

    def __init__(self, *args: object, field: str | None = None):
        super().__init__(*args)
        self.field = field


class GearSpecError(SpurCadError, ValueError):
    """A gear specification that cannot be made (or cut) as given.

    `field` names the offending input (a GearSpec field name) when one input is to blame.
    """

    def __init__(self, message: str, field: str | None = None):
        super().__init__(message, field=field)


class JobFileError(SpurCadError, ValueError):
    """A job file that cannot be read: bad TOML, unknown key, wrong type, missing value."""
