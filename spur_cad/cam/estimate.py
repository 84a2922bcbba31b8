"""Path lengths, move counts and cycle time of a toolpath on a machine.

Each move takes max(length / feed, rotary angle / rotary speed, block processing time): the
length is the tool tip's path relative to the part; rapids run at the machine's rapid feed;
inverse-time moves take 1 / F minutes as programmed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from spur_cad.cam.ir import MoveKind, Toolpath, relative_path_lengths
from spur_cad.cam.machine import Machine


@dataclass(frozen=True)
class Estimate:
    """Moves, cutting and rapid path lengths (relative to the part) and cycle time of one operation."""

    moves: int
    cutting_length_mm: float
    rapid_length_mm: float
    time_s: float

    def as_dict(self) -> dict[str, float | int]:
        return dict(self.__dict__)


def estimate(path: Toolpath, machine: Machine) -> Estimate:
    """Cycle-time estimate of one operation (pure function)."""
    motion = path.motion_mask
    if not motion.any():
        return Estimate(int(len(path)), 0.0, 0.0, len(path) * machine.block_time_s)

    x0, y0, z0, a0 = path.start_poses().T
    length = relative_path_lengths(x0, y0, z0, a0, path.x, path.y, path.z, path.a, substeps=8)
    rotary = np.abs(path.a - a0)
    rapid = path.kind == MoveKind.RAPID
    linear = path.kind == MoveKind.LINEAR
    minutes = np.zeros(len(path))
    minutes[rapid] = length[rapid] / machine.rapid_feed_mm_min
    inverse = linear & path.inverse_time
    plain = linear & ~path.inverse_time
    minutes[inverse] = 1.0 / path.feed[inverse]
    minutes[plain] = length[plain] / path.feed[plain]
    minutes = np.maximum(minutes, rotary / machine.max_rotary_speed_deg_min)
    seconds = np.maximum(minutes * 60.0, machine.block_time_s)
    return Estimate(int(len(path)), float(length[linear].sum()), float(length[rapid].sum()), float(seconds.sum()))
