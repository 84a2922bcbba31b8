"""Restart after an alarm: the tail of an operation from a tooth space, level, station or pass on, behind a
safe approach (docs/shop-floor.md).

`roughing:space=5` starts roughing at tooth space 5 (numbered from 0, space k at A = -k * 360/z, as in
`spur-cad verify`), `roughing:space=5,level=2` at its third level; `finishing:station=40` starts a
station-wise finishing (perimeter) at station 40, `finishing:space=5` / `finishing:space=5,pass=12` a
space-wise one (generating) at a space or at a pass of it. The restarted toolpath is the full one's moves
from that point on, unchanged, after an approach: unclamp A (when the machine has clamp codes), a rapid to
the first move's X, Y and A (the unwound angle the full program has there) at the clearance height, and
the clamp again when the full program has A clamped there. The post puts the program's own start (tool,
spindle, coolant, a Z-only move to the clearance height) in front.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from spur_cad.cam.ir import MoveKind, Toolpath, ToolpathBuilder
from spur_cad.errors import SpurCadError, shown

UNITS: dict[str, str | None] = {"space": "space", "level": "station", "station": "station", "pass": None}
"""Restart units and the IR column that numbers them (`pass`: the rapids of a space, one per generating pass)."""


class RestartError(SpurCadError, ValueError):
    """A restart point that does not exist in the job's toolpaths; the message names it and what exists."""


@dataclass(frozen=True)
class RestartPoint:
    """Where to restart: the operation and up to two (unit, index) pairs, e.g. roughing, (("space", 5),)."""

    operation: str
    at: tuple[tuple[str, int], ...]

    def label(self) -> str:
        """'roughing_space5_level2': for the file name."""
        return "_".join([self.operation, *(f"{unit}{index}" for unit, index in self.at)])

    def text(self) -> str:
        return f"{self.operation}:" + ",".join(f"{unit}={index}" for unit, index in self.at)


_POINT = re.compile(r"(roughing_bottom|roughing|finishing):((?:space|station)=\d{1,7})(?:,((?:level|pass)=\d{1,7}))?")


def parse_restart(text: str) -> RestartPoint:
    """'roughing:space=5', 'roughing:space=5,level=2', 'finishing:station=40', 'finishing:space=3,pass=7'."""
    found = _POINT.fullmatch(text.strip())
    usage = ("expected roughing:space=K[,level=N], finishing:station=N or finishing:space=K[,pass=N] "
             "(numbered from 0)")
    if found is None:
        raise RestartError(f"--restart {text[:40]!r}: {usage}", field="restart")
    operation = found.group(1)
    at = tuple((unit, int(index)) for unit, index in (part.split("=") for part in found.groups()[1:] if part))
    units = tuple(unit for unit, _ in at)
    allowed = {"roughing": (("space",), ("space", "level")), "roughing_bottom": (("space",), ("space", "level")),
               "finishing": (("station",), ("space",), ("space", "pass"))}[operation]
    if units not in allowed:
        raise RestartError(f"--restart {shown(text)}: {usage}", field="restart")
    return RestartPoint(operation, at)


def restart_index(path: Toolpath, point: RestartPoint) -> int:
    """The index of the first move of the full toolpath the restarted one keeps."""
    candidates = np.ones(len(path), bool)
    where: list[str] = []
    for unit, index in point.at:
        if unit == "pass":
            rapids = np.flatnonzero(candidates & (path.kind == MoveKind.RAPID))
            available = len(rapids)
            if index >= available:
                raise RestartError(f"--restart {point.text()}: {' '.join(where)} has {available} passes "
                                   f"(0..{available - 1})", field="restart")
            candidates = np.arange(len(path)) >= rapids[index]
        else:
            column = getattr(path, UNITS[unit] or unit)  # None only for "pass", handled above
            present = np.unique(column[candidates & (column >= 0)])
            if index not in present:
                shown = f"{present.min()}..{present.max()}" if len(present) else "none"
                inside = f" in {' '.join(where)}" if where else ""
                raise RestartError(f"--restart {point.text()}: the {point.operation} toolpath has no {unit} {index}"
                                   f"{inside} ({unit}s {shown})", field="restart")
            candidates &= column == index
        where.append(f"{unit} {index}")
    return int(np.flatnonzero(candidates)[0])


def _clamped_before(path: Toolpath, start: int) -> bool:
    """Whether the full program has A clamped when it reaches move `start` (the last clamp marker before it)."""
    kinds = path.kind[:start]
    markers = np.flatnonzero((kinds == MoveKind.CLAMP_ROTARY) | (kinds == MoveKind.UNCLAMP_ROTARY))
    return bool(len(markers)) and path.kind[markers[-1]] == MoveKind.CLAMP_ROTARY


def run_reference_a_deg(path: Toolpath, start: int) -> float:
    """A of the first move of the run of one tooth space that move `start` belongs to (the post writes a run's
    A words relative to it: a restart program uses the same reference, so its A words round as the full
    program's do)."""
    space = path.space
    first = start
    while first > 0 and space[first - 1] == space[start]:
        first -= 1
    return float(path.a[first])


def restart_toolpath(path: Toolpath, point: RestartPoint, clearance_z_mm: float) -> tuple[Toolpath, int]:
    """The restarted toolpath (approach + the full one's moves from the restart point) and the index of the
    first kept move in the full toolpath."""
    start = restart_index(path, point)
    x, y, a = float(path.x[start]), float(path.y[start]), float(path.a[start])
    approach = ToolpathBuilder(path.operation, path.tool_number, path.spindle_rpm)
    approach.move(MoveKind.UNCLAMP_ROTARY, x, y, clearance_z_mm, a, space=-1)
    approach.move(MoveKind.RAPID, x, y, clearance_z_mm, a, space=-1)
    if _clamped_before(path, start):
        approach.move(MoveKind.CLAMP_ROTARY, x, y, clearance_z_mm, a, space=-1)
    head = approach.build()
    tail = {name: getattr(path, name)[start:] for name in ("kind", "x", "y", "z", "a", "feed", "inverse_time",
                                                           "space", "station", "feature")}
    arrays = {name: np.concatenate([getattr(head, name), values]) for name, values in tail.items()}
    return path.replace(**arrays), start
