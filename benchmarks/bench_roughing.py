"""Roughing by levels against flank roughing (issue 29, docs/benchmarks.md): the estimated machine time with
accelerations of both strategies with the same tool and cutting data, for the reference job and other gears of
module 0.5 to 6 and 8 to 120 teeth (tools sized as a user would, tests/gears.tools_for), spur and helical; and the
planning time (median of `runs`).

    python -m benchmarks.bench_roughing [--runs 3]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path

from benchmarks.common import median_seconds
from spur_cad.cam.estimate import estimate
from spur_cad.cam.machine import Machine, RoughingParams
from spur_cad.cam.recommend import recommend_tools
from spur_cad.cam.roughing import roughing_toolpath
from spur_cad.cam.strategies import REGISTRY
from spur_cad.cam.tools import Tool
from spur_cad.geometry import GearSpec
from spur_cad.job import load_job

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "resources" / "examples"

# name: (teeth, module, pressure angle, shift, rack tip radius)
GEARS = {
    "z8 m2 undercut": (8, 2.0, 20.0, 0.0, 0.6),
    "z12 m3 x 0.5": (12, 3.0, 20.0, 0.5, 0.5),
    "z30 m0.5": (30, 0.5, 20.0, 0.0, 0.1),
    "z40 m6": (40, 6.0, 20.0, 0.0, 1.2),
    "z120 m1": (120, 1.0, 20.0, 0.0, 0.25),
}


def _tool(spec: GearSpec, blank: float) -> Tool:
    """The roughing tool a user would pick: 0.8 x the largest that reaches the root next to a finishing tool of
    0.6 x its limits (tests/gears.tools_for: within perimeter finishing's plunge allowance), flutes 3 D long."""
    perimeter = REGISTRY["perimeter"]
    rec = recommend_tools(spec, blank, 1.0, strategy=perimeter)
    corner = round(0.6 * min(rec.finishing_max_corner_radius_mm, spec.rack_tip_radius_mm), 3)
    finishing = Tool(diameter_mm=round(0.6 * rec.finishing_max_flat_width_mm, 3) + 2 * corner, kind="bull_nose",
                     corner_radius_mm=corner)
    diameter = round(0.8 * recommend_tools(spec, blank, 1.0, finishing, strategy=perimeter).roughing_max_diameter_mm,
                     3)
    return Tool(diameter_mm=diameter, kind="flat", flutes=3, flute_length_mm=3.0 * diameter)


def _minutes(spec, tool, machine, params, blank, stock=None) -> float:
    margins = (stock.back_margin_mm, stock.stub_diameter_mm / 2.0, stock.front_margin_mm) if stock else ()
    return estimate(roughing_toolpath(spec, tool, machine, params, blank, *margins),
                    machine).time_with_acceleration_s / 60.0


def _compare(spec, tool, machine, params, blank, runs: int, stock=None) -> dict:
    levels = dataclasses.replace(params, strategy="levels")
    flank = dataclasses.replace(params, strategy="flank")
    old, new = (_minutes(spec, tool, machine, p, blank, stock) for p in (levels, flank))
    return {"tool_mm": tool.diameter_mm, "levels_min": round(old, 1), "flank_min": round(new, 1),
            "ratio": round(old / new, 2),
            "flank_plan_s": round(median_seconds(lambda: roughing_toolpath(spec, tool, machine, flank, blank), runs),
                                  2)}


def figures(runs: int = 3) -> dict:
    out = {}
    for example in ("reference_gear.toml", "helical_gear.toml"):
        job = load_job(EXAMPLES / example)
        out[example] = _compare(job.gear, job.tools.roughing, job.machine, job.roughing,
                                job.stock.blank_radius_mm(job.gear), runs, job.stock)
    for helix in (0.0, 15.0):
        for name, (z, m, pa, x, rho) in GEARS.items():
            spec = GearSpec(teeth=z, module_mm=m, pressure_angle_deg=pa, profile_shift_coefficient=x,
                            rack_tip_radius_mm=rho, face_width_mm=max(5.0 * m, 6.0), helix_angle_deg=helix)
            blank = spec.tip_radius_mm + 0.5
            params = RoughingParams(flank_allowance_mm=0.075 * m, finish_stock_mm=0.005 * m)
            out[f"{name}{' helix 15' if helix else ''}"] = _compare(spec, _tool(spec, blank), Machine(), params,
                                                                  blank, runs)
    return out


TWO_STAGE = {"reference_gear.toml": (4.5, 6.0, 8.0), "z120 m1": (1.0, 1.5, 2.0), "z40 m6": (5.0, 6.0, 8.0)}
"""Larger tools tried above the roughing tool (two-stage roughing by flanks, the same cutting data)."""


def two_stage_figures() -> dict:
    """Two-stage roughing by flanks against the roughing tool alone (estimated with accelerations; the plan uses the
    quicker): each larger tool (flutes 3 D long, or the job tool's length if longer) above the example's tool or
    the sized one (its flute length not given), the same cutting data."""
    from spur_cad.cad.specs import StockSpec
    from spur_cad.cam.plan import CamInputs, plan_cam
    from spur_cad.cam.strategies import FinishingParams

    out = {}
    for name, sizes in TWO_STAGE.items():
        if name in GEARS:
            z, m, pa, x, rho = GEARS[name]
            spec = GearSpec(teeth=z, module_mm=m, pressure_angle_deg=pa, profile_shift_coefficient=x,
                            rack_tip_radius_mm=rho, face_width_mm=max(5.0 * m, 6.0))
            stock = StockSpec(radial_allowance_mm=0.5)
            tool = dataclasses.replace(_tool(spec, spec.tip_radius_mm + 0.5), flute_length_mm=0.0)  # 3 D: shorter
            # than this blank's spaces need, so "not given" (the axial depth limit stays 3 D)
            params = RoughingParams(flank_allowance_mm=0.075 * m, finish_stock_mm=0.005 * m, strategy="flank")
            machine = Machine()
        else:
            job = load_job(EXAMPLES / name)
            spec, stock, tool, machine = job.gear, job.stock, job.tools.roughing, job.machine
            params = dataclasses.replace(job.roughing, strategy="flank")
        for diameter in sizes:
            top = dataclasses.replace(tool, diameter_mm=diameter, tool_number=4,
                                      flute_length_mm=max(tool.flute_length_mm, 3.0 * diameter))
            plan = plan_cam(CamInputs(spec, stock, tool, None, params, FinishingParams(), machine, top_tool=top))
            stage = plan.two_stage or plan.two_stage_declined
            out[f"{name} D{diameter:g} over D{tool.diameter_mm:g}"] = {
                "two_stage_min": round(stage.two_stage_time_s / 60.0, 1),
                "alone_min": round(stage.bottom_tool_alone_time_s / 60.0, 1), "used": plan.two_stage is not None}
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    print(json.dumps({"strategies": figures(args.runs), "two_stage": two_stage_figures()}, indent=2))


if __name__ == "__main__":
    main()
