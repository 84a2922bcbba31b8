"""Long work in FreeCAD's GUI (export, simulate, verify, restart planning): FreeCAD's progress indicator in
the status bar, a wait cursor, and Qt's events processed between the stages so the window repaints and its
timers fire. Outside the GUI (freecadcmd, macros run headless) it does nothing."""

from __future__ import annotations

from typing import Any

import FreeCAD

from spur_cad_workbench import compat

TICKS_PER_STAGE = 20
"""Steps of FreeCAD's indicator per stage (the indicator counts whole steps; stages report fractions)."""


class WorkProgress:
    """Context manager over one long piece of work made of `stages` (names in order, as `run_job`'s progress
    callback names them). `advance(stage, fraction)` moves the indicator, `events()` lets Qt process events."""

    def __init__(self, title: str, stages: tuple[str, ...]):
        self.title = title
        self.stages = stages
        self._indicator = None
        self._ticks_done = 0
        self._qt: tuple[Any, Any] | None = None

    def __enter__(self) -> WorkProgress:
        if not FreeCAD.GuiUp:
            return self
        from PySide import QtCore, QtGui

        self._qt = (QtCore, QtGui)
        QtGui.QApplication.setOverrideCursor(compat.qt_enum(QtCore.Qt, "CursorShape", "WaitCursor"))
        self._indicator = compat.progress_indicator(FreeCAD)
        if self._indicator is not None:
            self._indicator.start(self.title, len(self.stages) * TICKS_PER_STAGE)
        self._show(self.stages[0] if self.stages else "")
        self.events()
        return self

    def __exit__(self, *exc_info) -> None:
        if self._qt is None:
            return
        if self._indicator is not None:
            self._indicator.stop()
        self._qt[1].QApplication.restoreOverrideCursor()
        self._show("")  # no events processed after the work: its results are shown by the caller
        self._qt = None

    def advance(self, stage: str, fraction: float) -> None:
        """`stage` is `fraction` (0..1) done: the indicator moves to there and events are processed."""
        if self._qt is None or stage not in self.stages:
            return
        target = self.stages.index(stage) * TICKS_PER_STAGE + round(min(max(fraction, 0.0), 1.0) * TICKS_PER_STAGE)
        while self._ticks_done < target and self._indicator is not None:
            self._indicator.next()
            self._ticks_done += 1
        self._show(stage)
        self.events()

    def stage_done(self, stage: str) -> None:
        """`stage` is finished (for work whose stages report no fractions)."""
        self.advance(stage, 1.0)

    def events(self) -> None:
        """Let Qt process pending events (repaints, timers) between two steps of the work."""
        if self._qt is not None:
            self._qt[1].QApplication.processEvents()

    def _show(self, stage: str) -> None:
        """The title and current stage in the main window's status bar (empty: cleared)."""
        if self._qt is None:
            return
        import FreeCADGui

        text = f"{self.title}: {stage}..." if stage else ""
        FreeCADGui.getMainWindow().statusBar().showMessage(text)
