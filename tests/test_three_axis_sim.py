"""The 3-axis cut simulated (spur_cad.sim.flat): swept areas of lines and arcs against a circle whose answer is known
in closed form, and the reference gear's plan against the exact outline measured independently here (the tool
centre walked densely from the IR's own ends and centres, the clearance of each exact design point from it)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

from spur_cad.cam.ir import MoveKind, Operation, ToolpathBuilder
from spur_cad.cam.machine import Machine, RoughingParams
from spur_cad.cam.three_axis import check_three_axis, finishing_toolpath, roughing_toolpath
from spur_cad.cam.tools import Tool
from spur_cad.geometry import GearSpec
from spur_cad.sim.design import DesignGrid
from spur_cad.sim.flat import simulate_flat, simulate_flat_grid
from spur_cad.sim.simulate import Cut, SimSettings

REFERENCE = GearSpec(teeth=23, module_mm=4.0, rack_tip_radius_mm=0.8, thickness_allowance_fraction=0.05,
                     face_width_mm=20.0)
SETTINGS = SimSettings(resolution_mm=0.005)


def flat(diameter_mm: float, number: int) -> Tool:
    return Tool(diameter_mm=diameter_mm, kind="flat", tool_number=number, cutting_speed_m_min=100.0,
                feed_per_tooth_mm=0.02)


def circle_grid(radius_mm: float, points: int, depths_mm: np.ndarray) -> DesignGrid:
    """A round part of `radius_mm` as a one-space design grid: points on the circle, normals outward."""
    angle = np.linspace(0.0, 2 * np.pi, points, endpoint=False)
    normals = np.stack([np.cos(angle), np.sin(angle)], axis=1)
    return DesignGrid(1, radius_mm * normals, normals, np.zeros(points, np.int8), np.zeros(points, np.int8),
                      radius_mm * angle, depths_mm, np.full(len(depths_mm), 1.0), 0.1)


def test_a_full_circle_and_a_line_cut_what_geometry_says():
    """A full-turn arc at R + r + e leaves e everywhere (to 1 nm); a line at Y = R + r - g across the top
    cuts the circle's top point g deep, and rows below its level keep e: levels cut upward only."""
    part, tool, leftover, gouge = 10.0, 1.0, 0.003, 0.004
    builder = ToolpathBuilder(Operation.FINISHING, 1, 1000.0)
    around = part + tool + leftover
    builder.move(MoveKind.LINEAR, around, 0.0, -5.0, 0.0, 100.0)
    builder.arc(False, around, 0.0, -5.0, 0.0, 0.0, 100.0)  # full turn, counterclockwise
    builder.move(MoveKind.RAPID, around, 0.0, 5.0, 0.0)
    builder.move(MoveKind.RAPID, -5.0, part + tool - gouge, 5.0, 0.0)
    builder.move(MoveKind.LINEAR, -5.0, part + tool - gouge, -2.0, 0.0, 100.0)
    builder.move(MoveKind.LINEAR, 5.0, part + tool - gouge, -2.0, 0.0, 100.0)
    grid = circle_grid(part, 720, np.array([1.0, 3.0]))
    result = simulate_flat_grid(grid, part + 2.0, [Cut(builder.build(), flat(2 * tool, 1))], SETTINGS, 4.0)
    deep, shallow = result.deviation[0, :, 1], result.deviation[0, :, 0]
    assert np.abs(deep - leftover).max() < 1e-6
    top = int(np.argmax(grid.points[:, 1]))
    assert shallow[top] == pytest.approx(-gouge, abs=1e-6)
    # the line's swept band (|Y - y_line| <= r) meets the circle's normal at the top point's neighbours too
    angle = np.arctan2(grid.points[:, 1], grid.points[:, 0])
    band = np.abs(np.cos(angle)) * part < 4.0  # well inside the line's X extent
    line_y = part + tool - gouge
    expected = np.where(band, np.minimum(leftover, (line_y - tool) / np.maximum(np.sin(angle), 1e-9) - part), leftover)
    assert np.abs(shallow - expected)[np.sin(angle) > 0.9].max() < 1e-6


def walked_centres(path, spacing_mm: float = 0.001) -> np.ndarray:
    """The tool centre on the deepest level, walked every `spacing_mm` along lines and arcs (centre and turn from the
    IR's start, end, centre and direction: this test's own arithmetic)."""
    z_min = path.z.min()
    x0, y0 = np.roll(path.x, 1), np.roll(path.y, 1)
    walked = []
    for i in np.flatnonzero(path.z == z_min)[1:]:
        if path.kind[i] in (MoveKind.ARC_CW, MoveKind.ARC_CCW):
            cx, cy = path.center_x[i], path.center_y[i]
            a0, a1 = math.atan2(y0[i] - cy, x0[i] - cx), math.atan2(path.y[i] - cy, path.x[i] - cx)
            ccw = path.kind[i] == MoveKind.ARC_CCW
            turn = (a1 - a0) % (2 * math.pi) if ccw else -((a0 - a1) % (2 * math.pi))
            r = math.hypot(x0[i] - cx, y0[i] - cy)
            a = a0 + turn * np.linspace(0.0, 1.0, max(2, math.ceil(abs(turn) * r / spacing_mm)))
            walked.append(np.stack([cx + r * np.cos(a), cy + r * np.sin(a)], axis=1))
        else:
            t = np.linspace(0.0, 1.0, max(2, math.ceil(math.hypot(path.x[i] - x0[i], path.y[i] - y0[i]) / spacing_mm)))
            walked.append(np.stack([x0[i] + (path.x[i] - x0[i]) * t, y0[i] + (path.y[i] - y0[i]) * t], axis=1))
    return np.concatenate(walked)


