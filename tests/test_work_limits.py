"""Work is bounded before it is done: inputs that would need runaway moves, points or memory are
refused quickly with a WorkLimitError / SimulationError naming the job key to change."""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pytest

from spur_cad.cam.ir import MAX_TOOLPATH_MOVES
from spur_cad.cam.machine import MachineError
from spur_cad.errors import SpurCadError, WorkLimitError
from spur_cad.geometry.sampling import sample_profile
from spur_cad.job import load_job
from spur_cad.pipeline import plan_cam
from spur_cad.sim.simulate import SimulationError, check_design_size, point_spacing_mm

REFERENCE = "resources/examples/reference_gear.toml"


@pytest.fixture(scope="module")
def small_job():
    job = load_job(REFERENCE)
    return dataclasses.replace(job, gear=dataclasses.replace(job.gear, face_width_mm=3.0))


@pytest.mark.parametrize("section, values, key", [
    ("finishing", {"strategy": "perimeter", "step_over_mm": 1e-9}, "finishing.step_over_mm"),
    ("roughing", {"step_over_fraction": 1e-9}, "roughing.step_over_fraction"),
    ("roughing", {"max_level_depth_fraction": 1e-9}, "roughing.max_level_depth_fraction"),
    ("roughing", {"flank_allowance_mm": 0.02 + 1e-9}, "roughing.flank_allowance_mm"),
])
def test_runaway_toolpaths_are_refused_before_they_are_built(small_job, section, values, key):
    job = dataclasses.replace(small_job, **{section: dataclasses.replace(getattr(small_job, section), **values)})
    started = time.perf_counter()
    with pytest.raises(WorkLimitError) as info:
        plan_cam(job)
    assert time.perf_counter() - started < 30.0  # generous: the refusal comes from an estimate, not the work
    assert info.value.key == key
    assert f"[{section}] {key.split('.')[1]}" in str(info.value)


def test_the_lowest_target_scallop_is_refused_before_perimeter_finishing_is_built():
    """A target scallop below its key's range is refused when the parameters are made (MachineError); at the
    lowest it takes, perimeter finishing of the reference gear (20 mm face width: about 3.5e7 moves) is refused
    by its estimate, naming the key."""
    job = load_job(REFERENCE)
    with pytest.raises(MachineError, match=r"\[finishing\] target_scallop_mm must be in \[0\.0001, 0\.1\] mm"):
        dataclasses.replace(job.finishing, strategy="perimeter", target_scallop_mm=1e-9)
    finishing = dataclasses.replace(job.finishing, strategy="perimeter", target_scallop_mm=0.0001)
    started = time.perf_counter()
    with pytest.raises(WorkLimitError) as info:
        plan_cam(dataclasses.replace(job, finishing=finishing))
    assert time.perf_counter() - started < 30.0  # generous: the refusal comes from an estimate, not the work
    assert info.value.key == "finishing.target_scallop_mm" and "[finishing] target_scallop_mm" in str(info.value)


def test_move_estimates_bound_the_real_toolpaths(small_job):
    """The estimates the limits use are not far below what the generators make (else the limit leaks)."""
    from spur_cad.cam.roughing import estimated_roughing_moves
    from spur_cad.cam.strategies import get_strategy, params_from_section

    plan = plan_cam(small_job)
    blank = small_job.stock.blank_radius_mm(small_job.gear)
    rough, _ = estimated_roughing_moves(small_job.gear, small_job.tools.roughing, small_job.roughing, blank)
    assert rough >= len(plan.roughing.toolpath)
    for name in ("perimeter", "along_x"):
        section = dataclasses.replace(small_job.finishing, strategy=name)
        strategy = get_strategy(name)
        estimate = strategy.estimate_moves(small_job.gear, small_job.tools.finishing,
                                           params_from_section(strategy, section))
        actual = len(plan_cam(dataclasses.replace(small_job, finishing=section)).finishing.toolpath)
        assert 0.95 * actual <= estimate <= 1.05 * actual + 100
    assert MAX_TOOLPATH_MOVES >= 10 * 759_759  # the reference job's perimeter finishing fits with room


def test_tiny_sampling_tolerance_is_refused_quickly(small_job):
    started = time.perf_counter()
    with pytest.raises(WorkLimitError, match="chordal tolerance"):
        sample_profile(small_job.gear.tooth_space_profile(), 1e-15)
    assert time.perf_counter() - started < 30.0


def test_simulation_grid_is_bounded(small_job):
    spec = small_job.gear
    spacing = point_spacing_mm(0.5, 0.005)
    check_design_size(spec, spacing, spec.face_width_mm + 3.0, 0, 0.005)  # the job itself: fine
    with pytest.raises(SimulationError) as info:
        check_design_size(dataclasses.replace(spec, teeth=1000, face_width_mm=2000.0), spacing, 2003.0, 0, 0.005)
    assert info.value.key == "simulation.resolution_mm"
    assert np.isfinite(spacing)


