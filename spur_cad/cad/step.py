"""STEP export of the gear, the stock and the job assembly (named, coloured parts), in millimetres.

Returns bytes (CadQuery's exporters write to a path, so they write into a private temporary
folder that is removed afterwards); the caller decides where the files go.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import cadquery as cq

GEAR_COLOUR = (0.55, 0.62, 0.72, 1.0)  # steel blue-grey
STOCK_COLOUR = (0.85, 0.75, 0.45, 0.35)  # translucent brass


def _export_shape(workplane: cq.Workplane, name: str, folder: Path) -> bytes:
    path = folder / f"{name}.step"
    cq.exporters.export(workplane, str(path), exportType="STEP")
    return path.read_bytes()


def job_assembly(gear: cq.Workplane, stock: cq.Workplane, name: str = "job") -> cq.Assembly:
    """Assembly with parts named `gear` and `stock`, both already in the machine frame."""
    assembly = cq.Assembly(name=name)
    assembly.add(gear, name="gear", color=cq.Color(*GEAR_COLOUR))
    assembly.add(stock, name="stock", color=cq.Color(*STOCK_COLOUR))
    return assembly


def step_files(gear: cq.Workplane, stock: cq.Workplane) -> dict[str, bytes]:
    """{'gear.step', 'stock.step', 'job.step'} as bytes."""
    with tempfile.TemporaryDirectory(prefix="spur_cad_step_") as tmp:
        folder = Path(tmp)
        files = {"gear.step": _export_shape(gear, "gear", folder),
                 "stock.step": _export_shape(stock, "stock", folder)}
        job_path = folder / "job.step"
        job_assembly(gear, stock).export(str(job_path), exportType="STEP")
        files["job.step"] = job_path.read_bytes()
    return files
