"""A new finishing strategy is one module plus its test: a strategy defined here alone (along_x's passes with the
tip land first, by along_x's `pass_order`, with a key, facts and advice of its own) is registered in a registry of
this test's (a new mapping: the default REGISTRY is read-only and stays as it was) and followed through the job
loader, the key documentation, a run's summary.json, report, output set and programs, and `spur-cad verify`
reading those programs back. What the strategy cuts is judged against independent references: the tip circle
(the bull-nose section's distance from the axis written out here) and verify's simulation of the programs as a
controller reads them, against the design."""

from __future__ import annotations

import json
from dataclasses import dataclass, replace

import numpy as np
import pytest

from spur_cad.cam.ir import Feature
from spur_cad.cam.machine import MachineError
from spur_cad.cam.plan import check_cam_inputs
from spur_cad.cam.setups import LYING_FLAT, ROTARY_TABLE
from spur_cad.cam.strategies import REGISTRY, strategy_names
from spur_cad.cam.strategies.along_x import AlongXParams, AlongXStrategy
from spur_cad.cam.strategies.perimeter import PerimeterStrategy
from spur_cad.errors import JobFileError
from spur_cad.job import parse_job
from spur_cad.keydocs import job_file_reference_markdown
from spur_cad.keys import key
from spur_cad.pipeline import cam_inputs, plan_cam, run_job
from tests.workbench_helper import small_job_text

LAND_FIRST_ORDER = (Feature.TIP, Feature.RIGHT_FLANK, Feature.LEFT_FLANK)


@dataclass(frozen=True)
class LandFirstParams(AlongXParams):
    """along_x's keys and one of the test strategy's own (how many times the land is cut before the flanks)."""

    land_first_passes: int = key(1, low=1, high=3, label="LandFirstPasses", group="Finishing strategy",
                                 meaning="land_first (a strategy defined by a test): cuts of the tip land first")


@dataclass(frozen=True)
class LandFirstFacts:
    """The test strategy's summary fields (in this order) and report sentence."""

    land_first_passes: int
    tip_poses: int

    def report_text(self) -> str:
        return f"Finishing: land_first, the tip land {self.land_first_passes} x first, {self.tip_poses} poses."


@dataclass(frozen=True)
class LandFirstAdvice:
    """The test strategy's tool advice (summary tools.land_first_advice, the report's advice table)."""

    land_first_tool_max_diameter_mm: float


class LandFirstStrategy(AlongXStrategy):
    """along_x's passes and capabilities, the tip land first (`pass_order`), with its own key, facts and advice."""

    name = "land_first"
    description = "a test's strategy: along_x's passes, the tip land first"
    params_type = LandFirstParams
    pass_order = LAND_FIRST_ORDER

    def generate(self, spec, tool, machine, params, blank_radius_mm, modifications=None,
                 profile_tolerance_mm=0.001):
        path, result = super().generate(spec, tool, machine, params, blank_radius_mm)
        return path, replace(result, facts=LandFirstFacts(params.land_first_passes, len(result.poses.tip.y)),
                             tool_advice=LandFirstAdvice(2.0 * tool.diameter_mm))


STRATEGIES = {**REGISTRY, LandFirstStrategy.name: LandFirstStrategy()}
JOB = small_job_text().replace("[finishing]\n", '[finishing]\nstrategy = "land_first"\nland_first_passes = 2\n')


def test_the_loader_takes_the_strategy_and_its_key_from_the_registry_it_is_given_only():
    job = parse_job(JOB, "land.toml", strategies=STRATEGIES)
    assert (job.finishing.strategy, job.finishing.land_first_passes) == ("land_first", 2)
    with pytest.raises(JobFileError, match=r"^land\.toml:\d+: unknown key 'land_first_passes' in \[finishing\]"):
        parse_job(JOB, "land.toml")  # the default registry knows neither the key nor the strategy
    line = JOB.splitlines().index("land_first_passes = 2") + 1
    with pytest.raises(JobFileError) as caught:
        parse_job(JOB.replace("land_first_passes = 2", "land_first_passes = 4"), "land.toml", strategies=STRATEGIES)
    assert str(caught.value) == f"land.toml:{line}: [finishing] land_first_passes must be in 1..3, got 4"
    helical = parse_job(JOB.replace("[gear]\n", "[gear]\nhelix_angle_deg = 15.0\n"), "land.toml",
                        strategies=STRATEGIES)
    with pytest.raises(MachineError, match=r"strategy = 'land_first' is for spur gears; .* by strategy = "
                                           r"\"generating\"$"):
        check_cam_inputs(cam_inputs(helical))  # its declared capability (helical = False, along_x's), asked


class LyingFlatStrategy(PerimeterStrategy):
    """perimeter's passes, declared to cut the gear lying flat (a capability no strategy of the registry has)."""

    name = "lying_flat_test"
    lying_flat = True


