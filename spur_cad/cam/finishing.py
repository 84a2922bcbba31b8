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
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.geometry.modifications import FlankModifications
from spur_cad.geometry.spec import GearSpec

MODIFYING_STRATEGIES = ("generating", "perimeter")
"""The finishing strategies that cut flank modifications (along_x places its contacts on the design flank)."""


def plan_finishing(spec: GearSpec, tool: Tool, machine: Machine, section: FinishingParams,
                   blank_radius_mm: float, strategies: Strategies = REGISTRY,
                   modifications: FlankModifications | None = None, profile_tolerance_mm: float = 0.001,
                   **overrides) -> tuple[Toolpath, FinishingResult]:
    """Toolpath and result of the strategy named by `section.strategy`, with its parameters taken from
    the section (`overrides` replace some, e.g. the reference process's contact spacing), found in
    `strategies`. Flank `modifications` are cut by the strategies in MODIFYING_STRATEGIES (others refuse them)."""
    strategy = get_strategy(section.strategy, strategies)
    params = params_from_section(strategy, section, **overrides)
    strategy.check_tool(spec, tool)
    if modifications is None:
        return strategy.generate(spec, tool, machine, params, blank_radius_mm)
    if strategy.name not in MODIFYING_STRATEGIES:
        raise ToolError(f"[finishing] strategy = '{strategy.name}' does not cut flank modifications "
                        "([gear.modifications]); use strategy = 'generating' or 'perimeter'", field="strategy",
                        section="finishing")
    return strategy.generate(spec, tool, machine, params, blank_radius_mm, modifications, profile_tolerance_mm)


def finishing_toolpath(spec: GearSpec, tool: Tool, machine: Machine, section: FinishingParams,
                       blank_radius_mm: float) -> Toolpath:
    """The finishing operation as IR (pure function)."""
    return plan_finishing(spec, tool, machine, section, blank_radius_mm)[0]
