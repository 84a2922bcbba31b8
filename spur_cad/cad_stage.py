"""The CAD stage of a run: the gear solid, its stock and their STEP files, with the facts the summary reports.

Its own module (the kernel imported inside `build_cad`) so that `spur_cad.cad_worker` can run it in a second
process importing little else; `spur_cad.pipeline.build_cad` is this function.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Callable

from spur_cad.cam.setups import LYING_FLAT, ROTARY_TABLE, MachineSetup
from spur_cad.result import CadResult

if TYPE_CHECKING:
    from OCP.TopoDS import TopoDS_Shape

    from spur_cad.job import Job


def build_cad(job: Job, checkpoint: Callable[[], None] | None = None,
              timestamp: str | None = None) -> tuple[CadResult, dict[str, bytes]]:
    """Gear solid, stock and STEP files; returns (CAD facts, files). `checkpoint()` between the steps;
    `timestamp` is the STEP headers' time (step_timestamp)."""
    from spur_cad.cad.solid import build_gear_shape, front_face_area_mm2, solid_volume_mm3
    from spur_cad.cad.step import step_files

    shape, report = build_gear_shape(job.gear, job.gear_section.blank_features(), modifications=job.modifications)
    if checkpoint is not None:
        checkpoint()
    stock = STOCK_SHAPES[job.machine.setup](job)
    files = step_files(shape, stock, timestamp)
    if job.modifications is not None and job.modifications.has_lead:  # the section varies along X
        gear_volume = solid_volume_mm3(shape)
    else:
        gear_volume = front_face_area_mm2(shape) * job.gear.face_width_mm  # exact: a section moved along X
    facts = CadResult(report, gear_volume, solid_volume_mm3(stock),
                      {name: len(content) for name, content in files.items()})
    return facts, files


def _stock_on_table(job: Job) -> TopoDS_Shape:
    """The blank on the rotary table: a cylinder along X with its holding stub."""
    from spur_cad.cad.solid import build_stock_shape

    return build_stock_shape(job.gear, job.stock)


def _stock_lying_flat(job: Job) -> TopoDS_Shape:
    """The blank lying flat: a disk of the face width, clamped on its bore."""
    from spur_cad.cad.solid import build_flat_stock_shape

    return build_flat_stock_shape(job.gear, job.stock, job.gear_section.blank_features())


STOCK_SHAPES: dict[MachineSetup, Callable[[Job], TopoDS_Shape]] = {ROTARY_TABLE: _stock_on_table,
                                                           LYING_FLAT: _stock_lying_flat}
"""Each set-up's blank (build_cad's stock.step)."""
