"""Paths of the addon's resources (icons), found relative to this package; imports nothing else."""

from __future__ import annotations

from pathlib import Path

ICONS = Path(__file__).resolve().parents[2] / "resources" / "icons"


def icon_path(name: str) -> str:
    """Absolute path of the SVG icon `name` in resources/icons."""
    return str(ICONS / f"{name}.svg")

