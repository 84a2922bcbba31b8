# FreeCAD runs this file when the GUI starts: it registers the spur_cad workbench. The commands,
# FeaturePython objects and task panel are imported only when the workbench is first activated.

import FreeCADGui


class SpurCadWorkbench(FreeCADGui.Workbench):
    """Spur gears cut with end mills on a 4-axis machining centre (rotary axis A about X)."""

    MenuText = "spur_cad"
    ToolTip = "Spur gears, stock and 4-axis jobs: exact gear solids, toolpaths, simulation, STEP and G-code"

    def __init__(self):
        from spur_cad_workbench.resources import icon_path

        self.__class__.Icon = icon_path("spur_cad")

    def Initialize(self):
        """Register the commands and build the toolbar and menu (first activation only)."""
        import FreeCAD

        try:
            import spur_cad  # noqa: F401
        except ImportError as exc:
            FreeCAD.Console.PrintError(f"spur_cad: cannot import spur_cad ({exc}); run `spur-cad install-freecad` "
                                       "from the Python environment where spur_cad is installed\n")
            return
        from spur_cad_workbench.commands import register_commands

        names = register_commands()
        self.appendToolbar("spur_cad", names)
        self.appendMenu("spur_cad", names)

    def Activated(self):
        return None

    def Deactivated(self):
        return None

    def GetClassName(self):
        return "Gui::PythonWorkbench"


FreeCADGui.addWorkbench(SpurCadWorkbench())