@pytest.fixture(scope="module")
def reference_plan():
    finishing, roughing = flat(2.0, 2), flat(3.5, 1)
    root = check_three_axis(REFERENCE, finishing, roughing)
    blank = REFERENCE.tip_radius_mm + 0.5
    rough, _, _ = roughing_toolpath(REFERENCE, roughing, Machine(), RoughingParams(), blank)
    finish, levels, _ = finishing_toolpath(REFERENCE, finishing, Machine(), 0.001, blank)
    return root, blank, Cut(rough, roughing), Cut(finish, finishing), -np.array(levels)


def deepest_row_deviations(result, finishing: Cut, chosen: np.ndarray):
    """(simulated deviation, independent deviation) of the deepest row's design points `chosen` (a mask over one
    space's points) in every space: the independent one is the design point's clearance from the walked tool centre
    less the tool radius."""
    tree = cKDTree(walked_centres(finishing.path))
    simulated, independent = [], []
    for k in range(result.grid.teeth):
        clearance, _ = tree.query(result.grid.space_points(k)[chosen])
        independent.append(clearance - finishing.tool.diameter_mm / 2.0)
        simulated.append(result.deviation[k, chosen, -1])
    return np.concatenate(simulated), np.concatenate(independent)


def involute_check(result, finishing: Cut, lowest_radius_mm: float):
    """deepest_row_deviations of the involute points above `lowest_radius_mm` and 0.05 mm below the tip (at the
    tip's corner a gouge read along the normal is deeper than the distance into the tool)."""
    grid = result.grid
    names = np.array(grid.feature_names())
    radius = np.hypot(*grid.points.T)
    involute = np.char.endswith(names.astype(str), "involute") & (radius >= lowest_radius_mm) \
        & (radius <= REFERENCE.tip_radius_mm - 0.05)
    return deepest_row_deviations(result, finishing, involute)


@pytest.mark.slow  # the lying-flat cut graded end to end (10 s); its level and row checks stay in the fast tier
def test_the_reference_gear_cut_lying_flat_measures_as_the_exact_outline_says(reference_plan):
    """No gouge beyond 1 um on the involute, leftover within the 5 um scallop target, each point's deviation as
    the independent clearance says (within 0.2 um); graded class 1 (an ideal machine); a finishing path moved
    3 um sideways gouges about 3 um on one side of each space and reads so in both measures."""
    root, blank, rough, finish, depths = reference_plan
    result = simulate_flat(REFERENCE, blank, [rough, finish], SETTINGS, depths)
    simulated, independent = involute_check(result, finish, root.form_radius_mm)
    assert simulated.min() >= -0.001 and simulated.max() <= 0.005
    assert np.abs(simulated - independent).max() < 0.0002
    assert result.max_gouge_mm <= 0.001  # fillet and root too (the tool D2 follows the rack's fillet)
    from spur_cad.grade.simulated import grade_simulation

    assert grade_simulation(REFERENCE, result, root.form_radius_mm).overall_class <= 2

    shift = 0.003
    moved = dataclasses.replace(finish.path, x=finish.path.x + shift, center_x=finish.path.center_x + shift)
    planted = Cut(moved, finish.tool)
    wrong = simulate_flat(REFERENCE, blank, [rough, planted], SETTINGS, depths)
    simulated, independent = involute_check(wrong, planted, root.form_radius_mm)
    assert simulated.min() < -0.002 and np.abs(simulated - independent).max() < 0.0002


def test_rows_above_a_level_are_cut_only_by_levels_at_or_above_them(reference_plan):
    """The finishing path stopped at its last level above half the face width leaves the rows below that level
    with the roughing's finish stock."""
    _, blank, rough, finish, depths = reference_plan
    path = finish.path
    stop = int(np.argmax(path.z < -REFERENCE.face_width_mm / 2.0 - 1e-9))  # the levels run from the top down
    names = ("kind", "x", "y", "z", "a", "feed", "inverse_time", "space", "station", "feature", "center_x", "center_y")
    shallow = Cut(dataclasses.replace(path, **{name: getattr(path, name)[:stop] for name in names}), finish.tool)
    result = simulate_flat(REFERENCE, blank, [rough, shallow], SETTINGS, depths)
    names = np.array(result.grid.feature_names())
    involute = np.char.endswith(names.astype(str), "involute")
    lowest_kept = -float(path.z[:stop].min())
    upper = result.grid.rows_x <= lowest_kept + 1e-9
    lower = result.grid.rows_x > lowest_kept + 1e-6
    assert result.deviation[:, involute][:, :, upper].max() <= 0.005
    stock = RoughingParams().finish_stock_mm
    assert result.deviation[:, involute][:, :, lower].min() >= stock - 0.01
