"""CAD layer (CadQuery / OCP): exact gear solid, stock, STEP. Import submodules explicitly:
`spur_cad.cad.solid` loads the CAD kernel; `spur_cad.cad.specs` does not."""
