"""Paths of the addon's resources (icons), found relative to this package; imports nothing else."""

from __future__ import annotations

from pathlib import Path

ICONS = Path(__file__).resolve().parents[2] / "resources" / "icons"


def icon_path(name: str) -> str:
    """Absolute path of the SVG icon `name` in resources/icons."""
    return str(ICONS / f"{name}.svg")


ERROR_BADGE_COLOUR = "#d00000"
ICON_SIZE_PX = 64


def error_icon(path: str):
    """The icon at `path` with a red "!" badge in its lower left corner: a spur_cad object whose last recompute
    failed (FreeCAD's own error mark needs an exception from `execute`, which 0.20 reports with a traceback)."""
    from PySide import QtCore, QtGui

    from spur_cad_workbench.compat import qt_enum

    pixmap = QtGui.QIcon(path).pixmap(ICON_SIZE_PX, ICON_SIZE_PX)
    badge = ICON_SIZE_PX // 2
    painter = QtGui.QPainter(pixmap)
    painter.setRenderHint(qt_enum(QtGui.QPainter, "RenderHint", "Antialiasing"))
    painter.setPen(qt_enum(QtCore.Qt, "PenStyle", "NoPen"))
    painter.setBrush(QtGui.QColor(ERROR_BADGE_COLOUR))
    painter.drawEllipse(0, ICON_SIZE_PX - badge, badge, badge)
    white = QtGui.QColor("white")
    stroke = badge // 8
    left, top = badge // 2 - stroke // 2, ICON_SIZE_PX - badge
    painter.fillRect(left, top + badge // 6, stroke, badge // 2, white)  # the "!": a bar and a dot
    painter.fillRect(left, top + badge * 3 // 4, stroke, stroke, white)
    painter.end()
    return QtGui.QIcon(pixmap)
