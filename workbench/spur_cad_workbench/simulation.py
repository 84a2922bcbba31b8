"""The Simulate command's link to spur_cad.sim, guarded for a spur_cad without the simulator.

`simulate_job` cuts the stock with the job's toolpaths through spur_cad.sim's pipeline stage
(`spur_cad.pipeline.simulate_stage`, as `spur-cad run` does); `show_result` draws every design
point of the face width, in the part frame, coloured by its deviation (blue gouge, green on
the design, red leftover) in a simulation object linked to its job; while it is visible, the
job's toolpath objects are hidden (views.py). The colour scale (`ColourScale`, editable) starts
at the largest deviation shown, so the worst point is fully coloured; a colour bar in the 3D
view gives the scale. The object remembers the values it was simulated for (`PlannedValues`):
when the job changes, the job marks it stale (grey). Without spur_cad.sim, `simulator()` raises
SimulationUnavailable with the message the command shows.
"""

from __future__ import annotations

import numpy as np

from spur_cad.errors import SpurCadError
from spur_cad_workbench.colours import deviation_colours
from spur_cad_workbench.compat import StatelessProxy
from spur_cad_workbench.views import show_toolpaths_unless_simulated

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


def simulate_job(job, plan, resolution_mm: float | None = None, progress=None):
    """spur_cad.sim's result for the job's roughing then finishing IR, at the job's [simulation] resolution
    unless `resolution_mm` is given (simulated even when [simulation] enabled is false: the user asked).
    `progress(fraction)` is told how far the simulation is."""
    import dataclasses

    simulator()
    from spur_cad.pipeline import simulate_stage

    # the resolution asked for is checked when the section is made (SimulationError naming it)
    settings = dataclasses.replace(job.simulation, enabled=True,
                                   resolution_mm=resolution_mm or job.simulation.resolution_mm)
    wanted = dataclasses.replace(job, simulation=settings)
    result = simulate_stage(wanted, plan, progress)
    if result is None:
        raise SpurCadError("the job has no toolpaths to simulate (choose a roughing or finishing tool)")
    return result


def colour_scale_mm(deviation: np.ndarray, resolution_mm: float) -> float:
    """Deviation shown fully blue (gouge) or red (leftover): the largest deviation, at least the resolution
    (differences below it are the simulation's own)."""
    largest = float(np.max(np.abs(deviation))) if len(deviation) else 0.0
    return max(largest, resolution_mm)


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

    points = np.concatenate([row(int(r)) for r in rows])
    deviation = np.concatenate([result.deviation[:, :, r].reshape(-1) for r in rows])
    return points, deviation


_RESULT_PROPERTIES = (
    ("Job", "App::PropertyLink", "the job simulated"),
    ("Color", "App::PropertyColorList", "deviation colour of each point (the Color display mode shows them)"),
    ("PlannedValues", "App::PropertyString", "fingerprint of the job values simulated"),
    ("Status", "App::PropertyString", "ok, or stale when the job changed after the simulation"),
    ("ColourScale", "App::PropertyLength", "deviation shown fully blue (gouge) or red (leftover); edit to rescale"),
    ("Deviations", "App::PropertyFloatList", "deviation of each point (mm, + leftover)"),
    ("ResolutionMicrons", "App::PropertyFloat", "simulation resolution (um)"),
    ("MaxGougeMicrons", "App::PropertyFloat", "largest gouge: material removed below the design (um)"),
    ("MaxLeftoverMicrons", "App::PropertyFloat", "largest leftover: material above the design (um)"),
    ("RemovedVolume", "App::PropertyFloat", "removed volume (mm^3)"),
    ("Seconds", "App::PropertyFloat", "simulation time (s)"),
    ("DesignPoints", "App::PropertyInteger", "design points of the face width (the points drawn are a subset)"),
    ("PlanSource", "App::PropertyString", "whether the job's plan was reused or planned for the simulation"),
    ("Legend", "App::PropertyString", "colour legend"),
)
_EDITABLE = {"ColourScale"}


def legend_text(scale_mm: float, shown: int, total: int) -> str:
    """What the colours mean, and how many of the design points are drawn."""
    return (f"blue: gouge of {scale_mm * 1000:.3g} um or more, green: on the design, red: leftover of "
            f"{scale_mm * 1000:.3g} um or more ({shown:,} of {total:,} design points shown)")


