"""The Restart program dialog: the operation, then the restart point chosen from what the job's toolpaths have
(tooth space and level for roughing; station, or space and pass, for finishing), with ranges read from the
job's plan so that a point that does not exist cannot be chosen. Numbering as in the programs' restart
comments, the verify report and docs/shop-floor.md: from 0, tooth space k at A = -k x 360/z.

`RestartDialog` builds the dialog without showing it: a test sets its widgets and calls `point()`; the GUI
command runs it modally (compat.exec_dialog). The choices' ranges (`OperationChoices`) need no Qt.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from spur_cad_workbench import compat

if TYPE_CHECKING:
    from spur_cad.cam.ir import Toolpath

OPERATION_TITLES = {"roughing": "Roughing", "roughing_bottom": "Roughing, bottom tool", "finishing": "Finishing"}
SECOND_UNIT = {"roughing": "level", "roughing_bottom": "level", "finishing": "pass"}


@dataclass(frozen=True)
class OperationChoices:
    """What one operation's toolpath offers as restart points: by station (perimeter finishing) or by tooth
    space, then optionally by level (roughing) or pass (generating finishing) within the space."""

    operation: str
    toolpath: Toolpath

    @property
    def by_station(self) -> bool:
        """Whether the operation restarts at a station (finishing station by station) rather than a space."""
        return self.operation == "finishing" and bool((self.toolpath.station >= 0).any())

    def spaces(self) -> list[int]:
        """The tooth spaces the toolpath cuts (numbered from 0)."""
        space = self.toolpath.space
        return [int(k) for k in np.unique(space[space >= 0])]

    def stations(self) -> list[int]:
        """The finishing stations the toolpath has (numbered from 0)."""
        station = self.toolpath.station
        return [int(n) for n in np.unique(station[station >= 0])]

    def within_space(self, space: int) -> list[int]:
        """The levels (roughing) or passes (generating finishing) of tooth space `space` (numbered from 0)."""
        from spur_cad.cam.ir import MoveKind

        path = self.toolpath
        in_space = path.space == space
        if SECOND_UNIT[self.operation] == "pass":  # a pass starts at each rapid of the space (cam.restart)
            return list(range(int((in_space & (path.kind == MoveKind.RAPID)).sum())))
        return [int(n) for n in np.unique(path.station[in_space & (path.station >= 0)])]


def operation_choices(plan) -> list[OperationChoices]:
    """The operations of a CAM plan that can be restarted, in cutting order."""
    return [OperationChoices(name, getattr(plan, name).toolpath) for name in OPERATION_TITLES
            if getattr(plan, name, None) is not None]


def point_in_words(point) -> str:
    """'roughing, space 5, level 2': a RestartPoint as the dialog names it."""
    return ", ".join([OPERATION_TITLES[point.operation].lower(), *(f"{unit} {index}" for unit, index in point.at)])


def reworded(message: str, point) -> str:
    """A restart error for `point` in the dialog's words: spur_cad's restart messages start with the CLI's
    '--restart <point text>: ', which becomes 'restart at <point in words>: '."""
    prefix = f"--restart {point.text()}: "
    if message.startswith(prefix):
        return f"restart at {point_in_words(point)}: {message[len(prefix):]}"
    return message


class RestartDialog:
    """The dialog (`self.dialog`, a QDialog not yet shown) for a job and its plan; `point()` is the choice."""

    def __init__(self, job, plan, parent=None):
        widgets = compat.qt_widgets()
        self.job = job
        self.teeth = job.gear.teeth
        self.choices = operation_choices(plan)
        if not self.choices:
            from spur_cad.errors import SpurCadError

            raise SpurCadError("the job has no roughing or finishing toolpath to restart (give the job a roughing or "
                               "finishing tool)")
        self.dialog = widgets.QDialog(parent)
        self.dialog.setObjectName("SpurCadRestartDialog")
        self.dialog.setWindowTitle("Restart program")
        form = widgets.QFormLayout()
        self.operation = widgets.QComboBox()
        self.operation.setObjectName("operation")
        for choice in self.choices:
            self.operation.addItem(OPERATION_TITLES[choice.operation], choice.operation)
        form.addRow("Operation", self.operation)
        self.space = widgets.QComboBox()
        self.space.setObjectName("space")
        self.station = widgets.QSpinBox()
        self.station.setObjectName("station")
        point_row = widgets.QHBoxLayout()  # one row: the space or the station, whichever the operation uses
        point_row.addWidget(self.space, 1)
        point_row.addWidget(self.station, 1)
        self.point_label = widgets.QLabel()
        form.addRow(self.point_label, point_row)
        self.use_second = widgets.QCheckBox()
        self.use_second.setObjectName("use_second")
        self.second = widgets.QSpinBox()
        self.second.setObjectName("second")
        row = widgets.QHBoxLayout()
        row.addWidget(self.use_second)
        row.addWidget(self.second, 1)
        self.second_label = widgets.QLabel()
        form.addRow(self.second_label, row)
        self.note = widgets.QLabel()
        self.note.setWordWrap(True)
        buttons = widgets.QDialogButtonBox()
        buttons.addButton("Save as...", compat.qt_enum(widgets.QDialogButtonBox, "ButtonRole", "AcceptRole"))
        buttons.addButton(compat.qt_enum(widgets.QDialogButtonBox, "StandardButton", "Cancel"))
        buttons.accepted.connect(self.dialog.accept)
        buttons.rejected.connect(self.dialog.reject)
        layout = widgets.QVBoxLayout(self.dialog)
        layout.addLayout(form)
        layout.addWidget(self.note)
        layout.addWidget(buttons)
        self.operation.currentIndexChanged.connect(self._operation_changed)
        self.space.currentIndexChanged.connect(self._space_changed)
        self.use_second.toggled.connect(self.second.setEnabled)
        self._operation_changed()

    def current(self) -> OperationChoices:
        """The chosen operation's choices."""
        return self.choices[max(self.operation.currentIndex(), 0)]

    def set_operation(self, operation: str) -> None:
        """Choose `operation` ("roughing", "roughing_bottom", "finishing"), as picking it in the combo box; one
        the job does not have is a ValueError and changes nothing."""
        self._choose(self.operation, operation, "operation")

    def set_space(self, space: int) -> None:
        """Choose tooth space `space` (numbered from 0), as picking it in the combo box; a space the operation
        does not cut is a ValueError and changes nothing."""
        self._choose(self.space, space, "tooth space")

    @staticmethod
    def _choose(combo, value, what: str) -> None:
        index = combo.findData(value)
        if index < 0:
            offered = [combo.itemData(i) for i in range(combo.count())]
            raise ValueError(f"no {what} {value!r} to choose (the choices: {offered[0]!r} to {offered[-1]!r})")
        combo.setCurrentIndex(index)

    def point(self):
        """The chosen restart point (spur_cad.cam.restart.RestartPoint)."""
        from spur_cad.cam.restart import RestartPoint

        choice = self.current()
        if choice.by_station:
            return RestartPoint(choice.operation, (("station", self.station.value()),))
        at = (("space", int(self.space.currentData())),)
        if self.use_second.isChecked():
            at += ((SECOND_UNIT[choice.operation], self.second.value()),)
        return RestartPoint(choice.operation, at)

    def file_name(self) -> str:
        """The chosen point's program name as `spur-cad run --restart` writes it (roughing_space5.ngc: the job's
        post dialect's extension)."""
        from spur_cad.post import dialect

        return f"{self.point().label()}.{dialect(self.job.post.dialect).extension}"

    def _operation_changed(self, *_) -> None:
        """Show the chosen operation's kind of point, with its ranges."""
        choice = self.current()
        self.point_label.setText("Station" if choice.by_station else "Tooth space")
        self.space.setVisible(not choice.by_station)
        self.station.setVisible(choice.by_station)
        for widget in (self.second_label, self.use_second, self.second):
            widget.setVisible(not choice.by_station)
        if choice.by_station:
            stations = choice.stations()
            self.station.setRange(stations[0], stations[-1])
            self.station.setSuffix(f"   (of {stations[0]} to {stations[-1]})")
            self.note.setText(f"Finishing station by station: {len(stations)} stations along the gear axis, "
                              "numbered from 0.")
            return
        self.space.blockSignals(True)
        self.space.clear()
        for space in choice.spaces():
            self.space.addItem(f"space {space} of 0 to {self.teeth - 1}   (A {-space * 360.0 / self.teeth + 0.0:.3f}°)",
                               space)
        self.space.blockSignals(False)
        unit = SECOND_UNIT[choice.operation]
        self.second_label.setText(f"From {unit}")
        self.use_second.setToolTip(f"Restart at a {unit} of the space instead of the space's start")
        self.use_second.setChecked(False)
        self.second.setEnabled(False)
        self.note.setText(f"{self.teeth} tooth spaces, numbered from 0 as in the verify report and the restart "
                          f"programs' comments: space k is at A = -k x {360.0 / self.teeth:.3f}°.")
        self._space_changed()

    def _space_changed(self, *_) -> None:
        """The level or pass spin box limited to what the chosen space has."""
        choice = self.current()
        if choice.by_station or self.space.currentIndex() < 0:
            return
        values = choice.within_space(int(self.space.currentData()))
        low, high = (values[0], values[-1]) if values else (0, 0)
        self.second.setRange(low, high)
        self.second.setSuffix(f"   (of {low} to {high})")
