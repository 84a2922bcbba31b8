"""What `spur-cad correct` changes in the programs for the table's error and an off-centre blank (docs/correction.md,
issue 46), and the record of it (AppliedCorrection, which correction.json and the report's Correction section show).

- The table: every block's A moved by -e(A) at its own commanded A (table_corrected): the table then stands at
  A - e(A) + e(A - e(A)), the commanded A within e's change over e itself (25 arcsec of a 25 arcsec once-per-turn
  error: 1e-4 arcsec).
- An off-centre blank: every block's Y and Z moved by the datum axis's offset turned to that block's A
  (blank_corrected): the part frame's origin, the gear's datum, is then where the program assumes the A axis.
- Both differ from block to block, so a folded program (one subprogram for every space, the space's A base its only
  parameter) cannot carry them: the corrected programs are written unfolded.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from spur_cad.correct.table import TableError
from spur_cad.geometry.frames import turn_points_by

ONCE_PER_TURN_MODELS = ("table", "blank")
"""What a once-per-turn error found on a datum-axis scan is taken for: the table's e(A) (corrected in the A words,
right for every later blank) or a blank off the A axis (corrected in Y and Z, right for this set-up only)."""


@dataclass(frozen=True)
class AppliedCorrection:
    """What the corrected programs change: the finishing tool's programmed diameter (mm), the orders of the table's
    e(A) moved out of the A words, the blank offset moved out of Y and Z (the datum axis from the A axis in the
    table's frame at A 0, um; None when not applied), which model a once-per-turn error was taken for (None without
    one), whether the programs were unfolded, and why the slopes were not corrected (None when they were)."""

    diameter_before_mm: float
    diameter_programmed_mm: float
    table_orders: tuple[int, ...]
    blank_offset_um: tuple[float, float] | None
    once_per_turn: str | None
    unfolded: bool
    slopes_not_corrected: str | None

    def __post_init__(self) -> None:
        if self.once_per_turn not in (None, *ONCE_PER_TURN_MODELS):
            raise ValueError(f"once_per_turn must be one of {ONCE_PER_TURN_MODELS} or None, got {self.once_per_turn!r}")
        if not (self.diameter_before_mm > 0.0 and self.diameter_programmed_mm > 0.0):
            raise ValueError("the finishing tool's diameters must be positive")
        if self.blank_offset_um is not None and not all(map(math.isfinite, self.blank_offset_um)):
            raise ValueError(f"blank offset {self.blank_offset_um} must be finite")

    @property
    def per_block(self) -> bool:
        """Whether a correction differs from block to block (and the programs are unfolded)."""
        return bool(self.table_orders) or self.blank_offset_um is not None


def table_corrected(path, table: TableError, orders: tuple[int, ...]):
    """The toolpath with every row's A moved by -e(A) of the given kept orders, e evaluated at the row's own A."""
    if not orders:
        return path
    return path.replace(a=path.a - table.at(path.a, orders) / 3600.0)


def blank_corrected(path, datum_offset_um: tuple[float, float]):
    """The toolpath with every row's Y and Z moved by the datum axis's offset from the A axis (um, the table's frame
    at A 0) turned to the row's A: a part point p about the datum is at R(A) (p + b) in the machine."""
    by, bz = np.asarray(datum_offset_um, dtype=float) / 1000.0
    moved = turn_points_by(np.array([[by, bz]]), np.radians(path.a))[:, 0]  # R(A) b at each row's A
    return path.replace(y=path.y + moved[:, 0], z=path.z + moved[:, 1])


LINUXCNC_COMP_SIZE = 256
"""The most entries LinuxCNC's motion controller takes in one joint's compensation table (EMCMOT_COMP_SIZE,
src/emc/motion/motion.h; command.c's EMCMOT_SET_JOINT_COMP refuses more, "too many compensation entries")."""


def linuxcnc_compensation(table: TableError, orders: tuple[int, ...], a_range_deg: tuple[float, float]) -> str:
    """A LinuxCNC joint compensation file for the A joint, for [JOINT_n] COMP_FILE with COMP_FILE_TYPE = 1 (which
    must be set: LinuxCNC's default, 0, reads the columns as actual positions): per line 'nominal forward_trim
    reverse_trim' in degrees (the joint's machine units with [TRAJ] ANGULAR_UNITS = degree), nominal strictly
    increasing, at most LINUXCNC_COMP_SIZE lines, nothing else in the file (LinuxCNC's loader stops at the first line
    that is not three numbers).

    The trim is what LinuxCNC adds to the commanded joint position (control.c: motor_pos_cmd = pos_cmd +
    backlash_filt, interpolated linearly between nominals, held at the end values outside the table), so trim =
    nominal - actual = -e(A) (usrmotintf.cc usrmotLoadComp: a type 0 file's actual positions become nom - actual):
    the table then stands at A - e(A) + e(A - e(A)), A within e's change over e (as table_corrected). Both
    directions alike: e(A) is a position error, no backlash.

    The nominals cover the A the programs command and the turn 0 to 360 deg (a [AXIS_A] WRAPPED_ROTARY machine
    commands the joint there), each widened by a step, at whole-degree steps as fine as the entry limit allows."""
    low = min(a_range_deg[0], 0.0)
    high = max(a_range_deg[1], 360.0)
    step = max(1.0, math.ceil((high - low) / (LINUXCNC_COMP_SIZE - 5)))  # lines <= span / step + 5
    start = (math.floor(low / step) - 1) * step
    stop = (math.ceil(high / step) + 1) * step
    nominal = start + step * np.arange(int(round((stop - start) / step)) + 1)
    trim = -table.at(nominal, orders) / 3600.0
    return "".join(f"{a:.4f} {t:.7f} {t:.7f}\n" for a, t in zip(nominal, trim))
