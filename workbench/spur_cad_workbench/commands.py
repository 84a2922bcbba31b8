"""The workbench's commands: Python entry points (used headless and by macros) and their GUI commands.

Entry points take and return document objects:

    gear = make_gear(doc, Teeth=12, Module=3.0)      # property names of schema.GEAR_FIELDS
    stock = make_stock(gear)
    job = make_job(gear, stock)                       # tools suggested within the recommendations
    doc.recompute()
    export_job(job, "/tmp/out")                       # the same files as `spur-cad run`
    write_restart_program(job, RestartPoint("roughing", (("space", 5),)), "/tmp/roughing_space5.ngc")
    gear, stock, job = import_job_file(doc, "job.toml")
    result = simulate(job)                            # needs spur_cad.sim

The GUI commands run the entry points through FreeCADGui.doCommandGui, so they are recorded
in macros; a SpurCadError is shown as its message (report view and a message box), never as a
traceback. Spur gear and Import job file also turn the 3D view isometric and fit it, Stock and 4-axis job
fit it (recorded lines calling views.orient_and_fit); the entry points leave the camera alone. Long work
(export, simulate, verify, restart planning) shows FreeCAD's progress indicator and a wait cursor and keeps
the window repainting (progress.WorkProgress).
"""

from __future__ import annotations

from pathlib import Path

import FreeCAD

from spur_cad_workbench import compat, schema
from spur_cad_workbench.features import (
    GEAR_ANGULAR_DEFLECTION_DEG,
    GEAR_COLOUR,
    GEAR_DEVIATION_PERCENT,
    OPERATION_COLOURS,
    STOCK_COLOUR,
    GearFeature,
    JobFeature,
    StockFeature,
    ToolpathFeature,
    ViewProvider,
)
from spur_cad_workbench.progress import WorkProgress
from spur_cad_workbench.properties import document_values, job_of

EXPORT_STAGES = ("CAD and STEP", "toolpaths", "simulation", "report")
"""The stages spur_cad.pipeline.run_job reports to its progress callback, in order."""


def _checked(values: dict, fields, what: str) -> dict:
    """`values` (property name -> value) restricted to `fields`; unknown names are an error."""
    from spur_cad.errors import SpurCadError

    known = {field.prop for field in fields}
    unknown = sorted(set(values) - known)
    if unknown:
        raise SpurCadError(f"unknown {what} properties: {', '.join(unknown)} (known: {', '.join(sorted(known))})")
    return values


def _view(obj, colour=None, transparency: int | None = None) -> None:
    if not FreeCAD.GuiUp or obj.ViewObject is None:
        return
    ViewProvider(obj.ViewObject)
    if colour is not None:
        compat.set_shape_colour(obj.ViewObject, colour)
        if hasattr(obj.ViewObject, "NormalColor"):
            obj.ViewObject.NormalColor = colour
        if hasattr(obj.ViewObject, "LineColor") and obj.TypeId.startswith("Part"):
            obj.ViewObject.LineColor = colour
    if transparency is not None and hasattr(obj.ViewObject, "Transparency"):
        obj.ViewObject.Transparency = transparency


def _document(doc):
    return doc if doc is not None else (FreeCAD.ActiveDocument or FreeCAD.newDocument("Gear"))


def make_gear(doc=None, **values):
    """A new parametric gear (schema.GEAR_FIELDS values, defaults: schema.NEW_GEAR) in `doc`."""
    doc = _document(doc)
    gear_values = {**schema.default_values()["gear"], **_checked(values, schema.GEAR_FIELDS, "gear")}
    obj = doc.addObject("Part::FeaturePython", "Gear")
    GearFeature(obj, gear_values)
    _view(obj, GEAR_COLOUR)
    if FreeCAD.GuiUp and obj.ViewObject is not None:  # a fine tessellation: the involute drawn smooth
        obj.ViewObject.Deviation = GEAR_DEVIATION_PERCENT
        obj.ViewObject.AngularDeflection = GEAR_ANGULAR_DEFLECTION_DEG
    return obj


