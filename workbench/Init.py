# FreeCAD runs this file at start-up (console and GUI), with the addon's `workbench` folder on
# sys.path (package.xml <subdirectory>). It only makes spur_cad importable: it adds the Python
# environment recorded by `spur-cad install-freecad`, or without that record (an install by the
# Addon Manager, which put the dependencies on sys.path) the addon's own folder, which holds the
# spur_cad package. Everything else is imported on first use.


def _spur_cad_activate_environment():
    """Put the recorded site-packages in front of sys.path; report problems in the report view."""
    import FreeCAD
    from spur_cad_workbench import environment

    try:
        problems = environment.activate(FreeCAD.getUserAppDataDir(),
                                        log=lambda text: FreeCAD.Console.PrintLog(f"spur_cad: {text}\n"))
    except RuntimeError as exc:
        problems = [str(exc)]
    for problem in problems:
        FreeCAD.Console.PrintWarning(f"spur_cad: {problem}\n")


_spur_cad_activate_environment()
