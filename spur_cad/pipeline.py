"""The job pipeline shared by the CLI and the FreeCAD workbench: job in, output files out (in memory).

`run_job` computes every output of a job (profile, STEP, toolpath programs, summary) without
touching the file system, so both front ends write exactly the same bytes for the same job.
"""

from __future__ import annotations

import io
import json
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable

import numpy as np

from spur_cad import __version__
from spur_cad.geometry.inspection import inspection_sheet
from spur_cad.geometry.sampling import ProfileSamples, sample_profile
from spur_cad.job import Job

if TYPE_CHECKING:
    from spur_cad.cam.ir import Toolpath


@dataclass(frozen=True)
class CamPlan:
    """The CAM stage's result: summary facts (tools, roughing, finishing, warnings) and the IR."""

    facts: dict
    roughing: Toolpath | None
    finishing: Toolpath | None


def profile_csv(samples: ProfileSamples) -> bytes:
    """Right half of one tooth space, root (x = 0) to tip, header x_mm,y_mm."""
    buffer = io.StringIO()
    buffer.write("x_mm,y_mm\n")
    np.savetxt(buffer, samples.points, fmt="%.9f", delimiter=",")
    return buffer.getvalue().encode()


def build_summary(job: Job, samples: ProfileSamples, cad: dict, cam: dict, seconds: dict[str, float]) -> dict:
    """summary.json content: gear data, inspection sheet, profile sampling facts, CAD and CAM facts, timings."""
    counts = {name: int(np.count_nonzero(np.array(samples.label_names()) == name))
              for name in ("root", "fillet", "involute", "tip")}
    return {
        "spur_cad_version": __version__,
        "job": {"name": job.job.name, "file": job.source},
        "gear": job.gear.describe(),
        "inspection": inspection_sheet(job.gear),
        "profile": {"tolerance_mm": job.job.profile_tolerance_mm, "points": len(samples),
                    "points_per_segment": counts},
        "cad": cad,
        **cam,
        "timings_s": seconds,
    }


def run_job(job: Job, progress: Callable[[str, float], None] | None = None) -> dict[str, bytes]:
    """Compute every output of the job in memory (no file I/O). `progress(stage, fraction)` is told how
    far each long stage is (the CLI draws progress bars with it)."""
    from spur_cad.report.plots import tooth_space_png
    from spur_cad.report.stage import report_stage
    from spur_cad.sim.stage import simulate_stage

    def tell(stage: str, fraction: float) -> None:
        if progress is not None:
            progress(stage, fraction)

    seconds: dict[str, float] = {}
    start = time.perf_counter()
    samples = sample_profile(job.gear.tooth_space_profile(), job.job.profile_tolerance_mm)
    seconds["profile"] = time.perf_counter() - start
    start = time.perf_counter()
    png = tooth_space_png(job.gear, samples)
    seconds["plot"] = time.perf_counter() - start
    start = time.perf_counter()
    tell("CAD and STEP", 0.0)
    cad, step = build_cad(job)
    tell("CAD and STEP", 1.0)
    seconds["cad_and_step"] = time.perf_counter() - start
    start = time.perf_counter()
    tell("toolpaths", 0.0)
    plan = plan_cam(job)
    tell("toolpaths", 1.0)
    seconds["cam"] = time.perf_counter() - start
    start = time.perf_counter()
    post, programs = build_programs(job, plan)
    seconds["post"] = time.perf_counter() - start
    start = time.perf_counter()
    tell("simulation", 0.0)
    simulation, sim_result = simulate_stage(job, plan, lambda fraction: tell("simulation", fraction))
    tell("simulation", 1.0)
    seconds["simulation"] = time.perf_counter() - start
    summary = build_summary(job, samples, cad, {**plan.facts, "post": post, "simulation": simulation}, seconds)
    start = time.perf_counter()
    tell("report", 0.0)
    report = report_stage(job, summary, png, plan, sim_result)
    tell("report", 1.0)
    seconds["report"] = time.perf_counter() - start
    return {
        "profile.csv": profile_csv(samples),
        "profile.png": png,
        **step,
        **programs,
        "report.html": report,
        "summary.json": (json.dumps(summary, indent=2, sort_keys=False) + "\n").encode(),
    }


