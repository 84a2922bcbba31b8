"""Flat end mills (corner radius 0) for finishing by generation (docs/cam.md, issue 18).

A flat end mill plays the generating rack with its sharp corner: the simulator (which sweeps every
straight pass exactly along X and measures along the design normals) cuts gears from the blank with
the generating passes alone and must find no gouge and at most the target on flanks, fillets, root
and lands. The largest flat end mill is checked against the rack's tip flat 2 d_1 derived here from
the gear's data, and a tool just above it is refused naming it. Perimeter and along-X finishing refuse
flat end mills (their scallop is bounded by the corner radius). The smallest end mill warning appears
for a module-0.3 gear and not for the reference gear.
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np
import pytest

from spur_cad.cad.specs import StockSpec
from spur_cad.cam.finishing import plan_finishing
from spur_cad.cam.ir import Feature, MoveKind
from spur_cad.cam.machine import Machine, RoughingParams
from spur_cad.cam.plan import CamInputs, check_cam_inputs, plan_cam
from spur_cad.cam.recommend import check_tools, recommend_tools
from spur_cad.cam.strategies import FinishingParams, get_strategy
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.geometry import GearSpec
from spur_cad.job import load_job
from spur_cad.sim import Cut, SimSettings, StockCylinder, simulate, subset
from spur_cad.sim.design import design_grid
from spur_cad.sim.simulate import simulate_grid
from spur_cad.summary import recommendations_section, simulation_section
from tests.gears import REFERENCE_JOB, spec_of
from tests.tiers import sweep

RES = 0.002
POINT_SPACING_MM = 0.001
"""Design points every 1 um along the profile: a flat end mill's cusps on the fillets are some 10 um apart and
wedge-shaped (the simulator's own spacing follows the smallest corner radius, and takes 0.5 mm for a flat
tool: 60 um at this resolution). Passes along X are swept exactly and the deviation is exact along each
design normal, so the simulation can only miss a cusp's peak between two points (by about half the spacing
times the wedge's slope), never report more than there is: the leftover is checked against the target
itself plus LEFTOVER_SLACK_MM."""
LEFTOVER_SLACK_MM = 0.0002
GOUGE_LIMIT_MM = 1e-5
TARGET = 0.005
FACE_WIDTH = 2.0  # every section of a generating pass is the same: a short face keeps the simulation quick


def _reference_spec() -> GearSpec:
    return dataclasses.replace(load_job(REFERENCE_JOB).gear, face_width_mm=FACE_WIDTH)


def _spec(name: str) -> GearSpec:
    return _reference_spec() if name == "reference" else dataclasses.replace(spec_of(name), face_width_mm=FACE_WIDTH)


def _tip_flat_half_width_mm(spec: GearSpec) -> float:
    """d_1 from the gear's data: the generating rack's tooth is the gear's space width e on the rolling line,
    its tip line (r - r_f) below it; a sharp tip corner would be e/2 - (r - r_f) tan(alpha) from the tooth's
    axis, and a round of radius rho tangent to tip line and flank takes rho tan(45 deg - alpha/2) off it."""
    m, z, alpha = spec.module_mm, spec.teeth, math.radians(spec.pressure_angle_deg)
    x, rho = spec.profile_shift_coefficient, spec.rack_tip_radius_mm
    s_nominal = m * (math.pi / 2 + 2 * x * math.tan(alpha))
    s = s_nominal * (1 - spec.thickness_allowance_fraction) - spec.thickness_allowance_mm
    e = math.pi * m - s
    r, r_f = m * z / 2, m * z / 2 - (spec.dedendum_coefficient - x) * m
    return e / 2 - (r - r_f) * math.tan(alpha) - rho * math.tan(math.pi / 4 - alpha / 2)


def _flat(diameter: float) -> Tool:
    return Tool(diameter_mm=diameter, kind="flat", flutes=2)


def _largest_flat(spec: GearSpec) -> float:
    return recommend_tools(spec, spec.tip_radius_mm + 0.5, 1.0).finishing_flat_end_mill_max_diameter_mm


@functools.lru_cache(maxsize=None)
def _planned(name: str, fraction: float, end: str = "rack"):
    """(spec, tool, path, result, cut) for a flat end mill `fraction` of the largest on gear `name`."""
    spec = _spec(name)
    tool = _flat(round(fraction * _largest_flat(spec), 4))
    return (spec, tool, *_cut_from_blank(spec, tool, flank_tool_end=end))


def _cut_from_blank(spec: GearSpec, tool: Tool, **finishing):
    """The generating passes, their result, and a function simulating a toolpath cut from the blank by the tool,
    measured on the design every POINT_SPACING_MM in three rows (both faces and the middle)."""
    blank = spec.tip_radius_mm + 0.5
    section = FinishingParams(strategy="generating", target_scallop_mm=TARGET, **finishing)
    path, result = plan_finishing(spec, tool, Machine(), section, blank)
    b = spec.face_width_mm
    grid = dataclasses.replace(design_grid(spec, POINT_SPACING_MM, 0.0, 0.0), rows_x=np.array([0.0, b / 2, b]),
                               row_width=np.array([b / 4, b / 2, b / 4]))
    stock = StockCylinder(blank, 0.0, b)
    return path, result, lambda p: simulate_grid(grid, stock, [Cut(p, tool)], SimSettings(resolution_mm=RES),
                                                 face_width_mm=b)


# (gear, fraction of the largest flat end mill, flank tool end): a rack with a tip round (reference gear,
# rho 0.8 mm), a sharp rack (rho = 0), an undercut gear, and the raised tool end.
CASES = [("reference", 0.999, "rack"), ("pa25_sharp_rack_z17", 0.999, "rack"), ("undercut_z8", 0.9, "rack"),
         ("reference", 0.7, "raised")]


@pytest.mark.parametrize("name, fraction, end", sweep(CASES, fast=["undercut_z8"]))  # 8 s each; the fast case is the
# undercut gear (the rack and raised ends on the reference gear are the slow tier's)
def test_a_flat_end_mill_finishes_by_generation_within_target_without_gouge(name, fraction, end):
    _, _, path, result, cut = _planned(name, fraction, end)
    facts = simulation_section(cut(path), RES)
    assert facts["uncut_points"] == 0
    assert {"right involute", "right fillet", "root", "left fillet", "left involute"} <= set(facts["per_feature"])
    for feature, values in facts["per_feature"].items():
        assert values["max_gouge_mm"] <= GOUGE_LIMIT_MM, (feature, values)
        assert values["max_leftover_mm"] <= TARGET + LEFTOVER_SLACK_MM, (feature, values)
    # The plan's own figures promise no more than the target.
    assert result.facts.flat_height_mm <= TARGET and result.facts.tip_mode_leftover_mm <= TARGET


@pytest.mark.slow  # a planted fault's simulated cut (8 s)
def test_a_fillet_pass_left_out_is_found_by_the_same_check():
    """The acceptance above sees a missing tip-mode pass of the flat tool (so it would see a plan whose cusps
    it misjudges)."""
    _, _, path, result, cut = _planned("reference", 0.999)
    rows = np.nonzero((path.feature == Feature.RIGHT_FLANK) & (path.space == 3) & (path.kind == MoveKind.LINEAR))[0]
    flank = result.facts.flank_passes_per_flank
    keep = np.ones(len(path), bool)
    keep[rows[flank + (len(rows) - flank) // 2]] = False  # a pass in the middle of the right fillet
    dev = cut(subset(path, keep)).deviation
    assert dev[3].max() > TARGET + LEFTOVER_SLACK_MM
    assert np.delete(dev, 3, axis=0).max() <= TARGET + LEFTOVER_SLACK_MM


@pytest.mark.parametrize("name", ["reference", "pa25_sharp_rack_z17", "undercut_z8", "many_teeth_z120",
                                  "shifted_z12", "small_module_z30", "big_shift_corner_above_rolling_line_z30"])
def test_the_largest_flat_end_mill_is_the_racks_tip_flat(name):
    """On these gears the flank passes take wider tools than the tip flat: the largest flat end mill is
    2 d_1, derived from the gear's data; 1 um above it the tool is refused, naming it."""
    spec = _spec(name)
    d1 = _tip_flat_half_width_mm(spec)
    largest = _largest_flat(spec)
    assert largest == pytest.approx(2 * d1, abs=1e-9)
    wider = _flat(largest + 0.001)
    rec = recommend_tools(spec, spec.tip_radius_mm + 0.5, 1.0, wider)
    with pytest.raises(ToolError, match=f"finishing_flat_end_mill_max_diameter_mm = {largest:.4f} mm") as caught:
        check_tools(spec, rec, None, wider)
    assert caught.value.key == "tools.finishing.diameter_mm"
    with pytest.raises(ToolError, match=rf"largest diameter for tip mode with a flat end mill: {2 * d1:.4f} mm"):
        get_strategy("generating").check_tool(spec, wider)
    get_strategy("generating").check_tool(spec, _flat(largest))


