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
