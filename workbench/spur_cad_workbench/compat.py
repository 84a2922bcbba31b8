"""FreeCAD 0.20 / 1.0 / 1.1 differences the workbench meets, each behind one small function.

Observed in Debian 12's FreeCAD 0.20.2 (Qt 5, PySide2 5.15), Debian 13's 1.0.0 (Qt 5, PySide2 5.15) and Debian
testing's 1.1.3 (Qt 6, PySide6 6.11); first written from their sources (docs/freecad-compat.md lists every file,
tag and pull request, and what the running versions showed). Each function takes the FreeCAD / Qt object or module
it works on as an argument and imports nothing at import time, so every branch is tested without FreeCAD
(tests/test_workbench_compat.py) and each FreeCAD's branches inside its freecadcmd and GUI.

What differs (more in docs/freecad-compat.md):
- the CAM workbench's Python module: `Path` is a C++ module in 0.20 and a Python package over the C++
  module `PathApp` in 1.0/1.1 (src/Mod/CAM/Path/__init__.py);
- Qt 5 / Qt 6 through FreeCAD's `PySide` wrapper: PySide6's enums are Python enums, so
  `int(QDialogButtonBox.Ok | QDialogButtonBox.Cancel)` raises TypeError; `exec_` is deprecated;
  the wrapper has `PySide.QtWidgets` only in 1.x (both re-export the widgets from `PySide.QtGui`);
- Gui::QuantitySpinBox: 1.x's sources have a per-widget `decimals`, but no running version declares it as a Qt
  property (observed); all three show a Quantity with the precision of its own `Format`;
- ViewProviderGeometryObject's `ShapeColor` property became `ShapeAppearance` (a material list) in 1.0;
- Control.showDialog returns None in 0.20 and a TaskDialog wrapper in 1.x;
- a proxy's state is restored through `__setstate__` in 0.20 and `loads` in 1.x (StatelessProxy).
FreeCAD 1.1's versioned user data folder (`v1-1`) concerns the installer: spur_cad/freecad_install.py.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable

# Names under which the CAM (formerly Path) workbench's C++ bindings import, newest layout last:
# 0.20: `Path` is the C++ module (Mod/Path/App/AppPath.cpp, PyMOD_INIT_FUNC(Path)); 1.0/1.1: `Path` is the
# package src/Mod/CAM/Path/__init__.py (`from PathApp import *`) and `PathApp` the C++ module
# (src/Mod/CAM/App/AppPath.cpp, PyMOD_INIT_FUNC(PathApp)). `CAM` is never tried: in 1.0 it imports as an
# empty namespace package (the Mod/CAM folder) without Path or Command.
PATH_MODULE_NAMES = ("Path", "PathApp")

# The document object type of a Python toolpath: kept through the CAM rename
# (src/Mod/CAM/App/FeaturePath.cpp: PROPERTY_SOURCE_TEMPLATE(Path::FeaturePython, Path::Feature)).
PATH_FEATURE_TYPE = "Path::FeaturePython"

QUANTITY_SPIN_BOX = "Gui::QuantitySpinBox"


class StatelessProxy:
    """Base of every proxy (document and view objects): saved as null, restored to nothing, in 0.20 and 1.x.

    All state lives in properties. FreeCAD saves a proxy's state from `dumps` (1.x) or `__getstate__` (0.20;
    Python 3.11's object has one) and restores it through `loads` (1.x: src/App/PropertyPythonObject.cpp,
    fromString) or `__setstate__` (0.20). A proxy without `__setstate__` breaks reopening in 0.20: it then
    assigns the saved null to the instance's `__dict__` and prints "AttributeError: setAttr failed"
    (observed with the simulation's proxy, issue 28). 1.x sets `__dict__` only for a state that is not None."""

    def dumps(self):
        return None

    def loads(self, state):
        return None

    def __getstate__(self):
        return None

    def __setstate__(self, state):
        return None


def freecad_version(freecad) -> tuple[int, int, int]:
    """(major, minor, patch) of the running FreeCAD, from `FreeCAD.Version()`.

    Version() is a list of strings starting [major, minor, point, revision, ...] in 0.20 and 1.x
    (src/App/ApplicationPy.cpp, sGetVersion); a part that does not start with digits counts as 0."""
    parts = list(freecad.Version())[:3]
    numbers = []
    for part in parts + [""] * (3 - len(parts)):
        digits = ""
        for char in str(part).strip():
            if not char.isdigit():
                break
            digits += char
        numbers.append(int(digits) if digits else 0)
    return numbers[0], numbers[1], numbers[2]


def path_module(importer: Callable = importlib.import_module):
    """The module holding `Path` (the G-code program class) and `Command`, or None without the CAM workbench.

    0.20: `import Path` is the C++ module; 1.0/1.1: the Python package `Path` re-exporting `PathApp`.
    A module of that name without Path/Command (another add-on's, or a half-installed CAM) is skipped."""
    for name in PATH_MODULE_NAMES:
        try:
            module = importer(name)
        except ImportError:
            continue
        if hasattr(module, "Path") and hasattr(module, "Command"):
            return module
    return None


def new_path(path_mod, gcode: str = ""):
    """A `Path.Path` program holding `gcode` (G0/G1 blocks); `setFromGCode` is unchanged from 0.20 to 1.1
    (src/Mod/CAM/App/Path.pyi). An empty text gives an empty program (setFromGCode is not called)."""
    program = path_mod.Path()
    if gcode.strip():
        program.setFromGCode(gcode)
    return program


def enum_int(member) -> int:
    """The integer value of a Qt enum or flag member on PySide2 and PySide6.

    PySide2 (0.20, Qt 5): shiboken enums convert with int() and have no `.value`. PySide6 >= 6.4 (FreeCAD
    1.x built with Qt 6): enums are Python `enum.Flag`/`enum.Enum` members, int() raises TypeError and the
    number is `.value` (FreeCAD issue 14639, LCInterlocking issue 78 on 1.1)."""
    try:
        return int(member)
    except TypeError:
        return int(member.value)


def qt_enum(owner, enum_name: str, member_name: str):
    """`owner.<enum_name>.<member_name>` (the scoped name, which PySide2 5.15 and PySide6 both have), else the
    unscoped `owner.<member_name>` (older PySide2; PySide6 keeps it only in its forgiveness mode)."""
    scoped = getattr(owner, enum_name, None)
    member = getattr(scoped, member_name, None) if scoped is not None else None
    return member if member is not None else getattr(owner, member_name)


def dialog_buttons(qt_widgets, *names: str) -> int:
    """What a task panel's `getStandardButtons` returns for the QDialogButtonBox buttons `names` ("Ok",
    "Cancel", ...): a plain int, which every version accepts.

    0.20's TaskDialogPython converts the result with Py::Int (an int is required); 1.x converts with
    PythonWrapper::toEnum (int or an object with `.value`, src/Gui/PythonWrapper.cpp tryEnum, PR 13902).
    `int(Ok | Cancel)` fails on PySide6, so the members are converted one by one and or-ed as ints."""
    box = qt_widgets.QDialogButtonBox
    value = 0
    for name in names:
        value |= enum_int(qt_enum(box, "StandardButton", name))
    return value


def qt_widgets(package: str = "PySide", importer: Callable = importlib.import_module):
    """The module of FreeCAD's PySide wrapper that holds QWidget, QDialogButtonBox, QMessageBox, ...

    1.x's wrapper has `PySide/QtWidgets.py` (cMake/FreeCAD_Helpers/SetupShibokenAndPyside.cmake writes it for
    PySide2 and PySide6); 0.20's has none (/usr/share/freecad/Ext/PySide: QtCore, QtGui, QtSvg, QtUiTools).
    Both wrappers' `QtGui` re-export the widgets (`from PySide<N>.QtWidgets import *`), the fallback."""
    try:
        module = importer(f"{package}.QtWidgets")
        if hasattr(module, "QWidget"):
            return module
    except ImportError:
        pass
    return importer(f"{package}.QtGui")


def exec_dialog(dialog):
    """Run a modal Qt dialog: `exec()` where the class defines it (PySide6; `exec_` is deprecated there and
    warns), else `exec_()` (PySide2 5.15, FreeCAD 0.20). The class is asked, not the instance: a PySide2
    QDialog instance also answers `exec` with a QtCore.MetaFunction (a meta-object slot lookup, seen in
    0.20's GUI), which is not PySide2's documented API."""
    if getattr(type(dialog), "exec", None) is not None:
        return dialog.exec()
    return dialog.exec_()


def has_qt_property(widget, name: str) -> bool:
    """Whether `widget`'s class declares the Qt property `name` (setProperty on an undeclared name does not
    fail: it adds a dynamic property that the widget ignores)."""
    return widget.metaObject().indexOfProperty(name) >= 0


def quantity_spin_box(ui_loader, unit: str, minimum: float | None = None, maximum: float | None = None,
                      decimals: int | None = None):
    """FreeCAD's unit-aware spin box (Gui::QuantitySpinBox) for quantities of `unit` ("mm", "deg",
    "mm/min"), or None where the UI loader cannot make one.

    `ui_loader` is `FreeCADGui.UiLoader()`. Properties unit, minimum, maximum, rawValue and value exist in
    0.20 and 1.x (src/Gui/QuantitySpinBox.h); `decimals` only in 1.x. In 0.20 the shown precision is the
    user's global "Number of decimals" preference, and the value is rounded to what is shown (a speed of
    100 mm/min shows as 1.67 mm/s under the default unit schema and reads back as 100.2 mm/min)."""
    widget = ui_loader.createWidget(QUANTITY_SPIN_BOX)
    if widget is None:
        return None
    widget.setProperty("unit", unit)
    if minimum is not None:
        widget.setProperty("minimum", float(minimum))
    if maximum is not None:
        widget.setProperty("maximum", float(maximum))
    if decimals is not None and has_qt_property(widget, "decimals"):
        widget.setProperty("decimals", int(decimals))
    return widget


def set_spin_box_value(widget, units, value: float, unit: str) -> None:
    """Show `value` (in `unit`) in a Gui::QuantitySpinBox: through its `value` property as a Quantity, the
    setter FreeCAD's own CAM panels use (a Python setValue call can pick the wrong C++ overload)."""
    widget.setProperty("value", units.Quantity(f"{float(value)!r} {unit}"))


def set_spin_box_quantity(widget, quantity) -> None:
    """Show a Base.Quantity in a Gui::QuantitySpinBox with the precision of its `Format`: 0.20's spin box
    formats the Quantity it is given with that format (Quantity::getUserString); 1.x's also has a per-widget
    `decimals` property, which is set to the same."""
    widget.setProperty("value", quantity)
    if has_qt_property(widget, "decimals"):
        widget.setProperty("decimals", int(quantity.Format["Precision"]))


def spin_box_value(widget, units, unit: str) -> float:
    """A Gui::QuantitySpinBox's value as a float in `unit`.

    The `value` property reads back as a Base.Quantity in 0.20 (checked here); where a binding hands back
    no Quantity, `rawValue` (the number in FreeCAD's internal unit: mm, mm/s, deg) is wrapped in one."""
    quantity = widget.property("value")
    if not hasattr(quantity, "getValueAs"):
        quantity = units.Quantity(float(widget.property("rawValue")), units.Unit(unit))
    return float(quantity.getValueAs(unit))


def set_path_start(view_object, point) -> bool:
    """Start a Path object's drawing at `point` instead of the origin; False where there is no such property.

    The drawn path begins with a rapid from the view provider's `StartPosition` (App::PropertyVector,
    default (0, 0, 0)) in 0.20 and 1.x alike (Mod/Path/Gui/ViewProviderPath.cpp, src/Mod/CAM/Gui/
    ViewProviderPath.cpp); the Path::Feature itself has only `Path` and `Placement`. No view object (console
    mode) or a Part wire object (no CAM module): nothing to set."""
    if "StartPosition" not in getattr(view_object, "PropertiesList", ()):
        return False
    view_object.StartPosition = tuple(float(c) for c in point)
    return True


def set_shape_colour(view_object, rgb) -> bool:
    """Colour a shape's faces: `ShapeAppearance` (1.0+, a list of App.Material) or `ShapeColor` (0.20).

    1.0 replaced ViewProviderGeometryObject's ShapeColor/ShapeMaterial properties by ShapeAppearance (PR
    13792 and follow-ups); ShapeColor survives only as a Python attribute (setEditorMode("ShapeColor") fails:
    FreeCAD-PCB issue 84). A material taken from the list must be assigned back for the view to update
    (PR 13499). Returns False for a view object with neither (or None, in console mode)."""
    properties = getattr(view_object, "PropertiesList", ())
    colour = tuple(float(c) for c in rgb[:3])
    if "ShapeAppearance" in properties:
        materials = list(view_object.ShapeAppearance)
        for material in materials:
            material.DiffuseColor = colour
        view_object.ShapeAppearance = materials
        return True
    if "ShapeColor" in properties:
        view_object.ShapeColor = colour
        return True
    return False


def show_task_dialog(control, panel, document_name: str | None = None):
    """Show `panel` in the task view (`control` is FreeCADGui.Control); returns FreeCAD's TaskDialog or None.

    0.20: showDialog returns None. 1.x: it returns the TaskDialog wrapper (PR 15116), which can be tied to a
    document so that closing the document closes the panel (setDocumentName, setAutoCloseOnDeletedDocument)."""
    dialog = control.showDialog(panel)
    if dialog is not None and document_name and hasattr(dialog, "setDocumentName"):
        dialog.setDocumentName(document_name)
        if hasattr(dialog, "setAutoCloseOnDeletedDocument"):
            dialog.setAutoCloseOnDeletedDocument(True)
    return dialog



def progress_indicator(freecad):
    """FreeCAD's progress indicator (start(text, steps), next(), stop()), or None where FreeCAD has none.

    `FreeCAD.Base.ProgressIndicator` has these three methods in 0.20 (checked in the GUI: in the GUI it drives
    the status bar's Gui::ProgressBar and sets a wait cursor) and 1.x (src/Base/ProgressIndicatorPy.cpp,
    unchanged since its split out of Sequencer.cpp in 2022)."""
    factory = getattr(getattr(freecad, "Base", None), "ProgressIndicator", None)
    return factory() if factory is not None else None


def refresh_icon(view_object) -> bool:
    """Make the tree ask a Python view provider for its icon again (`signalChangeIcon`, 0.19 to 1.1,
    src/Gui/ViewProviderPy.xml); False where there is no such call (console mode: no view object)."""
    signal = getattr(view_object, "signalChangeIcon", None)
    if signal is None:
        return False
    signal()
    return True
