"""Simulation of the whole reference job (roughing + finishing) at 5 um and 2 um, and the speed ratio of
the fast simulation vs OCP booleans on the subsets the cross-check tests use."""

from __future__ import annotations

import statistics
import time
from pathlib import Path

import numpy as np

from spur_cad.cam.ir import Feature
from spur_cad.job import load_job
from spur_cad.pipeline import job_stock, plan_cam
from spur_cad.sim import Cut, SimSettings, finishing_stations, simulate, subset
from spur_cad.sim.occ_check import cross_check
from spur_cad.summary import simulation_section

REFERENCE_JOB = Path(__file__).resolve().parents[1] / "resources" / "examples" / "reference_gear.toml"


def full_job(resolution_mm: float, runs: int) -> dict:
    """Median seconds of the whole reference job's simulation (numba compiled beforehand) and its facts."""
    job = load_job(REFERENCE_JOB)
    plan = plan_cam(job)
    ops = [Cut(plan.roughing.toolpath, job.tools.roughing), Cut(plan.finishing.toolpath, job.tools.finishing)]
    stations = finishing_stations(plan.finishing.toolpath)
    times, result = [], None
    for _ in range(runs):
        start = time.perf_counter()
        result = simulate(job.gear, job_stock(job), ops, SimSettings(resolution_mm=resolution_mm), station_x=stations)
        times.append(time.perf_counter() - start)
    facts = simulation_section(result, result.settings.resolution_mm)
    return {"median_s": statistics.median(times), "runs": runs, "moves": facts["moves"],
            "poses_clipped": facts["poses_clipped"], "design_points": facts["design_points"],
            "max_gouge_mm": facts["max_gouge_mm"], "max_leftover_mm": facts["max_leftover_mm"],
            "removed_volume_mm3": facts["removed_volume_mm3"]}


def occ_ratio(runs: int) -> dict:
    """Fast simulation vs OCP booleans on the cross-check subsets (6 finishing flank moves, 5 roughing moves)."""
    job = load_job(REFERENCE_JOB)
    plan = plan_cam(job)
    fin, rough = plan.finishing.toolpath, plan.roughing.toolpath
    x = finishing_stations(fin)
    finishing = np.zeros(len(fin), bool)
    window = (fin.station == 70) & (fin.space == 3) & (fin.feature == Feature.RIGHT_FLANK)
    finishing[np.nonzero(window)[0][40:46]] = True
    roughing = np.zeros(len(rough), bool)
    roughing[np.nonzero(rough.space == 0)[0][:5]] = True
    out = {}
    for name, path, tool, rows, stations in (("finishing", subset(fin, finishing), job.tools.finishing,
                                              (x[64], x[76]), x),
                                             ("roughing", subset(rough, roughing), job.tools.roughing, (0.0, 20.0),
                                              np.zeros(0))):
        checks = [cross_check(job.gear, job_stock(job), path, tool, SimSettings(), rows, stations)
                  for _ in range(runs)]
        fast = statistics.median(c.fast_seconds for c in checks)
        occ = statistics.median(c.occ_seconds for c in checks)
        out[name] = {"moves": int(len(path)), "tool_solids": checks[0].tool_solids, "fast_s": fast, "occ_s": occ,
                     "speed_ratio": occ / fast, "max_difference_mm": max(c.max_difference_mm for c in checks)}
    return out


def bench_sim(runs: int) -> dict:
    full_job(0.005, 1)  # compile (numba caches machine code; the first run of a fresh install compiles)
    return {"reference_job_5um": full_job(0.005, runs), "reference_job_2um": full_job(0.002, max(1, runs // 2)),
            "occ_cross_check": occ_ratio(max(1, runs // 2))}
