"""summary.json, built here and nowhere else: from the job, the sampled profile, the CAD result,
the typed CAM plan, the posted programs and the simulation result. Its keys are a public
interface (users' scripts read them): add keys, never rename or remove one."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from spur_cad import __version__
from spur_cad.cam.estimate import Estimate
from spur_cad.cam.machine import Machine
from spur_cad.cam.plan import CamPlan, FinishingPlan, RoughingPlan
from spur_cad.cam.recommend import ToolRecommendations
from spur_cad.cam.tools import Tool
from spur_cad.geometry.inspection import inspection_sheet
from spur_cad.geometry.sampling import ProfileSamples
from spur_cad.post.program import PostedProgram
from spur_cad.post.settings import PostSettings

if TYPE_CHECKING:  # the CAD kernel and the simulator load only when a job uses them
    from spur_cad.cad.solid import GearSolidReport
    from spur_cad.sim.simulate import SimResult

SEGMENT_NAMES = ("root", "fillet", "involute", "tip")


@dataclass(frozen=True)
class CadResult:
    """The CAD stage's facts: the solid's spline-fit report, volumes and STEP file sizes."""

    report: GearSolidReport
    gear_volume_mm3: float
    stock_volume_mm3: float
    step_bytes: dict[str, int]


def build_summary(job, samples: ProfileSamples, cad: CadResult, plan: CamPlan, post: PostSettings,
                  programs: dict[str, PostedProgram], simulation: SimResult | None,
                  seconds: dict[str, float]) -> dict:
    """The whole summary.json content (`job` is a spur_cad.job.Job)."""
    counts = {name: int(np.count_nonzero(np.array(samples.label_names()) == name)) for name in SEGMENT_NAMES}
    return {
        "spur_cad_version": __version__,
        "job": {"name": job.job.name, "file": job.source},
        "gear": job.gear.describe(),
        "inspection": inspection_sheet(job.gear),
        "profile": {"tolerance_mm": job.job.profile_tolerance_mm, "points": len(samples),
                    "points_per_segment": counts},
        "cad": cad_section(cad),
        **cam_sections(plan, job.machine, job.tools.roughing, job.tools.finishing),
        "post": post_section(post, programs),
        "simulation": simulation_section(simulation, job.simulation.resolution_mm),
        "grading": grading_section(job.gear, simulation),
        **({"lathe": lathe_section(job)} if job.lathe is not None else {}),
        "timings_s": seconds,
    }


def lathe_section(job) -> dict:
    """summary.json's `lathe` (with [lathe]): the control, the bar and the part the lathe program turns."""
    from spur_cad.cam.turning import lathe_geometry

    g = lathe_geometry(job.gear, job.stock, job.lathe)
    return {"dialect": job.lathe.dialect, "bar_diameter_mm": g.bar_diameter, "blank_diameter_mm": g.blank_diameter,
            "blank_length_mm": g.blank_length, "stub_diameter_mm": g.stub_diameter, "stub_length_mm": g.stub_length,
            "part_off": job.lathe.part_off, "work_offset": job.lathe.work_offset}


def grading_section(spec, result: SimResult | None) -> dict | None:
    """summary.json's `grading`: the simulated gear's ISO 1328-1:2013 deviations and classes (None without a
    simulation, or without a finished flank to measure)."""
    from spur_cad.grade.simulated import grade_simulation

    if result is None:
        return None
    grading = grade_simulation(spec, result)
    grading.pop("traces")
    return grading


def cad_section(cad: CadResult) -> dict:
    """summary.json's `cad` section."""
    report = cad.report
    return {
        "fit_tolerance_mm": report.fit_tolerance_mm,
        "fillet_max_deviation_mm": report.fillet_max_deviation_mm,
        "involute_max_deviation_mm": report.involute_max_deviation_mm,
        "fillet_spline_poles": report.fillet_poles,
        "involute_spline_poles": report.involute_poles,
        "gear_volume_mm3": cad.gear_volume_mm3,
        "stock_volume_mm3": cad.stock_volume_mm3,
        "step_bytes": dict(cad.step_bytes),
    }


def cam_sections(plan: CamPlan, machine: Machine, roughing_tool: Tool | None, finishing_tool: Tool | None) -> dict:
    """summary.json's `tools`, `roughing`, `finishing` (when planned) and `warnings` sections."""
    sections: dict = {"tools": {**recommendations_section(plan.recommendations),
                                "roughing": tool_section(roughing_tool, machine),
                                "finishing": tool_section(finishing_tool, machine)}}
    if plan.finishing is not None and plan.finishing.result.tool_advice:
        sections["tools"][f"{plan.finishing.result.strategy}_advice"] = dict(plan.finishing.result.tool_advice)
    if plan.roughing is not None:
        sections["roughing"] = roughing_section(plan.roughing)
    if plan.roughing_bottom is not None:
        stage = plan.two_stage
        sections["roughing"]["two_stage"] = {
            "bottom_tool": {**tool_section(plan.roughing_bottom.tool, machine),
                            "tool_number": plan.roughing_bottom.tool.tool_number},
            "split_height_above_root_mm": stage.split_height_above_root_mm, "split_chosen_by": stage.chosen,
            "bottom": roughing_section(plan.roughing_bottom), "two_stage_time_s": stage.two_stage_time_s,
            "bottom_tool_alone_time_s": stage.bottom_tool_alone_time_s, "time_saved_s": stage.gain_s}
    if plan.finishing is not None:
        sections["finishing"] = finishing_section(plan.finishing)
    sections["warnings"] = list(plan.warnings)
    return sections


