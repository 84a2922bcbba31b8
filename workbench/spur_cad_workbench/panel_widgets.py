"""The job task panel's building blocks (taskpanel.py assembles them): folding sections, number boxes, wrapped
labels, the panel's field widgets looked up afresh, its styles and widths, and small Qt helpers. Each works on
FreeCAD 0.20 (PySide2) and 1.x (PySide6) through compat."""

from __future__ import annotations

from collections.abc import Mapping

from PySide import QtCore, QtGui

from spur_cad_workbench import compat, schema

ERROR_COLOUR = "#b00020"
ERROR_STYLE = f"color: {ERROR_COLOUR};"
HIGHLIGHT_STYLE = f"border: 2px solid {ERROR_COLOUR};"
NOTE_STYLE = "color: #555555;"
ADVICE_STYLE = "color: #8a5a00;"
BIG = 1e9
TITLE_WIDTH_PX = 120
"""The task box's title (the job's label) is elided to this width: FreeCAD's task box never wraps its title,
so a long job name would widen the panel beyond the dock."""
FIELD_MIN_WIDTH_PX = 112
PANEL_MIN_WIDTH_PX = 170  # fits a 240 px task dock: its scroll area's 220 px less the task box's margins
QUANTITY_UNITS = {"length": "mm", "distance": "mm", "angle": "deg", "speed": "mm/min"}
NUMBER_DECIMALS = 6
MODIFICATIONS_TITLE = "Flank modifications"  # the gear's: a longer title is elided in a narrow dock
CHART_DPI = 96
CHART_MIN_WIDTH_IN = 2.5
"""The modification chart is drawn this wide at least (its tick labels need it) and scaled down to the section's
width in a narrower dock."""
REVALIDATE_DELAY_MS = 250  # typing: check once the keys pause (a check plans roughing levels: up to 0.5 s)


def quantity_unit(field) -> str:
    """The unit a quantity field is set and read in: the key's own for micrometres (machine accuracy), else its
    kind's (mm, deg, mm/min)."""
    return field.unit if field.unit in schema.SET_IN_KEY_UNIT else QUANTITY_UNITS[field.kind]


def size_policy(name: str):
    """A QSizePolicy.Policy member (scoped name on PySide6, see compat.qt_enum)."""
    return compat.qt_enum(QtGui.QSizePolicy, "Policy", name)


def group_names() -> list[str]:
    names: list[str] = []
    for field in schema.JOB_FIELDS:
        if field.group not in names:
            names.append(field.group)
    return names


class NumberBox(QtGui.QDoubleSpinBox):
    """A spin box for numbers with a unit suffix: six decimals can be typed, the text shows only the digits the
    value has (87.5 m/min, 0.0005 s), not a fixed count."""

    def __init__(self):
        super().__init__()
        self.setDecimals(NUMBER_DECIMALS)
        self.setRange(-BIG, BIG)

    def textFromValue(self, value: float) -> str:  # noqa: N802 (Qt's name)
        return format(round(value, NUMBER_DECIMALS), f".{NUMBER_DECIMALS + 6}g")


