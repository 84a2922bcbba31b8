"""LinuxCNC's joint compensation, re-implemented for the tests from LinuxCNC's own source (LinuxCNC/linuxcnc, commit
5c41560ebbc3a40f84a5547bc6f7c5cd9278ba6b), not from spur_cad:

- loading: src/emc/motion/usrmotintf.cc, usrmotLoadComp (lines 634-684): each line is read with
  sscanf("%lf %lf %lf") and loading stops at the first line that is not three numbers; COMP_FILE_TYPE 0 gives
  'nominal forward_actual reverse_actual', stored as trims nom - fwd and nom - rev; any other type takes the trims
  as written;
- storing: src/emc/motion/command.c, EMCMOT_SET_JOINT_COMP (lines 1956-1989): more than EMCMOT_COMP_SIZE = 256
  entries (src/emc/motion/motion.h line 396) is an error ("too many compensation entries"), and so is a nominal
  not above the previous one ("compensation values must increase"); both drop the entry; the first entry's trims
  are also taken below it (the -DBL_MAX entry, motion.c lines 936-952), the last entry's slope stays zero;
- applying: src/emc/motion/control.c, compute_screw_comp (lines 1686-1726): the trim at the commanded joint
  position, linear between the entries, forward trim when moving up, reverse when moving down; output_to_hal
  (lines 2046-2047) adds it: motor_pos_cmd = pos_cmd + backlash_filt (+ motor_offset).
- [JOINT_n] COMP_FILE_TYPE defaults to 0 (src/emc/ini/inijoint.cc line 182, findIntV(..., 0, 0, 1)); the values are
  in the joint's machine units, degrees with [TRAJ] ANGULAR_UNITS = degree (docs/src/config/ini-config.adoc
  lines 1111-1145, 939-940).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

EMCMOT_COMP_SIZE = 256


class CompError(ValueError):
    """What LinuxCNC's motion controller reports (reportError) for an entry it drops."""


@dataclass(frozen=True)
class CompEntry:
    nominal: float
    fwd_trim: float
    rev_trim: float


def load_comp(text: str, comp_file_type: int) -> tuple[CompEntry, ...]:
    """The entries LinuxCNC keeps from a compensation file's text (usrmotLoadComp + EMCMOT_SET_JOINT_COMP); raises
    CompError where LinuxCNC reports an error, and counts how many lines it read (the caller compares with the
    file's lines: a line that is not three numbers silently ends the loading)."""
    entries: list[CompEntry] = []
    for line in text.splitlines():
        fields = line.split()
        try:
            nom, fwd, rev = (float(field) for field in fields[:3])
        except ValueError:
            break
        if comp_file_type == 0:
            fwd, rev = nom - fwd, nom - rev
        if len(entries) >= EMCMOT_COMP_SIZE:
            raise CompError("too many compensation entries")
        if entries and nom <= entries[-1].nominal:
            raise CompError("compensation values must increase")
        entries.append(CompEntry(nom, fwd, rev))
    return tuple(entries)


def trim_at(entries: tuple[CompEntry, ...], pos_cmd: np.ndarray, moving_up: bool) -> np.ndarray:
    """compute_screw_comp's trim at the commanded joint positions: linear between entries, the end entries' trims
    beyond them."""
    nominal = np.array([entry.nominal for entry in entries])
    trims = np.array([entry.fwd_trim if moving_up else entry.rev_trim for entry in entries])
    pos = np.asarray(pos_cmd, dtype=float)
    index = np.clip(np.searchsorted(nominal, pos, side="right") - 1, 0, len(nominal) - 1)
    nxt = np.minimum(index + 1, len(nominal) - 1)
    span = nominal[nxt] - nominal[index]
    slope = np.where(span > 0.0, (trims[nxt] - trims[index]) / np.where(span > 0.0, span, 1.0), 0.0)
    below = pos < nominal[0]
    return np.where(below, trims[0], trims[index] + slope * (pos - nominal[index]))


def motor_command(entries: tuple[CompEntry, ...], pos_cmd: np.ndarray, moving_up: bool) -> np.ndarray:
    """output_to_hal's motor position for the commanded joint positions (motor_offset 0, the ramp settled)."""
    return np.asarray(pos_cmd, dtype=float) + trim_at(entries, pos_cmd, moving_up)
