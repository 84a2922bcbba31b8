"""The questions the pipeline, summary, report, post and workbench ask a machine set-up or a gear kind instead of
reading its flags (issue 45), checked against independent facts: the CAD kernel's stock solid, what the error
budget really reads, the gear's own radii; and every table keyed by set-up or kind covers every one."""

from __future__ import annotations

import dataclasses
import string
from pathlib import Path
from types import SimpleNamespace

import pytest

from spur_cad import cad_stage, pipeline
from spur_cad.cam import plan
from spur_cad.cam.machine import Machine, RoughingParams, default_roughing_strategy
from spur_cad.cam.materials import MATERIALS
from spur_cad.cam.setups import LYING_FLAT, ROTARY_TABLE, SETUPS
from spur_cad.correct.correct import CORRECTED_KINDS
from spur_cad.geometry.internal import InternalGearSpec
from spur_cad.geometry.kinds import KINDS
from spur_cad.geometry.spec import GearSpec
from spur_cad.job import load_job
from spur_cad.report.sheet import KIND_LABELS
from tests.ocp_helper import exact_bounds

EXAMPLES = Path(__file__).resolve().parents[1] / "resources" / "examples"
JOBS = {ROTARY_TABLE: "reference_gear.toml", LYING_FLAT: "flat_gear.toml"}
BUDGET_PLACES = {"klass", "total", "runout", "tool_radius", "linear", "deflection", "thickness", "index_source",
                 "seed", "largest_index", "bent", "micro"}  # what report/sheet.py's error_budget_text fills


@pytest.mark.parametrize("table", [plan.SETUP_PLANS, plan.SETUP_CHECKS, pipeline.SETUP_BUDGETS,
                                   pipeline.SETUP_COMMENTS, pipeline.SETUP_SIMULATIONS, cad_stage.STOCK_SHAPES])
def test_every_table_keyed_by_setup_has_every_setup(table):
    assert set(table) == set(SETUPS.values())


def test_tables_keyed_by_kind_name_known_kinds():
    kinds = set(KINDS.values())
    for table in (KIND_LABELS, pipeline.KIND_HEADER_LINES, pipeline.CONTACT_KINDS, CORRECTED_KINDS):
        assert set(table) <= kinds


@pytest.mark.parametrize("setup", [ROTARY_TABLE, LYING_FLAT], ids=["table", "flat"])
def test_the_program_box_is_the_stock_solid_in_the_programs_frame(setup):
    """Siemens WORKPIECE's box against the CAD kernel's stock solid (stock.step). On the table the frames agree
    (gear axis = X, the stub toward +X); lying flat the solid lies along X 0..b with the front face at X = 0, the
    programs' Z0 on that top face and the gear below it: z = -x."""
    job = load_job(EXAMPLES / JOBS[setup])
    assert job.machine.setup is setup
    spec, stock = job.gear, job.stock
    box = setup.program_box_mm(stock.blank_radius_mm(spec), stock.blank_x_range_mm(spec), stock.stub_length_mm,
                               spec.face_width_mm)
    x0, y0, z0, x1, y1, z1 = exact_bounds(cad_stage.STOCK_SHAPES[setup](job))
    solid = (x0, y0, z0, x1, y1, z1) if setup is ROTARY_TABLE else (y0, z0, -x1, y1, z1, -x0)
    assert box == pytest.approx(solid, abs=1e-6)


@pytest.mark.parametrize("setup", [ROTARY_TABLE, LYING_FLAT], ids=["table", "flat"])
def test_the_budget_inputs_are_the_machine_keys_the_budget_reads(setup):
    """summary.json's error-budget inputs list a [machine] key exactly where changing it changes the set-up's
    budget (pipeline.error_budget; the calibration file is read into the job, not from the key)."""
    job = load_job(EXAMPLES / JOBS[setup])
    finishing = SimpleNamespace(finishing=SimpleNamespace(tool=job.tools.finishing))  # the plan's part it reads
    budget = pipeline.error_budget(job, finishing)
    inputs = setup.budget_inputs(job.machine, job.job.material)
    for name in ("rotary_accuracy_arcsec", "rotary_repeatability_arcsec", "spindle_runout_um", "tool_runout_um",
                 "tool_radius_error_um", "linear_accuracy_um"):
        machine = dataclasses.replace(job.machine, **{name: getattr(job.machine, name) + 1.0})
        changed = pipeline.error_budget(dataclasses.replace(job, machine=machine), finishing) != budget
        assert changed == (name in inputs), name
        assert name not in inputs or inputs[name] == getattr(job.machine, name)
    other = next(name for name in MATERIALS if name != job.job.material)
    section = dataclasses.replace(job.job, material=other)
    changed = pipeline.error_budget(dataclasses.replace(job, job=section), finishing) != budget
    assert changed == ("material" in inputs)


@pytest.mark.parametrize("setup", [ROTARY_TABLE, LYING_FLAT], ids=["table", "flat"])
def test_each_setup_words_the_error_budget_with_the_places_the_report_fills(setup):
    places = {field for _, field, _, _ in string.Formatter().parse(setup.error_budget_text) if field}
    assert places <= BUDGET_PLACES and {"klass", "total", "thickness"} <= places
    indexed = {"index_source", "largest_index"} <= places  # only a table indexes the spaces
    assert indexed == setup.writes_a


def test_roughing_by_flanks_is_the_default_only_where_a_turns():
    """Roughing by flanks turns A to each flank segment: the default only on a set-up whose programs turn A."""
    for setup in SETUPS.values():
        chosen = default_roughing_strategy(setup)
        assert RoughingParams(strategy=chosen).strategy == chosen  # a value the [roughing] key accepts
        assert (chosen == "flank") == setup.writes_a


def test_each_setup_sums_itself_up_in_the_workbench():
    """The folded Machine group names the axes where they are not the default set-up's."""
    assert ROTARY_TABLE.machine_summary == ""
    assert LYING_FLAT.machine_summary == ", 3 axes"
    assert Machine().setup is ROTARY_TABLE


@pytest.mark.parametrize("spec", [GearSpec(teeth=20, module_mm=2.0),
                                  GearSpec(teeth=20, module_mm=2.0, helix_angle_deg=15.0),
                                  InternalGearSpec(teeth=60, module_mm=2.0, addendum_coefficient=0.9,
                                                   rack_tip_radius_mm=0.4, shaper_cutter_teeth=20,
                                                   rim_outer_diameter_mm=140.0, face_width_mm=10.0)],
                         ids=["spur", "helical", "ring"])
def test_a_kind_has_a_rim_where_the_root_lies_outside_the_tip(spec):
    assert spec.kind.has_rim == (spec.root_radius_mm > spec.tip_radius_mm)
