"""The 4-axis job's task panel: a summary on top, then tools, cutting data, strategies, machine and post in
collapsible sections, checked as you type.

- Fields: titles for people (schema.title), FreeCAD's unit-aware Gui::QuantitySpinBox for lengths,
  angles and feeds (in the user's unit schema, with enough decimals for a micrometre: units.py), spin
  boxes with the unit as suffix for the other units (mm/rev and mm/s^2 in the schema's length unit);
  each row fits FreeCAD's default task dock width (labels wrap above their field when the dock is narrow).
- Texts: notes, limits and messages name fields by their titles and give lengths and feeds in the
  user's unit schema (validation.py, summary.py and units.py with `FreeCAD.Units`).
- Summary: validity, the tool limits (cheap, as you type), and the cycle time by both estimators,
  moves and program lines. Those need a plan: they are shown from the job's last recompute while
  the values are the job's, from the panel's own plan after "Plan", and marked outdated otherwise.
- Flank modifications: the gear's (edited on the gear's properties), charted in their own section
  (spur_cad.report.figures.modification_chart_figure, stacked for the dock's width); none: no section.
- Variants: a 3-axis job says so in its title, its "3-axis" fields are on only with 3 axes; an internal gear or a
  tool the variant refuses gets the command line's message at the top.
- Errors: every change runs validation.validate (the command line's own checks); the problem is
  shown in its section as what to change, and its field is highlighted. OK with a problem keeps
  the panel open, opens the section, scrolls to the field and focuses it.
"""

from __future__ import annotations

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

from spur_cad.cam.setups import SETUP_SECTIONS
from spur_cad_workbench import compat, schema, units
from spur_cad_workbench.panel_widgets import (
    ADVICE_STYLE,
    BIG,
    CHART_DPI,
    CHART_MIN_WIDTH_IN,
    ERROR_STYLE,
    FIELD_MIN_WIDTH_PX,
    HIGHLIGHT_STYLE,
    MODIFICATIONS_TITLE,
    NOTE_STYLE,
    PANEL_MIN_WIDTH_PX,
    QUANTITY_UNITS,
    REVALIDATE_DELAY_MS,
    TITLE_WIDTH_PX,
    FieldWidgets,
    NumberBox,
    Section,
    group_names,
    png_bytes,
    quantity_unit,
    scroll_area_of,
    show_start,
    size_policy,
    wrapped_label,
)
from spur_cad_workbench.properties import document_values, write_values
from spur_cad_workbench.summary import (
    figures_text,
    group_summary,
    limits_text,
    long_job_advice,
    machine_setup,
    modification_summary,
    plan_figures,
    values_signature,
)
from spur_cad_workbench.validation import recommendation_notes, sentence, unusual_value_notes, validate


