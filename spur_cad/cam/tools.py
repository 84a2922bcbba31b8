"""Cutting tools and their cutting data (catalogue values: V_c, f_z), METHOD.md 3 and 6."""

from __future__ import annotations

import math
from dataclasses import dataclass

from spur_cad.cam.machine import Machine
from spur_cad.errors import SpurCadError

TOOL_KINDS = ("flat", "bull_nose", "ball")


class ToolError(SpurCadError, ValueError):
    """A tool that does not exist or does not suit the job; the message names the limit and value."""


@dataclass(frozen=True)
class Tool:
    """[tools.roughing] / [tools.finishing]: an end mill. `corner_radius_mm` is r_t of a bull-nose
    (0 for flat, D/2 for ball); flat width d = D - 2 r_t."""

    diameter_mm: float
    kind: str = "flat"
    corner_radius_mm: float = 0.0
    flutes: int = 2
    flute_length_mm: float = 0.0  # 0: not given (no check)
    stick_out_mm: float = 0.0  # 0: not given (no check)
    tool_number: int = 1
    cutting_speed_m_min: float = 100.0
    feed_per_tooth_mm: float = 0.02

    def validate(self, role: str) -> None:
        """Raise ToolError for a tool that cannot exist; `role` names it in the message."""
        if self.kind not in TOOL_KINDS:
            raise ToolError(f"{role} tool kind '{self.kind}' is unknown (use one of {', '.join(TOOL_KINDS)})")
        if not (math.isfinite(self.diameter_mm) and self.diameter_mm > 0.0):
            raise ToolError(f"{role} tool diameter_mm = {self.diameter_mm:g} must be positive")
        r = self.corner_radius_mm
        if self.kind == "flat" and r != 0.0:
            raise ToolError(f"{role} tool is flat but corner_radius_mm = {r:g}; use kind = \"bull_nose\"")
        if self.kind == "bull_nose" and not 0.0 < r < self.diameter_mm / 2.0:
            raise ToolError(f"{role} bull-nose corner_radius_mm = {r:g} must be in (0, {self.diameter_mm / 2:g})")
        if self.kind == "ball" and abs(r - self.diameter_mm / 2.0) > 1e-9 and r != 0.0:
            raise ToolError(f"{role} ball tool corner_radius_mm = {r:g} must equal diameter / 2 (or be omitted)")
        for name in ("flutes", "tool_number"):
            if getattr(self, name) < 1:
                raise ToolError(f"{role} tool {name} = {getattr(self, name)} must be at least 1")
        for name in ("cutting_speed_m_min", "feed_per_tooth_mm"):
            if not getattr(self, name) > 0.0:
                raise ToolError(f"{role} tool {name} = {getattr(self, name):g} must be positive")
        for name in ("flute_length_mm", "stick_out_mm"):
            if getattr(self, name) < 0.0:
                raise ToolError(f"{role} tool {name} = {getattr(self, name):g} must not be negative")

    @property
    def effective_corner_radius_mm(self) -> float:
        """r_t (a ball's is D/2 even when the file omits it)."""
        return self.diameter_mm / 2.0 if self.kind == "ball" else self.corner_radius_mm

    @property
    def flat_width_mm(self) -> float:
        """d = D - 2 r_t: the flat part of the tool's bottom."""
        return self.diameter_mm - 2.0 * self.effective_corner_radius_mm

    def spindle_rpm(self, machine: Machine) -> float:
        """n = 1000 V_c / (pi D), capped by the spindle's maximum."""
        return min(1000.0 * self.cutting_speed_m_min / (math.pi * self.diameter_mm), machine.max_spindle_rpm)

    def feed_mm_min(self, machine: Machine) -> float:
        """F = n * flutes * f_z, capped by the machine's maximum linear feed."""
        return min(self.spindle_rpm(machine) * self.flutes * self.feed_per_tooth_mm, machine.max_feed_mm_min)
