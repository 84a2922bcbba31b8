"""Measuring OCP shapes in tests the same way under OCP 7.9 and 8.0, with no front-end (CadQuery or build123d)."""

from __future__ import annotations

from OCP.Bnd import Bnd_Box
from OCP.BRepBndLib import BRepBndLib
from OCP.IFSelect import IFSelect_RetDone
from OCP.STEPControl import STEPControl_Reader
from OCP.TopoDS import TopoDS_Shape


def exact_bounds(shape: TopoDS_Shape) -> tuple[float, float, float, float, float, float]:
    """(x_min, y_min, z_min, x_max, y_max, z_max): OCP's optimal box on the geometry (not on a triangulation), no
    gap. Read through its corners: OCP 8.0 cannot return Bnd_Box.Get()'s value to Python."""
    box = Bnd_Box()
    box.SetGap(0.0)
    BRepBndLib.AddOptimal_s(shape, box, False, False)
    low, high = box.CornerMin(), box.CornerMax()
    return low.X(), low.Y(), low.Z(), high.X(), high.Y(), high.Z()


def read_step(path) -> TopoDS_Shape:
    """The shape of a STEP file, read with OCP's reader."""
    reader = STEPControl_Reader()
    assert reader.ReadFile(str(path)) == IFSelect_RetDone, path
    reader.TransferRoots()
    return reader.OneShape()
