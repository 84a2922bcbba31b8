"""The report's figures from typed inputs: from the CAM plan, the simulation and the graded result (the page itself is
spur_cad.report.html.render_report's)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from spur_cad.cam.plan import CamPlan
    from spur_cad.geometry.modifications import FlankModifications
    from spur_cad.geometry.spec import GearSpec
    from spur_cad.result import JobResult
    from spur_cad.sim.simulate import SimResult


def plan_images(profile_png: bytes, spec: GearSpec, blank_radius_mm: float, plan: CamPlan,
                modifications: FlankModifications | None = None) -> dict[str, bytes]:
    """The report's figures that need no simulation ({name: PNG bytes} for spur_cad.report.html.render_report;
    pure): the tooth space's profile, the flank modification chart from the design's `modifications`, and the
    roughing levels and finishing contact poses from the plan. A run draws them while its CAD worker builds."""
    from spur_cad.report.figures import finishing_png, passes_png, roughing_flank_png, roughing_levels_png

    images = {"profile": profile_png}
    if modifications is not None:
        from spur_cad.report.figures import modification_chart_png

        images["modifications"] = modification_chart_png(modifications, spec.base_radius_mm)
    if plan.finishing is not None and plan.finishing.result.lying_flat:
        return images  # [machine] axes = 3: no level or contact figures (the report's text says what was planned)
    if plan.roughing is not None and plan.roughing.flank is not None:
        images["roughing"] = roughing_flank_png(spec, plan.roughing.flank, plan.roughing.tool, blank_radius_mm)
    elif plan.roughing is not None:
        levels = plan.roughing.levels
        images["roughing"] = roughing_levels_png(spec, levels.heights_mm, levels.half_widths_mm, plan.roughing.tool,
                                                 blank_radius_mm)
    if plan.finishing is not None and plan.finishing.result.passes:
        images["finishing"] = passes_png(spec, plan.finishing.tool, plan.finishing.result.passes, blank_radius_mm)
    elif plan.finishing is not None and plan.finishing.result.poses is not None:  # a contact strategy's poses
        poses = plan.finishing.result.poses
        parts = (poses.right_flank, poses.root, poses.left_flank, poses.tip)
        y = np.concatenate([p.y for p in parts])
        z = np.concatenate([p.z for p in parts])
        a = np.concatenate([p.a for p in parts])
        images["finishing"] = finishing_png(spec, plan.finishing.tool, y, z, a)
    return images


def simulation_images(result: JobResult, spec: GearSpec, plan: CamPlan, sim: SimResult | None) -> dict[str, bytes]:
    """The report's figures from the simulation and the graded result ({name: PNG bytes}; pure; none without a
    simulation): the deviation map (from the simulation, not recomputed), the roughing engagement and the K-chart.
    They read the result's set-up, tools and grading but not its CAD facts."""
    if sim is None:
        return {}
    from spur_cad.report.figures import deviation_map_png

    lying_flat = plan.finishing is not None and plan.finishing.result.lying_flat
    images = {"deviation": deviation_map_png(sim, lying_flat)}
    rough = result.setup
    # step-down and step-over: both given (with a roughing tool) or neither
    step_down = rough.roughing_step_down_mm if rough is not None else None
    step_over = rough.roughing_step_over_mm if rough is not None else None
    if (sim.engagement is not None and result.tools.roughing is not None and step_down is not None
            and step_over is not None):
        from spur_cad.report.figures import engagement_png

        diameter = result.tools.roughing.diameter_mm
        flank = plan.roughing.flank if plan.roughing is not None and plan.roughing_bottom is None else None
        images["engagement"] = engagement_png(sim.engagement, step_over / diameter, step_down / diameter,
                                              flank.limits.slot_depth_mm / diameter if flank is not None else None)
    if result.grading is not None and result.grading.has_profile_traces:
        from spur_cad.report.figures import k_chart_png

        images["kchart"] = k_chart_png(spec, result.grading, lying_flat)
    return images