@pytest.mark.parametrize("strategy", ["perimeter", "along_x"])
def test_perimeter_and_along_x_refuse_a_flat_end_mill_with_the_reason(strategy):
    job = load_job(REFERENCE_JOB)
    flat = _flat(1.5)  # within the root arc (1.64 mm) and the rack's tip flat
    with pytest.raises(ToolError, match=r"flat end mill \(corner radius 0\).*bounded by the corner radius.*"
                                        r"strategy = \"generating\"") as caught:
        get_strategy(strategy).check_tool(job.gear, flat)
    assert caught.value.key == "tools.finishing.kind"
    inputs = CamInputs(job.gear, job.stock, None, flat, job.roughing,
                       dataclasses.replace(job.finishing, strategy=strategy), job.machine)
    with pytest.raises(ToolError, match="strategy perimeter" if strategy == "perimeter" else "along_x"):
        check_cam_inputs(inputs)
    if strategy == "perimeter":  # the same tool passes the checks of the default strategy (generating)
        generating = CamInputs(job.gear, job.stock, None, flat, job.roughing, job.finishing, job.machine)
        assert check_cam_inputs(generating)[0].finishing_flat_end_mill_max_diameter_mm > 1.5


def test_a_helical_gear_with_a_round_rack_refuses_a_flat_end_mill_with_the_reason():
    spec = load_job(REFERENCE_JOB.parent / "helical_gear.toml").gear
    rec = recommend_tools(spec, spec.tip_radius_mm + 0.5, 1.0)
    assert rec.finishing_flat_end_mill_max_diameter_mm == 0.0
    with pytest.raises(ToolError, match="no flat end mill can finish this gear.*rack tip radius rho = 0.8 mm"):
        check_tools(spec, rec, None, _flat(1.0))
    with pytest.raises(ToolError, match=r"a flat end mill \(r_t = 0\) plays only a sharp rack .* rho = 0.8 mm"):
        get_strategy("generating").check_tool(spec, _flat(1.0))


