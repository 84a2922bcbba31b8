"""The finishing-strategy protocol: what a strategy is and what it gives back (docs/architecture.md).

A strategy has a name, a one-line description, a frozen parameters dataclass whose fields are
keys of the job file's [finishing] section, and a pure `generate` function that turns the gear,
tool and machine into a toolpath (IR) and a typed result. Register it in
`spur_cad.cam.strategies.REGISTRY`; the job file, CLI, workbench, simulation and report find it
there.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from spur_cad.cam.allowances import BottomAllowance, plunge_allowance
from spur_cad.cam.contacts import SpacePoses
from spur_cad.cam.ir import Operation, Toolpath, ToolpathBuilder
from spur_cad.cam.machine import Machine, MachineError
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.geometry.spec import GearSpec
from spur_cad.keys import check_section, key


class StrategyFacts(Protocol):
    """A strategy's own typed facts for summary.json's `finishing` section (its fields, in order, after
    `strategy`) and the report's sentence about them."""

    def report_text(self) -> str:
        """One or two plain sentences for the report (the report escapes them)."""
        ...


@dataclass(frozen=True)
class StationFacts:
    """Facts of strategies that finish by contacts at X stations (perimeter, along_x)."""

    stations: int
    station_step_mm: float
    points_per_flank: int

    def report_text(self, strategy: str = "") -> str:
        return (f"Finishing: {strategy}, {self.stations} stations ({self.station_step_mm:.4f} mm apart), "
                f"{self.points_per_flank} contact points per flank.")


@dataclass(frozen=True)
class FinishingResult:
    """What a finishing strategy planned, besides its toolpath (typed facts for summary and report)."""

    strategy: str
    params: Any  # the strategy's parameters dataclass, as used
    poses: SpacePoses  # transverse contact poses of one tooth space (report figure)
    stations: int  # transverse stations across the face width (1 when the strategy has none)
    station_step_mm: float
    station_x_mm: np.ndarray  # X of the stations, where the simulation puts extra rows (empty: none)
    passes_per_space: int = 0  # straight passes per tooth space (strategies with A clamped per pass)
    passes: tuple = ()  # the strategy's passes of one space, typed by the strategy (generating: GeneratingPass)
    facts: Any = None  # the strategy's own typed facts (StrategyFacts; None: StationFacts of the stations)
    tool_advice: Any = None  # the strategy's typed tool advice (summary `tools.<strategy>_advice`), or None

    @property
    def points_per_flank(self) -> int:
        return self.poses.points_per_flank

    def describe(self) -> str:
        """What was planned, in a few words (program header, report)."""
        if self.passes_per_space:
            return f"{self.passes_per_space} straight passes per space with A clamped"
        return f"{self.stations} stations, {self.points_per_flank} contacts per flank"

    @property
    def strategy_facts(self) -> Any:
        """The strategy's own facts: its typed `facts`, or the stations of a contact strategy."""
        if self.facts is not None:
            return self.facts
        return StationFacts(self.stations, self.station_step_mm, self.points_per_flank)

    def report_text(self) -> str:
        facts = self.strategy_facts
        return facts.report_text(self.strategy) if isinstance(facts, StationFacts) else facts.report_text()


@dataclass(frozen=True)
class TargetScallopParams:
    """The [finishing] key every strategy reads: the target scallop (its range is checked here, once)."""

    target_scallop_mm: float = key(0.005, unit="mm", low=0.0001, high=0.1, label="TargetScallop",
                                   group="Finishing strategy", meaning="target scallop height")

    def validate(self) -> None:
        check_section(self, "finishing", MachineError)


@dataclass(frozen=True)
class ScallopParams(TargetScallopParams):
    """The [finishing] keys of strategies with X stations: the target scallop and the X step (0: derived)."""

    step_over_mm: float = key(0.0, unit="mm", low=0.0, high=2000.0, label="FinishingStepOver",
                              group="Finishing strategy", meaning="X step between stations, 0: from the target scallop")


class FinishingStrategy(Protocol):
    """A finishing strategy (see the module docstring)."""

    name: str
    description: str
    params_type: type  # frozen dataclass; its `key(...)` fields are [finishing] keys (job file, workbench, docs)
    simultaneous_rotary: bool  # feed moves turn A (needs [machine] rotary_simultaneous = true)
    helical: bool  # finishes helical gears too (else spur gears only)

    def estimate_moves(self, spec: GearSpec, tool: Tool, params: Any) -> int:
        """How many IR moves `generate` would make, counted cheaply beforehand (the plan refuses
        work beyond its limits before generating)."""
        ...

    def largest_tool(self, recommendations: Any) -> tuple[str, float]:
        """The largest finishing tool this strategy takes on the gear, from its ToolRecommendations: the
        figure's name there (or how it is made of them) and its diameter (mm); 0 when none fits."""
        ...

    def suggested_tool(self, spec: GearSpec, recommendations: Any, target_scallop_mm: float,
                       blank_radius_mm: float) -> tuple[float, float] | None:
        """(corner radius, flat width D - 2 r) in mm of a finishing tool a new job starts with (the workbench
        suggests it), within this strategy's limits; None when no tool fits."""
        ...

    def bottom_allowance(self, tool: Tool | None, recommendations: Any) -> BottomAllowance:
        """What roughing may leave above the root for this strategy to take with the finishing `tool` (None: the
        largest it takes, from the finishing limits of `recommendations`): its size and the rule in words. It
        sets the largest roughing tool and the roughing reach check (recommend_tools)."""
        ...

    def check_tool(self, spec: GearSpec, tool: Tool) -> None:
        """ToolError (naming the tool key) when the tool's shape cannot do this strategy on this gear;
        cheap (the plan's and the workbench's checks run it before generating)."""
        ...

    def generate(self, spec: GearSpec, tool: Tool, machine: Machine, params: Any,
                 blank_radius_mm: float) -> tuple[Toolpath, FinishingResult]:
        """The finishing operation as IR plus its facts (pure function)."""
        ...


