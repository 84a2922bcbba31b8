"""An OCP shape as BREP text, the form in which spur_cad's solids cross to FreeCAD (Part.Shape's
importBrepFromString): OCP's own writer, so that the workbench needs neither CadQuery nor build123d."""

from __future__ import annotations

import io

from OCP.BRepTools import BRepTools
from OCP.TopoDS import TopoDS_Shape
from OCP.TopTools import TopTools_FormatVersion_VERSION_3

from spur_cad.errors import require_instance

BREP_FORMAT = TopTools_FormatVersion_VERSION_3
"""Written explicitly rather than OCP's current default: version 3 is what OCCT 7.6 (FreeCAD 0.20) and later read,
and what OCP 7.9 and 8.0 write today; a newer default in a later OCP must not make FreeCAD 0.20 refuse our shapes."""


def brep_text(shape: TopoDS_Shape) -> str:
    """`shape` as BREP text (geometry and topology, no triangulation)."""
    require_instance(shape, TopoDS_Shape, "shape")
    buffer = io.BytesIO()
    BRepTools.Write_s(shape, buffer, False, False, BREP_FORMAT)
    return buffer.getvalue().decode("ascii")
