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
from typing import TYPE_CHECKING, Any, ClassVar, Protocol

import numpy as np

from spur_cad.cam.allowances import BottomAllowance, plunge_allowance
from spur_cad.cam.contacts import SpacePoses
from spur_cad.cam.estimate import Estimate, estimate
from spur_cad.cam.ir import Operation, Toolpath, ToolpathBuilder
from spur_cad.cam.machine import Machine, MachineError
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.geometry.modifications import FlankModifications
from spur_cad.geometry.spec import GearSpec
from spur_cad.keys import check_section, key

if TYPE_CHECKING:  # annotations only: computed by cam.recommend, above the strategies
    from spur_cad.cam.allowances import ToolRecommendations


class StrategyFacts(Protocol):
    """A strategy's own typed facts for summary.json's `finishing` section (a dataclass: its fields, in order,
    after `strategy`) and the report's sentence about them."""

    __dataclass_fields__: ClassVar[dict[str, Any]]

    def report_text(self) -> str:
        """One or two plain sentences for the report (the report escapes them)."""
        ...


class ToolAdvice(Protocol):
    """A strategy's typed tool advice: a dataclass whose fields are summary.json's `tools.<strategy>_advice` and
    the rows of the report's advice table (None values left out)."""

    __dataclass_fields__: ClassVar[dict[str, Any]]


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
    params: TargetScallopParams | None  # the strategy's parameters dataclass, as used (None: the 3-axis finishing)
    poses: SpacePoses | None  # transverse contact poses of one tooth space (report figure; None: the 3-axis finishing)
    stations: int  # transverse stations across the face width (1 when the strategy has none)
    station_step_mm: float
    station_x_mm: np.ndarray  # X of the stations, where the simulation puts extra rows (empty: none)
    passes_per_space: int = 0  # straight passes per tooth space (strategies with A clamped per pass)
    passes: tuple[Any, ...] = ()  # one space's passes, typed by the strategy (generating: GeneratingPass)
    facts: StrategyFacts | None = None  # the strategy's own typed facts (None: StationFacts of the stations)
    tool_advice: ToolAdvice | None = None  # the strategy's typed tool advice (summary `tools.<strategy>_advice`)
    lying_flat: bool = False  # made by a strategy that is `lying_flat` (the 3-axis finishing)

    @property
    def points_per_flank(self) -> int:
        return self.poses.points_per_flank if self.poses is not None else 0

    def describe(self) -> str:
        """What was planned, in a few words (program header, report)."""
        if self.passes_per_space:
            return f"{self.passes_per_space} straight passes per space with A clamped"
        return f"{self.stations} stations, {self.points_per_flank} contacts per flank"

    @property
    def strategy_facts(self) -> StrategyFacts:
        """The strategy's own facts: its typed `facts`, or the stations of a contact strategy."""
        if self.facts is not None:
            return self.facts
        return StationFacts(self.stations, self.station_step_mm, self.points_per_flank)

    def report_text(self) -> str:
        facts = self.strategy_facts
        return facts.report_text(self.strategy) if isinstance(facts, StationFacts) else facts.report_text()


def target_scallop_key() -> Any:
    """The [finishing] key every strategy reads, declared here once (the parameters below and the default
    registry's section, strategies.FinishingParams, take their field from here)."""
    return key(0.005, unit="mm", low=0.0001, high=0.1, label="TargetScallop", group="Finishing strategy",
               meaning="target scallop height")


def step_over_key() -> Any:
    """The [finishing] key of the strategies with X stations, declared here once."""
    return key(0.0, unit="mm", low=0.0, high=2000.0, label="FinishingStepOver", group="Finishing strategy",
               meaning="X step between stations, 0: from the target scallop")


@dataclass(frozen=True)
class TargetScallopParams:
    """The [finishing] key every strategy reads: the target scallop (its range is checked here, once)."""

    target_scallop_mm: float = target_scallop_key()

    def __post_init__(self) -> None:
        """Every key in its range (MachineError naming it): checked when made, trusted by the strategy's functions."""
        check_section(self, "finishing", MachineError)


@dataclass(frozen=True)
class ScallopParams(TargetScallopParams):
    """The [finishing] keys of strategies with X stations: the target scallop and the X step (0: derived)."""

    step_over_mm: float = step_over_key()


