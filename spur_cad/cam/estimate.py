"""Path lengths, move counts and two cycle-time estimates of a toolpath on a machine.

Feed-bound: each move takes max(length / feed, rotary angle / rotary speed, block processing
time): the length is the tool tip's path relative to the part; rapids run at the machine's
rapid feed; inverse-time moves take 1 / F minutes as programmed.

With acceleration: the moves' feed-bound speeds are the cruise limits of a look-ahead velocity
plan as machine controllers make it: every move is a trapezoidal speed profile (constant
acceleration, cruise, constant braking) along its straight line in joint space (X, Y, Z mm, A
deg), with the largest acceleration that keeps every axis within `[machine] x/y/z_acceleration_mm_s2`
and `a_acceleration_deg_s2`; the speed through a junction is limited by the corner the control may
round within `path_tolerance_mm` (centripetal acceleration on that arc, the junction-deviation rule
of look-ahead planners such as grbl's) and by both moves' speeds; markers and the ends of the
program are exact stops; a backward and a forward pass make every profile reachable. Jerk limits
and the control's own block look-ahead depth are not modelled (docs/cam.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from spur_cad.cam.ir import MoveKind, Toolpath, arc_sweeps_rad, relative_path_lengths
from spur_cad.cam.machine import Machine


@dataclass(frozen=True)
class Estimate:
    """Moves, cutting and rapid path lengths (relative to the part) and cycle time of one operation."""

    moves: int
    cutting_length_mm: float
    rapid_length_mm: float
    time_s: float  # feed-bound: every move at its programmed feed from start to end
    time_with_acceleration_s: float  # look-ahead trapezoidal profiles with the machine's accelerations


def move_seconds(path: Toolpath, machine: Machine) -> np.ndarray:
    """Feed-bound seconds of every move (at least the block time), e.g. to compare parts of a toolpath."""
    if not path.motion_mask.any():
        return np.full(len(path), machine.block_time_s)
    return _lengths_and_minutes(path, machine)[2]


def _lengths_and_minutes(path: Toolpath, machine: Machine) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Relative path length, feed-bound minutes and seconds (at least the block time) of every move."""
    x0, y0, z0, a0 = path.start_poses().T
    length = relative_path_lengths(x0, y0, z0, a0, path.x, path.y, path.z, path.a, substeps=8)
    if path.center_x is not None:  # arcs (3-axis paths): their own length, not the chord's
        radius, sweep = arc_sweeps_rad(path)
        arcs = path.arc_mask
        length[arcs] = np.hypot(radius[arcs] * sweep[arcs], path.z[arcs] - z0[arcs])
    rotary = np.abs(path.a - a0)
    rapid = path.kind == MoveKind.RAPID
    linear = path.feed_mask
    minutes = np.zeros(len(path))
    minutes[rapid] = length[rapid] / machine.rapid_feed_mm_min
    inverse = linear & path.inverse_time
    plain = linear & ~path.inverse_time
    minutes[inverse] = 1.0 / path.feed[inverse]
    minutes[plain] = length[plain] / path.feed[plain]
    minutes = np.maximum(minutes, rotary / machine.max_rotary_speed_deg_min)
    return length, minutes, np.maximum(minutes * 60.0, machine.block_time_s)


def estimate(path: Toolpath, machine: Machine) -> Estimate:
    """Cycle-time estimate of one operation (pure function)."""
    if not path.motion_mask.any():
        return Estimate(int(len(path)), 0.0, 0.0, len(path) * machine.block_time_s, len(path) * machine.block_time_s)
    length, minutes, seconds = _lengths_and_minutes(path, machine)
    rapid = path.kind == MoveKind.RAPID
    linear = path.feed_mask
    with_acceleration = acceleration_aware_seconds(path, machine, np.where(path.motion_mask, minutes * 60.0, 0.0))
    return Estimate(int(len(path)), float(length[linear].sum()), float(length[rapid].sum()), float(seconds.sum()),
                    float(with_acceleration.sum()))


def _min_plus_scan(own: np.ndarray, gain: np.ndarray) -> np.ndarray:
    """y_i = min(own_i, y_(i-1) + gain_i) for every i, gain_i = inf restarting at y_i = own_i (gain_0 must be).

    Each step is the map y -> min(own, y + gain); two maps compose to one, (own_1, gain_1) then (own_2, gain_2)
    being (min(own_2, own_1 + gain_2), gain_1 + gain_2), so a prefix scan by doubling gives every y_i in as many
    passes as the longest chain between restarts has binary digits. Gains are summed within the chain only, so
    the figures keep their own precision however long the path."""
    own, gain = own.copy(), gain.copy()
    step = 1
    while step < len(own) and np.isfinite(gain[step:]).any():
        own[step:] = np.minimum(own[step:], own[:-step] + gain[step:])
        gain[step:] = gain[:-step] + gain[step:]
        step *= 2
    return own