class SimulationFeature(StatelessProxy):
    """Proxy of a simulation object (Points::FeaturePython): recolours the points when ColourScale changes.
    Saved as null (compat.StatelessProxy); the deviations live in the Deviations property."""

    KIND = "simulation"

    def __init__(self, obj):
        obj.Proxy = self

    def execute(self, obj):
        return None

    def onChanged(self, obj, prop):
        if prop == "ColourScale" and "Deviations" in obj.PropertiesList and len(obj.Deviations):
            recolour(obj)


def recolour(obj) -> None:
    """Colour the points by their deviation on the object's ColourScale; update the legend and the colour bar."""
    import FreeCAD

    scale = max(float(obj.ColourScale.Value), 1e-6)
    obj.Color = [tuple(c) for c in deviation_colours(np.asarray(obj.Deviations), scale)]
    obj.Legend = legend_text(scale, len(obj.Deviations), obj.DesignPoints)
    if FreeCAD.GuiUp and obj.Status == "ok":
        from spur_cad_workbench.colourbar import show_colour_bar

        show_colour_bar(scale, obj.Document)


def show_current(obj) -> None:
    """A simulation whose job has the simulated values again (after being stale): its colours and colour bar."""
    import FreeCAD

    obj.Status = "ok"
    if FreeCAD.GuiUp and obj.ViewObject is not None:
        obj.ViewObject.DisplayMode = "Color"
    recolour(obj)


def _simulation_object(job_obj, role: str, view_provider):
    """The job's simulation object of `role` ("simulation" of its own toolpaths, "verification" of programs;
    made when missing, its view given a `view_provider` proxy in the GUI), linked to the job."""
    import FreeCAD

    doc = job_obj.Document
    for obj in job_obj.InList:
        if getattr(getattr(obj, "Proxy", None), "KIND", "") == "simulation" and \
                obj.Label == f"{job_obj.Label} {role}":
            return obj
    obj = doc.addObject("Points::FeaturePython", role.capitalize())
    SimulationFeature(obj)
    for prop, type_id, doc_text in _RESULT_PROPERTIES:
        # read-only outputs (1 | 8): setting them (stale marking) does not ask for a recompute
        obj.addProperty(type_id, prop, "Simulation", doc_text, 0 if prop in _EDITABLE else 1 | 8)
    for hidden in ("Deviations", "Color"):  # hundreds of thousands of numbers
        obj.setEditorMode(hidden, 2)
    obj.Job = job_obj
    if FreeCAD.GuiUp and obj.ViewObject is not None:
        view_provider(obj.ViewObject)
    return obj


def show_result(job_obj, result, planned_values: str = "", plan_source: str = "", role: str = "simulation", *,
                view_provider):
    """The job's object '<job> <role>' with the coloured design points and the result's facts (role
    "simulation": the job's own toolpaths; "verification": programs read by `verify_programs`).
    `view_provider` is the proxy class of a new object's view (features.ViewProvider), passed in by the
    caller because features imports this module."""
    import FreeCAD
    import Points

    obj = _simulation_object(job_obj, role, view_provider)
    obj.Label = f"{job_obj.Label} {role}"
    points, deviation = result_points(result)
    scale = colour_scale_mm(deviation, result.settings.resolution_mm)
    obj.Points = Points.Points([FreeCAD.Vector(*p) for p in points])
    obj.Deviations = [float(d) for d in deviation]
    obj.PlannedValues = planned_values
    obj.Status = "ok"
    obj.ResolutionMicrons = result.settings.resolution_mm * 1000.0
    obj.MaxGougeMicrons = result.max_gouge_mm * 1000.0
    obj.MaxLeftoverMicrons = result.max_leftover_mm * 1000.0
    obj.RemovedVolume = result.removed_volume_mm3
    obj.Seconds = result.seconds
    obj.PlanSource = plan_source
    obj.DesignPoints = int(result.deviation[:, :, result.gear_rows].size)
    if abs(float(obj.ColourScale.Value) - scale) > 1e-15:
        obj.ColourScale = scale  # recolours (onChanged)
    else:
        recolour(obj)
    obj.purgeTouched()
    if FreeCAD.GuiUp and obj.ViewObject is not None:
        obj.ViewObject.DisplayMode = "Color"
        obj.ViewObject.PointSize = 3
        obj.ViewObject.Visibility = True
        show_toolpaths_unless_simulated(job_obj)  # the points lie under the toolpaths: hide those
    FreeCAD.Console.PrintMessage(f"{obj.Label}: max gouge {result.max_gouge_mm * 1000:.2f} um, max leftover "
                                 f"{result.max_leftover_mm * 1000:.2f} um\n")
    return obj
