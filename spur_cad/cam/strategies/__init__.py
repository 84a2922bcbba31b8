"""Finishing strategies as plug-ins: one protocol (`base.FinishingStrategy`) and this registry.

Adding a strategy is one new module here plus one entry in REGISTRY; the job file's
[finishing] strategy key, the CLI, the workbench's strategy list, the simulation and the report
find it through `strategy_names()` and `get_strategy()`.
"""

from __future__ import annotations

from spur_cad.cam.machine import MachineError
from spur_cad.cam.strategies.along_x import AlongXStrategy
from spur_cad.cam.strategies.base import FinishingResult, FinishingStrategy, params_from_section
from spur_cad.cam.strategies.generating import GeneratingStrategy
from spur_cad.cam.strategies.perimeter import PerimeterStrategy

REGISTRY: dict[str, FinishingStrategy] = {
    PerimeterStrategy.name: PerimeterStrategy(),
    AlongXStrategy.name: AlongXStrategy(),
    GeneratingStrategy.name: GeneratingStrategy(),
}


def strategy_names() -> tuple[str, ...]:
    """Names of the registered finishing strategies, in registry order."""
    return tuple(REGISTRY)


def get_strategy(name: str) -> FinishingStrategy:
    """The registered strategy called `name`; MachineError naming the known ones otherwise."""
    try:
        return REGISTRY[name]
    except KeyError:
        raise MachineError(f"[finishing] strategy '{name}' is unknown (use one of {', '.join(REGISTRY)})",
                           field="strategy", section="finishing") from None


__all__ = ["REGISTRY", "FinishingResult", "FinishingStrategy", "get_strategy", "params_from_section",
           "strategy_names"]
