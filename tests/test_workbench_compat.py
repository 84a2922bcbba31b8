"""spur_cad_workbench.compat: every branch without FreeCAD, against small fakes of FreeCAD 0.20's and 1.x's
APIs (each fake says which source or observation it follows; docs/freecad-compat.md has the details), then
each FreeCAD's own branches inside the real FreeCAD (0.20, 1.0 and 1.1): freecadcmd (console) and the GUI under Xvfb."""

from __future__ import annotations

import enum
import importlib.util
import types

import pytest

from tests.freecad_helper import describe
from tests.workbench_helper import ROOT, run_workbench_code


def _load_compat():
    """workbench/spur_cad_workbench/compat.py, loaded from its file (it imports nothing of the workbench), so
    that sys.path stays as the other tests expect it."""
    spec = importlib.util.spec_from_file_location("spur_cad_workbench_compat",
                                                  ROOT / "workbench" / "spur_cad_workbench" / "compat.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


compat = _load_compat()

# --- FreeCAD.Version() ---------------------------------------------------------------------------------

# Observed in Debian's 0.20.2 (freecadcmd): FreeCAD.Version()
VERSION_020 = ["0", "20", "2", "", "https://code.launchpad.net/~vcs-imports/freecad/trunk", "2026/10/03 17:20:59"]
# src/App/ApplicationPy.cpp sGetVersion: [BuildVersionMajor, BuildVersionMinor, BuildVersionPoint, BuildRevision, ...]
VERSION_100 = ["1", "0", "0", "39109 (Git)", "https://github.com/FreeCAD/FreeCAD.git main", "2024/11/18 19:41:46"]
VERSION_110 = ["1", "1", "0", "", "https://github.com/FreeCAD/FreeCAD.git", "2026/03/25 10:00:00"]


def _freecad(version):
    return types.SimpleNamespace(Version=lambda: list(version))


@pytest.mark.parametrize("version, expected", [
    (VERSION_020, (0, 20, 2)), (VERSION_100, (1, 0, 0)), (VERSION_110, (1, 1, 0)),
    (["1", "2", "0dev"], (1, 2, 0)),  # a development point release: the digits before the suffix
    (["1", "0", "0rc2"], (1, 0, 0)),
    (["1", "1"], (1, 1, 0)),  # a short list: missing parts are 0
    (["", "x", " 3"], (0, 0, 3)),
])
def test_freecad_version(version, expected):
    assert compat.freecad_version(_freecad(version)) == expected


# --- the CAM / Path module ------------------------------------------------------------------------------


class FakeProgram:
    """Path.Path: a constructor without arguments and setFromGCode(str) (src/Mod/CAM/App/Path.pyi; 0.20's
    Mod/Path/App/PathPy.xml has the same methods)."""

    def __init__(self):
        self.gcode = []

    def setFromGCode(self, text):
        self.gcode.append(text)


def _module(name, **attrs):
    module = types.ModuleType(name)
    module.__dict__.update(attrs)
    return module


def _importer(modules: dict):
    def importer(name):
        if name not in modules:
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return modules[name]
    return importer


# 0.20: `Path` is the C++ module itself (/usr/lib/freecad-python3/lib/Path.so, PyMOD_INIT_FUNC(Path)).
PATH_020 = _module("Path", Path=FakeProgram, Command=object, Area=object)
# 1.0/1.1: the C++ module is `PathApp` (src/Mod/CAM/App/AppPath.cpp PyMOD_INIT_FUNC(PathApp)) and `Path` the package
# src/Mod/CAM/Path/__init__.py, which does `from PathApp import *` and imports Path.Log, Path.Geom, Path.Preferences.
PATHAPP_1X = _module("PathApp", Path=FakeProgram, Command=object, Area=object)
PATH_1X = _module("Path", Log=object(), Geom=object(), Preferences=object(), **{
    key: value for key, value in vars(PATHAPP_1X).items() if not key.startswith("__")})
# A `Path` that is not FreeCAD's (an empty namespace package, another add-on's module): skipped.
FOREIGN_PATH = _module("Path")


@pytest.mark.parametrize("modules, expected", [
    ({"Path": PATH_020}, PATH_020),
    ({"Path": PATH_1X, "PathApp": PATHAPP_1X}, PATH_1X),
    ({"Path": FOREIGN_PATH, "PathApp": PATHAPP_1X}, PATHAPP_1X),
    ({"PathApp": PATHAPP_1X}, PATHAPP_1X),  # a `Path` package that fails to import (e.g. a broken Path.Log)
    ({}, None),  # a FreeCAD built without the CAM workbench: toolpaths fall back to Part wires
    ({"Path": FOREIGN_PATH}, None),
])
def test_path_module(modules, expected):
    assert compat.path_module(_importer(modules)) is expected


def test_new_path_sets_gcode_only_when_there_is_some():
    program = compat.new_path(PATH_1X, "G0 X1 Y2 Z3\n")
    assert isinstance(program, FakeProgram) and program.gcode == ["G0 X1 Y2 Z3\n"]
    assert compat.new_path(PATH_020, "").gcode == []
    assert compat.new_path(PATH_020, " \n").gcode == []


# --- Qt 5 / Qt 6 enums, dialogs and widgets -------------------------------------------------------------


class Pyside2Enum:
    """A PySide2 5.15 (shiboken) enum member, as observed in 0.20's GUI: int() works, there is no `.value`,
    `|` gives a StandardButtons flags object that int() also accepts."""

    def __init__(self, value):
        self._value = value

    def __int__(self):
        return self._value

    def __or__(self, other):
        return Pyside2Enum(self._value | int(other))


def _pyside2_button_box():
    # Observed in 0.20: QDialogButtonBox.Ok (unscoped) and QDialogButtonBox.StandardButton.Ok (scoped) both exist;
    # int(Ok) == 1024 and int(Ok | Cancel) == 4195328.
    scoped = types.SimpleNamespace(Ok=Pyside2Enum(0x400), Cancel=Pyside2Enum(0x400000), Apply=Pyside2Enum(0x2000000))
    return type("QDialogButtonBox", (), {"StandardButton": scoped, **vars(scoped)})


class StandardButton(enum.Flag):
    """PySide6 >= 6.4's QDialogButtonBox.StandardButton: a Python enum.Flag (doc.qt.io, "The new Python enums"),
    so int() raises the TypeError seen on FreeCAD 1.1 (LCInterlocking issue 78)."""

    Ok = 0x400
    Cancel = 0x400000
    Apply = 0x2000000


PYSIDE6_BOX = type("QDialogButtonBox", (), {"StandardButton": StandardButton})
PYSIDE2_BOX = _pyside2_button_box()
# Older PySide2 without scoped enum classes: only the unscoped names.
UNSCOPED_BOX = type("QDialogButtonBox", (), {"Ok": Pyside2Enum(0x400), "Cancel": Pyside2Enum(0x400000)})


def test_enum_int_on_pyside2_and_pyside6():
    assert compat.enum_int(Pyside2Enum(0x400)) == 0x400
    assert compat.enum_int(StandardButton.Ok) == 0x400
    assert compat.enum_int(StandardButton.Ok | StandardButton.Cancel) == 0x400400
    with pytest.raises(TypeError):
        int(StandardButton.Ok | StandardButton.Cancel)  # what the task panel's getStandardButtons did


def test_qt_enum_prefers_the_scoped_name():
    assert compat.qt_enum(PYSIDE6_BOX, "StandardButton", "Ok") is StandardButton.Ok
    assert compat.qt_enum(PYSIDE2_BOX, "StandardButton", "Cancel") is PYSIDE2_BOX.StandardButton.Cancel
    assert compat.qt_enum(UNSCOPED_BOX, "StandardButton", "Ok") is UNSCOPED_BOX.Ok
    message_box = type("QMessageBox", (), {"Icon": types.SimpleNamespace(Warning="scoped"), "Information": "plain"})
    assert compat.qt_enum(message_box, "Icon", "Warning") == "scoped"
    assert compat.qt_enum(message_box, "Icon", "Information") == "plain"


@pytest.mark.parametrize("box", [PYSIDE2_BOX, PYSIDE6_BOX, UNSCOPED_BOX], ids=["pyside2", "pyside6", "unscoped"])
def test_dialog_buttons_is_one_int_everywhere(box):
    value = compat.dialog_buttons(types.SimpleNamespace(QDialogButtonBox=box), "Ok", "Cancel")
    assert type(value) is int and value == 4195328  # = int(Ok | Cancel) in 0.20's GUI
    assert compat.dialog_buttons(types.SimpleNamespace(QDialogButtonBox=box)) == 0


QWIDGET = type("QWidget", (), {})
WRAPPER_QTGUI = _module("PySide.QtGui", QWidget=QWIDGET, QColor=object)  # both wrappers: QtGui + QtWidgets
WRAPPER_QTWIDGETS = _module("PySide.QtWidgets", QWidget=QWIDGET)  # 1.x only (SetupShibokenAndPyside.cmake)


@pytest.mark.parametrize("modules, expected", [
    ({"PySide.QtGui": WRAPPER_QTGUI, "PySide.QtWidgets": WRAPPER_QTWIDGETS}, WRAPPER_QTWIDGETS),  # 1.x
    ({"PySide.QtGui": WRAPPER_QTGUI}, WRAPPER_QTGUI),  # 0.20: /usr/share/freecad/Ext/PySide has no QtWidgets.py
    ({"PySide.QtGui": WRAPPER_QTGUI, "PySide.QtWidgets": _module("PySide.QtWidgets")}, WRAPPER_QTGUI),
])
def test_qt_widgets(modules, expected):
    assert compat.qt_widgets("PySide", _importer(modules)) is expected


class Pyside2Dialog:
    """PySide2 5.15's QDialog as observed in 0.20's GUI: the class has exec_ and no exec, but an instance
    answers `exec` with a QtCore.MetaFunction (a meta-object slot lookup)."""

    def __init__(self):
        self.calls = []

    def exec_(self):
        self.calls.append("exec_")
        return 1

    def __getattr__(self, name):
        if name == "exec":
            return lambda: self.calls.append("MetaFunction exec") or 1
        raise AttributeError(name)


class Pyside6Dialog:
    """PySide6's QDialog: exec, and exec_ kept with a DeprecationWarning."""

    def __init__(self):
        self.calls = []

    def exec(self):
        self.calls.append("exec")
        return 1

    def exec_(self):
        raise AssertionError("exec_ is deprecated on PySide6")


@pytest.mark.parametrize("dialog_class, called", [(Pyside2Dialog, "exec_"), (Pyside6Dialog, "exec")])
def test_exec_dialog(dialog_class, called):
    dialog = dialog_class()
    assert compat.exec_dialog(dialog) == 1
    assert dialog.calls == [called]


# --- Gui::QuantitySpinBox -------------------------------------------------------------------------------

# Gui::QuantitySpinBox Qt properties: 0.20 as its metaObject lists them in the GUI; 1.x: src/Gui/QuantitySpinBox.h
# (the running 1.0.0 and 1.1.3 declare no `decimals` property: the 1.x fake keeps the branch for a FreeCAD that does).
SPIN_BOX_PROPERTIES_020 = ("unit", "minimum", "maximum", "singleStep", "rawValue", "value", "binding", "expression")
SPIN_BOX_PROPERTIES_1X = ("unit", "minimum", "maximum", "singleStep", "rawValue", "decimals", "value", "binding",
                          "expression", "autoNormalize")


class FakeMetaObject:
    def __init__(self, names):
        self.names = names

    def indexOfProperty(self, name):
        return self.names.index(name) if name in self.names else -1


class FakeSpinBox:
    def __init__(self, names, value=None, raw=0.0):
        self.meta = FakeMetaObject(names)
        self.properties = {"value": value, "rawValue": raw}
        self.set_calls = []

    def metaObject(self):
        return self.meta

    def setProperty(self, name, value):
        self.set_calls.append((name, value))
        self.properties[name] = value
        return name in self.meta.names  # Qt: False for an undeclared (dynamic) property

    def property(self, name):
        return self.properties.get(name)


class FakeUiLoader:
    """FreeCADGui.UiLoader(): createWidget(class name) -> widget, or None for an unknown class (observed in 0.20)."""

    def __init__(self, names):
        self.names = names

    def createWidget(self, class_name):
        return FakeSpinBox(self.names) if class_name == "Gui::QuantitySpinBox" and self.names else None


def test_quantity_spin_box_on_020_and_1x():
    old = compat.quantity_spin_box(FakeUiLoader(SPIN_BOX_PROPERTIES_020), "mm", minimum=0, maximum=1e6, decimals=4)
    assert old.set_calls == [("unit", "mm"), ("minimum", 0.0), ("maximum", 1e6)]  # no per-widget decimals in 0.20
    new = compat.quantity_spin_box(FakeUiLoader(SPIN_BOX_PROPERTIES_1X), "mm/min", decimals=4)
    assert new.set_calls == [("unit", "mm/min"), ("decimals", 4)]
    assert compat.quantity_spin_box(FakeUiLoader(()), "mm") is None


class FakeQuantity:
    """Base.Quantity reduced to what the spin box helpers use: a value in FreeCAD's internal unit (mm, mm/s,
    deg) and getValueAs(unit) returning a Quantity that float() converts (0.20: observed; 1.x:
    src/Base/QuantityPyImp.cpp getValueAs returns a new QuantityPy)."""

    SCALE = {"mm": 1.0, "mm/s": 1.0, "mm/min": 1.0 / 60.0, "deg": 1.0}

    def __init__(self, value, unit=None):
        if isinstance(value, str):
            number, unit = value.split(" ", 1)
            value = float(number) * self.SCALE[unit]
        self.Value = float(value)
        self.unit = unit

    def getValueAs(self, unit):
        return FakeQuantity(self.Value / self.SCALE[unit], unit)

    def __float__(self):
        return self.Value


FAKE_UNITS = types.SimpleNamespace(Quantity=FakeQuantity, Unit=lambda text: text)


def test_spin_box_value_from_the_value_property_or_from_raw_value():
    widget = FakeSpinBox(SPIN_BOX_PROPERTIES_020, value=FakeQuantity("120 mm/min"))
    assert compat.spin_box_value(widget, FAKE_UNITS, "mm/min") == pytest.approx(120.0)
    no_quantity = FakeSpinBox(SPIN_BOX_PROPERTIES_1X, value=None, raw=2.0)  # rawValue: 2 mm/s internal
    assert compat.spin_box_value(no_quantity, FAKE_UNITS, "mm/min") == pytest.approx(120.0)


def test_set_spin_box_value_sets_a_quantity():
    widget = FakeSpinBox(SPIN_BOX_PROPERTIES_020)
    compat.set_spin_box_value(widget, FAKE_UNITS, 100, "mm/min")
    (name, quantity), = widget.set_calls
    assert name == "value" and quantity.Value == pytest.approx(100 / 60)


# --- view objects ---------------------------------------------------------------------------------------


class FakeViewObject:
    def __init__(self, *properties, **values):
        object.__setattr__(self, "PropertiesList", list(properties))
        object.__setattr__(self, "assigned", {})
        for key, value in values.items():
            object.__setattr__(self, key, value)

    def __setattr__(self, name, value):
        self.assigned[name] = value
        object.__setattr__(self, name, value)


# PathGui::ViewProviderPath's properties: observed in 0.20's GUI; 1.x: src/Mod/CAM/Gui/ViewProviderPath.cpp.
PATH_VIEW_020 = ("DisplayMode", "LineWidth", "MarkerColor", "NormalColor", "ShapeColor", "ShowCount", "ShowNodes",
                 "StartIndex", "StartPosition", "Transparency", "Visibility")
PATH_VIEW_1X = ("DisplayMode", "LineWidth", "MarkerColor", "NormalColor", "ShapeAppearance", "ShowCount",
                "ShowNodes", "StartIndex", "StartPosition", "Transparency", "Visibility")
PART_VIEW_020 = ("AngularDeflection", "Deviation", "DiffuseColor", "LineColor", "PointSize", "ShapeColor",
                 "ShapeMaterial", "Transparency", "Visibility")
PART_VIEW_1X = ("AngularDeflection", "Deviation", "LineColor", "PointSize", "ShapeAppearance", "Transparency",
                "Visibility")  # src/Mod/Part/Gui/ViewProviderExt.cpp + src/Gui/ViewProviderGeometryObject.cpp


@pytest.mark.parametrize("properties", [PATH_VIEW_020, PATH_VIEW_1X], ids=["0.20", "1.x"])
def test_set_path_start_on_a_path_view_object(properties):
    view = FakeViewObject(*properties)
    assert compat.set_path_start(view, [1, 2.5, -3]) is True
    assert view.assigned == {"StartPosition": (1.0, 2.5, -3.0)}


def test_set_path_start_without_a_path_view():
    assert compat.set_path_start(None, (0, 0, 0)) is False  # console mode: obj.ViewObject is None
    part = FakeViewObject(*PART_VIEW_020)  # Part wire fallback when the CAM module is missing
    assert compat.set_path_start(part, (0, 0, 0)) is False and part.assigned == {}


class FakeMaterial:
    """App.Material (src/App/MaterialPy): DiffuseColor is an attribute."""

    def __init__(self):
        self.DiffuseColor = (0.8, 0.8, 0.8, 0.0)


class AppearanceViewObject(FakeViewObject):
    """1.x ShapeAppearance reads back as a new tuple of materials each time: an edit of a material taken from it
    changes nothing until the list is assigned back (PR 13499's review)."""

    @property
    def ShapeAppearance(self):
        stored = self.assigned.get("ShapeAppearance")
        return tuple(stored) if stored is not None else (FakeMaterial(),)

    @ShapeAppearance.setter
    def ShapeAppearance(self, value):
        self.assigned["ShapeAppearance"] = list(value)


def test_set_shape_colour_on_020_and_1x():
    old = FakeViewObject(*PART_VIEW_020)
    assert compat.set_shape_colour(old, (0.1, 0.2, 0.3, 0.0)) is True
    assert old.assigned == {"ShapeColor": (0.1, 0.2, 0.3)}
    new = AppearanceViewObject(*PART_VIEW_1X)
    assert compat.set_shape_colour(new, (0.1, 0.2, 0.3)) is True
    assert [m.DiffuseColor for m in new.ShapeAppearance] == [(0.1, 0.2, 0.3)]
    assert compat.set_shape_colour(FakeViewObject("Visibility"), (1, 0, 0)) is False
    assert compat.set_shape_colour(None, (1, 0, 0)) is False


# --- task dialog ----------------------------------------------------------------------------------------


class FakeTaskDialog:
    """1.x Gui.TaskDialog wrapper (src/Gui/TaskView/TaskDialogPython.cpp TaskDialogPy::init_type)."""

    def __init__(self):
        self.calls = []

    def setDocumentName(self, name):
        self.calls.append(("setDocumentName", name))

    def setAutoCloseOnDeletedDocument(self, flag):
        self.calls.append(("setAutoCloseOnDeletedDocument", flag))


class FakeControl:
    def __init__(self, returned):
        self.returned = returned
        self.shown = []

    def showDialog(self, panel):
        self.shown.append(panel)
        return self.returned


def test_show_task_dialog_on_020_and_1x():
    panel = object()
    old = FakeControl(None)  # 0.20 ControlPy::showDialog returns None
    assert compat.show_task_dialog(old, panel, "Gear") is None and old.shown == [panel]
    dialog = FakeTaskDialog()
    new = FakeControl(dialog)  # 1.x returns the TaskDialog (PR 15116)
    assert compat.show_task_dialog(new, panel, "Gear") is dialog
    assert dialog.calls == [("setDocumentName", "Gear"), ("setAutoCloseOnDeletedDocument", True)]
    untied = FakeTaskDialog()
    assert compat.show_task_dialog(FakeControl(untied), panel) is untied and untied.calls == []


def test_progress_indicator_where_freecad_has_one():
    # 0.20 and 1.x: FreeCAD.Base.ProgressIndicator() with start(text, steps), next(), stop()
    # (src/Base/ProgressIndicatorPy.cpp); the 0.20 object is checked in tests/test_workbench_dialogs_gui.py
    class Indicator:
        pass

    with_one = types.SimpleNamespace(Base=types.SimpleNamespace(ProgressIndicator=Indicator))
    assert isinstance(compat.progress_indicator(with_one), Indicator)
    assert compat.progress_indicator(types.SimpleNamespace(Base=types.SimpleNamespace())) is None
    assert compat.progress_indicator(types.SimpleNamespace()) is None


# --- the real FreeCAD: 0.20, 1.0, 1.1 ------------------------------------------------------------------------------

CONSOLE_BODY = r"""
import FreeCAD
from spur_cad_workbench import compat

version = compat.freecad_version(FreeCAD)
RESULT["version"] = list(version)
module = compat.path_module()
RESULT["path_module"] = [module.__name__, getattr(module, "__file__", "")]
program = compat.new_path(module, "G0 X1 Y2 Z3\nG1 X4 Y5 Z6\n")
RESULT["commands"] = [command.Name for command in program.Commands]
RESULT["empty"] = len(compat.new_path(module, "").Commands)
doc = FreeCAD.newDocument("Compat")
obj = doc.addObject(compat.PATH_FEATURE_TYPE, "Toolpath")
obj.Path = program
RESULT["object"] = [obj.TypeId, len(obj.Path.Commands), obj.ViewObject is None]
RESULT["console_view"] = [compat.set_path_start(obj.ViewObject, (1, 2, 3)),
                          compat.set_shape_colour(obj.ViewObject, (1, 0, 0))]
widgets = compat.qt_widgets()
RESULT["widgets"] = widgets.__name__
RESULT["buttons"] = compat.dialog_buttons(widgets, "Ok", "Cancel")
try:
    RESULT["buttons_int"] = int(widgets.QDialogButtonBox.Ok | widgets.QDialogButtonBox.Cancel)
except TypeError as exc:   # PySide6's enum.Flag (1.1)
    RESULT["buttons_int"] = type(exc).__name__
RESULT["dialog_exec"] = [hasattr(widgets.QDialog, "exec"), hasattr(widgets.QDialog, "exec_")]
"""


# What each FreeCAD running here gives, observed: Debian 12's 0.20.2 (Qt 5, PySide2 5.15.8), Debian 13's 1.0.0
# (Qt 5, PySide2 5.15.16) and Debian testing's 1.1.3 (Qt 6, PySide6 6.11). A FreeCAD not listed fails the tests.
OBSERVED = {
    (0, 20): dict(path_file="/Path.so",                    # the C++ module itself
                  widgets="PySide.QtGui",                  # the wrapper has no PySide.QtWidgets
                  buttons_int=4195328,                     # shiboken flags: int(Ok | Cancel) works
                  dialog_exec=[False, True],               # the class: exec_ only (an instance also answers exec)
                  exec_called="exec_", dialog="None",      # showDialog returns nothing
                  appearance=False),                       # ShapeColor is a property
    (1, 0): dict(path_file="/Mod/CAM/Path/__init__.py",   # the CAM package over PathApp
                 widgets="PySide.QtWidgets", buttons_int=4195328, dialog_exec=[False, True], exec_called="exec_",
                 dialog="Task Dialog",                     # a Gui.TaskDialog
                 appearance=True),                         # ShapeAppearance; ShapeColor a Python attribute
    (1, 1): dict(path_file="/Mod/CAM/Path/__init__.py", widgets="PySide.QtWidgets",
                 buttons_int="TypeError",                  # PySide6's enum.Flag: int(Ok | Cancel) raises
                 dialog_exec=[True, True],                 # exec, and the deprecated exec_
                 exec_called=None,                         # compat.exec_dialog calls exec
                 dialog="<Task Dialog for 'CompatGui' >", appearance=True),
}


def _observed(version) -> dict:
    major, minor = version[:2]
    assert (major, minor) in OBSERVED, f"FreeCAD {major}.{minor}: not observed yet; add what it gives to OBSERVED"
    return OBSERVED[major, minor]


@pytest.mark.freecad
def test_the_branches_in_freecadcmd(freecadcmd, tmp_path):
    result, proc = run_workbench_code(CONSOLE_BODY, tmp_path / "fc", freecadcmd=freecadcmd)
    assert result is not None and result.get("ok"), describe(proc, result)
    expected = _observed(result["version"])
    name, file = result["path_module"]
    assert name == "Path" and file.endswith(expected["path_file"])
    assert result["commands"] == ["G0", "G1"] and result["empty"] == 0
    assert result["object"] == ["Path::FeaturePython", 2, True]
    assert result["console_view"] == [False, False]  # no view objects without the GUI
    assert result["widgets"] == expected["widgets"]
    assert result["buttons"] == 4195328  # = Ok | Cancel as one int, in every version
    assert result["buttons_int"] == expected["buttons_int"]
    assert result["dialog_exec"] == expected["dialog_exec"]


GUI_BODY = r"""
import FreeCAD, FreeCADGui, Part
from PySide import QtCore
from spur_cad_workbench import compat

RESULT["version"] = list(compat.freecad_version(FreeCAD))
widgets = compat.qt_widgets()
doc = FreeCAD.newDocument("CompatGui")
toolpath = doc.addObject(compat.PATH_FEATURE_TYPE, "Toolpath")
toolpath.Path = compat.new_path(compat.path_module(), "G0 X10 Y0 Z5\nG1 X10 Y0 Z0\n")
box = doc.addObject("Part::Feature", "Box")
box.Shape = Part.makeBox(1, 1, 1)
doc.recompute()
RESULT["start"] = compat.set_path_start(toolpath.ViewObject, FreeCAD.Vector(10, 0, 5))
RESULT["start_value"] = list(toolpath.ViewObject.StartPosition)
RESULT["colour"] = compat.set_shape_colour(box.ViewObject, (1.0, 0.0, 0.0))
RESULT["colour_value"] = list(box.ViewObject.ShapeColor)[:3]   # 1.x: a Python attribute over ShapeAppearance
RESULT["appearance"] = "ShapeAppearance" in box.ViewObject.PropertiesList
RESULT["part_start"] = compat.set_path_start(box.ViewObject, (0, 0, 0))

field = compat.quantity_spin_box(FreeCADGui.UiLoader(), "mm", minimum=0, maximum=1000, decimals=4)
RESULT["field"] = [field.metaObject().className(), compat.has_qt_property(field, "decimals")]
compat.set_spin_box_value(field, FreeCAD.Units, 12.5, "mm")
RESULT["field_value"] = [compat.spin_box_value(field, FreeCAD.Units, "mm"), field.text()]
RESULT["field_quantity"] = hasattr(field.property("value"), "getValueAs")
RESULT["field_dynamic"] = [bytes(name).decode() for name in field.dynamicPropertyNames()]
speed = compat.quantity_spin_box(FreeCADGui.UiLoader(), "mm/min")
compat.set_spin_box_value(speed, FreeCAD.Units, 100.0, "mm/min")
RESULT["speed"] = [compat.spin_box_value(speed, FreeCAD.Units, "mm/min"), speed.text()]
precise = FreeCAD.Units.Quantity("100 mm/min")
precise.Format = dict(precise.Format, Precision=4)   # a per-widget precision through the Quantity's format
compat.set_spin_box_quantity(speed, precise)
RESULT["precise_speed"] = [compat.spin_box_value(speed, FreeCAD.Units, "mm/min"), speed.text()]
RESULT["no_widget"] = compat.quantity_spin_box(FreeCADGui.UiLoader(), "mm") is None

class Panel:
    def __init__(self):
        self.form = widgets.QWidget()
    def getStandardButtons(self):
        return compat.dialog_buttons(widgets, "Ok", "Cancel")
    def reject(self):
        FreeCADGui.Control.closeDialog()
        return True

RESULT["dialog"] = repr(compat.show_task_dialog(FreeCADGui.Control, Panel(), doc.Name))
QtCore.QCoreApplication.processEvents()
boxes = [b for b in FreeCADGui.getMainWindow().findChildren(widgets.QDialogButtonBox) if b.isVisible()]
RESULT["task_buttons"] = sorted(b.text() for bb in boxes for b in bb.buttons())
FreeCADGui.Control.closeDialog()

class Dialog(widgets.QDialog):
    def exec_(self):
        RESULT["exec_called"] = "exec_"
        return super().exec_()

dialog = Dialog(FreeCADGui.getMainWindow())
QtCore.QTimer.singleShot(0, dialog.accept)
RESULT["exec"] = compat.exec_dialog(dialog)
"""


@pytest.mark.freecad
def test_the_branches_in_the_gui(freecad_gui, tmp_path):
    result, proc = run_workbench_code(GUI_BODY, tmp_path / "fc", gui=freecad_gui)
    assert result is not None and result.get("ok"), describe(proc, result)
    expected = _observed(result["version"])
    assert result["start"] is True and result["start_value"] == [10.0, 0.0, 5.0]
    assert result["colour"] is True and result["colour_value"] == [1.0, 0.0, 0.0]
    assert result["appearance"] is expected["appearance"]
    assert result["part_start"] is False  # a Part view provider has no StartPosition
    # no per-widget decimals property in any of them (observed; 1.x's sources have a C++ setDecimals only)
    assert result["field"] == ["Gui::QuantitySpinBox", False]
    value, text = result["field_value"]
    assert value == pytest.approx(12.5) and text.endswith("mm")
    assert result["field_quantity"] is True  # `value` reads back as a Base.Quantity
    assert "decimals" not in result["field_dynamic"]  # not set where the class lacks the property
    # the speed shows in mm/s with the global 2 decimals, and the stored value is the rounded one
    speed, speed_text = result["speed"]
    assert speed_text == "1.67 mm/s" and speed == pytest.approx(100.2)
    # ... unless the Quantity it is given carries its own precision (what the task panel does)
    speed, speed_text = result["precise_speed"]
    assert speed_text == "1.6667 mm/s" and speed == pytest.approx(100.002)
    assert result["no_widget"] is False
    assert result["dialog"] == expected["dialog"]
    assert "OK" in result["task_buttons"] and "Cancel" in result["task_buttons"]
    assert result["exec"] == 1 and result.get("exec_called") == expected["exec_called"]