def build_programs(job: Job, plan: CamPlan) -> tuple[dict, dict[str, bytes]]:
    """G-code for each toolpath the plan has (roughing.<ext>, finishing.<ext>); returns (summary facts, files)."""
    from spur_cad.post import ProgramInfo, dialect, post_program

    settings = job.post
    facts: dict = {"dialect": settings.dialect, "folded": settings.folded}
    files: dict[str, bytes] = {}
    for name, path in (("roughing", plan.roughing), ("finishing", plan.finishing)):
        if path is None:
            continue
        info = ProgramInfo(title=f"spur_cad {__version__} {name}: {job.job.name}",
                           comments=program_comments(job, plan, name),
                           rotary_clamp_code=job.machine.rotary_clamp_code,
                           rotary_unclamp_code=job.machine.rotary_unclamp_code)
        program = post_program(path, settings, info)
        files[f"{name}.{dialect(settings.dialect).extension}"] = program.text.encode()
        facts[f"{name}_lines"] = program.lines
        facts[f"{name}_bytes"] = program.bytes
        facts[f"{name}_subprograms"] = program.subprograms
    return facts, files


def program_comments(job: Job, plan: CamPlan, operation: str) -> tuple[str, ...]:
    """Header comments of a program: gear data, tool, strategy, estimated time (no date: outputs are reproducible)."""
    spec = job.gear
    tool = job.tools.roughing if operation == "roughing" else job.tools.finishing
    facts = plan.facts[operation]
    if operation == "roughing":
        strategy = (f"strategy: {facts['levels_per_space']} levels per space, flank allowance "
                    f"{job.roughing.flank_allowance_mm:g} mm")
    else:
        strategy = (f"strategy: {facts['strategy']}, {facts['stations']} stations, {facts['points_per_flank']} "
                    f"contacts per flank, target scallop {job.finishing.target_scallop_mm * 1000:g} um")
    minutes = facts["estimated_time_s"] / 60.0
    return (
        f"gear: z = {spec.teeth}, m = {spec.module_mm:g} mm, alpha = {spec.pressure_angle_deg:g} deg, "
        f"x = {spec.profile_shift_coefficient:g}, b = {spec.face_width_mm:g} mm, rho = {spec.rack_tip_radius_mm:g} mm",
        f"radii: tip {spec.tip_radius_mm:.4f} mm, root {spec.root_radius_mm:.4f} mm",
        f"tool T{tool.tool_number}: {tool.kind} D {tool.diameter_mm:g} mm, corner radius {tool.corner_radius:g} mm, "
        f"S {tool.spindle_rpm(job.machine):.0f} rpm, F {tool.feed_mm_min(job.machine):.0f} mm/min",
        strategy,
        f"estimated time: {minutes:.1f} min ({facts['moves']} moves)",
        "frame: X = gear axis (front face X0), Y0 Z0 on the A axis, tool tip centre programmed",
    )


def build_cad(job: Job) -> tuple[dict, dict[str, bytes]]:
    """Gear solid, stock and STEP files; returns (summary facts, files)."""
    import cadquery as cq

    from spur_cad.cad.solid import build_gear_shape, make_stock, solid_volume_mm3
    from spur_cad.cad.step import step_files

    shape, report = build_gear_shape(job.gear, job.gear_section.blank_features())
    gear = cq.Workplane("YZ").add(cq.Solid(shape))
    stock = make_stock(job.gear, job.stock)
    files = step_files(gear, stock)
    facts = {
        "fit_tolerance_mm": report.fit_tolerance_mm,
        "fillet_max_deviation_mm": report.fillet_max_deviation_mm,
        "involute_max_deviation_mm": report.involute_max_deviation_mm,
        "fillet_spline_poles": report.fillet_poles,
        "involute_spline_poles": report.involute_poles,
        "gear_volume_mm3": solid_volume_mm3(shape),
        "stock_volume_mm3": solid_volume_mm3(stock.val().wrapped),
        "step_bytes": {name: len(content) for name, content in files.items()},
    }
    return facts, files


