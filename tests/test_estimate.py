"""The acceleration-aware cycle time against trapezoidal profiles computed by hand."""

from __future__ import annotations

import math

import pytest

from spur_cad.cam.estimate import estimate
from spur_cad.cam.ir import MoveKind, Operation, ToolpathBuilder
from spur_cad.cam.machine import Machine

MACHINE = Machine(x_acceleration_mm_s2=1000.0, y_acceleration_mm_s2=1000.0, z_acceleration_mm_s2=1000.0,
                  a_acceleration_deg_s2=1500.0, block_time_s=0.0, max_rotary_speed_deg_min=3600.0,
                  path_tolerance_mm=0.0)


def path_of(*moves, feed=6000.0):
    builder = ToolpathBuilder(Operation.FINISHING, 1, 1000.0)
    builder.move(MoveKind.RAPID, 0.0, 0.0, 10.0, 0.0)  # the start (its own move has no length)
    for x, y, z, a in moves:
        builder.move(MoveKind.LINEAR, x, y, z, a, feed)
    return builder.build()


def trapezoid(length, speed, accel):
    """Rest to rest: accelerate to `speed` (or as far as the length allows), cruise, brake."""
    if speed**2 / accel <= length:
        return 2 * speed / accel + (length - speed**2 / accel) / speed
    return 2 * math.sqrt(accel * length) / accel


def test_one_long_move_accelerates_cruises_and_brakes():
    result = estimate(path_of((100.0, 0.0, 10.0, 0.0)), MACHINE)
    assert result.time_s == pytest.approx(1.0)  # 100 mm at 100 mm/s
    assert result.time_with_acceleration_s == pytest.approx(trapezoid(100.0, 100.0, 1000.0))  # 1.1 s


def test_a_short_move_never_reaches_its_feed():
    result = estimate(path_of((1.0, 0.0, 10.0, 0.0)), MACHINE)
    assert result.time_with_acceleration_s == pytest.approx(2 * math.sqrt(1000.0 * 1.0) / 1000.0)


def test_collinear_moves_do_not_stop_between_them():
    result = estimate(path_of((50.0, 0.0, 10.0, 0.0), (100.0, 0.0, 10.0, 0.0)), MACHINE)
    assert result.time_with_acceleration_s == pytest.approx(trapezoid(100.0, 100.0, 1000.0))


def test_a_sharp_corner_without_tolerance_is_an_exact_stop():
    result = estimate(path_of((50.0, 0.0, 10.0, 0.0), (50.0, 50.0, 10.0, 0.0)), MACHINE)
    assert result.time_with_acceleration_s == pytest.approx(2 * trapezoid(50.0, 100.0, 1000.0))


def test_a_path_tolerance_lets_the_corner_be_taken_faster():
    corner = (50.0, 0.0, 10.0, 0.0), (50.0, 50.0, 10.0, 0.0)
    exact = estimate(path_of(*corner), MACHINE).time_with_acceleration_s
    rounded = estimate(path_of(*corner), Machine(**{**MACHINE.__dict__, "path_tolerance_mm": 0.05}))
    # Junction speed from a centripetal acceleration a on the arc within the tolerance: v^2 = a d s/(1-s),
    # s = sin(45 deg) for a right angle.
    s = math.sin(math.radians(45.0))
    v = math.sqrt(1000.0 * 0.05 * s / (1.0 - s))
    # Each leg: accelerate (or brake) between rest and 100 mm/s, brake (or accelerate) between 100 mm/s and
    # v at the corner, cruise in between.
    ramp_rest, ramp_corner = 100.0**2 / 2000.0, (100.0**2 - v**2) / 2000.0
    expected = 2 * (100.0 / 1000.0 + (100.0 - v) / 1000.0 + (50.0 - ramp_rest - ramp_corner) / 100.0)
    assert rounded.time_with_acceleration_s == pytest.approx(expected)
    assert rounded.time_with_acceleration_s < exact


def test_the_rotary_axis_limits_a_pure_a_move():
    result = estimate(path_of((0.0, 0.0, 10.0, 90.0)), MACHINE)
    assert result.time_s == pytest.approx(1.5)  # 90 deg at 60 deg/s
    assert result.time_with_acceleration_s == pytest.approx(trapezoid(90.0, 60.0, 1500.0))


def _sequential_plan(lengths, nominal, accel, junction, stops):
    """The look-ahead plan as a controller makes it: a backward pass, then a forward pass, move by move."""
    n = len(lengths)
    entry, exit_ = [0.0] * n, [0.0] * n
    following = 0.0
    for i in range(n - 1, -1, -1):
        limit = 0.0 if (i == n - 1 or stops[i]) else min(junction[i], following)
        exit_[i] = min(limit, nominal[i])
        entry[i] = min(nominal[i], math.sqrt(exit_[i] ** 2 + 2.0 * accel[i] * lengths[i]))
        following = entry[i]
    previous = 0.0
    for i in range(n):
        entry[i] = min(entry[i], 0.0 if (i == 0 or stops[i - 1]) else previous)
        exit_[i] = min(exit_[i], math.sqrt(entry[i] ** 2 + 2.0 * accel[i] * lengths[i]))
        previous = exit_[i]
    return entry, exit_


def _sequential_seconds(lengths, nominal, accel, entry, exit_):
    seconds = []
    for length, vmax, a, v0, v1 in zip(lengths, nominal, accel, entry, exit_):
        up, down = (vmax**2 - v0**2) / (2 * a), (vmax**2 - v1**2) / (2 * a)
        if up + down <= length:
            seconds.append((vmax - v0) / a + (vmax - v1) / a + (length - up - down) / vmax)
        else:
            peak = math.sqrt((2 * a * length + v0**2 + v1**2) / 2)
            seconds.append((peak - v0) / a + (peak - v1) / a)
    return seconds


@pytest.mark.parametrize("seed", range(6))
def test_the_scanned_plan_is_the_backward_and_forward_passes(seed):
    """plan_velocities scans the passes' min-plus recurrences by doubling (no numba): on random moves (short and long,
    stops between some, corners of every sharpness and straight junctions without a limit) it gives the speeds of
    the two passes run move by move, and trapezoid_seconds their times, to rounding."""
    import numpy as np

    from spur_cad.cam.estimate import plan_velocities, trapezoid_seconds

    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 3000))
    lengths = rng.exponential(1.0, n) * rng.choice([0.001, 0.1, 5.0, 200.0], n)
    nominal, accel = rng.uniform(0.5, 300.0, n), rng.uniform(50.0, 5000.0, n)
    junction = np.where(rng.random(n) < 0.3, np.inf, rng.uniform(0.0, 200.0, n))
    stops = rng.random(n) < [0.0, 0.002, 0.05, 0.5, 0.9, 1.0][seed]
    entry, exit_ = plan_velocities(lengths, nominal, accel, junction, stops)
    want_entry, want_exit = _sequential_plan(lengths, nominal, accel, junction, stops)
    np.testing.assert_allclose(entry, want_entry, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(exit_, want_exit, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(trapezoid_seconds(lengths, nominal, accel, entry, exit_),
                               _sequential_seconds(lengths, nominal, accel, want_entry, want_exit), rtol=1e-9)
