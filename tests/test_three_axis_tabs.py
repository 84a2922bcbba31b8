"""Holding a through-cut gear in the 3-axis variant ([three_axis] tabs, onion_skin_mm): the tab's bridge is never
reached by a tool circle below its top (walked tool centres of both programs against points of the bridge), the
simulated cut leaves it on the chosen tips only, and an onion skin leaves the bottom uncut; rs274 accepts the
programs; the job file refuses tabs with a skin and heights beyond the face width."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

from spur_cad.cam.machine import Machine, RoughingParams
from spur_cad.cam.three_axis import finishing_toolpath, roughing_toolpath
from spur_cad.cam.three_axis_tabs import ThreeAxisSection
from spur_cad.post import ProgramInfo, post_program
from spur_cad.post.settings import PostSettings
from spur_cad.sim.flat import simulate_flat
from spur_cad.sim.simulate import Cut, SimSettings
from tests.rs274_helper import run_rs274
from tests.test_three_axis import MODULE_1, TOLERANCE_MM, exact_outline, flat

BLANK_MM = MODULE_1.tip_radius_mm + 0.5
TABS = ThreeAxisSection(tabs=2, tab_width_mm=1.0, tab_height_mm=1.5)


def centres_below(path, z_top: float, spacing_mm: float = 0.002) -> np.ndarray:
    """The tool centre walked along every line and arc cutting below `z_top` (this test's own walk)."""
    from spur_cad.cam.ir import MoveKind

    x0, y0, z0 = np.roll(path.x, 1), np.roll(path.y, 1), np.roll(path.z, 1)
    walked = []
    for i in range(1, len(path)):
        if min(path.z[i], z0[i]) >= z_top - 1e-9:
            continue
        if path.kind[i] in (MoveKind.ARC_CW, MoveKind.ARC_CCW):
            cx, cy = path.center_x[i], path.center_y[i]
            a0, a1 = math.atan2(y0[i] - cy, x0[i] - cx), math.atan2(path.y[i] - cy, path.x[i] - cx)
            turn = (a1 - a0) % (2 * math.pi) if path.kind[i] == MoveKind.ARC_CCW else -((a0 - a1) % (2 * math.pi))
            r = math.hypot(x0[i] - cx, y0[i] - cy)
            a = a0 + turn * np.linspace(0.0, 1.0, max(2, math.ceil(abs(turn) * r / spacing_mm)))
            walked.append(np.stack([cx + r * np.cos(a), cy + r * np.sin(a)], axis=1))
        else:
            t = np.linspace(0.0, 1.0, max(2, math.ceil(math.hypot(path.x[i] - x0[i], path.y[i] - y0[i]) / spacing_mm)))
            walked.append(np.stack([x0[i] + (path.x[i] - x0[i]) * t, y0[i] + (path.y[i] - y0[i]) * t], axis=1))
    return np.concatenate(walked)


def tab_tips() -> list[np.ndarray]:
    """Unit directions of the tips nearest the angles 90 deg + 180/z + k 360/2 (k = 0, 1): the middles of the exact
    outline's tip points."""
    outline, labels = exact_outline(MODULE_1, 0.01)
    tips = outline[labels == "tip"]
    found = []
    for k in range(2):
        angle = math.pi / 2 + math.pi / MODULE_1.teeth + k * math.pi
        near = tips[np.abs(np.angle(np.exp(1j * (np.arctan2(tips[:, 1], tips[:, 0]) - angle)))) < math.pi
                    / MODULE_1.teeth]
        middle = near.mean(axis=0)
        found.append(middle / np.hypot(*middle))
    return found


@pytest.fixture(scope="module")
def tabbed():
    rough, finish = flat(1.0, 1), flat(1.0, 2)
    roughing, _, _ = roughing_toolpath(MODULE_1, rough, Machine(), RoughingParams(), BLANK_MM, TABS)
    finishing, levels, _ = finishing_toolpath(MODULE_1, finish, Machine(), TOLERANCE_MM, BLANK_MM, None, TABS)
    return Cut(roughing, rough), Cut(finishing, finish), -np.array(levels)


def test_no_tool_circle_reaches_the_tabs_below_their_top(tabbed):
    rough, finish, _ = tabbed
    top = -(MODULE_1.face_width_mm - TABS.tab_height_mm)
    across = np.linspace(-TABS.tab_width_mm / 2, TABS.tab_width_mm / 2, 21)
    along = np.linspace(MODULE_1.tip_radius_mm - 0.05, BLANK_MM, 60)
    for cut in (rough, finish):
        tree = cKDTree(centres_below(cut.path, top))
        for u in tab_tips():
            v = np.array([-u[1], u[0]])
            bridge = (along[:, None, None] * u + across[None, :, None] * v).reshape(-1, 2)
            clearance, _ = tree.query(bridge)
            assert clearance.min() >= cut.tool.diameter_mm / 2 - 1e-6
    # the cut goes through everywhere else: the deepest centres surround the gear
    assert finish.path.z.min() == pytest.approx(-MODULE_1.face_width_mm - 0.5)


@pytest.mark.slow  # a simulated cut (8 s); the tabs' geometry tests above stay in the fast tier
def test_the_simulated_cut_keeps_the_tabs_on_their_tips_only(tabbed):
    rough, finish, depths = tabbed
    result = simulate_flat(MODULE_1, BLANK_MM, [rough, finish], SimSettings(resolution_mm=0.005), depths)
    grid = result.grid
    tip = np.array([name == "tip" for name in grid.feature_names()])
    below = grid.rows_x > MODULE_1.face_width_mm - TABS.tab_height_mm + 1e-6
    held = set()
    for u in tab_tips():
        for k in range(grid.teeth):
            points = grid.space_points(k)[tip]
            if (points @ u).max() > MODULE_1.tip_radius_mm * math.cos(0.2 * math.pi / MODULE_1.teeth):
                held.add(k)
    assert len(held) >= 2
    for k in range(grid.teeth):
        tips_here = result.deviation[k][tip]
        assert tips_here[:, ~below].max() <= 0.005  # above the tabs: cut to size
        if k in held:
            assert tips_here[:, below].max() >= 0.5  # the bridge stands on the tip
        else:
            assert tips_here[:, below].max() <= 0.005


def test_an_onion_skin_leaves_the_bottom_uncut():
    skin = ThreeAxisSection(onion_skin_mm=0.4)
    rough, finish = flat(1.0, 1), flat(1.0, 2)
    roughing, _, _ = roughing_toolpath(MODULE_1, rough, Machine(), RoughingParams(), BLANK_MM, skin)
    finishing, levels, _ = finishing_toolpath(MODULE_1, finish, Machine(), TOLERANCE_MM, BLANK_MM, None, skin)
    assert roughing.z.min() == pytest.approx(-4.6) and min(levels) == pytest.approx(-4.6)
    result = simulate_flat(MODULE_1, BLANK_MM, [Cut(roughing, rough), Cut(finishing, finish)],
                           SimSettings(resolution_mm=0.005), -np.array(levels))
    involute = np.array([name.endswith("involute") for name in result.grid.feature_names()])
    skin_rows = result.grid.rows_x > 4.6 + 1e-6
    assert result.deviation[:, involute][:, :, skin_rows].min() >= 0.5
    assert result.deviation[:, involute][:, :, ~skin_rows].max() <= 0.005


@pytest.mark.linuxcnc
def test_rs274_accepts_the_tabbed_programs(tabbed, tmp_path):
    for name, cut in zip(("roughing", "finishing"), tabbed[:2]):
        program = tmp_path / f"{name}.ngc"
        program.write_text(post_program(cut.path, PostSettings(), ProgramInfo(name, (), writes_a=False)).text)
        ok, _, messages = run_rs274(program)
        assert ok, messages


@pytest.mark.parametrize("keys, blamed", [("tabs = 2\nonion_skin_mm = 0.5\n", "onion_skin_mm"),
                                          ("tabs = 1\ntab_height_mm = 25\n", "tab_height_mm")])
def test_the_job_file_refuses_tabs_with_a_skin_and_heights_beyond_the_face(keys, blamed, tmp_path):
    from spur_cad.errors import SpurCadError
    from spur_cad.job import load_job
    from tests.gears import REFERENCE_JOB

    job_file = tmp_path / "three.toml"
    job_file.write_text(REFERENCE_JOB.read_text() + "\n[three_axis]\n" + keys)
    with pytest.raises(SpurCadError) as caught:
        load_job(job_file)
    assert caught.value.field == blamed and "[three_axis]" in str(caught.value)
