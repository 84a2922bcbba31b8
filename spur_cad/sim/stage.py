"""The pipeline's simulation stage: the job's stock cut by its roughing then finishing IR."""

from __future__ import annotations

from typing import TYPE_CHECKING, Callable

import numpy as np

from spur_cad.cam.ir import Feature, MoveKind, Toolpath
from spur_cad.sim.simulate import Operation, SimResult, SimSettings, StockCylinder, simulate

if TYPE_CHECKING:
    from spur_cad.job import Job
    from spur_cad.pipeline import CamPlan


def job_stock(job: Job) -> StockCylinder:
    """The blank cylinder of the job's stock (front margin to back margin; the holding stub is not cut)."""
    spec, stock = job.gear, job.stock
    return StockCylinder(stock.blank_radius_mm(spec), -stock.front_margin_mm,
                         spec.face_width_mm + stock.back_margin_mm)


def finishing_stations(path: Toolpath | None) -> np.ndarray:
    """X of the transverse finishing stations found in the IR (cutting moves that do not move X)."""
    if path is None or len(path) == 0:
        return np.zeros(0)
    prev_x = np.concatenate([[path.x[0]], path.x[:-1]])
    cutting = (path.kind == MoveKind.LINEAR) & (path.feature != Feature.NONE) & (path.x == prev_x)
    return np.unique(path.x[cutting])


def simulate_stage(job: Job, plan: CamPlan,
                   progress: Callable[[float], None] | None = None) -> tuple[dict, SimResult | None]:
    """summary.json's `simulation` facts and the result (None when disabled or there is nothing to cut)."""
    settings = job.simulation
    operations = [Operation(path, tool) for path, tool in ((plan.roughing, job.tools.roughing),
                                                           (plan.finishing, job.tools.finishing))
                  if path is not None and tool is not None]
    if not settings.enabled or not operations:
        return {"enabled": False, "resolution_mm": settings.resolution_mm}, None
    stations = finishing_stations(plan.finishing) if job.finishing.strategy == "perimeter" else np.zeros(0)
    result = simulate(job.gear, job_stock(job), operations, SimSettings(resolution_mm=settings.resolution_mm),
                      station_x=stations, progress=progress)
    return {"enabled": True, **result.facts()}, result
