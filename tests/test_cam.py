"""CAM: tool recommendations against docs/method.md computed independently, tool limits, the
A-motion rule, inverse-time feeds from the true relative path, and the time estimator."""

from __future__ import annotations

import dataclasses
import math
from types import SimpleNamespace

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, Polygon

from spur_cad.cam.contacts import station_positions, station_step_mm
from spur_cad.cam.estimate import estimate
from spur_cad.cam.finishing import finishing_toolpath
from spur_cad.cam.ir import Feature, MoveKind, Operation, ToolpathBuilder
from spur_cad.cam.machine import Machine, RoughingParams
from spur_cad.cam.recommend import check_tools, recommend_tools
from spur_cad.cam.roughing import roughing_levels, roughing_toolpath
from spur_cad.cam.strategies import FinishingParams, get_strategy
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.geometry import gear_outline, sample_profile
from tests.gears import CAM_GEARS, spec_of, textbook_of, tools_for


@pytest.mark.parametrize("name", CAM_GEARS)
def test_recommendations_match_method_formulas(name):
    spec, g = spec_of(name), textbook_of(name)
    _, finishing = tools_for(name)
    # the plunge allowance: the rule of the strategies whose flat bottom plunges at the root
    rec = recommend_tools(spec, spec.tip_radius_mm + 0.5, 1.0, finishing, strategy=get_strategy("perimeter"))
    # Root arc length 2 v r_f with v = d_1 / r (docs/method.md, textbook rack).
    assert rec.finishing_max_flat_width_mm == pytest.approx(2 * g.corner_offset / g.r * g.rf, abs=1e-9)
    # Smallest fillet curvature radius: circumradius of close triples of dense fillet samples.
    samples = sample_profile(spec.tooth_space_profile(), 1e-7)
    fillet = samples.points[np.array(samples.label_names()) == "fillet"]
    a, b, c = fillet[:-2:5], fillet[1:-1:5], fillet[2::5]
    cross = np.abs((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0])
    circum = (np.linalg.norm(b - a, axis=1) * np.linalg.norm(c - b, axis=1) * np.linalg.norm(a - c, axis=1)
              / (2 * np.maximum(cross, 1e-300)))
    assert rec.finishing_max_corner_radius_mm == pytest.approx(circum.min(), rel=1e-3)
    assert rec.finishing_max_corner_radius_mm >= spec.rack_tip_radius_mm - 1e-12
    # Roughing: width of the space (shapely on the gear outline) at height r_f + 0.5 d on the axis.
    a_p = 0.5 * finishing.flat_width_mm
    assert rec.plunge_allowance_mm == pytest.approx(a_p)
    gear = Polygon(gear_outline(spec, 1e-6))
    height = g.rf + a_p
    line = LineString([(-g.m * 3, height), (g.m * 3, height)]).difference(gear)
    pieces = [piece for piece in getattr(line, "geoms", [line]) if piece.distance(shapely.Point(0, height)) < 1e-9]
    assert rec.roughing_max_diameter_mm == pytest.approx(pieces[0].length, abs=1e-5)
    # Tool and flute length: from the blank surface to the root.
    assert rec.required_flute_length_mm == pytest.approx(g.ra + 0.5 - g.rf)


@pytest.mark.parametrize("change, words", [
    (dict(finishing=Tool(diameter_mm=3.0, kind="bull_nose", corner_radius_mm=1.3)), "finishing_max_corner_radius_mm"),
    (dict(finishing=Tool(diameter_mm=2.0, kind="flat")), "must have a corner radius"),
    (dict(roughing=Tool(diameter_mm=5.0, kind="flat")), "roughing_max_diameter_mm"),
    (dict(roughing=Tool(diameter_mm=3.0, kind="bull_nose", corner_radius_mm=0.5)), "flat end mill"),
    (dict(roughing=Tool(diameter_mm=3.0, flute_length_mm=5.0)), "required_flute_length_mm"),
    (dict(roughing=Tool(diameter_mm=3.0, stick_out_mm=8.0)), "required_stick_out_mm"),
])
def test_tool_limits_are_clear_errors(change, words):
    spec = spec_of("reference_z23_m4")
    finishing = change.get("finishing", Tool(diameter_mm=2.0, kind="bull_nose", corner_radius_mm=0.5))
    roughing = change.get("roughing", Tool(diameter_mm=3.0))
    rec = recommend_tools(spec, 50.5, 1.0, finishing)
    with pytest.raises(ToolError, match=words):
        check_tools(spec, rec, roughing, finishing)


