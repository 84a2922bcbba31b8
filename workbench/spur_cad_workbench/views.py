"""What the 3D view shows of new objects: turned and fitted to them, and a simulation above the toolpaths.

A new document's camera looks down Z (FreeCAD 0.20's default), along the gear's face: the gear, whose
axis is the machine's rotary axis X (the job's frame), shows side-on as a rectangle. A new gear or an
imported job therefore turns the view to FreeCAD's isometric view (the gear seen obliquely, its axis
still X) and fits all objects; a new stock or job only fits, keeping the orientation the user chose.
The simulation's points lie on the gear's flanks, under the toolpaths: while a simulation or
verification of a job is visible, the job's toolpath objects are hidden; hiding the simulation (Space)
shows them again. Everything here does nothing without the GUI (freecadcmd, FreeCAD.GuiUp false).
"""

from __future__ import annotations


def view_3d(document):
    """The 3D view of a FreeCAD document (None without the GUI or a 3D view)."""
    import FreeCAD

    if not FreeCAD.GuiUp:
        return None
    import FreeCADGui

    gui_document = FreeCADGui.getDocument(document.Name)
    view = gui_document.ActiveView if gui_document is not None else None
    return view if view is not None and hasattr(view, "getSceneGraph") else None


def orient_and_fit(document, isometric: bool = True) -> bool:
    """Turn `document`'s 3D view to the isometric view (unless `isometric` is False) and fit all objects into
    it; False when there is no 3D view (console mode)."""
    view = view_3d(document)
    if view is None:
        return False
    if isometric:
        view.viewIsometric()
    view.fitAll()
    return True


def _is_simulation(obj) -> bool:
    return getattr(getattr(obj, "Proxy", None), "KIND", "") == "simulation"


def simulation_shown(job_obj) -> bool:
    """Whether a simulation or verification of the job is visible in the 3D view."""
    return any(_is_simulation(obj) and obj.ViewObject is not None and obj.ViewObject.Visibility
               for obj in job_obj.InList)


def show_toolpaths_unless_simulated(job_obj) -> None:
    """Hide the job's toolpath objects while one of its simulations is visible, show them otherwise (GUI only)."""
    import FreeCAD

    if not FreeCAD.GuiUp:
        return
    visible = not simulation_shown(job_obj)
    for path in (job_obj.RoughingToolpath, job_obj.FinishingToolpath):
        if path is not None and path.ViewObject is not None and path.ViewObject.Visibility != visible:
            path.ViewObject.Visibility = visible


def simulation_visibility_changed(simulation) -> None:
    """The user showed or hid a simulation: show or hide its job's toolpaths. Not while the document is being
    opened (the saved visibilities are already consistent, and the other objects' views may not exist yet)."""
    job_obj = getattr(simulation, "Job", None)
    if job_obj is None or simulation.Document.Restoring:
        return
    show_toolpaths_unless_simulated(job_obj)