class FinishingStrategy(Protocol):
    """A finishing strategy (see the module docstring): what the plan, the job loader, the workbench, spur-cad
    correct and the report call, and the capabilities they ask it about. A strategy declares each capability as
    a class attribute; no other module keeps a list of strategy names."""

    name: str
    description: str
    simultaneous_rotary: bool  # feed moves turn A (needs [machine] rotary_simultaneous = true)
    helical: bool  # finishes helical gears too (else spur gears only)
    follows_modifications: bool  # `generate` cuts flank modifications ([gear.modifications]); else they are refused
    corrects_slopes: bool  # spur-cad correct may move its flank passes for profile and helix slopes (GeneratingPass)
    lying_flat: bool  # it cuts the gear lying flat ([machine] axes = 3); else on the rotary table

    @property
    def params_type(self) -> type[TargetScallopParams]:
        """Its frozen parameters dataclass; the `key(...)` fields are [finishing] keys (a class attribute)."""
        ...

    def estimate_moves(self, spec: GearSpec, tool: Tool, params: Any) -> int:
        """How many IR moves `generate` would make, counted cheaply beforehand (the plan refuses
        work beyond its limits before generating)."""
        ...

    def estimate(self, spec: GearSpec, tool: Tool, machine: Machine, params: Any,
                 blank_radius_mm: float) -> Estimate:
        """The estimate of `generate`'s toolpath (the plan's comparison figures); a strategy may count it without
        building the toolpath (perimeter), or build and estimate it (`estimate_by_generating`)."""
        ...

    def largest_tool(self, recommendations: ToolRecommendations) -> tuple[str, float]:
        """The largest finishing tool this strategy takes on the gear, from its ToolRecommendations: the
        figure's name there (or how it is made of them) and its diameter (mm); 0 when none fits."""
        ...

    def suggested_tool(self, spec: GearSpec, recommendations: ToolRecommendations, target_scallop_mm: float,
                       blank_radius_mm: float) -> tuple[float, float] | None:
        """(corner radius, flat width D - 2 r) in mm of a finishing tool a new job starts with (the workbench
        suggests it), within this strategy's limits; None when no tool fits."""
        ...

    def bottom_allowance(self, tool: Tool | None, recommendations: ToolRecommendations) -> BottomAllowance:
        """What roughing may leave above the root for this strategy to take with the finishing `tool` (None: the
        largest it takes, from the finishing limits of `recommendations`): its size and the rule in words. It
        sets the largest roughing tool and the roughing reach check (recommend_tools)."""
        ...

    def check_tool(self, spec: GearSpec, tool: Tool) -> None:
        """ToolError (naming the tool key) when the tool's shape cannot do this strategy on this gear;
        cheap (the plan's and the workbench's checks run it before generating, once: `generate` trusts it)."""
        ...

    def generate(self, spec: GearSpec, tool: Tool, machine: Machine, params: Any, blank_radius_mm: float,
                 modifications: FlankModifications | None = None,
                 profile_tolerance_mm: float = 0.001) -> tuple[Toolpath, FinishingResult]:
        """The finishing operation as IR plus its facts (pure function). `modifications` are given only to a
        strategy that `follows_modifications` (the plan refuses them for the others);
        `profile_tolerance_mm` is how closely it may follow them."""
        ...


def estimate_by_generating(strategy: FinishingStrategy, spec: GearSpec, tool: Tool, machine: Machine, params: Any,
                           blank_radius_mm: float) -> Estimate:
    """A strategy's estimate made from its toolpath (the `estimate` of strategies that cannot count it cheaper)."""
    return estimate(strategy.generate(spec, tool, machine, params, blank_radius_mm)[0], machine)


def contact_largest_tool(recommendations: ToolRecommendations) -> tuple[str, float]:
    """The largest tool of the strategies that place the corner on flank contacts (perimeter, along_x): the
    root arc's flat plus twice the fillet's smallest curvature radius."""
    rec = recommendations
    return ("finishing_max_flat_width_mm + 2 finishing_max_corner_radius_mm",
            rec.finishing_max_flat_width_mm + 2.0 * rec.finishing_max_corner_radius_mm)


def contact_bottom_allowance(tool: Tool | None, recommendations: ToolRecommendations) -> BottomAllowance:
    """The strategies whose flat bottom plunges at the root (perimeter, along_x): the plunge allowance A_p = 0.5 x
    the tool's flat width (without a tool: the largest flat allowed, the root arc)."""
    if tool is None:
        return plunge_allowance(recommendations.finishing_max_flat_width_mm, largest=True)
    return plunge_allowance(tool.flat_width_mm)


def floor_to_step(value: float, step: float) -> float:
    """`value` rounded down to a multiple of `step` (a catalogue-like size)."""
    return math.floor(value / step + 1e-9) * step


def contact_suggested_tool(recommendations: ToolRecommendations) -> tuple[float, float] | None:
    """A bull-nose tool for the contact strategies: corner radius at 90 % of the fillet's smallest curvature
    radius (0.05 mm steps, at most 1 mm), flat width at 90 % of the root arc; None when either is 0."""
    rec = recommendations
    corner = min(floor_to_step(0.9 * rec.finishing_max_corner_radius_mm, 0.05), 1.0)
    flat = floor_to_step(0.9 * rec.finishing_max_flat_width_mm, 0.05)
    return (corner, flat) if corner > 0.0 and flat > 0.0 else None


class ContactStrategy:
    """What the strategies placing the tool's corner on transverse flank contacts share (perimeter, along_x):
    their largest and suggested tools, and the plunge allowance at the root."""

    def bottom_allowance(self, tool: Tool | None, recommendations: ToolRecommendations) -> BottomAllowance:
        return contact_bottom_allowance(tool, recommendations)

    def largest_tool(self, recommendations: ToolRecommendations) -> tuple[str, float]:
        return contact_largest_tool(recommendations)

    def suggested_tool(self, spec: GearSpec, recommendations: ToolRecommendations, target_scallop_mm: float,
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


def check_flat_fits_root_arc(spec: GearSpec, tool: Tool, strategy: str) -> None:
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


def finishing_builder(tool: Tool, machine: Machine) -> ToolpathBuilder:
    """Start a strategy's toolpath (its first step). The tool and the machine are trusted: the job loader
    validated them, and the plan ran the strategy's `check_tool`."""
    return ToolpathBuilder(Operation.FINISHING, tool.tool_number, tool.spindle_rpm(machine))


def params_from_section(strategy: FinishingStrategy, section: object, **overrides: Any) -> TargetScallopParams:
    """The strategy's parameters taken by name from the [finishing] section (fields it lacks keep defaults),
    checked as they are made (MachineError naming the key)."""
    values = {f.name: getattr(section, f.name) for f in dataclasses.fields(strategy.params_type)
              if hasattr(section, f.name)}
    return strategy.params_type(**{**values, **overrides})