class Section:
    """A titled, collapsible part of the panel: a header button and a body with a form layout."""

    def __init__(self, title: str, collapsed: bool, on_open=None):
        self.widget = QtGui.QWidget()
        layout = QtGui.QVBoxLayout(self.widget)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(1)
        self.header = QtGui.QToolButton()
        self.header.setObjectName(f"section:{title}")
        self.header.setText(title)
        self.header.setCheckable(True)
        self.header.setToolButtonStyle(compat.qt_enum(QtCore.Qt, "ToolButtonStyle", "ToolButtonTextBesideIcon"))
        self.header.setSizePolicy(size_policy("Ignored"), size_policy("Fixed"))  # a long summary never widens the panel
        self.header.setStyleSheet("QToolButton { border: none; font-weight: bold; text-align: left; }")
        self.body = QtGui.QWidget()
        self.form = QtGui.QFormLayout(self.body)
        self.form.setRowWrapPolicy(compat.qt_enum(QtGui.QFormLayout, "RowWrapPolicy", "WrapLongRows"))
        self.form.setFieldGrowthPolicy(compat.qt_enum(QtGui.QFormLayout, "FieldGrowthPolicy", "AllNonFixedFieldsGrow"))
        self.form.setContentsMargins(8, 0, 0, 4)
        self.summary = wrapped_label(NOTE_STYLE, f"section-summary:{title}")
        self.summary.setContentsMargins(22, 0, 0, 0)
        self.summary.setVisible(False)
        layout.addWidget(self.header)
        layout.addWidget(self.summary)
        layout.addWidget(self.body)
        self.on_open = on_open  # called after the body is shown (the panel scrolls its fields to their start)
        self.header.toggled.connect(self.set_open)
        self.header.setChecked(not collapsed)
        self.set_open(not collapsed)

    def set_summary(self, summary: str) -> None:
        """Show what the group holds under its title while it is folded ('T1 flat D 4 mm')."""
        self.summary.setText(summary)
        self.summary.setVisible(bool(summary) and not self.is_open)

    def set_open(self, is_open: bool) -> None:
        self.header.setChecked(is_open)
        arrow = "DownArrow" if is_open else "RightArrow"
        self.header.setArrowType(compat.qt_enum(QtCore.Qt, "ArrowType", arrow))
        self.body.setVisible(is_open)
        self.summary.setVisible(bool(self.summary.text()) and not is_open)
        if is_open and self.on_open is not None:
            self.on_open()

    @property
    def is_open(self) -> bool:
        return self.header.isChecked()


def show_start(widget: QtGui.QWidget) -> None:
    """Scroll a field's text to its start unless the user is typing in it: a narrow field shows "-1000.00 mm"
    cut as "-1000.0" rather than "000.00 mm" (a lost minus sign), and "generic 4-axis VM" not "eneric 4-axis VMC"."""
    edit = widget if isinstance(widget, QtGui.QLineEdit) else getattr(widget, "lineEdit", lambda: None)()
    if edit is not None and not edit.hasFocus():
        edit.setCursorPosition(0)


def wrapped_label(style: str = "", name: str = "") -> QtGui.QLabel:
    label = QtGui.QLabel()
    label.setWordWrap(True)
    label.setObjectName(name)
    if style:
        label.setStyleSheet(style)
    label.setSizePolicy(size_policy("Ignored"), size_policy("Preferred"))
    return label


class FieldWidgets(Mapping):
    """The panel's fields by property name, looked up by object name on every access.

    Python wrappers of FreeCAD's Gui::QuantitySpinBox (made by FreeCADGui.UiLoader) are invalidated
    ("Internal C++ object already deleted") after some Qt calls that take them, although the widget
    lives on (FreeCAD 0.20, PySide2 5.15); a wrapper looked up afresh is always valid."""

    def __init__(self, form: QtGui.QWidget):
        self._form = form
        self._props: list[str] = []

    def add(self, prop: str) -> None:
        self._props.append(prop)

    def __getitem__(self, prop: str) -> QtGui.QWidget:
        widget = self._form.findChild(QtGui.QWidget, prop) if prop in self._props else None
        if widget is None:
            raise KeyError(prop)
        return widget

    def __iter__(self):
        return iter(self._props)

    def __len__(self) -> int:
        return len(self._props)


def png_bytes(figure, dpi: int) -> bytes:
    """A matplotlib figure as PNG bytes at `dpi` (the screen's: the chart's text at its point size)."""
    import io

    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(figure)
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=dpi)
    return buffer.getvalue()


def scroll_area_of(widget):
    """The nearest scroll area holding `widget` (FreeCAD's task view is one), or None."""
    parent = widget.parentWidget()
    while parent is not None and not isinstance(parent, QtGui.QScrollArea):
        parent = parent.parentWidget()
    return parent
