"""The OCP names that differ between OCP 7.9 (OCCT 7.9: what CadQuery 2.8 brings) and OCP 8.0 (OCCT 8.0: what
build123d 0.13 brings), each imported once here so that the rest of the engine uses one name for both.

OCCT 8.0 dropped the per-package typedefs of its collection templates (TColgp_HArray1OfPnt, TopTools_ListOfShape,
...): OCP 8.0 binds each instantiated template once, in `OCP.collections` (Array1_gp_Vec, HArray1_gp_Pnt,
List_TopoDS_Shape, ...), with the same constructors and methods. It also folded the GCE2d package into GC
(GCE2d_MakeSegment is GC_MakeSegment2d). Found by importing every OCP name the package uses under OCP 8.0.1
(tests/test_build123d.py and CI's build123d 0.13 tier run the engine there).
"""

from __future__ import annotations

try:  # OCP 8.0
    from OCP.collections import Array1_gp_Vec as Array1OfVec
    from OCP.collections import HArray1_bool as HArray1OfBoolean
    from OCP.collections import HArray1_double as HArray1OfReal
    from OCP.collections import HArray1_gp_Pnt as HArray1OfPnt
    from OCP.collections import List_TopoDS_Shape as ListOfShape
    from OCP.GC import GC_MakeSegment2d as MakeSegment2d
except ImportError:  # OCP 7.9
    from OCP.GCE2d import GCE2d_MakeSegment as MakeSegment2d
    from OCP.TColgp import TColgp_Array1OfVec as Array1OfVec
    from OCP.TColgp import TColgp_HArray1OfPnt as HArray1OfPnt
    from OCP.TColStd import TColStd_HArray1OfBoolean as HArray1OfBoolean
    from OCP.TColStd import TColStd_HArray1OfReal as HArray1OfReal
    from OCP.TopTools import TopTools_ListOfShape as ListOfShape

__all__ = ["Array1OfVec", "HArray1OfBoolean", "HArray1OfPnt", "HArray1OfReal", "ListOfShape", "MakeSegment2d"]