def recommendations_section(rec: ToolRecommendations) -> dict:
    return {"finishing_max_flat_width_mm": rec.finishing_max_flat_width_mm,
            "finishing_max_corner_radius_mm": rec.finishing_max_corner_radius_mm,
            "plunge_allowance_mm": rec.plunge_allowance_mm,
            "roughing_max_diameter_mm": rec.roughing_max_diameter_mm,
            "required_flute_length_mm": rec.required_flute_length_mm,
            "required_stick_out_mm": rec.required_stick_out_mm,
            "finishing_generating_max_diameter_mm": rec.finishing_generating_max_diameter_mm,
            "finishing_flat_end_mill_max_diameter_mm": rec.finishing_flat_end_mill_max_diameter_mm}


def tool_section(tool: Tool | None, machine: Machine) -> dict | None:
    if tool is None:
        return None
    return {"kind": tool.kind, "diameter_mm": tool.diameter_mm, "corner_radius_mm": tool.effective_corner_radius_mm,
            "flat_width_mm": tool.flat_width_mm, "spindle_rpm": tool.spindle_rpm(machine),
            "feed_mm_min": tool.feed_mm_min(machine)}


def _estimate_facts(est: Estimate) -> dict:
    return {"moves": est.moves, "cutting_length_mm": est.cutting_length_mm, "rapid_length_mm": est.rapid_length_mm,
            "estimated_time_s": est.time_s, "estimated_time_with_acceleration_s": est.time_with_acceleration_s}


def roughing_section(roughing: RoughingPlan) -> dict:
    return {"levels_per_space": len(roughing.levels.heights_mm),
            "lowest_level_height_mm": roughing.lowest_level_above_root_mm,
            "level_heights_mm": [float(h) for h in roughing.levels.heights_mm],
            **_estimate_facts(roughing.estimate)}


def finishing_section(finishing: FinishingPlan) -> dict:
    """The strategy and its facts, its estimate, and the comparison estimates (null when left out)."""
    result = finishing.result
    facts = {"strategy": result.strategy, **result.summary_facts(), **_estimate_facts(finishing.estimate)}
    for prefix, other in (("perimeter", finishing.perimeter_estimate),
                          ("reference_strategy", finishing.reference_estimate)):
        facts[f"{prefix}_moves"] = other.moves if other else None
        facts[f"{prefix}_time_s"] = other.time_s if other else None
        facts[f"{prefix}_time_with_acceleration_s"] = other.time_with_acceleration_s if other else None
    return facts


def post_section(settings: PostSettings, programs: dict[str, PostedProgram]) -> dict:
    """summary.json's `post` section: dialect, folding, and lines/bytes/subprograms of each program."""
    facts: dict = {"dialect": settings.dialect, "folded": settings.folded}
    for name, program in programs.items():
        facts[f"{name}_lines"] = program.lines
        facts[f"{name}_bytes"] = program.bytes
        facts[f"{name}_subprograms"] = program.subprograms
    return facts


def simulation_section(result: SimResult | None, resolution_mm: float) -> dict:
    """summary.json's `simulation` section (only `enabled` and the resolution when nothing was simulated)."""
    if result is None:
        return {"enabled": False, "resolution_mm": resolution_mm}
    dev = result.deviation[:, :, result.gear_rows]
    finished = dev[dev < result.settings.leftover_range_mm - 1e-9]
    positive = np.maximum(finished, 0.0)
    names = np.array(result.grid.feature_names())
    per_feature = {}
    for name in ("right involute", "right fillet", "root", "left fillet", "left involute", "tip"):
        mask = np.array([n.endswith(name) if name in ("root", "tip") else n == name for n in names])
        if mask.any():
            values = dev[:, mask, :]
            per_feature[name] = {"max_gouge_mm": float(max(0.0, -values.min())),
                                 "max_leftover_mm": float(max(0.0, values.max())),
                                 "mean_mm": float(values.mean())}
    return {
        "enabled": True,
        "resolution_mm": result.settings.resolution_mm,
        "max_gouge_mm": result.max_gouge_mm,
        "max_leftover_mm": result.max_leftover_mm,
        "removed_volume_mm3": result.removed_volume_mm3,
        "seconds": result.seconds,
        "design_points": int(dev.size),
        "points_per_space": int(result.grid.points.shape[0]),
        "rows": int(result.gear_rows.sum()),
        "point_spacing_mm": result.grid.spacing_mm,
        "uncut_points": result.uncut_points,
        "scallop_mean_mm": float(positive.mean()) if positive.size else 0.0,
        "scallop_p95_mm": float(np.percentile(positive, 95)) if positive.size else 0.0,
        "scallop_p99_mm": float(np.percentile(positive, 99)) if positive.size else 0.0,
        "worst_gouge": result.worst(True),
        "worst_leftover": result.worst(False),
        "per_feature": per_feature,
        "moves": result.moves,
        "poses_clipped": result.poses_clipped,
        "x_sweeps": result.x_sweeps,
        "gouge_range_mm": result.settings.gouge_range_mm,
        "leftover_range_mm": result.settings.leftover_range_mm,
    }
