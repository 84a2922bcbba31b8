"""A rotary table's calibration table ([machine] rotary_calibration_file): the error of A at each angle, as
machines' compensation tables hold it, read from a file the job names (spur_cad.job reads it; the error budget,
spur_cad.sim.budget, applies it)."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from spur_cad.errors import shown

MAX_TABLE_ERROR_ARCSEC = 3600.0
MAX_TABLE_ROWS = 100_000


@dataclass(frozen=True)
class CalibrationTable:
    """A rotary table's error at each A (deg, increasing in [0, 360]) in arcsec, read from a file; between its
    angles the error is interpolated linearly, around the turn (360 deg is 0)."""

    source: str
    a_deg: tuple[float, ...]
    error_arcsec: tuple[float, ...]

    def error_at(self, a_deg: np.ndarray) -> np.ndarray:
        """The error (arcsec) at angles A (deg, any turn)."""
        return np.interp(np.mod(a_deg, 360.0), self.a_deg, self.error_arcsec, period=360.0)


_SEPARATOR = re.compile(r"[\s,;]+")


def parse_calibration_table(text: str, source: str) -> CalibrationTable:
    """A table of lines 'A_deg error_arcsec' (space, comma or semicolon between; '#' starts a comment; blank
    lines skipped). ValueError with one line naming the table's line for anything else: not two numbers, a
    number that is not finite, A outside [0, 360] or not increasing, an error beyond +-3600 arcsec, fewer than
    two rows."""
    angles: list[float] = []
    errors: list[float] = []
    for number, line in enumerate(text.splitlines(), start=1):
        body = line.split("#", 1)[0].strip()
        if not body:
            continue
        fields = [f for f in _SEPARATOR.split(body) if f]
        try:
            a, e = (float(f) for f in fields) if len(fields) == 2 else (math.nan, math.nan)
        except ValueError:
            a = e = math.nan
        if not (math.isfinite(a) and math.isfinite(e)):
            raise ValueError(f"{source}:{number}: expected two finite numbers 'A_deg error_arcsec', got "
                             f"{shown(body, 60)}")
        if not 0.0 <= a <= 360.0 or (angles and a <= angles[-1]):
            raise ValueError(f"{source}:{number}: A = {a:g} deg must be in [0, 360] and above the line before's")
        if abs(e) > MAX_TABLE_ERROR_ARCSEC:
            raise ValueError(f"{source}:{number}: error {e:g} arcsec is beyond +-{MAX_TABLE_ERROR_ARCSEC:g} (1 deg): "
                             "a compensation table's entries are seconds of arc")
        if len(angles) >= MAX_TABLE_ROWS:
            raise ValueError(f"{source}:{number}: more than {MAX_TABLE_ROWS} rows")
        angles.append(a)
        errors.append(e)
    if len(angles) < 2:
        raise ValueError(f"{source}: a calibration table needs at least two rows 'A_deg error_arcsec'")
    if angles[0] == 0.0 and angles[-1] == 360.0 and errors[0] != errors[-1]:
        raise ValueError(f"{source}: A = 0 and A = 360 deg are the same place but have different errors")
    return CalibrationTable(source, tuple(angles), tuple(errors))