def test_a_tool_that_cannot_exist_is_refused_when_the_plan_s_inputs_are_made():
    """The tools' own checks run once, when CamInputs is made; the limits against the gear (check_tools) trust them."""
    from spur_cad.cad.specs import StockSpec
    from spur_cad.cam.machine import Machine, RoughingParams
    from spur_cad.cam.plan import CamInputs
    from spur_cad.cam.strategies import FinishingParams

    spec = spec_of("reference_z23_m4")
    with pytest.raises(ToolError, match="roughing tool kind 'conical' is unknown"):
        CamInputs(spec, StockSpec(), Tool(diameter_mm=3.0, kind="conical"), None, RoughingParams(), FinishingParams(),
                  Machine())


@pytest.mark.parametrize("strategy, words", [
    ("perimeter", r"flat width 2.0000 mm \(D - 2 r_t\) exceeds finishing_max_flat_width_mm = 1.6376 mm"),
    ("along_x", r"flat width 2.0000 mm \(D - 2 r_t\) exceeds finishing_max_flat_width_mm = 1.6376 mm"),
    ("generating", r"flat width d = 2 mm \(D - 2 r_t\) is wider than the rack's tip flat 2 d_1 = 1.8373 mm"),
])
def test_each_strategy_has_its_own_flat_width_rule(strategy, words):
    """Root arc 2 v r_f = 1.6376 mm (summary figure) for the root sweepers; the rack's tip flat for
    generating: 2 d_1 = 2 (s_rack / 2 - h_f tan(alpha) - rho (1 - sin(alpha)) / cos(alpha)), the rack's
    tooth s_rack = 1.05 pi m / 2 (the gear's tooth is 5 % thinner)."""
    spec = spec_of("reference_z23_m4")
    alpha, m, rho = math.radians(20.0), 4.0, 0.8
    d1 = 1.05 * math.pi * m / 4 - 1.25 * m * math.tan(alpha) - rho * (1 - math.sin(alpha)) / math.cos(alpha)
    assert 2 * d1 == pytest.approx(1.8373, abs=1e-4)
    wide = Tool(diameter_mm=3.0, kind="bull_nose", corner_radius_mm=0.5)
    with pytest.raises(ToolError, match=words) as caught:
        get_strategy(strategy).check_tool(spec, wide)
    assert caught.value.key == "tools.finishing.diameter_mm"
    get_strategy(strategy).check_tool(spec, Tool(diameter_mm=2.0, kind="bull_nose", corner_radius_mm=0.5))


def _previous(values: np.ndarray) -> np.ndarray:
    return np.concatenate([[values[0]], values[:-1]])


@pytest.mark.parametrize("name", CAM_GEARS)
def test_a_moves_only_above_the_gear_or_in_designed_finishing_moves(name):
    spec = spec_of(name)
    roughing, finishing = tools_for(name)
    machine = Machine()
    blank = spec.tip_radius_mm + 0.5
    paths = [roughing_toolpath(spec, roughing, machine, RoughingParams(flank_allowance_mm=0.1 * spec.module_mm,
                                                                       finish_stock_mm=0.005 * spec.module_mm,
                                                                       strategy="levels"),
                               blank),
             finishing_toolpath(spec, finishing, machine,
                                FinishingParams(strategy="perimeter", step_over_mm=spec.face_width_mm), blank)]
    for path in paths:
        moving = np.abs(path.a - _previous(path.a)) > 1e-12
        designed = np.isin(path.feature, [Feature.RIGHT_FLANK, Feature.LEFT_FLANK, Feature.ROOT, Feature.TIP])
        high = np.minimum(path.z, _previous(path.z)) >= spec.tip_radius_mm + machine.clearance_mm - 1e-9
        assert np.all(high[moving & ~designed]), path.operation
        if path.operation == Operation.ROUGHING:
            assert not np.any(moving & designed)