def test_the_recommendations_list_the_flat_end_mill_and_the_largest_generating_tool():
    spec = _reference_spec()
    rec = recommend_tools(spec, spec.tip_radius_mm + 0.5, 1.0)
    section = recommendations_section(rec)
    d1 = _tip_flat_half_width_mm(spec)
    assert section["finishing_flat_end_mill_max_diameter_mm"] == pytest.approx(2 * d1, abs=1e-9)
    # With the advised corner radius rho the tip flat takes 2 d_1 + 2 rho (the flanks take more).
    assert section["finishing_generating_max_diameter_mm"] == pytest.approx(2 * d1 + 1.6, abs=1e-9)
    assert all(isinstance(v, float) for v in rec.as_dict().values())


def _warnings(spec: GearSpec) -> list[str]:
    inputs = CamInputs(spec, StockSpec(), None, None, RoughingParams(), FinishingParams(), Machine())
    return [w for w in plan_cam(inputs).warnings if "smallest_end_mill_mm" in w]


def test_recommended_tools_below_the_smallest_end_mill_are_warned_about():
    small = GearSpec(teeth=30, module_mm=0.3, rack_tip_radius_mm=0.06, face_width_mm=3.0)
    rec = recommend_tools(small, small.tip_radius_mm + 0.5, 1.0)
    warned = _warnings(small)
    for key in ("roughing_max_diameter_mm", "finishing_generating_max_diameter_mm",
                "finishing_flat_end_mill_max_diameter_mm"):
        assert getattr(rec, key) < 1.0
        assert sum(f"({key} = {getattr(rec, key):.3f} mm)" in w for w in warned) == 1, (key, warned)
    assert all("smallest_end_mill_mm = 1 mm" in w for w in warned)
    assert _warnings(_reference_spec()) == []


@pytest.mark.slow
def test_a_helical_gear_with_a_sharp_rack_is_finished_by_a_flat_end_mill():
    """rho = 0: the flat end mill's corner is the rack's sharp corner along the whole pass (generating_helical).
    Its wedge-shaped cusps need many evenly spaced rolls: 5 um is refused by the roll limit, 20 um is planned.
    Three spaces cut from the blank, the middle one measured (about 20 s)."""
    from spur_cad.errors import WorkLimitError

    spec = dataclasses.replace(load_job(REFERENCE_JOB.parent / "helical_gear.toml").gear, rack_tip_radius_mm=0.0,
                               face_width_mm=FACE_WIDTH)
    target, res = 0.02, 0.005
    rec = recommend_tools(spec, spec.tip_radius_mm + 0.5, 1.0, target_scallop_mm=target)
    largest = rec.finishing_flat_end_mill_max_diameter_mm
    d_n = _tip_flat_half_width_mm(dataclasses.replace(spec, helix_angle_deg=0.0))  # the normal section's rack
    assert largest == pytest.approx(2 * d_n, abs=1e-9)
    tool = _flat(round(0.999 * largest, 4))
    blank = spec.tip_radius_mm + 0.5
    with pytest.raises(WorkLimitError, match="target_scallop_mm"):
        plan_finishing(spec, tool, Machine(), FinishingParams(strategy="generating", target_scallop_mm=TARGET), blank)
    path, _ = plan_finishing(spec, tool, Machine(), FinishingParams(strategy="generating", target_scallop_mm=target),
                             blank)
    result = simulate(spec, StockCylinder(blank, 0.0, spec.face_width_mm),
                      [Cut(subset(path, np.isin(path.space, [0, 1, 2])), tool)], SimSettings(resolution_mm=res))
    middle = result.deviation[1][:, result.gear_rows]
    assert -middle.min() <= res  # helical passes are sampled poses: gouge within the resolution
    assert middle.max() <= target + res
