"""The pipeline's report stage: figures from the job's plan and simulation, values from the summary."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from spur_cad.report.html import render_report

if TYPE_CHECKING:
    from spur_cad.job import Job
    from spur_cad.pipeline import CamPlan
    from spur_cad.sim.simulate import SimResult


def report_stage(job: Job, summary: dict, profile_png: bytes, plan: CamPlan, sim: SimResult | None) -> bytes:
    """report.html for the job (pure: bytes out)."""
    from spur_cad.cam.finishing import space_poses
    from spur_cad.cam.roughing import roughing_levels
    from spur_cad.report.figures import deviation_map_png, finishing_png, roughing_levels_png

    spec = job.gear
    blank = job.stock.blank_radius_mm(spec)
    images = {"profile": profile_png}
    if plan.roughing is not None and job.tools.roughing is not None:
        levels = roughing_levels(spec, job.tools.roughing, job.roughing, blank)
        images["roughing"] = roughing_levels_png(spec, levels.heights_mm, levels.half_widths_mm, job.tools.roughing,
                                                 blank)
    if plan.finishing is not None and job.tools.finishing is not None:
        poses = space_poses(spec, job.tools.finishing, job.finishing.target_scallop_mm)
        parts = (poses.right_flank, poses.root, poses.left_flank, poses.tip)
        y = np.concatenate([p.y for p in parts])
        z = np.concatenate([p.z for p in parts])
        a = np.concatenate([p.a for p in parts])
        images["finishing"] = finishing_png(spec, job.tools.finishing, y, z, a)
    if sim is not None:
        images["deviation"] = deviation_map_png(sim)
    return render_report(summary, images)
