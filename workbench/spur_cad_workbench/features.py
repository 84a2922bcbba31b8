"""FeaturePython document objects: gear, stock, 4-axis job and its toolpaths.

Every value lives in a primitive property (schema.py's fields, read and written by properties.py);
`dumps` / `__getstate__` return None, so a saved document names the proxy classes but pickles nothing.
The one thing a proxy keeps in memory is the job's last plan (`JobFeature.plan_for`, keyed by the
values' fingerprint): the panel's Plan leaves its plan there for OK's recompute, and Simulate reuses it.
It is never saved (a reopened document plans again) and is planned again when any value differs.
`SchemaVersion` on each object lets `onDocumentRestored` migrate older documents (add the properties a
newer schema introduced, with their defaults).

Shapes come from spur_cad's CadQuery/OCP solids, transferred as BREP text. Input errors
(SpurCadError): the object's `Status` property says what is wrong in one sentence that names the field
by its title, with lengths in the user's unit schema (validation.sentence), the report view gets the same
line, computed values are cleared, the tree icon gets a red error badge, and what depends on the object
(stock, job, toolpaths, simulations) is marked stale and drawn grey. `execute` never raises: FreeCAD 0.20
prints a Python exception from `execute` with its traceback in the report view (Base::PyException::
throwException reports it), and a user's typing error is no program error. So FreeCAD's own error state
("Invalid" in `State`) is not set; scripts read `Status`.
"""

from __future__ import annotations

from collections.abc import Set as AbstractSet

import FreeCAD

from spur_cad.cam.setups import LYING_FLAT
from spur_cad_workbench import compat, schema, units
from spur_cad_workbench.properties import (
    add_bookkeeping,
    add_fields,
    document_values,
    job_of,
    read_values,
    source_of,
    write_outputs,
    write_values,
)
from spur_cad_workbench.resources import icon_path

GEAR_COLOUR = (0.55, 0.62, 0.72)
STOCK_COLOUR = (0.85, 0.75, 0.45)
ROUGHING_COLOUR = (0.85, 0.45, 0.1)
FINISHING_COLOUR = (0.1, 0.55, 0.2)
STALE_COLOUR = (0.62, 0.62, 0.62)  # toolpaths and simulations that no longer match their job
OPERATION_COLOURS = {"roughing": ROUGHING_COLOUR, "finishing": FINISHING_COLOUR}
# The gear's display tessellation: chord deviation in % of the part's size (FreeCAD's default 0.5 % is
# 0.5 mm on a 100 mm gear: the involute looks faceted beside the toolpaths) and angular deflection.
GEAR_DEVIATION_PERCENT = 0.02
GEAR_ANGULAR_DEFLECTION_DEG = 5.0


DRAWN_LYING_FLAT = frozenset({LYING_FLAT})
"""The set-ups whose programs are drawn with the gear lying flat (Z0 on its top face: display.display_flat_path)."""
ERROR_PREFIX = "error: "


def report(obj, message: str | None) -> None:
    """Record the recompute's outcome; an error also goes to the report view as one line."""
    status = "ok" if message is None else f"{ERROR_PREFIX}{message}"
    if obj.Status != status:
        was_error = obj.Status.startswith(ERROR_PREFIX)
        obj.Status = status
        if FreeCAD.GuiUp and was_error != (message is not None):
            compat.refresh_icon(obj.ViewObject)  # the error badge comes or goes
    if message is not None:
        FreeCAD.Console.PrintError(f"{obj.Label}: {message}\n")


def fail(obj, exc) -> None:
    """An input error (a SpurCadError) on `obj`: one sentence in its Status and the report view, computed values
    cleared, dependants marked stale. Never raises (see the module docstring)."""
    from spur_cad_workbench.validation import sentence

    report(obj, sentence(exc, source_of(obj), FreeCAD.Units))
    clear_outputs(obj)
    for dependant in dependants(obj):
        mark_stale(dependant, f"{obj.Label} has an error")


def failed_input(obj):
    """The spur_cad object `obj` depends on whose last recompute failed (its error is reported there), or None."""
    return next((other for other in obj.OutListRecursive
                 if getattr(getattr(other, "Proxy", None), "KIND", "") and
                 str(getattr(other, "Status", "")).startswith(ERROR_PREFIX)), None)