def test_a_strategy_declared_lying_flat_is_refused_on_the_rotary_table_in_one_line_at_its_key():
    """The set-up reads the strategy's declared capability (MachineSetup.accepts_strategy): the rotary table takes
    the strategies that are not `lying_flat`; the 3-axis set-up none of the registry's (its finishing is the plan's
    own, cam/three_axis.py). A strategy declared lying flat, registered from this test alone, is refused on the
    rotary table before planning, blamed on its [finishing] strategy line, naming the strategies that fit."""
    assert all(ROTARY_TABLE.accepts_strategy(s) and not LYING_FLAT.accepts_strategy(s) for s in REGISTRY.values())
    assert LYING_FLAT.accepts_strategy(LyingFlatStrategy()) and not ROTARY_TABLE.accepts_strategy(LyingFlatStrategy())
    text = small_job_text().replace("[finishing]\n", '[finishing]\nstrategy = "lying_flat_test"\n')
    job = parse_job(text, "flat.toml", strategies={**REGISTRY, LyingFlatStrategy.name: LyingFlatStrategy()})
    with pytest.raises(MachineError) as caught:
        check_cam_inputs(cam_inputs(job))
    line = text.splitlines().index('strategy = "lying_flat_test"') + 1
    assert job.located(caught.value) == (
        f"flat.toml:{line}: [finishing] strategy = 'lying_flat_test' cuts the gear lying flat; on the rotary table "
        '([machine] axes = 4) finish by strategy = "perimeter" or "along_x" or "generating"')


def test_the_key_documentation_lists_the_strategy_and_its_key():
    text = job_file_reference_markdown(STRATEGIES)
    assert "| `land_first_passes` | integer | - | `1` | 1..3 | land_first (a strategy defined by a test): cuts of " \
           "the tip land first" in text
    assert "`perimeter`, `along_x`, `generating`, `land_first`" in text
    assert "land_first" not in job_file_reference_markdown()


@pytest.fixture(scope="module")
def run():
    """One plan and run of the job (its own simulation off: verify simulates the programs); a whole run (about
    40 s with verify), so these are in the slow tier (tests/test_strategy_registry.py runs a registry strategy's
    job in the fast one)."""
    job = parse_job(JOB + "\n[simulation]\nenabled = false\n", "land.toml", strategies=STRATEGIES)
    plan = plan_cam(job)
    return job, plan, run_job(job, plan=plan)


@pytest.mark.slow
def test_the_summary_the_report_and_the_output_set_show_the_strategy(run):
    from spur_cad.outputs import is_output_name

    job, _, result = run
    summary = json.loads(result.files["summary.json"])
    tip_poses = result.finishing.strategy_facts.tip_poses
    assert list(summary["finishing"])[:3] == ["strategy", "land_first_passes", "tip_poses"]  # its fields, in order
    assert (summary["finishing"]["strategy"], summary["finishing"]["land_first_passes"]) == ("land_first", 2)
    assert summary["tools"]["land_first_advice"] == {"land_first_tool_max_diameter_mm": 2.0 * 1.5}
    report = result.files["report.html"].decode()
    assert f"Finishing: land_first, the tip land 2 x first, {tip_poses} poses." in report
    assert "Advice for finishing strategy land_first" in report
    assert "finishing strategy land_first: each contact line is cut by one pass" in report  # its warning, its name
    assert "along_x" not in report.split("<h2")[0] + "".join(w for w in result.warnings)
    program = result.files["finishing.ngc"].decode()
    assert "(strategy: land_first, " in program
    assert all(is_output_name(name) for name in result.files)


@pytest.mark.slow
def test_the_tip_land_is_cut_first_on_the_tip_circle(run):
    job, plan, _ = run
    path = plan.finishing.toolpath
    cutting = path.feature != Feature.NONE
    for k in range(job.gear.teeth):
        features = path.feature[cutting & (path.space == k)]
        assert features[0] == Feature.TIP and Feature.TIP not in features[np.argmax(features != Feature.TIP):]
    tool = job.tools.finishing
    tip = cutting & (path.feature == Feature.TIP)
    beside = np.maximum(np.abs(path.y[tip]) - tool.flat_width_mm / 2.0, 0.0)
    distance = np.hypot(beside, path.z[tip] + tool.corner_radius_mm) - tool.corner_radius_mm
    assert np.allclose(distance, job.gear.tip_radius_mm, atol=1e-6)


@pytest.mark.slow
def test_verify_reads_its_programs_and_passes_the_cut_part(run):
    from spur_cad.verify.reader import read_program
    from spur_cad.verify.verify import verify_moves

    job, _, result = run
    programs = [read_program(result.files[name].decode(), job.post.dialect, name)
                for name in ("roughing.ngc", "finishing.ngc")]
    verified = verify_moves(job, programs)
    assert verified.passed, verified.lines()[-1]
    assert len(verified.spaces) == job.gear.teeth
    # the finishing program is this strategy's: without it the flanks keep roughing's stock, far beyond tolerance
    rough_only = verify_moves(job, programs[:1])
    assert not rough_only.passed and rough_only.max_leftover_mm > 3 * verified.leftover_tolerance_mm


def test_the_default_registry_is_unchanged():
    assert strategy_names() == ("perimeter", "along_x", "generating")
    assert "land_first" not in REGISTRY
