"""Finishing through the strategy registry: the job's [finishing] section -> strategy -> IR."""

from __future__ import annotations

from spur_cad.cam.ir import Toolpath
from spur_cad.cam.machine import Machine
from spur_cad.cam.strategies import (
    REGISTRY,
    FinishingParams,
    FinishingResult,
    Strategies,
    get_strategy,
    params_from_section,
)
from spur_cad.cam.tools import Tool
from spur_cad.geometry.spec import GearSpec


def plan_finishing(spec: GearSpec, tool: Tool, machine: Machine, section: FinishingParams,
                   blank_radius_mm: float, strategies: Strategies = REGISTRY,
                   **overrides) -> tuple[Toolpath, FinishingResult]:
    """Toolpath and result of the strategy named by `section.strategy`, with its parameters taken from
    the section (`overrides` replace some, e.g. the reference process's contact spacing), found in
    `strategies`."""
    strategy = get_strategy(section.strategy, strategies)
    params = params_from_section(strategy, section, **overrides)
    strategy.check_tool(spec, tool)
    return strategy.generate(spec, tool, machine, params, blank_radius_mm)


def finishing_toolpath(spec: GearSpec, tool: Tool, machine: Machine, section: FinishingParams,
                       blank_radius_mm: float) -> Toolpath:
    """The finishing operation as IR (pure function)."""
    return plan_finishing(spec, tool, machine, section, blank_radius_mm)[0]