def test_inverse_time_feed_matches_relative_path_length():
    """For simultaneous moves, 1/F (min) x feed = the tool tip's path length relative to the part,
    integrated here independently with the rotation convention of docs/architecture.md."""
    spec = spec_of("reference_z23_m4")
    tool = Tool(diameter_mm=2.0, kind="bull_nose", corner_radius_mm=0.5, cutting_speed_m_min=120,
                feed_per_tooth_mm=0.02)
    machine = Machine()
    path = finishing_toolpath(spec, tool, machine, FinishingParams(strategy="perimeter", step_over_mm=100.0), 50.5)
    feed = tool.feed_mm_min(machine)
    idx = np.nonzero(path.inverse_time)[0]
    assert len(idx) > 100
    for i in idx[::37]:
        t = np.linspace(0, 1, 2001)
        y = path.y[i - 1] + (path.y[i] - path.y[i - 1]) * t
        z = path.z[i - 1] + (path.z[i] - path.z[i - 1]) * t
        a = np.radians(path.a[i - 1] + (path.a[i] - path.a[i - 1]) * t)
        # A point at (Y, Z) of the machine at angle A sits at R(-A)(Y, Z) on the part.
        py, pz = y * np.cos(a) + z * np.sin(a), -y * np.sin(a) + z * np.cos(a)
        length = np.hypot(np.diff(py), np.diff(pz)).sum()
        minutes = max(length / feed, abs(path.a[i] - path.a[i - 1]) / machine.max_rotary_speed_deg_min)
        assert 1.0 / path.feed[i] == pytest.approx(minutes, rel=2e-3)


def test_estimate_of_a_small_program_by_hand():
    machine = Machine(rapid_feed_mm_min=6000.0, max_rotary_speed_deg_min=600.0, block_time_s=0.5)
    b = ToolpathBuilder(Operation.ROUGHING, 1, 1000.0)
    b.move(MoveKind.RAPID, 0.0, 0.0, 60.0, 0.0)
    b.move(MoveKind.RAPID, 0.0, 0.0, 60.0, 90.0)  # rotary only: 90 deg at 600 deg/min = 9 s
    b.move(MoveKind.LINEAR, 100.0, 0.0, 60.0, 90.0, 200.0)  # 100 mm at 200 mm/min = 30 s
    b.move(MoveKind.LINEAR, 100.0, 1.0, 60.0, 90.0, 6000.0)  # 1 mm at 6000 mm/min = 0.01 s -> block time 0.5 s
    result = estimate(b.build(), machine)
    assert result.moves == 4
    assert result.cutting_length_mm == pytest.approx(101.0)
    assert result.time_s == pytest.approx(0.5 + 9.0 + 30.0 + 0.5)


def test_stations_cover_the_face_width_with_the_scallop_step():
    tool = Tool(diameter_mm=2.0, kind="bull_nose", corner_radius_mm=0.5)
    params = FinishingParams(strategy="perimeter", target_scallop_mm=0.005)
    step = station_step_mm(tool, params.target_scallop_mm, params.step_over_mm)
    # Worst case of docs/method.md: flat width d at the root, corner radius elsewhere.
    h, d, r_t = 0.005, 1.0, 0.5
    assert d / 2 - math.sqrt((d / 2) ** 2 - (step / 2) ** 2) <= h + 1e-12
    assert r_t - math.sqrt(r_t**2 - (step / 2) ** 2) <= h + 1e-12
    stations = station_positions(20.0, step)
    assert stations[0] == 0.0 and stations[-1] == 20.0 and np.diff(stations).max() <= step + 1e-12