@pytest.mark.parametrize("strategy", ["perimeter", "along_x"])
def test_index_only_tables_refuse_strategies_that_turn_a_while_cutting(small_job, strategy):
    machine = dataclasses.replace(small_job.machine, rotary_simultaneous=False)
    job = dataclasses.replace(small_job, machine=machine,
                              finishing=dataclasses.replace(small_job.finishing, strategy=strategy))
    with pytest.raises(SpurCadError) as info:
        plan_cam(job)
    assert info.value.key == "finishing.strategy"
    assert strategy in str(info.value) and "rotary_simultaneous" in str(info.value)
    plan_cam(dataclasses.replace(job, tools=dataclasses.replace(job.tools, finishing=None)))  # roughing indexes only


def test_an_index_only_table_finishes_by_generation_and_still_sees_the_comparisons(small_job):
    machine = dataclasses.replace(small_job.machine, rotary_simultaneous=False)
    plan = plan_cam(dataclasses.replace(small_job, machine=machine))
    assert small_job.finishing.strategy == "generating"
    path = plan.finishing.toolpath
    feed = path.kind == 1
    assert not path.inverse_time.any() and np.all(np.diff(path.a)[feed[1:]] == 0.0)
    assert plan.finishing.perimeter_estimate.time_s > plan.finishing.estimate.time_s
    assert plan.finishing.reference_estimate is not None


def test_comparisons_too_large_to_build_are_left_out_not_refused(small_job):
    """A 60 mm face: perimeter finishing would need some 2.5 million moves (over MAX_COMPARISON_MOVES), so
    it is not built for comparison; the job's own finishing by generation is planned as usual."""
    from spur_cad.cam.plan import MAX_COMPARISON_MOVES
    from spur_cad.cam.strategies import get_strategy, params_from_section
    from spur_cad.report.html import finishing_comparison
    from spur_cad.summary import finishing_facts, finishing_json

    job = dataclasses.replace(small_job, gear=dataclasses.replace(small_job.gear, face_width_mm=60.0))
    perimeter = get_strategy("perimeter")
    section = dataclasses.replace(job.finishing, strategy="perimeter")
    assert perimeter.estimate_moves(job.gear, job.tools.finishing,
                                    params_from_section(perimeter, section)) > MAX_COMPARISON_MOVES
    plan = plan_cam(job)
    assert plan.finishing.perimeter_estimate is None and plan.finishing.reference_estimate is None
    assert plan.finishing.estimate.moves == len(plan.finishing.toolpath)
    facts = finishing_json(finishing_facts(plan.finishing))
    assert facts["perimeter_time_s"] is None and facts["reference_strategy_moves"] is None
    table = finishing_comparison(finishing_facts(plan.finishing))
    assert sum(cell.startswith("not estimated (too large to build for comparison") for row in table.rows
               for cell in row) == 2


COMPARISON_GEARS = ["reference_z23_m4", "undercut_z8", "shifted_z12", "pa14_5_z40", "undercut_negative_shift_z14"]


@pytest.mark.slow  # builds the full perimeter toolpaths to compare with: make test-all
@pytest.mark.parametrize("name", COMPARISON_GEARS)
@pytest.mark.parametrize("continuous", [True, False])
def test_the_comparison_estimate_equals_the_full_toolpath_s_own(name, continuous):
    """PerimeterStrategy.estimate (two stations' worth, extrapolated) against the estimate of the whole
    toolpath `generate` builds: moves exactly, lengths and both times within 1 % (in practice to rounding),
    on five gears, with a table that keeps turning and with one that unwinds after every station."""
    from spur_cad.cam.estimate import estimate
    from spur_cad.cam.machine import Machine
    from spur_cad.cam.strategies.perimeter import PerimeterParams, PerimeterStrategy
    from spur_cad.cam.tools import Tool
    from tests.gears import spec_of

    spec = dataclasses.replace(spec_of(name), face_width_mm=6.0)
    largest = 2.0 * spec.tooth_space_profile().min_fillet_curvature_radius_mm
    corner = min(0.5, 0.45 * largest) if np.isfinite(largest) else 0.5
    flat = 0.8 * 2.0 * spec.tooth_space_profile().root_arc_half_angle_rad * spec.root_radius_mm
    tool = Tool(diameter_mm=flat + 2.0 * corner, kind="bull_nose", corner_radius_mm=corner, flutes=2)
    machine = Machine(rotary_continuous=continuous)
    params = PerimeterParams(target_scallop_mm=0.01)
    blank = spec.tip_radius_mm + 0.5
    strategy = PerimeterStrategy()
    strategy.check_tool(spec, tool)
    path, result = strategy.generate(spec, tool, machine, params, blank)
    assert result.stations > 2
    full, closed = estimate(path, machine), strategy.estimate(spec, tool, machine, params, blank)
    assert closed.moves == full.moves == len(path)
    for field in ("cutting_length_mm", "rapid_length_mm", "time_s", "time_with_acceleration_s"):
        assert getattr(closed, field) == pytest.approx(getattr(full, field), rel=0.01), field