def plan_velocities(lengths: np.ndarray, nominal: np.ndarray, accel: np.ndarray, junction: np.ndarray,
                    stops: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Look-ahead velocity planning over a move sequence: the largest entry/exit speeds that respect each move's
    nominal speed and acceleration and each junction's speed limit, as a backward then a forward pass over the
    moves gives them (a stop after move i where stops[i], and after the last).

    In squared speeds each pass is a min-plus recurrence, entry_i = min(c_i, entry_(i+1) + 2 a_i L_i) backward and
    exit_i = min(k_i, exit_(i-1) + 2 a_i L_i) forward, restarted at every stop (_min_plus_scan)."""
    n = len(lengths)
    if n == 0:
        return np.zeros(0), np.zeros(0)
    gain = 2.0 * accel * lengths  # v^2 gained (or lost) over a move at full acceleration
    top = nominal * nominal
    linked = ~np.asarray(stops, bool)
    linked[-1] = False  # move i runs on into move i + 1 without a stop
    with np.errstate(over="ignore"):
        corner = np.where(linked, np.minimum(junction * junction, top), 0.0)  # exit^2 before looking further ahead
    # backward: entry_i = min(top_i, corner_i + gain_i, entry_(i+1) + gain_i) where linked, min(top_i, gain_i) not
    own = np.minimum(top, corner + gain)
    entry2 = _min_plus_scan(own[::-1], np.where(linked, gain, np.inf)[::-1])[::-1]
    exit2 = np.where(linked, np.minimum(corner, np.append(entry2[1:], 0.0)), 0.0)
    # forward: a chain starts at rest; exit_i = min(exit2_i, entry_i' + gain_i), entry_i' = min(entry2_i, exit_(i-1))
    follows = np.concatenate([[False], linked[:-1]])  # move i runs on from move i - 1
    first = np.where(follows, np.minimum(exit2, entry2 + gain), np.minimum(exit2, gain))
    exit_final = _min_plus_scan(first, np.where(follows, gain, np.inf))
    entry_final = np.where(follows, np.minimum(entry2, np.concatenate([[0.0], exit_final[:-1]])), 0.0)
    return np.sqrt(entry_final), np.sqrt(exit_final)


def trapezoid_seconds(lengths: np.ndarray, nominal: np.ndarray, accel: np.ndarray, entry: np.ndarray,
                      exit_: np.ndarray) -> np.ndarray:
    """Time of each move under a trapezoidal speed profile from `entry` to `exit_`, cruising at most at `nominal`
    (0 for a move of no length)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        accelerating = (nominal * nominal - entry * entry) / (2.0 * accel)
        braking = (nominal * nominal - exit_ * exit_) / (2.0 * accel)
        cruising = (nominal - entry) / accel + (nominal - exit_) / accel + (lengths - accelerating - braking) / nominal
        peak = np.sqrt((2.0 * accel * lengths + entry * entry + exit_ * exit_) / 2.0)
        peaking = (peak - entry) / accel + (peak - exit_) / accel
        seconds = np.where(accelerating + braking <= lengths, cruising, peaking)
    return np.where(lengths > 0.0, seconds, 0.0)


def acceleration_aware_seconds(path: Toolpath, machine: Machine, feed_bound_seconds: np.ndarray) -> np.ndarray:
    """Seconds of every move when the axes accelerate as the machine allows (see the module docstring).

    Each move is a straight line in joint space (X, Y, Z in mm, A in deg; an arc: its chord, an approximation)
    run at its feed-bound nominal speed at most; its acceleration along the line is the largest that keeps
    every axis within its limit. At a junction the speed is limited as a controller that rounds corners within the path
    tolerance limits it (centripetal acceleration on the largest arc within the tolerance: the "junction
    deviation" rule of look-ahead planners); markers (clamp codes) and the ends are exact stops.
    """
    start = path.start_poses()
    delta = path.poses() - start
    lengths = np.linalg.norm(delta, axis=1)
    limits = np.array([machine.x_acceleration_mm_s2, machine.y_acceleration_mm_s2, machine.z_acceleration_mm_s2,
                       machine.a_acceleration_deg_s2])
    with np.errstate(divide="ignore", invalid="ignore"):
        direction = np.where(lengths[:, None] > 0.0, delta / lengths[:, None], 0.0)
        accel = np.min(np.where(np.abs(direction) > 0.0, limits / np.abs(direction), np.inf), axis=1)
        nominal = np.where(feed_bound_seconds > 0.0, lengths / feed_bound_seconds, 0.0)
    accel = np.where(np.isfinite(accel), accel, limits.min())
    motion = path.motion_mask & (lengths > 0.0) & (nominal > 0.0)
    cos_turn = np.einsum("ij,ij->i", direction[:-1], direction[1:])  # between move i and i + 1
    sin_half = np.sqrt(np.clip((1.0 + cos_turn) / 2.0, 0.0, 1.0))  # of the angle between -u_i and u_{i+1}
    with np.errstate(divide="ignore"):
        junction = np.sqrt(np.minimum(accel[:-1], accel[1:]) * machine.path_tolerance_mm * sin_half
                           / np.maximum(1.0 - sin_half, 1e-12))
    junction = np.where(sin_half >= 1.0 - 1e-12, np.inf, junction)  # straight on: no corner to round
    junction = np.append(junction, 0.0)
    stops = ~motion | np.append(~motion[1:], True)
    idx = np.nonzero(motion)[0]
    seconds = np.full(len(path), machine.block_time_s)
    if len(idx):
        keep = np.zeros(len(path), bool)
        keep[idx] = True
        # Junction limits between consecutive motion rows; a stop wherever the next row is not motion.
        entry, exit_ = plan_velocities(lengths[idx], nominal[idx], accel[idx], junction[idx], stops[idx])
        seconds[idx] = np.maximum(trapezoid_seconds(lengths[idx], nominal[idx], accel[idx], entry, exit_),
                                  machine.block_time_s)
    return seconds