def make_stock(gear, **values):
    """The stock (blank) for `gear`, linked to it (a new stock's radial allowance: schema.new_stock_values)."""
    gear_values = {"Module": schema.plain_value(schema.field_by_prop("Module"), gear.Module)}
    stock_values = {**schema.new_stock_values(gear_values), **_checked(values, schema.STOCK_FIELDS, "stock")}
    obj = gear.Document.addObject("Part::FeaturePython", "Stock")
    StockFeature(obj, gear, stock_values)
    _view(obj, STOCK_COLOUR, transparency=75)
    return obj


def _toolpath_object(doc, operation: str):
    """A toolpath object: a FreeCAD Path object when the Path module loads, else a Part wire compound."""
    type_id = compat.PATH_FEATURE_TYPE if compat.path_module() is not None else "Part::FeaturePython"
    obj = doc.addObject(type_id, f"{operation.capitalize()}Toolpath")
    ToolpathFeature(obj, operation)
    _view(obj, OPERATION_COLOURS[operation])
    return obj


def make_job(gear, stock, suggest: bool = True, **values):
    """A 4-axis job for `gear` and `stock` with its roughing and finishing toolpath objects.

    Without tool values the job starts from what a gear maker would start from (validation.new_job_values: the
    suggested tools, two-stage roughing when it pays, the flank allowance unless given); `suggest=False` keeps
    the job file's defaults (no tools).
    """
    from spur_cad_workbench.validation import new_job_values, suggest_tools

    job_values = {**schema.default_values()["job"], **_checked(values, schema.JOB_FIELDS, "job")}
    tool_props = {field.prop for field in schema.JOB_FIELDS if field.section.startswith("tools.")}
    if suggest and not tool_props & set(values):
        from spur_cad_workbench.progress import WorkProgress

        current = {**document_values(stock), "job": job_values}
        with WorkProgress("4-axis job", ("choosing tools",)) as progress:  # a second or more: a wait cursor
            job_values.update(suggest_tools(current) if "FlankAllowance" in values else new_job_values(current))
            progress.stage_done("choosing tools")
    doc = gear.Document
    obj = doc.addObject("App::FeaturePython", "Job")
    JobFeature(obj, gear, stock, job_values)
    _view(obj)
    obj.RoughingToolpath = _toolpath_object(doc, "roughing")
    obj.FinishingToolpath = _toolpath_object(doc, "finishing")
    return obj


def import_job_file(doc, path: str):
    """Gear, stock and job objects holding the job file at `path` (validated as `spur-cad run` does)."""
    from spur_cad.job import load_job

    job = load_job(path)
    values = schema.values_from_job(job)
    doc = doc if doc is not None else FreeCAD.newDocument(document_name(path))
    gear = make_gear(doc, **values["gear"])
    stock = make_stock(gear, **values["stock"])
    job_obj = make_job(gear, stock, suggest=False, **values["job"])
    job_obj.Label = job.job.name
    doc.recompute()
    return gear, stock, job_obj


def find_job(doc):
    """The document's job object if there is exactly one; None otherwise."""
    jobs = [obj for obj in doc.Objects if getattr(getattr(obj, "Proxy", None), "KIND", "") == "job"]
    return jobs[0] if len(jobs) == 1 else None