def clear_outputs(obj) -> None:
    """Reset the computed values of a spur_cad object (0, False, empty), so no stale figure reads as current."""
    kind = getattr(getattr(obj, "Proxy", None), "KIND", "")
    empty = {"length": 0.0, "distance": 0.0, "float": 0.0, "int": 0, "bool": False, "strings": [], "string": ""}
    for field in schema.OUTPUTS.get(kind, ()):
        if field.prop in obj.PropertiesList and field.prop != "Operation":
            value = empty[field.kind]
            if schema.plain_value(field, getattr(obj, field.prop)) != value:
                setattr(obj, field.prop, value)


def dependants(obj) -> list:
    """The spur_cad objects whose results depend on `obj`: stock, job, toolpaths and simulations (FreeCAD does
    not recompute what depends on an object in error, so their old results would read as current)."""
    found = []
    for other in obj.InListRecursive:
        kind = getattr(getattr(other, "Proxy", None), "KIND", "")
        if kind == "job":
            found += [other] + [path for path in (other.RoughingToolpath, other.FinishingToolpath) if path is not None]
        if kind in ("stock", "simulation"):
            found.append(other)
    if getattr(getattr(obj, "Proxy", None), "KIND", "") == "job":
        found += [path for path in (obj.RoughingToolpath, obj.FinishingToolpath) if path is not None]
    return list({item.Name: item for item in found}.values())


def mark_stale(obj, reason: str) -> None:
    """Say on `obj` that its results no longer match its inputs: a stock or job gets the reason in its Status
    and its computed values cleared; a toolpath or simulation keeps its drawing, in grey."""
    status = f"stale: {reason}"
    if obj.Status != status:
        obj.Status = status
    kind = getattr(getattr(obj, "Proxy", None), "KIND", "")
    if kind in ("stock", "job"):
        clear_outputs(obj)
        return
    view = obj.ViewObject if FreeCAD.GuiUp else None
    if view is None:
        return
    _colour(view, STALE_COLOUR)
    if kind == "simulation":
        view.DisplayMode = "Points"  # plain grey points instead of the deviation colours
        from spur_cad_workbench.colourbar import remove_colour_bar

        remove_colour_bar(obj.Document)


def show_fresh(obj) -> None:
    """Draw a toolpath in its operation's colour again (after mark_stale)."""
    view = obj.ViewObject if FreeCAD.GuiUp else None
    colour = OPERATION_COLOURS.get(getattr(obj, "Operation", ""))
    if view is None or colour is None:
        return
    _colour(view, colour)


def _colour(view, colour) -> None:
    """Colour a view object's lines (toolpaths) and faces."""
    for colour_property in ("NormalColor", "LineColor"):
        if colour_property in view.PropertiesList:
            setattr(view, colour_property, colour)
    compat.set_shape_colour(view, colour)


def part_shape(ocp_shape):
    """An OCP shape as a FreeCAD Part.Shape, via BREP text written by OCP itself (no CadQuery or build123d)."""
    import Part

    from spur_cad.cad.brep import brep_text

    shape = Part.Shape()
    shape.importBrepFromString(brep_text(ocp_shape))
    return shape


def set_shape(obj, shape) -> None:
    """Replace obj.Shape keeping the object's placement (the solids are already in the machine frame)."""
    placement = obj.Placement
    obj.Shape = shape
    obj.Placement = placement


ERROR_BADGE_COLOUR = "#d00000"
ICON_SIZE_PX = 64