def test_roughing_levels_junction_and_depth_limit():
    spec = spec_of("reference_z23_m4")
    tool = Tool(diameter_mm=3.5, flutes=3)
    params = RoughingParams(flank_allowance_mm=0.3, finish_stock_mm=0.02, max_level_depth_fraction=0.5)
    levels = roughing_levels(spec, tool, params, 50.5)
    heights = levels.heights_mm
    assert np.all(np.diff(heights) < 0)  # top to bottom
    assert np.max(-np.diff(heights)) <= 0.5 * 3.5 + 1e-9
    assert 50.5 - heights[0] <= 0.5 * 3.5 + 1e-9
    assert np.min(np.abs(heights - levels.junction_height_mm)) < 1e-9
    # Lowest level: the space (design offset by the finish stock) is exactly as wide as the tool there.
    gear = Polygon(gear_outline(spec, 1e-6)).buffer(0.02, quad_segs=64)
    low = heights[-1]
    line = LineString([(-8, low), (8, low)]).difference(gear)
    pieces = [p for p in getattr(line, "geoms", [line]) if p.distance(shapely.Point(0, low)) < 1e-9]
    assert pieces[0].length == pytest.approx(3.5, abs=1e-4)


def test_travel_limits_name_the_axis():
    from spur_cad.cam.machine import MachineError, check_travel

    spec = spec_of("reference_z23_m4")
    tool = Tool(diameter_mm=2.0, kind="bull_nose", corner_radius_mm=0.5)
    machine = Machine(z_max_mm=50.0, rotary_continuous=False, a_min_deg=-90.0, a_max_deg=90.0)
    path = finishing_toolpath(spec, tool, machine, FinishingParams(strategy="perimeter", step_over_mm=20.0), 50.5)
    with pytest.raises(MachineError, match=r"finishing needs Z = 51.500 mm, outside the machine's travel"):
        check_travel(machine, path.x, path.y, path.z, path.a, "finishing")
    limited = Machine(rotary_continuous=False, a_min_deg=-90.0, a_max_deg=90.0)
    with pytest.raises(MachineError, match=r"finishing needs A = -3"):
        check_travel(limited, path.x, path.y, path.z, path.a, "finishing")
    check_travel(Machine(), path.x, path.y, path.z, path.a, "finishing")  # generous defaults pass


def test_roughing_that_leaves_too_much_above_the_root_is_an_error():
    """A roughing tool at the diameter limit still leaves a little more than A_p once the finish
    stock is added; the reach check names A_p."""
    from spur_cad.cam.recommend import check_roughing_reach

    spec = spec_of("reference_z23_m4")
    finishing = Tool(diameter_mm=2.0, kind="bull_nose", corner_radius_mm=0.5)
    rec = recommend_tools(spec, 50.5, 1.0, finishing, strategy=get_strategy("perimeter"))
    at_limit = Tool(diameter_mm=rec.roughing_max_diameter_mm, flutes=3)
    levels = roughing_levels(spec, at_limit, RoughingParams(finish_stock_mm=0.05), 50.5)
    leftover = levels.lowest_height_mm - spec.root_radius_mm
    assert leftover > rec.plunge_allowance_mm
    with pytest.raises(ToolError, match=r"more than the finishing tool can plunge \(A_p = 0.500 mm: 0.5 x its flat "
                                        r"width 1 mm\)"):
        check_roughing_reach(at_limit, leftover, rec)
    small = Tool(diameter_mm=3.0, flutes=3)
    check_roughing_reach(small, roughing_levels(spec, small, RoughingParams(), 50.5).lowest_height_mm
                         - spec.root_radius_mm, rec)


def _space_width_mm(spec, height_mm: float) -> float:
    """Width of the tooth space on its axis at `height_mm` from the gear's centre (shapely on the gear outline)."""
    gear = Polygon(gear_outline(spec, 1e-6))
    m = spec.module_mm
    line = LineString([(-m * 3, height_mm), (m * 3, height_mm)]).difference(gear)
    pieces = [piece for piece in getattr(line, "geoms", [line]) if piece.distance(shapely.Point(0, height_mm)) < 1e-9]
    return pieces[0].length