def export_job(job_obj, out_dir: str) -> list[str]:
    """Write the job's files (STEP gear/stock/assembly, G-code, profile, summary) as `spur-cad run` does."""
    from spur_cad.errors import SpurCadError
    from spur_cad.job import with_files
    from spur_cad.outputs import write_output_set
    from spur_cad.pipeline import run_job

    # A relative ReportTemplate or RotaryCalibrationFile is found beside the saved document, as a job file's beside
    # the job file; an unsaved document has no folder, so it may name none.
    document = job_obj.Document.FileName
    job = job_of(job_obj)
    if document:
        job = with_files(job, Path(document).parent)
    elif job.job.report_template or job.machine.rotary_calibration_file:
        raise SpurCadError("the job names a ReportTemplate or RotaryCalibrationFile, which is found beside the "
                           "document: save the document first (in the folder those files are in)")
    with WorkProgress("Export", EXPORT_STAGES) as work:
        files = run_job(job, progress=work.advance, checkpoint=work.events).files
    out = Path(out_dir)
    try:
        paths = write_output_set(out, files)
    except OSError as exc:
        raise SpurCadError(f"cannot write to {out}: {exc.strerror or exc}") from None
    show_message("Export", f"{job_obj.Label}: wrote {len(paths)} files to {out}", level="message")
    return [str(path) for path in paths]


def simulate(job_obj, resolution_mm: float | None = None):
    """Simulate the job's toolpaths (spur_cad.sim, at the job's SimulationResolution unless given) and show
    the design points coloured by their deviation. Reuses the job's plan when its values have not changed."""
    from spur_cad_workbench.simulation import show_result, simulate_job, simulator
    from spur_cad_workbench.summary import values_signature

    simulator()  # raises SimulationUnavailable before any work
    signature = values_signature(document_values(job_obj))
    cached = getattr(job_obj.Proxy, "cached_plan", None)
    reused = cached is not None and cached[0] == signature
    with WorkProgress("Simulate", ("toolpaths", "simulation")) as work:
        job, plan = job_obj.Proxy.plan_for(job_obj, checkpoint=work.events)
        work.stage_done("toolpaths")
        result = simulate_job(job, plan, resolution_mm, progress=lambda done: work.advance("simulation", done))
    source = "the job's plan (reused)" if reused else "planned for this simulation"
    return show_result(job_obj, result, signature, source, view_provider=ViewProvider)


def verify_programs(job_obj, paths: list[str], dialect: str | None = None, point: str = "tip"):
    """`spur-cad verify` inside FreeCAD: read the G-code programs (from anywhere; the job's post dialect unless
    given), cut the job's stock with them and show the deviations on the gear in '<job> verification';
    the verdict goes to the report view and a message box. Returns the object."""
    from spur_cad.verify.reader import read_program_file
    from spur_cad.verify.verify import VerifyOptions, verify_moves
    from spur_cad_workbench.simulation import show_result, simulator
    from spur_cad_workbench.summary import values_signature

    simulator()
    job = job_of(job_obj)
    programs = []
    with WorkProgress("Verify program", ("reading", "simulation")) as work:
        for path in paths:  # regular files of bounded size, read as a stream (spur-cad verify's reader)
            programs.append(read_program_file(path, dialect or job.post.dialect, dialects=job.dialects))
            work.events()
        work.stage_done("reading")
        result = verify_moves(job, programs, VerifyOptions(point), progress=lambda done: work.advance("simulation",
                                                                                                     done))
    names = ", ".join(Path(path).name for path in paths)
    obj = show_result(job_obj, result.simulation, values_signature(document_values(job_obj)),
                      f"verified programs: {names}", role="verification", view_provider=ViewProvider)
    show_message("Verify program", "\n".join(result.lines()), level="message" if result.passed else "error")
    return obj


