"""Cutting tools and their cutting data (catalogue values: V_c, f_z), docs/method.md."""

from __future__ import annotations

import math
from dataclasses import dataclass

from spur_cad.cam.machine import Machine
from spur_cad.errors import SpurCadError
from spur_cad.keys import check_section, key

TOOL_KINDS = ("flat", "bull_nose", "ball")


class ToolError(SpurCadError, ValueError):
    """A tool that does not exist or does not suit the job; the message names the limit and value."""


@dataclass(frozen=True)
class Tool:
    """[tools.roughing] / [tools.finishing]: an end mill. `corner_radius_mm` is r_t of a bull-nose
    (0 for flat, D/2 for ball); flat width d = D - 2 r_t.

    A job file may give the roughing and finishing tools' `diameter_mm` and `corner_radius_mm` as "auto": the
    tools spur_cad suggests for the gear take their place (and the kind, where the table gives none): the
    finishing tool the strategy suggests (by generation r_t = rho and 95 % of the largest diameter, in 0.05 mm
    steps), then the largest flat roughing tool in 0.1 mm steps that fits the spaces and reaches their bottom."""

    diameter_mm: float = key(unit="mm", low=0.1, high=100.0, label="{Role}ToolDiameter", group="{Role} tool",
                             meaning='tool diameter D (a job file may say "auto" for the roughing and finishing '
                                     'tools: the size spur_cad suggests for the gear)')
    kind: str = key("flat", label="{Role}ToolKind", group="{Role} tool", names_from=lambda: TOOL_KINDS,
                    meaning="end mill shape: flat, bull_nose or ball")
    corner_radius_mm: float = key(0.0, unit="mm", low=0.0, high=50.0, label="{Role}CornerRadius", group="{Role} tool",
                                  meaning='corner radius r_t: 0 flat, in (0, D/2) bull-nose, D/2 (or 0) ball (a job '
                                          'file may say "auto", as for the diameter)')
    flutes: int = key(2, low=1, high=20, label="{Role}Flutes", group="{Role} tool", meaning="number of flutes")
    flute_length_mm: float = key(0.0, unit="mm", low=0.0, high=500.0, label="{Role}FluteLength", group="{Role} tool",
                                 meaning="flute length, 0: not given (not checked)")
    stick_out_mm: float = key(0.0, unit="mm", low=0.0, high=1000.0, label="{Role}StickOut", group="{Role} tool",
                              meaning="stick-out from the holder, 0: not given (not checked)")
    gauge_length_mm: float = key(0.0, unit="mm", low=0.0, high=1000.0, label="{Role}GaugeLength",
                                 group="{Role} tool",
                                 meaning="spindle nose to tool tip, 0: not given (the stick-out stands in for it "
                                         "in the spindle nose check)")
    tool_number: int = key(1, low=1, high=9999, label="{Role}ToolNumber", group="{Role} tool",
                           meaning="tool number in the machine's magazine (T word); a [tools.finishing] "
                                   "without it takes 2; two different tools may not share one")
    cutting_speed_m_min: float = key(100.0, unit="m/min", low=1.0, high=3000.0, label="{Role}CuttingSpeed",
                                     group="{Role} tool", meaning="cutting speed V_c (catalogue value)")
    feed_per_tooth_mm: float = key(0.02, unit="mm", low=0.0005, high=2.0, label="{Role}FeedPerTooth",
                                   group="{Role} tool", meaning="feed per tooth f_z (catalogue value)")

    def validate(self, role: str) -> None:
        """Raise ToolError for a tool that cannot exist; `role` names it in the message."""
        check_section(self, f"tools.{role}", ToolError)
        if self.kind not in TOOL_KINDS:
            raise ToolError(f"{role} tool kind '{self.kind}' is unknown (use one of {', '.join(TOOL_KINDS)})",
                            field="kind")
        r = self.corner_radius_mm
        if self.kind == "flat" and r != 0.0:
            raise ToolError(f"{role} tool is flat but corner_radius_mm = {r:g}; use kind = \"bull_nose\"",
                            field="corner_radius_mm")
        if self.kind == "bull_nose" and not 0.0 < r < self.diameter_mm / 2.0:
            raise ToolError(f"{role} bull-nose corner_radius_mm = {r:g} must be in (0, {self.diameter_mm / 2:g})",
                            field="corner_radius_mm")
        if self.kind == "ball" and abs(r - self.diameter_mm / 2.0) > 1e-9 and r != 0.0:
            raise ToolError(f"{role} ball tool corner_radius_mm = {r:g} must equal diameter / 2 (or be omitted)",
                            field="corner_radius_mm")

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
