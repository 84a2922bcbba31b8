"""The Simulate command's link to spur_cad.sim, guarded for a spur_cad without the simulator.

`simulate_job` cuts the stock with the job's toolpaths through spur_cad.sim's pipeline stage
(`spur_cad.pipeline.simulate_stage`, as `spur-cad run` does); `show_result` draws every design
point of the face width, in the part frame, coloured by its deviation (blue gouge, green on
the design, red leftover). Without spur_cad.sim, `simulator()` raises SimulationUnavailable
with the message the command shows.
"""

from __future__ import annotations

import numpy as np

from spur_cad.errors import SpurCadError

MAX_SHOWN_POINTS = 300_000

NOT_AVAILABLE = "simulation not available: this spur_cad has no simulator (spur_cad.sim)"


class SimulationUnavailable(SpurCadError):
    """The installed spur_cad cannot simulate (no spur_cad.sim)."""


def simulator():
    """The spur_cad.sim module; raises SimulationUnavailable when it is not installed."""
    import importlib

    try:
        return importlib.import_module("spur_cad.sim")
    except ModuleNotFoundError as exc:
        if exc.name in ("spur_cad.sim", "spur_cad"):
            raise SimulationUnavailable(NOT_AVAILABLE) from None
        raise


def simulate_job(job, plan, resolution_mm: float | None = None):
    """spur_cad.sim's result for the job's roughing then finishing IR, at the job's [simulation] resolution
    unless `resolution_mm` is given (simulated even when [simulation] enabled is false: the user asked)."""
    import dataclasses

    simulator()
    from spur_cad.pipeline import simulate_stage

    settings = dataclasses.replace(job.simulation, enabled=True,
                                   resolution_mm=resolution_mm or job.simulation.resolution_mm)
    settings.validate()
    wanted = dataclasses.replace(job, simulation=settings)
    result = simulate_stage(wanted, plan)
    if result is None:
        raise SpurCadError("the job has no toolpaths to simulate (choose a roughing or finishing tool)")
    return result


def colour_scale_mm(resolution_mm: float) -> float:
    """Deviation shown fully blue (gouge) or red (leftover): five times the simulation's resolution."""
    return 5.0 * resolution_mm


def deviation_colours(deviation: np.ndarray, scale_mm: float) -> np.ndarray:
    """(N, 3) RGB in [0, 1]: blue at -scale (gouge), green at 0, red at +scale (leftover) and beyond."""
    t = np.clip(np.asarray(deviation, float) / scale_mm, -1.0, 1.0)
    red = np.clip(t, 0.0, 1.0)
    blue = np.clip(-t, 0.0, 1.0)
    return np.column_stack([red, 1.0 - np.abs(t), blue])


def result_points(result) -> tuple[np.ndarray, np.ndarray]:
    """Design points of the face width in the part frame (N, 3) and their deviations (N,), rows thinned
    evenly when there are more than MAX_SHOWN_POINTS."""
    grid = result.grid
    rows = np.nonzero(result.gear_rows)[0]
    per_row = grid.teeth * len(grid.points)
    stride = max(1, int(np.ceil(len(rows) * per_row / MAX_SHOWN_POINTS)))
    rows = rows[::stride]
    def row(r: int) -> np.ndarray:  # (teeth * M, 3): every space's points in this row (turned by a helix)
        transverse = np.concatenate([grid.row_points(k, grid.rows_x[r])[0] for k in range(grid.teeth)])
        return np.column_stack([np.full(len(transverse), grid.rows_x[r]), transverse])

    points = np.concatenate([row(r) for r in rows])
    deviation = np.concatenate([result.deviation[:, :, r].reshape(-1) for r in rows])
    return points, deviation


def show_result(job_obj, result):
    """A Points object '<job> simulation' with the coloured design points and the result's facts."""
    import FreeCAD
    import Points

    doc = job_obj.Document
    name = f"{job_obj.Label} simulation"
    found = [obj for obj in doc.Objects if obj.TypeId == "Points::Feature" and obj.Label == name]
    obj = found[0] if found else doc.addObject("Points::Feature", "Simulation")
    obj.Label = name
    points, deviation = result_points(result)
    scale = colour_scale_mm(result.settings.resolution_mm)
    properties = (("Color", "App::PropertyColorList", "deviation colour per point"),
                  ("Resolution", "App::PropertyLength", "simulation resolution"),
                  ("MaxGouge", "App::PropertyLength", "largest gouge (material removed below the design)"),
                  ("MaxLeftover", "App::PropertyLength", "largest leftover (material above the design)"),
                  ("RemovedVolume", "App::PropertyFloat", "removed volume (mm^3)"),
                  ("Seconds", "App::PropertyFloat", "simulation time (s)"),
                  ("Legend", "App::PropertyString", "colour legend"))
    for prop, type_id, doc_text in properties:
        if prop not in obj.PropertiesList:
            obj.addProperty(type_id, prop, "Simulation", doc_text, 1 if prop != "Color" else 0)
    obj.Points = Points.Points([FreeCAD.Vector(*p) for p in points])
    obj.Color = [tuple(c) for c in deviation_colours(deviation, scale)]
    obj.Resolution = result.settings.resolution_mm
    obj.MaxGouge = result.max_gouge_mm
    obj.MaxLeftover = result.max_leftover_mm
    obj.RemovedVolume = result.removed_volume_mm3
    obj.Seconds = result.seconds
    obj.Legend = (f"blue: gouge of {scale:g} mm or more, green: on the design, red: leftover of {scale:g} mm or "
                  f"more ({len(points)} of {result.deviation[:, :, result.gear_rows].size} design points shown)")
    doc.recompute()
    if FreeCAD.GuiUp and obj.ViewObject is not None:
        obj.ViewObject.DisplayMode = "Color"
        obj.ViewObject.PointSize = 3
    FreeCAD.Console.PrintMessage(f"{name}: max gouge {result.max_gouge_mm:.4f} mm, max leftover "
                                 f"{result.max_leftover_mm:.4f} mm\n")
    return obj
