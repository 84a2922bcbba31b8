"""spur_cad's FreeCAD workbench: parametric gear, stock and 4-axis job objects, commands, task panel.

Modules that import FreeCAD (features, commands, taskpanel, display's FreeCAD part) are
imported lazily by InitGui.py and by the entry points; `schema`, `validation` and
`environment` are plain Python and run (and are tested) without FreeCAD.
"""