def write_restart_program(job_obj, point, path: str) -> str:
    """`spur-cad run --restart POINT` inside FreeCAD: the program restarting the job's roughing or finishing at
    `point` written to `path`. `point` is a spur_cad.cam.restart.RestartPoint (what the Restart program dialog
    records: RestartPoint("roughing", (("space", 5), ("level", 2)))) or its text ("roughing:space=5,level=2",
    "finishing:station=40"; docs/shop-floor.md). Errors name the point as the dialog does."""
    from spur_cad.cam.restart import RestartError, parse_restart
    from spur_cad.errors import SpurCadError
    from spur_cad.outputs import write_file_atomically
    from spur_cad.pipeline import restart_program
    from spur_cad_workbench.restart_dialog import reworded

    restart = parse_restart(point) if isinstance(point, str) else point
    with WorkProgress("Restart program", ("toolpaths", "restart program")) as work:
        job, plan = job_obj.Proxy.plan_for(job_obj, checkpoint=work.events)
        work.stage_done("toolpaths")
        try:
            _, text = restart_program(job, plan, restart)
        except RestartError as exc:
            raise SpurCadError(reworded(str(exc), restart)) from None
    try:
        written = write_file_atomically(path, text)
    except OSError as exc:
        raise SpurCadError(f"cannot write {path}: {exc.strerror or exc}") from None
    show_message("Restart program", f"{job_obj.Label}: wrote the restart program {written}", level="message")
    return str(written)


def document_name(path: str) -> str:
    """A FreeCAD document name for a job file: its stem with characters FreeCAD names cannot hold replaced."""
    import re

    stem = re.sub(r"[^A-Za-z0-9_]", "_", Path(path).stem) or "Job"
    return stem if not stem[0].isdigit() else f"Job_{stem}"


# --- GUI commands ------------------------------------------------------------------------------


def _icon(name: str) -> str:
    from spur_cad_workbench.resources import icon_path

    return icon_path(name)


def _selected(kind: str):
    import FreeCADGui

    for obj in FreeCADGui.Selection.getSelection():
        if getattr(getattr(obj, "Proxy", None), "KIND", "") == kind:
            return obj
    doc = FreeCAD.ActiveDocument
    if doc is None:
        return None
    found = [obj for obj in doc.Objects if getattr(getattr(obj, "Proxy", None), "KIND", "") == kind]
    return found[-1] if found else None


MESSAGE_LEVELS = {"message": ("PrintMessage", "Information"), "warning": ("PrintWarning", "Warning"),
                  "error": ("PrintError", "Critical")}
"""A message's level -> (FreeCAD.Console method, QMessageBox icon)."""


def show_message(title: str, message: str, level: str = "error") -> None:
    """A message for the user at `level` ("message": a result such as PASS, "warning", "error"): in the report
    view at that level (black, orange, red) and in a (non-blocking) message box with the level's icon."""
    print_name, icon_name = MESSAGE_LEVELS[level]
    getattr(FreeCAD.Console, print_name)(f"{title}: {message}\n")
    if FreeCAD.GuiUp:
        import FreeCADGui
        from PySide import QtGui

        icon = compat.qt_enum(QtGui.QMessageBox, "Icon", icon_name)
        ok = compat.qt_enum(QtGui.QMessageBox, "StandardButton", "Ok")
        box = QtGui.QMessageBox(icon, title, message, ok, FreeCADGui.getMainWindow())
        box.setObjectName("SpurCadMessage")
        box.setModal(False)
        box.show()


def run_recorded(lines: list[str], title: str) -> bool:
    """Run Python lines through FreeCADGui.doCommandGui (recorded in macros); show SpurCadErrors."""
    import FreeCADGui

    from spur_cad.errors import SpurCadError

    try:
        FreeCADGui.doCommandGui("import spur_cad_workbench.commands")
        for line in lines:
            FreeCADGui.doCommandGui(line)
    except SpurCadError as exc:
        from spur_cad_workbench.validation import sentence

        doc = FreeCAD.ActiveDocument
        source = (doc.FileName or doc.Name) if doc is not None else ""
        show_message(title, sentence(exc, source, FreeCAD.Units))  # field titles, the user's units
        return False
    return True


NEW_DOCUMENT = "if App.ActiveDocument is None: App.newDocument('Gear')"
RECOMPUTE = "App.ActiveDocument.recompute()"


