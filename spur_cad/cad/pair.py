"""The gear and its [mate] as solids, placed at the centre distance and meshing, and the pair as an assembly STEP
(docs/cad.md, "The gear pair"). For scripts:

    from spur_cad.job import load_job
    from spur_cad.cad.pair import pair_shapes, pair_step_bytes
    job = load_job("pair.toml")                      # a job with [mate]
    gear, mate = pair_shapes(job.gear, job.pair)     # OCP shapes, machine frame (gear axis X)
    open("pair.step", "wb").write(pair_step_bytes(job.gear, job.pair))

Placement (machine frame, the gear's as gear_shape builds it, its tooth space 0 on +Z at the front face): an
external mate's axis at Z = +a, turned by pi - pi/z_2 about its own axis so that a tooth points into space 0; a
ring mate's axis at Z = -a, turned by pi/z_2; a ring gear's pinion at Z = +a, turned by pi/z_2. A helical mate has
the opposite hand (a ring's the same): its sections turn with X just as meshing asks (turn_1 z_1 / z_2 = turn_2),
so the placement at the front face holds through the face width. Both gears then stand in the symmetric position:
each flank of the mate's tooth is half the normal backlash from the gear's.
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

from OCP.gp import gp_Ax1, gp_Dir, gp_Pnt, gp_Trsf, gp_Vec
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS_Shape

from spur_cad.cad.solid import build_gear_shape, in_frame
from spur_cad.cad.step import GEAR_COLOUR, STOCK_COLOUR, _own_model, _settings, coloured_assembly
from spur_cad.errors import require_instance
from spur_cad.geometry.mate import GearPair, pair_facts
from spur_cad.geometry.mate_gear import mate_spec
from spur_cad.geometry.spec import GearSpec


def mate_placement(pair: GearPair) -> gp_Trsf:
    """The rigid motion putting the mate (built in the machine frame about its own axis) in mesh with the gear (see
    the module docstring): a turn about the X axis, then a shift along Z by the centre distance."""
    require_instance(pair, GearPair, "pair")
    a = pair_facts(pair).centre_distance_mm
    z2 = pair.mate.teeth
    if pair.mate.internal:
        turn, offset = math.pi / z2, -a
    elif pair.gear.internal:
        turn, offset = math.pi / z2, a
    else:
        turn, offset = math.pi - math.pi / z2, a
    rotation, shift = gp_Trsf(), gp_Trsf()
    rotation.SetRotation(gp_Ax1(gp_Pnt(0.0, 0.0, 0.0), gp_Dir(1.0, 0.0, 0.0)), turn)
    shift.SetTranslation(gp_Vec(0.0, 0.0, offset))
    return shift.Multiplied(rotation)


def pair_shapes(spec: GearSpec, pair: GearPair, frame: str = "machine") -> tuple[TopoDS_Shape, TopoDS_Shape]:
    """The gear and the mate as OCP solids in `frame` ("machine": the gear's axis X; "part": its axis Z, centred),
    the mate placed at the centre distance and meshing (mate_placement)."""
    require_instance(frame, str, "frame")
    gear, _ = build_gear_shape(spec)
    mate, _ = build_gear_shape(mate_spec(spec, pair))
    mate = mate.Moved(TopLoc_Location(mate_placement(pair)))
    return in_frame(gear, spec, frame), in_frame(mate, spec, frame)


def pair_document(gear: TopoDS_Shape, mate: TopoDS_Shape, name: str = "pair"):
    """An XCAF document holding the assembly `name` of the parts "gear" and "mate" (each a named, coloured
    compound of its solid, placed at the identity: the shapes carry their placement), as step.job_document."""
    mate_colour = (*STOCK_COLOUR[:3], 1.0)
    return coloured_assembly(name, (("gear", gear, GEAR_COLOUR), ("mate", mate, mate_colour)),
                             as_cadquery_does=False)


def pair_step_bytes(spec: GearSpec, pair: GearPair, frame: str = "part", timestamp: str | None = None) -> bytes:
    """The pair as an assembly STEP (parts "gear" and "mate", millimetres) in `frame` (default "part": the gear's
    axis Z); `timestamp` ('YYYY-MM-DDTHH:MM:SS', UTC) the header's time, OCCT's clock when None."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPCAFControl import STEPCAFControl_Writer
    from OCP.STEPControl import STEPControl_StepModelType
    from OCP.XSControl import XSControl_WorkSession

    gear, mate = pair_shapes(spec, pair, frame)
    writer = STEPCAFControl_Writer(XSControl_WorkSession(), False)
    writer.SetColorMode(True)
    writer.SetNameMode(True)
    _settings()
    writer.Transfer(pair_document(gear, mate), STEPControl_StepModelType.STEPControl_AsIs)
    _own_model(writer.ChangeWriter().Model(), None, timestamp)
    with tempfile.TemporaryDirectory(prefix="spur_cad_pair_") as tmp:
        path = Path(tmp) / "pair.step"
        if writer.Write(str(path)) != IFSelect_RetDone:
            raise RuntimeError("OCP could not write pair.step")
        return path.read_bytes()