def contact_largest_tool(recommendations: Any) -> tuple[str, float]:
    """The largest tool of the strategies that place the corner on flank contacts (perimeter, along_x): the
    root arc's flat plus twice the fillet's smallest curvature radius."""
    rec = recommendations
    return ("finishing_max_flat_width_mm + 2 finishing_max_corner_radius_mm",
            rec.finishing_max_flat_width_mm + 2.0 * rec.finishing_max_corner_radius_mm)


def contact_bottom_allowance(tool: Tool | None, recommendations: Any) -> BottomAllowance:
    """The strategies whose flat bottom plunges at the root (perimeter, along_x): the plunge allowance A_p = 0.5 x
    the tool's flat width (without a tool: the largest flat allowed, the root arc)."""
    if tool is None:
        return plunge_allowance(recommendations.finishing_max_flat_width_mm, largest=True)
    return plunge_allowance(tool.flat_width_mm)


def floor_to_step(value: float, step: float) -> float:
    """`value` rounded down to a multiple of `step` (a catalogue-like size)."""
    return math.floor(value / step + 1e-9) * step


def contact_suggested_tool(recommendations: Any) -> tuple[float, float] | None:
    """A bull-nose tool for the contact strategies: corner radius at 90 % of the fillet's smallest curvature
    radius (0.05 mm steps, at most 1 mm), flat width at 90 % of the root arc; None when either is 0."""
    rec = recommendations
    corner = min(floor_to_step(0.9 * rec.finishing_max_corner_radius_mm, 0.05), 1.0)
    flat = floor_to_step(0.9 * rec.finishing_max_flat_width_mm, 0.05)
    return (corner, flat) if corner > 0.0 and flat > 0.0 else None


class ContactStrategy:
    """What the strategies placing the tool's corner on transverse flank contacts share (perimeter, along_x):
    spur gears only, their largest and suggested tools, and the plunge allowance at the root."""

    helical = False  # transverse contacts of a spur gear

    def bottom_allowance(self, tool: Tool | None, recommendations: Any) -> BottomAllowance:
        return contact_bottom_allowance(tool, recommendations)

    def largest_tool(self, recommendations: Any) -> tuple[str, float]:
        return contact_largest_tool(recommendations)

    def suggested_tool(self, spec: GearSpec, recommendations: Any, target_scallop_mm: float,
                       blank_radius_mm: float) -> tuple[float, float] | None:
        return contact_suggested_tool(recommendations)


def check_corner_contacts_tool(tool: Tool, strategy: str) -> None:
    """Strategies that place the tool's corner on spaced flank contacts (perimeter, along_x) need a round
    corner: their contact spacing and X stations bound the cusps by the corner radius, and a sharp corner
    (a flat end mill) leaves cusps thick in proportion to the spacing that no such bound covers."""
    if tool.effective_corner_radius_mm <= 0.0:
        raise ToolError(f"finishing strategy {strategy}: a flat end mill (corner radius 0) cannot finish the flanks "
                        "by contacts: the scallop between contacts and stations is bounded by the corner radius, and "
                        "a sharp corner gives no bound; use a bull_nose or ball tool, or [finishing] strategy = "
                        "\"generating\", which takes flat end mills up to "
                        "tools.finishing_flat_end_mill_max_diameter_mm",
                        field="kind", section="tools.finishing")


def check_flat_fits_root_arc(spec: GearSpec, tool: Tool, strategy: str = "perimeter or along_x") -> None:
    """Strategies that sweep the root arc with the flat bottom (perimeter, along_x): the corner must be round
    (`check_corner_contacts_tool`) and the flat must fit in the root arc, D - 2 r_t <= 2 v r_f (summary
    `tools.finishing_max_flat_width_mm`)."""
    check_corner_contacts_tool(tool, strategy)
    profile = spec.tooth_space_profile()
    max_flat = 2.0 * profile.root_arc_half_angle_rad * spec.root_radius_mm
    if tool.flat_width_mm > max_flat + 1e-9:
        raise ToolError(f"finishing tool flat width {tool.flat_width_mm:.4f} mm (D - 2 r_t) exceeds "
                        f"finishing_max_flat_width_mm = {max_flat:.4f} mm (root arc length 2 v r_f)",
                        field="diameter_mm", section="tools.finishing")


def finishing_builder(tool: Tool, machine: Machine, params: Any) -> ToolpathBuilder:
    """Validate a strategy's inputs and start its toolpath (every strategy's first step)."""
    params.validate()
    machine.validate()
    tool.validate("finishing")
    return ToolpathBuilder(Operation.FINISHING, tool.tool_number, tool.spindle_rpm(machine))


def params_from_section(strategy: FinishingStrategy, section: object, **overrides: Any) -> Any:
    """The strategy's parameters taken by name from the [finishing] section (fields it lacks keep defaults)."""
    values = {f.name: getattr(section, f.name) for f in dataclasses.fields(strategy.params_type)
              if hasattr(section, f.name)}
    return strategy.params_type(**{**values, **overrides})
