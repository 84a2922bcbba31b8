"""The 4-axis job's task panel: tools, cutting data, strategies, machine and post, checked as you type.

One group box per property group of schema.JOB_FIELDS. Every change re-runs
validation.validate (the command line's own checks) and shows each SpurCadError message
inside the group it is about; the tool recommendations for the gear stand beside the tool
fields. OK writes the values to the job and recomputes; with an error OK keeps the panel open.
"""

from __future__ import annotations

import FreeCADGui
from PySide import QtCore, QtGui

from spur_cad_workbench import schema
from spur_cad_workbench.features import document_values, write_values
from spur_cad_workbench.validation import recommendation_notes, validate

ERROR_STYLE = "color: #b00020;"
NOTE_STYLE = "color: #555555;"
BIG = 1e9


def _group_names() -> list[str]:
    names: list[str] = []
    for field in schema.JOB_FIELDS:
        if field.group not in names:
            names.append(field.group)
    return names


class JobTaskPanel:
    """Task panel editing one job object; `widgets`, `notes` and `messages` are keyed for tests and macros."""

    def __init__(self, job_obj):
        self.job = job_obj
        self.form = QtGui.QWidget()
        self.form.setObjectName("SpurCadJobPanel")
        self.form.setWindowTitle(f"4-axis job: {job_obj.Label}")
        self.widgets: dict[str, QtGui.QWidget] = {}
        self.notes: dict[str, QtGui.QLabel] = {}
        self.messages: dict[str, QtGui.QLabel] = {}
        self.boxes: dict[str, QtGui.QGroupBox] = {}
        layout = QtGui.QVBoxLayout(self.form)
        self.summary = QtGui.QLabel()
        self.summary.setWordWrap(True)
        layout.addWidget(self.summary)
        for extra in ("Gear", "Stock"):
            label = self._message_label(extra)
            layout.addWidget(label)
        values = document_values(job_obj)
        self._gear_values, self._stock_values = values["gear"], values["stock"]
        for group in _group_names():
            layout.addWidget(self._group_box(group, values["job"]))
        layout.addStretch(1)
        self.revalidate()

    # --- building --------------------------------------------------------------------------
    def _message_label(self, group: str) -> QtGui.QLabel:
        label = QtGui.QLabel()
        label.setObjectName(f"message:{group}")
        label.setWordWrap(True)
        label.setStyleSheet(ERROR_STYLE)
        label.setVisible(False)
        self.messages[group] = label
        return label

    def _group_box(self, group: str, values: dict) -> QtGui.QGroupBox:
        box = QtGui.QGroupBox(group)
        grid = QtGui.QGridLayout(box)
        row = 0
        for field in schema.JOB_FIELDS:
            if field.group != group:
                continue
            widget = self._widget(field, values[field.prop])
            widget.setObjectName(field.prop)
            widget.setToolTip(field.doc)
            self.widgets[field.prop] = widget
            note = QtGui.QLabel()
            note.setStyleSheet(NOTE_STYLE)
            note.setWordWrap(True)
            self.notes[field.prop] = note
            grid.addWidget(QtGui.QLabel(field.prop), row, 0)
            grid.addWidget(widget, row, 1)
            grid.addWidget(note, row, 2)
            row += 1
        grid.addWidget(self._message_label(group), row, 0, 1, 3)
        grid.setColumnStretch(2, 1)
        self.boxes[group] = box
        return box

    def _widget(self, field, value) -> QtGui.QWidget:
        if field.kind == "bool":
            widget = QtGui.QCheckBox()
            widget.setChecked(bool(value))
            widget.toggled.connect(self.revalidate)
        elif field.kind == "choice":
            widget = QtGui.QComboBox()
            widget.addItems(list(field.choices))
            widget.setCurrentIndex(max(0, list(field.choices).index(value) if value in field.choices else 0))
            widget.currentIndexChanged.connect(self.revalidate)
        elif field.kind == "string":
            widget = QtGui.QLineEdit(str(value))
            widget.textChanged.connect(self.revalidate)
        elif field.kind == "int":
            widget = QtGui.QSpinBox()
            widget.setRange(-2**31 + 1, 2**31 - 1)
            widget.setValue(int(value))
            widget.valueChanged.connect(self.revalidate)
        else:  # length, distance, angle, float: any number, so spur_cad's own messages judge it
            widget = QtGui.QDoubleSpinBox()
            widget.setDecimals(6)
            widget.setRange(-BIG, BIG)
            widget.setValue(float(value))
            widget.valueChanged.connect(self.revalidate)
        return widget

    # --- values and checks -----------------------------------------------------------------
    def job_values(self) -> dict:
        """The job property values as the panel's widgets hold them."""
        values = {}
        for field in schema.JOB_FIELDS:
            widget = self.widgets[field.prop]
            if field.kind == "bool":
                values[field.prop] = widget.isChecked()
            elif field.kind == "choice":
                values[field.prop] = widget.currentText()
            elif field.kind == "string":
                values[field.prop] = widget.text()
            elif field.kind == "int":
                values[field.prop] = int(widget.value())
            else:
                values[field.prop] = float(widget.value())
        return values

    def set_value(self, prop: str, value) -> None:
        """Set a field as a user would (tests, macros)."""
        widget = self.widgets[prop]
        if isinstance(widget, QtGui.QCheckBox):
            widget.setChecked(bool(value))
        elif isinstance(widget, QtGui.QComboBox):
            widget.setCurrentIndex(widget.findText(str(value)))
        elif isinstance(widget, QtGui.QLineEdit):
            widget.setText(str(value))
        else:
            widget.setValue(value)

    def current_messages(self) -> dict[str, str]:
        """{group: message} shown now."""
        return {group: label.text() for group, label in self.messages.items() if label.text()}

    def revalidate(self, *_):
        """Check the values and show messages beside the groups and recommendations beside the fields."""
        values = {"gear": self._gear_values, "stock": self._stock_values, "job": self.job_values()}
        result = validate(values, self.job.Label)
        for group, label in self.messages.items():
            text = result.messages.get(group, "")
            label.setText(text)
            label.setVisible(bool(text))
        notes = recommendation_notes(result.recommendations)
        for prop, label in self.notes.items():
            label.setText(notes.get(prop, ""))
        for role, switch in schema.TOOL_SWITCHES.items():
            enabled = self.widgets[switch.prop].isChecked()
            for field in schema.JOB_FIELDS:
                if field.section == f"tools.{role}" and field.key:
                    self.widgets[field.prop].setEnabled(enabled)
        self.summary.setText("All values are valid." if result.ok else
                             f"{len(result.messages)} problem(s): see the red messages below.")
        return result

    # --- task dialog interface ---------------------------------------------------------------
    def getStandardButtons(self):
        return int(QtGui.QDialogButtonBox.Ok | QtGui.QDialogButtonBox.Cancel)

    def accept(self) -> bool:
        """Apply the values and recompute; keep the panel open while a value is invalid."""
        result = self.revalidate()
        if not result.ok:
            return False
        doc = self.job.Document
        doc.openTransaction("Edit spur_cad job")
        write_values(self.job, self.job_values())
        doc.commitTransaction()
        doc.recompute()
        self._close()
        return True

    def reject(self) -> bool:
        self._close()
        return True

    def _close(self) -> None:
        gui_doc = FreeCADGui.getDocument(self.job.Document.Name)
        if gui_doc is not None and gui_doc.getInEdit() is not None:
            gui_doc.resetEdit()
        else:
            FreeCADGui.Control.closeDialog()


def show_job_panel(job_obj) -> JobTaskPanel:
    """Open the task panel for `job_obj` (closing any other task dialog) and return it."""
    if FreeCADGui.Control.activeDialog():
        FreeCADGui.Control.closeDialog()
    panel = JobTaskPanel(job_obj)
    FreeCADGui.Control.showDialog(panel)
    job_obj.ViewObject.Proxy.panel = panel
    QtCore.QCoreApplication.processEvents()
    return panel
