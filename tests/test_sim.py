"""The cutting simulation against independent references: analytic cuts of a cylinder, planted faults in
the reference job's finishing program, and the whole reference job against its design."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from spur_cad.cam.ir import Feature, MoveKind, Operation, ToolpathBuilder
from spur_cad.cam.tools import Tool
from spur_cad.geometry.sampling import full_space_points, sample_profile
from spur_cad.job import parse_job
from spur_cad.pipeline import job_stock, plan_cam
from spur_cad.sim import Cut, SimSettings, StockCylinder, finishing_stations, simulate, simulate_grid, subset
from spur_cad.sim.design import DesignGrid, row_positions
from spur_cad.summary import simulation_section
from tests.gears import reference_job_text
from tests.tiers import sweep

ROOT = Path(__file__).resolve().parents[1]
REFERENCE_JOB = ROOT / "resources" / "examples" / "reference_gear.toml"
RES = 0.005


def cylinder_grid(radius: float, points: int, x_min: float, x_max: float, spacing: float) -> DesignGrid:
    """A plain cylinder as the 'design': points on a circle with radial normals (one sector)."""
    beta = np.linspace(0.0, 2 * math.pi, points, endpoint=False)
    normals = np.stack([-np.sin(beta), np.cos(beta)], axis=-1)  # machine angle beta from +Z, counter-clockwise
    rows, width = row_positions(x_min, x_max, spacing)
    return DesignGrid(1, radius * normals, normals, np.zeros(points, np.int8), np.zeros(points, np.int8),
                      radius * beta, rows, width, spacing)


def one_move_path(start, end, tool_number=1):
    builder = ToolpathBuilder(Operation.ROUGHING, tool_number, 1000.0)
    builder.move(MoveKind.RAPID, *start)
    builder.move(MoveKind.LINEAR, *end, feed=100.0, feature=Feature.LEVEL)
    return builder.build()


def radial_entry_in_half_strip(beta, design_r, y_t, z_t, half_width):
    """Independent reference: radius where the ray from the axis at angle beta enters the half-strip
    |Y - y_t| <= w, Z >= z_t (a flat end mill's section through its axis), by interval arithmetic."""
    ys, zs = -np.sin(beta), np.cos(beta)
    lo = np.full_like(beta, design_r - 1.5)  # the blades' ends
    hi = np.full_like(beta, design_r + 1.5)
    # Z = rho zs >= z_t
    pos = zs > 1e-12
    lo = np.where(pos, np.maximum(lo, z_t / np.where(pos, zs, 1.0)), lo)
    hi = np.where(zs < -1e-12, np.minimum(hi, z_t / np.where(zs < -1e-12, zs, 1.0)), hi)
    hi = np.where(np.abs(zs) <= 1e-12, np.where(0.0 >= z_t, hi, -np.inf), hi)
    # |rho ys - y_t| <= w
    for bound, sign in ((y_t + half_width, 1.0), (y_t - half_width, -1.0)):
        # sign * rho ys <= sign * bound
        c = sign * ys
        rhs = sign * bound
        hi = np.where(c > 1e-12, np.minimum(hi, rhs / np.where(c > 1e-12, c, 1.0)), hi)
        lo = np.where(c < -1e-12, np.maximum(lo, rhs / np.where(c < -1e-12, c, 1.0)), lo)
        hi = np.where((np.abs(c) <= 1e-12) & (rhs < 0), -np.inf, hi)
    return np.where(lo <= hi, lo, np.inf)


@pytest.mark.parametrize("y_t, diameter", [(0.0, 20.0), (1.3, 3.0)])
def test_flat_tool_pass_along_x_over_a_cylinder_matches_interval_arithmetic_and_segment_volume(y_t, diameter):
    stock_r, design_r, z_t = 10.0, 9.0, 8.6
    grid = cylinder_grid(design_r, 1800, 0.0, 20.0, 0.1)
    tool = Tool(diameter_mm=diameter)
    path = one_move_path((-15.0, y_t, 30.0, 0.0), (-15.0, y_t, z_t, 0.0))  # plunge outside the part
    path2 = one_move_path((-15.0, y_t, z_t, 0.0), (35.0, y_t, z_t, 0.0))  # the pass along X
    settings = SimSettings(resolution_mm=0.005, gouge_range_mm=1.5, leftover_range_mm=1.5)
    result = simulate_grid(grid, StockCylinder(stock_r, 0.0, 20.0), [Cut(path, tool), Cut(path2, tool)],
                           settings, face_width_mm=20.0)
    beta = np.linspace(0.0, 2 * math.pi, 1800, endpoint=False)
    entry = radial_entry_in_half_strip(beta, design_r, y_t, z_t, diameter / 2) - design_r
    expected = np.minimum(np.clip(entry, -1.5, None), stock_r - design_r)
    assert np.allclose(result.deviation[0], expected[:, None], atol=1e-9)
    if diameter < 2 * stock_r:
        return  # a pocket with walls: blades crossing a wall leave the part beyond it uncounted (docs/simulation.md)
    # Removed volume: the part of the stock circle inside the half-strip, times the length (20 mm).
    yy = np.linspace(max(y_t - diameter / 2, -stock_r), min(y_t + diameter / 2, stock_r), 200001)
    height = np.clip(np.sqrt(np.maximum(stock_r**2 - yy**2, 0.0)) - z_t, 0.0, None)
    area = np.trapezoid(height, yy)
    assert result.removed_volume_mm3 == pytest.approx(area * 20.0, rel=2e-3)


def tool_contains(kind: str, diameter: float, corner: float, dx, dy, dz):
    """Independent membership: union of the shank cylinder, the flat-bottom cylinder and the corner torus."""
    radius = diameter / 2
    rt = corner if kind != "ball" else radius
    rho = radius - rt
    s = np.hypot(dx, dy)
    shank = (s <= radius) & (dz >= rt)
    core = (s <= rho) & (dz >= 0)
    torus = (s >= rho) & ((s - rho) ** 2 + (dz - rt) ** 2 <= rt**2)
    return shank | core | torus


@pytest.mark.parametrize("kind, diameter, corner", sweep([("bull_nose", 2.0, 0.5), ("ball", 3.0, 1.5)],
                                                          fast=["bull_nose"]))  # 5 s each
def test_plunge_of_a_curved_tool_matches_brute_force_membership(kind, diameter, corner):
    stock_r, design_r = 10.0, 9.5
    grid = cylinder_grid(design_r, 720, 0.0, 4.0, 0.05)
    tool = Tool(diameter_mm=diameter, kind=kind, corner_radius_mm=corner if kind == "bull_nose" else 0.0)
    y_t, z_t, x_t = 0.4, 9.3, 2.0
    path = one_move_path((x_t, y_t, 30.0, 0.0), (x_t, y_t, z_t, 0.0))
    settings = SimSettings(resolution_mm=0.005, gouge_range_mm=0.5, leftover_range_mm=0.5)
    result = simulate_grid(grid, StockCylinder(stock_r, 0.0, 4.0), [Cut(path, tool)], settings,
                           face_width_mm=4.0)
    beta = np.linspace(0.0, 2 * math.pi, 720, endpoint=False)
    t = np.arange(-0.5, 0.5 + 1e-12, 2e-5)
    checked = 0
    for r, x in enumerate(grid.rows_x):
        if abs(x - x_t) >= diameter / 2:
            assert np.allclose(result.deviation[0, :, r], 0.5)  # beyond the tool: untouched stock
            continue
        for j in np.nonzero(np.cos(beta) > 0.9)[0]:
            rho = design_r + t
            inside = tool_contains(kind, diameter, corner, x - x_t, -rho * np.sin(beta[j]) - y_t,
                                   rho * np.cos(beta[j]) - z_t)
            expected = t[np.argmax(inside)] if inside.any() else 0.5
            assert result.deviation[0, j, r] == pytest.approx(expected, abs=2.5e-5)
            checked += inside.any()
    assert checked > 50


@pytest.fixture(scope="module")
def reference():
    """The reference job finished by the perimeter strategy (stations: the window tests need them)."""
    job = parse_job(reference_job_text("perimeter"), str(REFERENCE_JOB))
    return job, plan_cam(job)


@pytest.mark.slow
def test_reference_job_is_cut_to_the_design_within_scallop_and_resolution(reference):
    job, plan = reference
    ops = [Cut(plan.roughing.toolpath, job.tools.roughing), Cut(plan.finishing.toolpath, job.tools.finishing)]
    result = simulate(job.gear, job_stock(job), ops, SimSettings(resolution_mm=RES),
                      station_x=finishing_stations(plan.finishing.toolpath))
    facts = simulation_section(result, result.settings.resolution_mm)
    assert facts["max_gouge_mm"] <= RES
    assert facts["max_leftover_mm"] <= job.finishing.target_scallop_mm + RES
    assert facts["uncut_points"] == 0
    # Every feature was finished (not only the worst point): all means within the scallop.
    for name, feature in facts["per_feature"].items():
        assert feature["max_leftover_mm"] <= job.finishing.target_scallop_mm + RES, name
    # Removed volume: stock cylinder minus the design section (CAD-independent: polygon of the exact
    # outline sampled at 0.1 um) over the stock length, less the margins' leftover (a thin layer).
    space = full_space_points(sample_profile(job.gear.tooth_space_profile(), 1e-4))
    y, z = space[:, 0], space[:, 1]
    area_space = 0.5 * float(np.sum(y[:-1] * z[1:] - y[1:] * z[:-1]))  # counter-clockwise sector polygon
    design_area = job.gear.teeth * area_space
    stock = job_stock(job)
    expected = (math.pi * stock.radius_mm**2 - design_area) * (stock.x_max - stock.x_min)
    assert result.removed_volume_mm3 == pytest.approx(expected, rel=0.01)
    assert result.removed_volume_mm3 < expected


def _finishing_window(plan, stations: range, spaces: range):
    fin = plan.finishing.toolpath
    mask = np.isin(fin.station, list(stations)) & np.isin(fin.space, list(spaces))
    return mask


def _window_result(job, plan, path, centre_station, spaces):
    """Simulate a window of the finishing program; deviation of the given spaces on rows within three
    stations of the centre (every station that reaches them is in the window)."""
    x = finishing_stations(plan.finishing.toolpath)
    rows = (x[centre_station - 3], x[centre_station + 3])
    result = simulate(job.gear, job_stock(job), [Cut(path, job.tools.finishing)], SimSettings(resolution_mm=RES),
                      station_x=x, rows_x_range=rows)
    return result, result.deviation[list(MEASURED)]


STATION, SPACE = 70, 5
WINDOW = range(STATION - 10, STATION + 11)
SPACES = range(SPACE - 1, SPACE + 2)
MEASURED = (SPACE, SPACE + 1)  # space k's right tip land is cut with space k - 1: SPACE - 1's is not in the window


def test_finishing_window_without_faults_is_clean(reference):
    job, plan = reference
    mask = _finishing_window(plan, WINDOW, SPACES)
    result, dev = _window_result(job, plan, subset(plan.finishing.toolpath, mask), STATION, SPACES)
    assert -dev.min() <= RES
    assert dev.max() <= job.finishing.target_scallop_mm + RES


def test_root_lowered_by_20um_at_one_station_reports_a_20um_gouge_there(reference):
    job, plan = reference
    fin = plan.finishing.toolpath
    mask = _finishing_window(plan, WINDOW, SPACES)
    fault = (fin.feature == Feature.ROOT) & (fin.station == STATION) & (fin.space == SPACE)
    z = fin.z - np.where(fault, 0.020, 0.0)
    result, dev = _window_result(job, plan, subset(fin, mask, z=z), STATION, SPACES)
    assert -dev.min() == pytest.approx(0.020, abs=RES)
    worst = result.worst(gouge=True)
    assert worst.space == SPACE and worst.feature in ("root", "right fillet", "left fillet")
    x_station = finishing_stations(fin)[STATION]
    assert abs(worst.x_mm - x_station) <= job.tools.finishing.diameter_mm / 2
    # At the station itself the middle of the root arc is 20 um deep (its ends taper where the unshifted
    # flank moves join); no other space is gouged.
    row = int(np.argmin(np.abs(result.grid.rows_x - x_station)))
    root_y = np.abs(result.grid.points[:, 0])
    root = (result.grid.feature == 0) & (root_y < 0.5 * root_y[result.grid.feature == 0].max())
    assert np.allclose(result.deviation[SPACE, root, row], -0.020, atol=RES)
    others = [k for k in range(job.gear.teeth) if k != SPACE]
    assert -result.deviation[others].min() <= RES


def test_right_flank_moved_20um_into_the_part_reports_a_20um_gouge_on_that_flank(reference):
    job, plan = reference
    fin, tool = plan.finishing.toolpath, job.tools.finishing
    mask = _finishing_window(plan, WINDOW, SPACES)
    fault = (fin.feature == Feature.RIGHT_FLANK) & (fin.station == STATION) & (fin.space == SPACE)
    # Independent normal at each contact: nearest exact design point to the right corner-circle centre.
    design = full_space_points(sample_profile(job.gear.tooth_space_profile(), 1e-5))
    idx = np.nonzero(fault)[0]
    a = np.radians(fin.a[idx]) + SPACE * 2 * math.pi / job.gear.teeth
    c, s = np.cos(a), np.sin(a)
    centre = np.stack([fin.y[idx] + tool.flat_width_mm / 2, fin.z[idx] + tool.effective_corner_radius_mm], axis=-1)
    dy, dz = fin.y.copy(), fin.z.copy()
    for i, (ci, si, cc) in enumerate(zip(c, s, centre)):
        turned = np.stack([design[:, 0] * ci - design[:, 1] * si, design[:, 0] * si + design[:, 1] * ci], axis=-1)
        d = np.hypot(*(turned - cc).T)
        p = turned[np.argmin(d)]
        n = (cc - p) / np.linalg.norm(cc - p)
        dy[idx[i]] -= 0.020 * n[0]
        dz[idx[i]] -= 0.020 * n[1]
    result, dev = _window_result(job, plan, subset(fin, mask, y=dy, z=dz), STATION, SPACES)
    assert -dev.min() == pytest.approx(0.020, abs=RES)
    worst = result.worst(gouge=True)
    assert worst.space == SPACE and worst.feature.startswith("right ")
    assert worst.station == STATION
    assert -result.deviation[[k for k in range(job.gear.teeth) if k != SPACE]].min() <= RES
    left = np.array([n == "left involute" for n in result.grid.feature_names()])  # the root may be touched
    assert -result.deviation[SPACE, left].min() <= RES


def test_a_station_left_out_reports_leftover_there(reference):
    job, plan = reference
    fin = plan.finishing.toolpath
    mask = _finishing_window(plan, WINDOW, SPACES) & (fin.station != STATION)
    result, dev = _window_result(job, plan, subset(fin, mask), STATION, SPACES)
    assert dev.max() > job.finishing.target_scallop_mm + RES
    x_station = finishing_stations(fin)[STATION]
    step = finishing_stations(fin)[1] - finishing_stations(fin)[0]
    k, j, r = np.unravel_index(int(np.argmax(dev)), dev.shape)
    assert result.grid.rows_x[r] == pytest.approx(x_station, abs=1e-9)
    assert result.grid.feature_names()[j].endswith(("involute", "fillet"))
    high = dev > job.finishing.target_scallop_mm + RES
    rows_high = np.nonzero(high.any(axis=(0, 1)))[0]
    assert np.all(np.abs(result.grid.rows_x[rows_high] - x_station) < step)
    assert high[0].any() and high[1].any()  # in both measured spaces
    assert -dev.min() <= RES


@pytest.mark.parametrize("spaces_per_block", [1, 4, 1000])
def test_worst_places_found_block_by_block_are_numpys_first_extremes(reference, monkeypatch, spaces_per_block):
    """SimResult.worst reads the gear in blocks of tooth spaces (argmin of the whole strided view would copy it):
    the place it names is the first extreme in C order, as np.argmin / np.argmax over all of it give."""
    from spur_cad.sim import statistics

    job, plan = reference
    fin = plan.finishing.toolpath
    mask = _finishing_window(plan, WINDOW, SPACES)
    fault = (fin.feature == Feature.ROOT) & (fin.station == STATION) & (fin.space == SPACE)
    result, _ = _window_result(job, plan, subset(fin, mask, z=fin.z - np.where(fault, 0.020, 0.0)), STATION, SPACES)
    monkeypatch.setattr(statistics, "BLOCK_VALUES", spaces_per_block * result.deviation[0].size)
    dev = result.gear_deviation
    for gouge, index in ((True, np.argmin(dev)), (False, np.argmax(dev))):
        k, j, r = np.unravel_index(index, dev.shape)
        place = result.worst(gouge)
        assert (place.space, place.point, place.value_mm) == (k, j, dev[k, j, r])
        assert place.x_mm == result.grid.rows_x[np.nonzero(result.gear_rows)[0][r]]