def _fit_view(obj: str, isometric: bool) -> list[str]:
    """Macro lines turning the 3D view of `obj`'s document to the isometric view (if asked) and fitting all."""
    return ["import spur_cad_workbench.views",
            f"spur_cad_workbench.views.orient_and_fit({obj}.Document, isometric={isometric})"]


def _call(result: str, function: str, *arguments: str) -> str:
    """A macro line calling an entry point of this module."""
    return f"{result} = spur_cad_workbench.commands.{function}({', '.join(arguments)})"


def _object(obj) -> str:
    """A macro expression for a document object."""
    return f"App.ActiveDocument.getObject({obj.Name!r})"


class _Command:
    """Base of the GUI commands: resources from class attributes."""

    NAME = ""
    ICON = "spur_cad"
    MENU = ""
    TIP = ""

    def GetResources(self):
        return {"Pixmap": _icon(self.ICON), "MenuText": self.MENU, "ToolTip": self.TIP}


class GearCommand(_Command):
    NAME, ICON, MENU = "SpurCad_Gear", "gear", "Spur gear"
    TIP = "Create a parametric spur gear (exact rack-generated teeth) on the rotary axis X"

    def IsActive(self):
        return True

    def Activated(self):
        run_recorded([NEW_DOCUMENT, _call("spur_cad_gear", "make_gear", "App.ActiveDocument"), RECOMPUTE,
                      *_fit_view("spur_cad_gear", isometric=True)], "Spur gear")


class StockCommand(_Command):
    NAME, ICON, MENU = "SpurCad_Stock", "stock", "Stock"
    TIP = "Create the blank (stock) for the selected gear, linked to it"

    def IsActive(self):
        return _selected("gear") is not None

    def Activated(self):
        gear = _selected("gear")
        run_recorded([_call("spur_cad_stock", "make_stock", _object(gear)), RECOMPUTE,
                      *_fit_view("spur_cad_stock", isometric=False)], "Stock")


class JobCommand(_Command):
    NAME, ICON, MENU = "SpurCad_Job", "job", "4-axis job"
    TIP = "Create a 4-axis job (tools, cutting data, strategies, machine, post) and edit it in a task panel"

    def IsActive(self):
        return _selected("stock") is not None

    def Activated(self):
        stock = _selected("stock")
        run_recorded([_call("spur_cad_job", "make_job", _object(stock.Gear), _object(stock)), RECOMPUTE,
                      *_fit_view("spur_cad_job", isometric=False), "Gui.ActiveDocument.setEdit(spur_cad_job.Name)"],
                     "4-axis job")


class ImportJobCommand(_Command):
    NAME, ICON, MENU = "SpurCad_ImportJob", "import_job", "Import job file..."
    TIP = "Create gear, stock and job objects from a spur_cad job file (TOML)"

    def IsActive(self):
        return True

    def Activated(self):
        import FreeCADGui
        from PySide import QtGui

        path, _ = QtGui.QFileDialog.getOpenFileName(FreeCADGui.getMainWindow(), "Import spur_cad job file", "",
                                                    "spur_cad job (*.toml)")
        if path:  # a new document named after the job file
            run_recorded([_call("spur_cad_objects", "import_job_file", "None", repr(path)),
                          *_fit_view("spur_cad_objects[0]", isometric=True)], "Import job file")


class SimulateCommand(_Command):
    NAME, ICON, MENU = "SpurCad_Simulate", "simulate", "Simulate"
    TIP = "Simulate the job's cutting and show the part coloured by deviation from the design"

    def IsActive(self):
        return _selected("job") is not None

    def Activated(self):
        from spur_cad_workbench.simulation import SimulationUnavailable, simulator

        try:
            simulator()
        except SimulationUnavailable as exc:
            show_message("Simulate", str(exc), level="warning")
            return
        job = _selected("job")
        run_recorded([_call("spur_cad_simulation", "simulate", _object(job))], "Simulate")