class JobTaskPanel:
    """Task panel editing one job object; `widgets`, `labels`, `notes`, `messages` and `sections` are keyed for
    tests and macros (by property name, and by group for messages and sections)."""

    def __init__(self, job_obj) -> None:
        self.job = job_obj
        self.form = QtGui.QWidget()
        self.form.setObjectName("SpurCadJobPanel")
        values = document_values(job_obj)
        title = f"{values['job']['MachineAxes']}-axis job: {job_obj.Label}"
        bold = QtGui.QFont(self.form.font())
        bold.setBold(True)
        elide = compat.qt_enum(QtCore.Qt, "TextElideMode", "ElideRight")
        self.form.setWindowTitle(QtGui.QFontMetrics(bold).elidedText(title, elide, TITLE_WIDTH_PX))
        self.form.setToolTip(title)
        self.form.setMinimumWidth(PANEL_MIN_WIDTH_PX)
        self.widgets = FieldWidgets(self.form)
        self.labels: dict[str, QtGui.QLabel] = {}
        self.notes: dict[str, QtGui.QLabel] = {}
        self.messages: dict[str, QtGui.QLabel] = {}
        self.sections: dict[str, Section] = {}
        self.highlighted: str | None = None
        self.result = None
        self._shown: dict[str, tuple[str, float]] = {}  # quantity fields: (text shown, exact value) when set
        self._per_unit: dict[str, float] = {}  # number fields shown in another unit: job-file units per shown one
        self._planned: tuple[str, object] | None = None  # (values signature, PlanFigures) planned by the panel
        layout = QtGui.QVBoxLayout(self.form)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(3)  # not the style's: FreeCAD 1.1's Qt 6 style spaced the folded groups past the dock
        layout.addWidget(self._summary_box())
        for extra in ("Gear", "Stock", "Job"):
            layout.addWidget(self._message_label(extra))
        self._timer = QtCore.QTimer(self.form)
        self._timer.setSingleShot(True)
        self._timer.timeout.connect(self.revalidate)
        for group in group_names():
            section = Section(group, collapsed=True,  # the summary on top and each header say what they hold
                              on_open=lambda group=group: self._show_starts(group))
            self.sections[group] = section
            if group not in self.messages:
                section.form.addRow(self._message_label(group))
            for field in schema.JOB_FIELDS:
                if field.group == group:
                    self._add_row(section, field, values["job"][field.prop])
            layout.addWidget(section.widget)
        layout.addWidget(self._modifications_section().widget)
        layout.addStretch(1)
        self.revalidate()

    # --- building --------------------------------------------------------------------------
    def _summary_box(self) -> QtGui.QWidget:
        box = QtGui.QFrame()
        box.setObjectName("summary")
        box.setFrameShape(compat.qt_enum(QtGui.QFrame, "Shape", "StyledPanel"))
        layout = QtGui.QVBoxLayout(box)
        self.summary = wrapped_label(name="summary:status")
        self.summary_figures = wrapped_label(name="summary:figures")
        self.summary_advice = wrapped_label(ADVICE_STYLE, "summary:advice")
        self.summary_limits = wrapped_label(NOTE_STYLE, "summary:limits")
        self.plan_button = QtGui.QPushButton("Plan (update the figures)")
        self.plan_button.setObjectName("summary:plan")
        self.plan_button.setToolTip("Plan the toolpaths for the values in this panel and show the cycle time, moves "
                                    "and program lines (the job itself changes only on OK)")
        self.plan_button.clicked.connect(self.plan)
        for widget in (self.summary, self.summary_figures, self.summary_advice, self.summary_limits,
                       self.plan_button):
            layout.addWidget(widget)
        return box

    def _modifications_section(self) -> Section:
        """The gear's flank modifications: a note (what they are, where to edit them) and their chart."""
        self._chart_key: str | None = None  # the gear values the chart was drawn for
        self.modifications_note = wrapped_label(NOTE_STYLE, "modifications:note")
        self.modifications_chart = QtGui.QLabel()
        self.modifications_chart.setObjectName("modifications:chart")
        self.modifications_chart.setSizePolicy(size_policy("Ignored"), size_policy("Fixed"))  # never widens the panel
        self.modifications_section = Section(MODIFICATIONS_TITLE, collapsed=True, on_open=self._show_modifications)
        self.modifications_section.form.addRow(self.modifications_note)
        self.modifications_section.form.addRow(self.modifications_chart)
        return self.modifications_section

    def _show_modifications(self) -> None:
        """Draw the gear's modifications into the open section (again only when the gear's values changed)."""
        import json

        from spur_cad.errors import SpurCadError
        from spur_cad.job import job_from_dict

        gear = document_values(self.job)["gear"]
        key = json.dumps(gear, sort_keys=True, default=repr)
        if key == self._chart_key or not self.modifications_section.is_open:
            return
        self._chart_key = key
        where = "Edit them on the gear's properties, group Flank modifications."
        try:
            job = job_from_dict(schema.job_data({"gear": gear}), self.job.Label)
        except SpurCadError as exc:
            job = None
            self.modifications_note.setText(sentence(exc, self.job.Label, FreeCAD.Units))
        if job is None or job.modifications is None:
            if job is not None:
                self.modifications_note.setText(f"The gear has no flank modifications. {where}")
            self.modifications_chart.clear()
            self.modifications_chart.setVisible(False)
            return
        from spur_cad.report.figures import modification_chart_figure

        self.modifications_note.setText(f"The gear's: {modification_summary(gear)}. {where}")
        width_px = max(1, self.modifications_section.body.width() - 12)
        figure = modification_chart_figure(job.modifications, job.gear.base_radius_mm,
                                           max(CHART_MIN_WIDTH_IN, width_px / CHART_DPI), stacked=True)
        pixmap = QtGui.QPixmap()
        pixmap.loadFromData(png_bytes(figure, CHART_DPI), "PNG")
        if pixmap.width() > width_px:
            pixmap = pixmap.scaledToWidth(width_px, compat.qt_enum(QtCore.Qt, "TransformationMode",
                                                                   "SmoothTransformation"))
        self.modifications_chart.setPixmap(pixmap)
        self.modifications_chart.setFixedHeight(pixmap.height())
        self.modifications_chart.setVisible(True)

    def _message_label(self, group: str) -> QtGui.QLabel:
        label = wrapped_label(ERROR_STYLE, f"message:{group}")
        label.setVisible(False)
        self.messages[group] = label
        return label

    def _add_row(self, section: Section, field, value) -> None:
        widget = self._widget(field, value)
        widget.setObjectName(field.prop)
        widget.setToolTip(field.doc)
        widget.setMinimumWidth(FIELD_MIN_WIDTH_PX)
        widget.setSizePolicy(size_policy("Ignored"), size_policy("Fixed"))
        label = QtGui.QLabel(schema.title(field))
        label.setWordWrap(True)  # a long title takes two lines rather than the field's width
        label.setObjectName(f"label:{field.prop}")
        label.setToolTip(field.doc)
        note = wrapped_label(NOTE_STYLE, f"note:{field.prop}")
        note.setVisible(False)
        self.labels[field.prop], self.notes[field.prop] = label, note
        section.form.addRow(label, widget)
        self.widgets.add(field.prop)
        show_start(widget)
        finished = getattr(widget, "editingFinished", None)
        if finished is not None:  # looked up afresh: see FieldWidgets
            finished.connect(lambda prop=field.prop: show_start(self.widgets[prop]))
        section.form.addRow(note)

    def _widget(self, field, value) -> QtGui.QWidget:
        if field.kind == "bool":
            widget = QtGui.QCheckBox()
            widget.setChecked(bool(value))
            widget.toggled.connect(self._schedule)
        elif field.kind == "choice":
            widget = QtGui.QComboBox()
            widget.addItems(list(field.choices))
            widget.setCurrentIndex(max(0, list(field.choices).index(value) if value in field.choices else 0))
            widget.currentIndexChanged.connect(self._schedule)
        elif field.kind == "string":
            widget = QtGui.QLineEdit(str(value))
            widget.textChanged.connect(self._schedule)
        elif field.kind == "int" and field.choices:  # a few values ([machine] axes: 4 or 3)
            widget = QtGui.QComboBox()
            widget.addItems(list(field.choices))
            widget.setCurrentIndex(max(0, list(field.choices).index(str(value)) if str(value) in field.choices else 0))
            widget.currentIndexChanged.connect(self._schedule)
        elif field.kind == "int":
            widget = QtGui.QSpinBox()
            widget.setRange(-2**31 + 1, 2**31 - 1)
            widget.setValue(int(value))
            widget.valueChanged.connect(self._schedule)
        elif field.kind in QUANTITY_UNITS and (widget := self._quantity_box(field, value)) is not None:
            pass
        else:  # other units (m/min, 1/min, mm/rev, %, s, ...) and plain numbers: the unit as a suffix
            widget = self._number_box(field, value)
        return widget

    def _number_box(self, field, value) -> NumberBox:
        """A number field with its unit as suffix; a mm-based unit (mm/rev, mm/s^2) in the user's schema."""
        widget = NumberBox()
        suffix, per_unit = units.display_unit(field.unit, FreeCAD.Units) if field.unit else ("", 1.0)
        if suffix:
            widget.setSuffix(f" {suffix}")
        if per_unit != 1.0:
            self._per_unit[field.prop] = per_unit
        widget.setValue(float(value) / per_unit)
        self._shown[field.prop] = (widget.text(), float(value))  # beyond 6 decimals: kept until edited
        widget.valueChanged.connect(self._schedule)
        return widget

    @staticmethod
    def _show_quantity(widget, value: float, unit: str) -> None:
        """Show `value` (in `unit`) in a quantity field, in the user's schema to the unit's resolution."""
        compat.set_spin_box_quantity(widget, units.field_quantity(value, unit, FreeCAD.Units))

    def _quantity_box(self, field, value):
        """FreeCAD's unit-aware spin box (any number: spur_cad's own messages judge it), or None without one."""
        unit = quantity_unit(field)
        widget = compat.quantity_spin_box(FreeCADGui.UiLoader(), unit, -BIG, BIG)
        if widget is None:
            return None
        self._show_quantity(widget, float(value), unit)
        # 0.20 rounds to the shown decimals: an untouched field keeps its exact value
        self._shown[field.prop] = (widget.text(), float(value))
        widget.lineEdit().textChanged.connect(self._schedule)
        return widget

    def _show_starts(self, group: str) -> None:
        """The fields of a group just opened show their text from its start (FreeCAD's quantity boxes set their
        text again when first shown)."""
        QtCore.QCoreApplication.processEvents()
        for field in schema.JOB_FIELDS:
            if field.group == group and field.prop in self.widgets:
                show_start(self.widgets[field.prop])

    # --- values and checks -----------------------------------------------------------------
    def _value(self, field):
        widget = self.widgets[field.prop]
        if field.kind == "bool":
            return widget.isChecked()
        if field.kind == "choice":
            return widget.currentText()
        if field.kind == "int" and field.choices:
            return int(widget.currentText())
        if field.kind == "string":
            return widget.text()
        if field.kind == "int":
            return int(widget.value())
        shown_text, exact = self._shown.get(field.prop, (None, 0.0))
        if widget.text() == shown_text:  # untouched since set: the exact value, not the rounded one shown
            return exact
        if isinstance(widget, QtGui.QDoubleSpinBox):
            return float(widget.value()) * self._per_unit.get(field.prop, 1.0)
        return compat.spin_box_value(widget, FreeCAD.Units, quantity_unit(field))

    def job_values(self) -> dict:
        """The job property values as the panel's widgets hold them."""
        return {field.prop: self._value(field) for field in schema.JOB_FIELDS}

    def set_value(self, prop: str, value) -> None:
        """Set a field as a user would (tests, macros)."""
        widget = self.widgets[prop]
        if isinstance(widget, QtGui.QCheckBox):
            widget.setChecked(bool(value))
        elif isinstance(widget, QtGui.QComboBox):
            widget.setCurrentIndex(widget.findText(str(value)))
        elif isinstance(widget, QtGui.QLineEdit):
            widget.setText(str(value))
        elif isinstance(widget, QtGui.QSpinBox):
            widget.setValue(value)
        elif isinstance(widget, QtGui.QDoubleSpinBox):
            widget.setValue(float(value) / self._per_unit.get(prop, 1.0))
            self._shown[prop] = (widget.text(), float(value))
        else:
            unit = quantity_unit(schema.field_by_prop(prop))
            self._show_quantity(widget, float(value), unit)
            self._shown[prop] = (widget.text(), float(value))
        show_start(self.widgets[prop])
        self.revalidate()  # at once (a user's typing waits for a pause: _schedule)

    def current_messages(self) -> dict[str, str]:
        """{group: the command line's message} of the problems shown now."""
        return {} if self.result is None else dict(self.result.messages)

    def _values(self) -> dict:
        """Gear and stock as the document holds them now (they may be edited while the panel is open), the job
        as the panel holds it."""
        values = document_values(self.job)
        return {"gear": values["gear"], "stock": values["stock"], "job": self.job_values()}

    def _schedule(self, *_):
        """A field changed: check the values once the user pauses (each check takes up to half a second)."""
        self._timer.start(REVALIDATE_DELAY_MS)

    def revalidate(self, *_):
        """Check the values; show the problem in its section and highlight its field; notes, limits, summary."""
        self._timer.stop()
        values = self._values()
        result = self.result = validate(values, self.job.Label, FreeCAD.Units)
        advice = {problem.group: problem.advice for problem in result.problems}
        for group, label in self.messages.items():
            label.setText(advice.get(group, ""))
            label.setVisible(group in advice)
        self._highlight(next((p.prop for p in result.problems if p.prop in self.widgets), None))
        two_stage = bool(values["job"].get("UseBottomTool"))
        fixed_limits = machine_setup(values["job"]).panel_limits_text  # the set-up's own: no computed notes
        notes = {**({} if fixed_limits else recommendation_notes(result.recommendations, two_stage, FreeCAD.Units)),
                 **unusual_value_notes(values["job"], FreeCAD.Units)}
        finishing_invalid = any(problem.group == "Finishing tool" for problem in result.problems)
        if finishing_invalid:  # the roughing limit depends on the finishing tool (A_p)
            notes.pop("BottomToolDiameter" if two_stage else "RoughingToolDiameter", None)
        for prop, label in self.notes.items():
            label.setText(notes.get(prop, ""))
            label.setVisible(prop in notes)
        for group, section in self.sections.items():
            section.set_summary(group_summary(group, values["job"], FreeCAD.Units))
        for section, switch in schema.SECTION_SWITCHES.items():
            enabled = self.widgets[switch.prop].isChecked()
            for field in schema.JOB_FIELDS:
                if field.section == section and field.key:
                    self.widgets[field.prop].setEnabled(enabled)
        setup = machine_setup(values["job"])
        for field in schema.JOB_FIELDS:
            if field.section in SETUP_SECTIONS:  # e.g. tabs and onion skin: 3-axis programs only
                self.widgets[field.prop].setEnabled(setup.reads_section(field.section))
        modified = bool(schema.modification_tables(values["gear"]))  # a gear without them: no section
        self.modifications_section.widget.setVisible(modified)
        self.modifications_section.set_summary(modification_summary(values["gear"]) if modified else "")
        if modified:
            self._show_modifications()
        self._show_summary(values, result, with_roughing_limit=not finishing_invalid)
        return result

    def _highlight(self, prop: str | None) -> None:
        if self.highlighted is not None and self.highlighted != prop:
            self.widgets[self.highlighted].setStyleSheet("")
        self.highlighted = prop
        if prop is not None:
            self.widgets[prop].setStyleSheet(HIGHLIGHT_STYLE)

    def _figures(self, signature: str):
        """(PlanFigures or None, where they come from) for the values whose signature is given."""
        if self._planned is not None and self._planned[0] == signature:
            return self._planned[1], "planned by this panel"
        if getattr(self.job, "PlannedValues", "") == signature and "ok" == self.job.Status:
            return _job_figures(self.job), "from the job's last recompute"
        return None, ""

    def _show_summary(self, values: dict, result, with_roughing_limit: bool) -> None:
        if result.ok:
            self.summary.setText("All values are valid.")
            self.summary.setStyleSheet("")
        else:
            first = result.problems[0]
            self.summary.setText(f"{len(result.problems)} problem: {first.advice}")
            self.summary.setStyleSheet(ERROR_STYLE)
        self.summary_limits.setText(machine_setup(values["job"]).panel_limits_text or limits_text(
            result.recommendations, with_roughing_limit, bool(values["job"].get("UseBottomTool")), FreeCAD.Units))
        figures, source = self._figures(values_signature(values)) if result.ok else (None, "")
        if figures is not None:
            self.summary_figures.setText(f"{figures_text(figures)}\n({source})")
            strategy = str(values["job"].get("FinishingStrategy", ""))
            rec, job = result.recommendations, values["job"]
            room = (rec.roughing_max_diameter_mm - float(job["RoughingToolDiameter"])
                    if rec is not None and job.get("UseRoughingTool") else None)
            self.summary_advice.setText(long_job_advice(figures, strategy, room))
        else:
            self.summary_figures.setText("Cycle time: press Plan (or OK) for the times, moves and program lines of "
                                         "these values." if result.ok else "")
            self.summary_advice.setText("")
        self.summary_advice.setVisible(bool(self.summary_advice.text()))
        self.plan_button.setEnabled(result.ok)

    # --- actions ---------------------------------------------------------------------------
    def plan(self) -> bool:
        """Plan the panel's values (not written to the job) and show their figures; False if invalid."""
        from spur_cad.errors import SpurCadError
        from spur_cad.pipeline import plan_cam

        result = self.revalidate()
        if not result.ok:
            self.show_problem()
            return False
        QtGui.QApplication.setOverrideCursor(compat.qt_enum(QtCore.Qt, "CursorShape", "WaitCursor"))
        try:
            plan = plan_cam(result.job)
            figures = plan_figures(result.job, plan)
        except SpurCadError as exc:
            self.summary.setText(sentence(exc, self.job.Label, FreeCAD.Units))
            self.summary.setStyleSheet(ERROR_STYLE)
            return False
        finally:
            QtGui.QApplication.restoreOverrideCursor()
        signature = values_signature(self._values())
        self._planned = (signature, figures)
        self.job.Proxy.cached_plan = (signature, result.job, plan)  # OK with these values plans no more
        self.revalidate()
        return True

    def show_problem(self) -> str | None:
        """Open the section of the highlighted field, scroll it into view and focus it; a problem of the gear or
        stock (no field here: their properties are edited on their objects) scrolls to its message at the
        top. Returns the property or the group shown."""
        problems = self.result.problems if self.result is not None else ()
        if not problems:
            return None
        prop = self.highlighted
        scroll = scroll_area_of(self.form)
        if prop is None:
            label = self.messages.get(problems[0].group, self.messages["Job"])
            if scroll is not None:
                scroll.ensureWidgetVisible(label, 20, 40)
            return problems[0].group
        self.sections[schema.field_by_prop(prop).group].set_open(True)
        QtCore.QCoreApplication.processEvents()
        if scroll is not None:
            scroll.ensureWidgetVisible(self.widgets[prop], 20, 40)
        self.widgets[prop].setFocus()
        return prop

    # --- task dialog interface ---------------------------------------------------------------
    def getStandardButtons(self):
        return compat.dialog_buttons(QtGui, "Ok", "Cancel")

    def accept(self) -> bool:
        """Apply the values and recompute; with a problem keep the panel open and show its field."""
        result = self.revalidate()
        if not result.ok:
            self.show_problem()
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


def _job_figures(job_obj):
    """PlanFigures from the job object's results (its last recompute)."""
    from spur_cad_workbench.summary import OperationFigures, PlanFigures

    found = {}
    for name, title in schema.OPERATION_TITLES.items():
        moves = int(getattr(job_obj, f"{title}Moves"))
        if moves:
            found[name] = OperationFigures(moves, float(getattr(job_obj, f"{title}Time")) * 60.0,
                                           float(getattr(job_obj, f"{title}TimeWithAcceleration")) * 60.0,
                                           int(getattr(job_obj, f"{title}ProgramLines")))
    return PlanFigures(found.get("roughing"), found.get("finishing"), tuple(job_obj.Warnings),
                       found.get("roughing_bottom"))


def show_job_panel(job_obj) -> JobTaskPanel:
    """Open the task panel for `job_obj` (closing any other task dialog) and return it."""
    if FreeCADGui.Control.activeDialog():
        FreeCADGui.Control.closeDialog()
    panel = JobTaskPanel(job_obj)
    compat.show_task_dialog(FreeCADGui.Control, panel, job_obj.Document.Name)
    job_obj.ViewObject.Proxy.panel = panel
    QtCore.QCoreApplication.processEvents()
    return panel
