"""Finishing strategies as plug-ins: one protocol (`base.FinishingStrategy`), the default registry
`REGISTRY`, and the [finishing] section made from a registry.

A strategy's module declares everything about it: its [finishing] keys (the `key(...)` fields of its
parameters dataclass, with their checks), its capabilities (helical, follows_modifications,
corrects_slopes, lying_flat, simultaneous_rotary), its tool check, its typed facts for summary.json and
the report (`FinishingResult.facts`, with `report_text()`) and its typed tool advice. The job loader, the
workbench panel, docs/job-file.md, the summary and the report learn them from a registry; adding a
strategy is one module and one entry in REGISTRY (docs/architecture.md). Functions take `strategies=` to
use another registry (a mapping name -> strategy), e.g. a strategy defined in a test.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, Protocol

from spur_cad.cam.machine import MachineError
from spur_cad.cam.strategies.along_x import AlongXStrategy
from spur_cad.cam.strategies.base import (
    FinishingResult,
    FinishingStrategy,
    TargetScallopParams,
    params_from_section,
    step_over_key,
    target_scallop_key,
)
from spur_cad.cam.strategies.generating import GeneratingStrategy
from spur_cad.cam.strategies.generating_plan import cutting_direction_key, flank_tool_end_key
from spur_cad.cam.strategies.perimeter import PerimeterStrategy
from spur_cad.errors import shown
from spur_cad.keys import METADATA_KEY, check_section, key

Strategies = Mapping[str, FinishingStrategy]

REGISTRY: Strategies = MappingProxyType({
    PerimeterStrategy.name: PerimeterStrategy(),
    AlongXStrategy.name: AlongXStrategy(),
    GeneratingStrategy.name: GeneratingStrategy(),
})
"""The default registry (read-only: another registry is a new mapping passed as `strategies=`)."""
DEFAULT_STRATEGY = GeneratingStrategy.name
COMPARISON_STRATEGY = PerimeterStrategy.name
"""The strategy every rotary-table finishing is compared with (the shop-tested process, and with the reference
process's spacing the reference strategy): summary.json's `perimeter_*` and `reference_strategy_*` keys."""


def strategy_names(strategies: Strategies = REGISTRY) -> tuple[str, ...]:
    """Names of the registered finishing strategies, in registry order."""
    return tuple(strategies)


def get_strategy(name: str, strategies: Strategies = REGISTRY) -> FinishingStrategy:
    """The registered strategy called `name`; MachineError naming the known ones otherwise."""
    try:
        return strategies[name]
    except KeyError:
        raise MachineError(f"[finishing] strategy {shown(name)} is unknown (use one of {', '.join(strategies)})",
                           field="strategy", section="finishing") from None


class FinishingSection(Protocol):
    """What every registry's [finishing] section holds: the strategy's name and the target scallop (every
    strategy reads it); the other keys are the registry's strategies' (taken by `params_from_section`). Every
    such section checks its keys and its strategy when it is made (`__post_init__`)."""

    @property
    def strategy(self) -> str: ...

    @property
    def target_scallop_mm(self) -> float: ...


def _strategy_key(default: str, names: tuple[str, ...]) -> Any:
    return key(default, label="FinishingStrategy", group="Finishing strategy",
               meaning="a finishing strategy name (see docs/cam.md)", names_from=lambda: names)


@dataclass(frozen=True)
class FinishingParams:
    """[finishing] of the default registry: the strategy and, in registry order, its strategies' keys (each
    declared once, by the strategy's module; tests/test_strategy_registry.py checks that this class is the
    section `finishing_section_type` makes from REGISTRY)."""

    strategy: str = _strategy_key(DEFAULT_STRATEGY, tuple(REGISTRY))
    target_scallop_mm: float = target_scallop_key()
    step_over_mm: float = step_over_key()
    cutting_direction: str = cutting_direction_key()
    flank_tool_end: str = flank_tool_end_key()

    def __post_init__(self) -> None:
        """Every key in its range and the strategy known, checked once when the section is made (MachineError
        naming the key): the plan and the strategies trust it."""
        check_section(self, "finishing", MachineError)
        get_strategy(self.strategy, REGISTRY)


def finishing_section_type(strategies: Strategies = REGISTRY) -> type:
    """The [finishing] section's dataclass for a registry: `strategy` and, in registry order, every
    strategy's keys (a key several strategies share is declared once, in a common base such as
    `base.TargetScallopParams`). FinishingParams for the default registry."""
    if tuple(strategies.items()) == tuple(REGISTRY.items()):
        return FinishingParams
    return _section_type(tuple(strategies.items()))


@functools.cache
def _section_type(entries: tuple[tuple[str, FinishingStrategy], ...]) -> type:
    strategies = dict(entries)
    names = tuple(strategies)
    default = DEFAULT_STRATEGY if DEFAULT_STRATEGY in strategies else names[0]
    fields: dict[str, tuple] = {"strategy": (str, _strategy_key(default, names))}
    declared: dict[str, str] = {}
    for strategy in strategies.values():
        if not issubclass(strategy.params_type, TargetScallopParams):  # the plan and the advice read the target
            raise TypeError(f"finishing strategy {strategy.name}: its parameters must derive from "
                            "TargetScallopParams")
        for f in dataclasses.fields(strategy.params_type):
            if METADATA_KEY not in f.metadata:
                continue
            if f.name in fields and (fields[f.name][0], fields[f.name][1].default, fields[f.name][1].metadata) \
                    != (f.type, f.default, f.metadata):
                raise TypeError(f"finishing strategies {declared[f.name]} and {strategy.name} declare the key "
                                f"{f.name} differently: declare a shared key once, in a common base")
            if f.name not in fields:
                fields[f.name] = (f.type, dataclasses.field(default=f.default, metadata=f.metadata))
                declared[f.name] = strategy.name

    def __post_init__(self: Any) -> None:
        check_section(self, "finishing", MachineError)
        get_strategy(self.strategy, strategies)

    doc = "[finishing]: the finishing strategy and its parameters (docs/cam.md); made from the strategies' keys."
    namespace = {"__post_init__": __post_init__, "__module__": __name__, "__doc__": doc}
    return dataclasses.make_dataclass("FinishingParams", [(name, kind, spec) for name, (kind, spec) in fields.items()],
                                      frozen=True, namespace=namespace)


__all__ = ["COMPARISON_STRATEGY", "DEFAULT_STRATEGY", "REGISTRY", "FinishingParams", "FinishingResult",
           "FinishingSection", "FinishingStrategy", "Strategies", "finishing_section_type", "get_strategy",
           "params_from_section", "strategy_names"]