def test_the_bottom_allowance_is_the_finishing_strategys_rule():
    """What roughing may leave above the root: by generation (no plunge; straight passes take it side-on) what
    the finishing tool takes off in one pass, 0.5 D; perimeter and along_x (the flat bottom plunges at the root)
    A_p = 0.5 x the flat width. The largest roughing tool is the space's width at that height, and a roughing
    tool that leaves more is refused naming the rule."""
    from spur_cad.cad.specs import StockSpec
    from spur_cad.cam.plan import CamInputs, check_cam_inputs

    spec = spec_of("reference_z23_m4")
    finishing = Tool(diameter_mm=2.0, kind="bull_nose", corner_radius_mm=0.5)  # flat width 1 mm
    blank = spec.tip_radius_mm + 0.5
    generating, perimeter, along_x = (recommend_tools(spec, blank, 1.0, finishing, strategy=get_strategy(name))
                                      for name in ("generating", "perimeter", "along_x"))
    assert generating.plunge_allowance_mm == pytest.approx(0.5 * 2.0)
    assert perimeter.plunge_allowance_mm == along_x.plunge_allowance_mm == pytest.approx(0.5 * 1.0)
    assert recommend_tools(spec, blank, 1.0, finishing) == generating  # the job file's default strategy
    for rec in (generating, perimeter):
        assert rec.roughing_max_diameter_mm == pytest.approx(
            _space_width_mm(spec, spec.root_radius_mm + rec.plunge_allowance_mm), abs=1e-5)
    # the report's limits table says which rule applies
    from spur_cad.report.sheet import limit_rows

    result = SimpleNamespace(tools=SimpleNamespace(recommendations=generating), setup=None)  # no set-up: on the table
    rows = {row.label: row.value for row in limit_rows(result)}
    assert rows["material roughing may leave above the root: as much as the finishing tool takes off in one generating "
                "pass (1.000 mm: 0.5 x D 2 mm, a slot's depth)"] == "1.000"
    # without a finishing tool: the largest each strategy takes
    no_tool = recommend_tools(spec, blank, 1.0, strategy=get_strategy("generating"))
    assert no_tool.plunge_allowance_mm == pytest.approx(0.5 * no_tool.finishing_generating_max_diameter_mm)
    no_tool = recommend_tools(spec, blank, 1.0, strategy=get_strategy("perimeter"))
    assert no_tool.plunge_allowance_mm == pytest.approx(0.5 * no_tool.finishing_max_flat_width_mm)
    # by the plan's checks (the job file's default strategy, generating): D 4.2 leaves more than 0.5 D above the
    # root, refused naming the rule; D 4 leaves less and passes, but perimeter refuses it (A_p = 0.5 mm)
    params = RoughingParams(finish_stock_mm=0.05)
    inputs = CamInputs(spec, StockSpec(radial_allowance_mm=0.5), roughing_tool=Tool(diameter_mm=4.2, flutes=3),
                       finishing_tool=finishing, roughing=params, finishing=FinishingParams(), machine=Machine())
    assert inputs.finishing.strategy == "generating"
    left = roughing_levels(spec, inputs.roughing_tool, params, blank).lowest_height_mm - spec.root_radius_mm
    assert left > generating.plunge_allowance_mm
    assert inputs.roughing_tool.diameter_mm < generating.roughing_max_diameter_mm
    with pytest.raises(ToolError, match=r"leaves \d\.\d{3} mm above the root, more than the finishing tool takes "
                                        r"off in one generating pass \(1\.000 mm: 0\.5 x D 2 mm, a slot's depth\)"):
        check_cam_inputs(inputs)
    within = dataclasses.replace(inputs, roughing_tool=Tool(diameter_mm=4.0, flutes=3))
    check_cam_inputs(within)
    with pytest.raises(ToolError, match=r"exceeds roughing_max_diameter_mm = 3\.6816 mm \(space width at root radius "
                                        r"\+ what the finishing tool can plunge \(A_p = 0\.500 mm"):
        check_cam_inputs(dataclasses.replace(within, finishing=FinishingParams(strategy="perimeter")))