def error_icon(path: str):
    """The icon at `path` with a red "!" badge in its lower left corner: a spur_cad object whose last recompute
    failed (FreeCAD's own error mark needs an exception from `execute`, which 0.20 reports with a traceback)."""
    from PySide import QtCore, QtGui, QtSvg

    # The SVG is drawn by QtSvg itself, as FreeCAD's BitmapFactory draws icons: QIcon(path) needs Qt's SVG
    # image-format plugin, which Debian testing's FreeCAD 1.1 (Qt 6) does not install; its pixmap is then null
    # and a painter on it fails ("QPainter::begin: Paint device returned engine == 0", observed).
    pixmap = QtGui.QPixmap(ICON_SIZE_PX, ICON_SIZE_PX)
    pixmap.fill(QtGui.QColor(0, 0, 0, 0))
    badge = ICON_SIZE_PX // 2
    painter = QtGui.QPainter(pixmap)
    QtSvg.QSvgRenderer(path).render(painter, QtCore.QRectF(0, 0, ICON_SIZE_PX, ICON_SIZE_PX))
    painter.setRenderHint(compat.qt_enum(QtGui.QPainter, "RenderHint", "Antialiasing"))
    painter.setPen(compat.qt_enum(QtCore.Qt, "PenStyle", "NoPen"))
    painter.setBrush(QtGui.QColor(ERROR_BADGE_COLOUR))
    painter.drawEllipse(0, ICON_SIZE_PX - badge, badge, badge)
    white = QtGui.QColor("white")
    stroke = badge // 8
    left, top = badge // 2 - stroke // 2, ICON_SIZE_PX - badge
    painter.fillRect(left, top + badge // 6, stroke, badge // 2, white)  # the "!": a bar and a dot
    painter.fillRect(left, top + badge * 3 // 4, stroke, stroke, white)
    painter.end()
    return QtGui.QIcon(pixmap)


class _Proxy(compat.StatelessProxy):
    """Common proxy behaviour: no state of its own, migration on restore."""

    KIND = ""
    FIELDS: tuple = ()
    OUTPUTS: tuple = ()

    def __init__(self, obj):
        obj.Proxy = self

    def onDocumentRestored(self, obj):
        """Migrate an older document: add the properties this schema has and the document lacks, re-create
        those whose type changed (keeping their values) and update drop-down lists."""
        version = obj.SchemaVersion if "SchemaVersion" in obj.PropertiesList else 0
        if version > schema.SCHEMA_VERSION:
            FreeCAD.Console.PrintWarning(f"{obj.Label}: saved by a newer spur_cad (schema {version}); "
                                         "properties it added are kept but not used\n")
            return
        defaults = schema.default_values().get(self.KIND, {})
        changed = add_fields(obj, self.FIELDS, defaults) + add_fields(obj, self.OUTPUTS, outputs=True)
        if changed or version < schema.SCHEMA_VERSION:
            add_bookkeeping(obj)
            obj.SchemaVersion = schema.SCHEMA_VERSION
            FreeCAD.Console.PrintMessage(f"{obj.Label}: migrated from schema {version} to {schema.SCHEMA_VERSION}"
                                         f" ({', '.join(changed) or 'no property changed'})\n")


SIDE_SWITCH_SECTIONS = {switch.prop: section for section, switch in schema.MODIFICATION_SWITCHES.items()}
"""{LeftFlankOwnValues: 'gear.modifications.left', ...}: the switch property of each side's table."""


class GearFeature(_Proxy):
    """The gear: ISO 21771 inputs, computed radii and inspection values, the exact solid."""

    KIND = "gear"
    FIELDS = schema.GEAR_FIELDS
    OUTPUTS = schema.GEAR_OUTPUTS

    def __init__(self, obj, values: dict):
        super().__init__(obj)
        add_fields(obj, self.FIELDS, values)
        add_fields(obj, self.OUTPUTS, outputs=True)
        add_bookkeeping(obj)

    def onChanged(self, obj, prop):
        """A flank side's switch turned on (by the user, not a document being read): the side's properties start
        from the common modification values, so that changing one of them gives the side table that one key."""
        section = SIDE_SWITCH_SECTIONS.get(prop)
        if section is None or not getattr(obj, prop) or "Restore" in obj.State:
            return
        if all(field.prop in obj.PropertiesList for field in self.FIELDS):  # not while __init__ adds them
            write_values(obj, schema.side_start_values(read_values(obj, self.FIELDS), section))

    def execute(self, obj):
        from spur_cad.cad.solid import build_gear_shape
        from spur_cad.errors import SpurCadError
        from spur_cad.geometry.inspection import inspection_sheet

        try:
            job = job_of(obj)
            shape, _ = build_gear_shape(job.gear, job.gear_section.blank_features(), modifications=job.modifications)
        except SpurCadError as exc:
            fail(obj, exc)
            return
        spec, sheet = job.gear, inspection_sheet(job.gear)
        outputs = {
            "ReferenceRadius": spec.reference_radius_mm, "BaseRadius": spec.base_radius_mm,
            "TipRadius": spec.tip_radius_mm, "RootRadius": spec.root_radius_mm, "FormRadius": spec.form_radius_mm,
            "ToothThickness": spec.tooth_thickness_mm, "SpanTeeth": sheet.span_teeth_k,
            "SpanMeasurement": sheet.span_measurement_mm, "PinDiameter": sheet.pin_diameter_mm,
            "DimensionOverPins": sheet.dimension_over_pins_mm, "Undercut": bool(spec.undercut),
            "UndercutDepth": spec.undercut_depth_mm,
            "MinTeethWithoutUndercut": sheet.min_teeth_without_undercut}
        # a ring has no span (and a helical gear none where the anvils do not fit the face): 0, its text "none"
        missing = {prop for prop, value in outputs.items() if value is None}
        write_outputs(obj, {prop: 0 if prop in missing else value for prop, value in outputs.items()})
        write_outputs(obj, precise_outputs(obj, missing))
        set_shape(obj, part_shape(shape))
        report(obj, None)


def precise_outputs(obj, missing: AbstractSet[str] = frozenset()) -> dict[str, str]:
    """The gear's length outputs as text to 0.1 um in the user's unit schema (schema.PRECISE); "none" for the
    `missing` ones (the gear has no such value)."""
    return {f"{field.prop}{schema.PRECISE_SUFFIX}": "none" if field.prop in missing else
            units.inspection_text(getattr(obj, field.prop).Value, FreeCAD.Units)
            for field in schema.GEAR_OUTPUTS if field.kind == "length"}


def skipped_for_failed_input(obj) -> bool:
    """Whether `obj` (a stock or job) depends on an object in error: then it is marked stale, not failed (the
    error is reported once, on the object that has it)."""
    broken = failed_input(obj)
    if broken is not None:
        mark_stale(obj, f"{broken.Label} has an error")
    return broken is not None


class StockFeature(_Proxy):
    """The blank, sized from the linked gear (tip radius + allowance, margins, holding stub)."""

    KIND = "stock"
    FIELDS = schema.STOCK_FIELDS
    OUTPUTS = schema.STOCK_OUTPUTS

    def __init__(self, obj, gear, values: dict):
        super().__init__(obj)
        obj.addProperty("App::PropertyLink", "Gear", "Stock", "the gear this stock is for")
        obj.Gear = gear
        add_fields(obj, self.FIELDS, values)
        add_fields(obj, self.OUTPUTS, outputs=True)
        add_bookkeeping(obj)

    def execute(self, obj):
        from spur_cad.cad.solid import build_stock_shape
        from spur_cad.errors import SpurCadError

        if skipped_for_failed_input(obj):
            return
        try:
            job = job_of(obj)
            shape = build_stock_shape(job.gear, job.stock)
        except SpurCadError as exc:
            fail(obj, exc)
            return
        write_outputs(obj, {"BlankRadius": job.stock.blank_radius_mm(job.gear)})
        set_shape(obj, part_shape(shape))
        report(obj, None)


class JobFeature(_Proxy):
    """The 4-axis job: tools, cutting data, strategies, machine, post; plans both toolpaths on recompute."""

    KIND = "job"
    FIELDS = schema.JOB_FIELDS
    OUTPUTS = schema.JOB_OUTPUTS

    def __init__(self, obj, gear, stock, values: dict):
        super().__init__(obj)
        obj.addProperty("App::PropertyLink", "Gear", "Job", "the gear to cut")
        obj.addProperty("App::PropertyLink", "Stock", "Job", "the blank it is cut from")
        obj.addProperty("App::PropertyLink", "RoughingToolpath", "Toolpaths", "roughing toolpath object")
        obj.addProperty("App::PropertyLink", "FinishingToolpath", "Toolpaths", "finishing toolpath object")
        obj.Gear, obj.Stock = gear, stock
        add_fields(obj, self.FIELDS, values)
        add_fields(obj, self.OUTPUTS, outputs=True)
        add_bookkeeping(obj)

    def plan_for(self, obj, checkpoint=None):
        """(job, plan) of the job's current values: the last plan when the values have not changed since.
        `checkpoint()` is called between planning steps (the GUI processes events there)."""
        from spur_cad.pipeline import plan_cam
        from spur_cad_workbench.summary import values_signature

        signature = values_signature(document_values(obj))
        cached = getattr(self, "cached_plan", None)
        if cached is not None and cached[0] == signature:
            return cached[1], cached[2]
        job = job_of(obj)
        plan = plan_cam(job, checkpoint)
        self.cached_plan = (signature, job, plan)
        return job, plan

    def execute(self, obj):
        from spur_cad.errors import SpurCadError
        from spur_cad_workbench.summary import plan_figures, values_signature

        if skipped_for_failed_input(obj):
            self.cached_plan = None
            return
        try:
            job, plan = self.plan_for(obj)  # the panel's Plan may have planned these values already
            figures = plan_figures(job, plan)
        except SpurCadError as exc:
            self.cached_plan = None
            fail(obj, exc)
            return
        rec = plan.recommendations
        outputs = {"FinishingMaxFlatWidth": rec.finishing_max_flat_width_mm,
                   "FinishingMaxCornerRadius": rec.finishing_max_corner_radius_mm,
                   "PlungeAllowance": rec.plunge_allowance_mm, "RoughingMaxDiameter": rec.roughing_max_diameter_mm,
                   "RequiredFluteLength": rec.required_flute_length_mm,
                   "RequiredStickOut": rec.required_stick_out_mm, "Warnings": list(plan.warnings),
                   "PlannedValues": values_signature(document_values(obj))}
        for name, title in schema.OPERATION_TITLES.items():
            op = getattr(figures, name)
            outputs[f"{title}Moves"] = op.moves if op is not None else 0
            outputs[f"{title}Time"] = op.seconds / 60.0 if op is not None else 0.0
            outputs[f"{title}TimeWithAcceleration"] = op.seconds_with_acceleration / 60.0 if op is not None else 0.0
            outputs[f"{title}ProgramLines"] = op.program_lines if op is not None else 0
        flat = job.gear.face_width_mm if job.machine.setup in DRAWN_LYING_FLAT else None
        for name in schema.TOOL_ROLES:  # the bottom tool's program has no toolpath object (see workbench/README.md)
            target = getattr(obj, f"{name.capitalize()}Toolpath")
            if target is not None:
                update_toolpath(target, getattr(plan, name), flat)
        write_outputs(obj, outputs)
        for dependant in dependants(obj):
            if getattr(dependant.Proxy, "KIND", "") != "simulation":
                continue
            if dependant.PlannedValues != outputs["PlannedValues"]:
                mark_stale(dependant, "the job changed after this simulation; simulate again")
            elif dependant.Status != "ok":  # the values are back to the simulated ones
                from spur_cad_workbench.simulation import show_current

                show_current(dependant)
        report(obj, None)


class ToolpathFeature(_Proxy):
    """One operation's toolpath drawn in the part frame; its content is set by the job's recompute."""

    KIND = "toolpath"
    OUTPUTS = schema.TOOLPATH_OUTPUTS

    def __init__(self, obj, operation: str):
        super().__init__(obj)
        add_fields(obj, self.OUTPUTS, outputs=True)
        add_bookkeeping(obj)
        obj.Operation = operation

    def execute(self, obj):
        return None


def toolpath_label(operation: str, shown: int, total: int) -> str:
    """The tree label of a toolpath; says when the 3D view shows only part of the moves."""
    label = f"{operation.capitalize()} toolpath"
    return label if shown >= total else f"{label} (3D view: {shown:,} of {total:,} moves)"


def uses_path_module(obj) -> bool:
    """Whether a toolpath object is a FreeCAD Path object (else a Part wire compound)."""
    return obj.isDerivedFrom("Path::Feature")


def update_toolpath(obj, planned, flat_face_width_mm: float | None = None) -> None:
    """Draw a planned operation (spur_cad.cam.plan RoughingPlan / FinishingPlan, or None) into the toolpath
    object and set its computed properties; `flat_face_width_mm`: the gear's face width for a 3-axis program
    (drawn with the gear lying flat, display.display_flat_path)."""
    from spur_cad_workbench.display import display_flat_path, display_path, gcode_text, polylines

    path = planned.toolpath if planned is not None else None
    if path is None:
        drawn, moves, outputs = None, 0, {"Moves": 0, "DisplayedMoves": 0, "CuttingLength": 0.0,
                                          "EstimatedTime": 0.0, "ToolNumber": 0, "SpindleSpeed": 0.0}
    else:
        drawn = display_path(path) if flat_face_width_mm is None else display_flat_path(path, flat_face_width_mm)
        moves = drawn.moves_shown
        outputs = {"Moves": int(planned.estimate.moves), "DisplayedMoves": int(moves),
                   "CuttingLength": float(planned.estimate.cutting_length_mm),
                   "EstimatedTime": float(planned.estimate.time_s) / 60.0, "ToolNumber": int(path.tool_number),
                   "SpindleSpeed": float(path.spindle_rpm)}
    if uses_path_module(obj):
        has_points = drawn is not None and len(drawn.points) > 0
        shown = gcode_text(drawn) if drawn is not None and has_points else ""
        obj.Path = compat.new_path(compat.path_module(), shown)
        if drawn is not None and has_points and FreeCAD.GuiUp:  # else drawn from (0, 0, 0), through the gear
            compat.set_path_start(obj.ViewObject, drawn.points[0])
    else:
        import Part

        wires = [] if drawn is None else [Part.makePolygon([FreeCAD.Vector(*p) for p in run])
                                          for _, run in polylines(drawn)]
        obj.Shape = Part.makeCompound(wires)
    write_outputs(obj, outputs)
    obj.Label = toolpath_label(obj.Operation, int(outputs["DisplayedMoves"]), int(outputs["Moves"]))
    report(obj, None)
    show_fresh(obj)
    obj.purgeTouched()  # set by the job's recompute: nothing left for the toolpath itself to do


class ViewProvider(compat.StatelessProxy):
    """Icon, tree children and editing of the workbench's objects; no state."""

    def __init__(self, vobj):
        vobj.Proxy = self

    def attach(self, vobj):
        self.Object = vobj.Object

    def getIcon(self):
        obj = getattr(self, "Object", None)
        kind = getattr(getattr(obj, "Proxy", None), "KIND", "")
        path = icon_path({"gear": "gear", "stock": "stock", "job": "job", "toolpath": "toolpath",
                          "simulation": "simulate"}.get(kind, "spur_cad"))
        if str(getattr(obj, "Status", "")).startswith(ERROR_PREFIX):
            return error_icon(path)
        return path

    def onChanged(self, vobj, prop):
        """A simulation shown or hidden (Space): its job's toolpaths hidden or shown again (views.py)."""
        if prop == "Visibility" and getattr(getattr(vobj.Object, "Proxy", None), "KIND", "") == "simulation":
            from spur_cad_workbench.views import simulation_visibility_changed

            simulation_visibility_changed(vobj.Object)

    def claimChildren(self):
        obj = getattr(self, "Object", None)
        if obj is None or getattr(obj.Proxy, "KIND", "") != "job":
            return []
        return [child for child in (obj.RoughingToolpath, obj.FinishingToolpath) if child is not None]

    def setEdit(self, vobj, mode=0):
        if getattr(vobj.Object.Proxy, "KIND", "") != "job":
            return False
        from spur_cad_workbench.taskpanel import show_job_panel

        show_job_panel(vobj.Object)
        return True

    def unsetEdit(self, vobj, mode=0):
        import FreeCADGui

        FreeCADGui.Control.closeDialog()
        return True

    def doubleClicked(self, vobj):
        if getattr(vobj.Object.Proxy, "KIND", "") != "job":
            return False
        import FreeCADGui

        FreeCADGui.ActiveDocument.setEdit(vobj.Object.Name)
        return True

