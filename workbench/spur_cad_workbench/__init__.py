"""spur_cad's FreeCAD workbench: parametric gear, stock and 4-axis job objects, commands, task panel.

Modules that import FreeCAD (properties, features, commands, taskpanel) are imported lazily by
InitGui.py and by the entry points; `schema`, `validation` and `environment` are plain Python and
run (and are tested) without FreeCAD. The modules and the order they import each other in (no
loops): workbench/README.md.
"""