def plan_cam(job: Job) -> CamPlan:
    """Tool recommendations always; toolpaths and estimates for the tools the job gives."""
    from spur_cad.cam.estimate import estimate
    from spur_cad.cam.finishing import (
        finishing_toolpath,
        space_poses,
        station_positions,
        station_step_mm,
    )
    from spur_cad.cam.machine import FinishingParams, check_travel
    from spur_cad.cam.recommend import (
        check_roughing_reach,
        check_tools,
        recommend_tools,
    )
    from spur_cad.cam.roughing import roughing_levels, roughing_toolpath

    spec, machine, stock = job.gear, job.machine, job.stock
    blank = stock.blank_radius_mm(spec)
    finishing_tool, roughing_tool = job.tools.finishing, job.tools.roughing
    rec = recommend_tools(spec, blank, machine.clearance_mm, finishing_tool)
    check_tools(spec, rec, roughing_tool, finishing_tool)
    result: dict = {"tools": {**rec.as_dict(),
                              "roughing": _tool_facts(roughing_tool, machine),
                              "finishing": _tool_facts(finishing_tool, machine)}}
    warnings: list[str] = []
    roughing = finishing = None
    if roughing_tool is not None:
        levels = roughing_levels(spec, roughing_tool, job.roughing, blank)
        lowest_above_root = levels.lowest_height_mm - spec.root_radius_mm
        if finishing_tool is not None:
            check_roughing_reach(roughing_tool, lowest_above_root, rec)
        path = roughing = roughing_toolpath(spec, roughing_tool, machine, job.roughing, blank,
                                            stock.back_margin_mm, stock.stub_diameter_mm / 2.0,
                                            stock.front_margin_mm)
        check_travel(machine, path.x, path.y, path.z, path.a, "roughing")
        est = estimate(path, machine)
        result["roughing"] = {"levels_per_space": len(levels.heights_mm),
                              "lowest_level_height_mm": lowest_above_root,
                              "level_heights_mm": [float(h) for h in levels.heights_mm],
                              "moves": est.moves, "cutting_length_mm": est.cutting_length_mm,
                              "rapid_length_mm": est.rapid_length_mm, "estimated_time_s": est.time_s}
        warnings.extend(path.warnings)
    if finishing_tool is not None:
        path = finishing = finishing_toolpath(spec, finishing_tool, machine, job.finishing, blank)
        check_travel(machine, path.x, path.y, path.z, path.a, "finishing")
        est = estimate(path, machine)
        reference = finishing_toolpath(spec, finishing_tool, machine, FinishingParams(
            strategy="perimeter", target_scallop_mm=job.finishing.target_scallop_mm, step_over_mm=0.14), blank,
            contact_spacing_mm=0.08)
        ref = estimate(reference, machine)
        poses = space_poses(spec, finishing_tool, job.finishing.target_scallop_mm)
        stations = station_positions(spec.face_width_mm, station_step_mm(finishing_tool, job.finishing))
        result["finishing"] = {"strategy": job.finishing.strategy,
                               "stations": len(stations) if job.finishing.strategy == "perimeter" else 1,
                               "station_step_mm": float(stations[1] - stations[0]) if len(stations) > 1 else 0.0,
                               "points_per_flank": poses.points_per_flank,
                               "moves": est.moves, "cutting_length_mm": est.cutting_length_mm,
                               "rapid_length_mm": est.rapid_length_mm, "estimated_time_s": est.time_s,
                               "reference_strategy_moves": ref.moves, "reference_strategy_time_s": ref.time_s}
        warnings.extend(path.warnings)
    result["warnings"] = warnings
    return CamPlan(result, roughing, finishing)


def _tool_facts(tool, machine) -> dict | None:
    if tool is None:
        return None
    return {"kind": tool.kind, "diameter_mm": tool.diameter_mm, "corner_radius_mm": tool.corner_radius,
            "flat_width_mm": tool.flat_width_mm, "spindle_rpm": tool.spindle_rpm(machine),
            "feed_mm_min": tool.feed_mm_min(machine)}