class VerifyCommand(_Command):
    NAME, ICON, MENU = "SpurCad_Verify", "verify", "Verify program..."
    TIP = ("Read G-code programs from anywhere, cut the job's stock with them and show gouge and leftover on the "
           "gear (as `spur-cad verify`)")

    def IsActive(self):
        return _selected("job") is not None

    def Activated(self):
        import FreeCADGui
        from PySide import QtGui

        job = _selected("job")
        paths, _ = QtGui.QFileDialog.getOpenFileNames(FreeCADGui.getMainWindow(), "Verify G-code programs", "",
                                                      "G-code (*.ngc *.nc *.mpf *.min *.tap *.gcode);;All files (*)")
        if paths:
            run_recorded([_call("spur_cad_verification", "verify_programs", _object(job), repr(list(paths)))],
                         "Verify program")


class RestartCommand(_Command):
    NAME, ICON, MENU = "SpurCad_Restart", "restart", "Restart program..."
    TIP = ("Write a program that restarts roughing or finishing after an alarm, at a tooth space, level, station or "
           "pass (as `spur-cad run --restart`)")

    def IsActive(self):
        return _selected("job") is not None

    def Activated(self):
        import FreeCADGui
        from PySide import QtGui

        from spur_cad.errors import SpurCadError

        job_obj = _selected("job")
        window = FreeCADGui.getMainWindow()
        try:
            dialog = restart_dialog(job_obj, window)
        except SpurCadError as exc:  # the job cannot be planned: said as the panel says it, not in key names
            from spur_cad_workbench.validation import sentence

            show_message("Restart program", sentence(exc, job_obj.Label, FreeCAD.Units))
            return
        if not compat.exec_dialog(dialog.dialog):
            return
        point, name = dialog.point(), dialog.file_name()
        document = job_obj.Document.FileName
        folder = Path(document).parent if document else Path.cwd()
        path, _ = QtGui.QFileDialog.getSaveFileName(window, "Save the restart program", str(folder / name),
                                                    f"G-code (*{Path(name).suffix});;All files (*)")
        if path:
            run_recorded(["from spur_cad.cam.restart import RestartPoint",
                          _call("spur_cad_restart", "write_restart_program", _object(job_obj), repr(point),
                                repr(path))], "Restart program")


def restart_dialog(job_obj, parent=None):
    """The Restart program dialog (restart_dialog.RestartDialog, not shown yet) for the job's current plan,
    planned first (with the progress indicator) when the job's values changed since the last plan."""
    from spur_cad_workbench.restart_dialog import RestartDialog

    with WorkProgress("Restart program", ("toolpaths",)) as work:
        job, plan = job_obj.Proxy.plan_for(job_obj, checkpoint=work.events)
    return RestartDialog(job, plan, parent)


class ExportCommand(_Command):
    NAME, ICON, MENU = "SpurCad_Export", "export", "Export STEP and G-code..."
    TIP = "Write the job's STEP files (gear, stock, assembly) and G-code programs, as `spur-cad run` does"

    def IsActive(self):
        return _selected("job") is not None

    def Activated(self):
        import FreeCADGui
        from PySide import QtGui

        job = _selected("job")
        folder = QtGui.QFileDialog.getExistingDirectory(FreeCADGui.getMainWindow(), "Export job files to")
        if folder:
            run_recorded([_call("spur_cad_files", "export_job", _object(job), repr(folder))], "Export")


COMMANDS = (GearCommand, StockCommand, JobCommand, ImportJobCommand, SimulateCommand, VerifyCommand, RestartCommand,
            ExportCommand)


def register_commands() -> list[str]:
    """Register the GUI commands with FreeCAD; returns their names (toolbar and menu order)."""
    import FreeCADGui

    for command in COMMANDS:
        FreeCADGui.addCommand(command.NAME, command())
    return [command.NAME for command in COMMANDS]
