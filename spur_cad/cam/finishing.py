"""Finishing through the strategy registry: the job's [finishing] section -> strategy -> IR."""

from __future__ import annotations

from typing import Any

from spur_cad.cam.ir import Toolpath
from spur_cad.cam.machine import Machine
from spur_cad.cam.strategies import (
    REGISTRY,
    FinishingResult,
    FinishingSection,
    Strategies,
    get_strategy,
    params_from_section,
)
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.geometry.modifications import FlankModifications
from spur_cad.geometry.spec import GearSpec


def plan_finishing(spec: GearSpec, tool: Tool, machine: Machine, section: FinishingSection,
                   blank_radius_mm: float, strategies: Strategies = REGISTRY,
                   modifications: FlankModifications | None = None, profile_tolerance_mm: float = 0.001,
                   **overrides: Any) -> tuple[Toolpath, FinishingResult]:
    """The strategy's tool check (`check_tool`), then `generate_finishing` (for callers that have not checked the
    tool: the plan checks it with its other cheap checks first, cam.plan.check_finishing_work)."""
    get_strategy(section.strategy, strategies).check_tool(spec, tool)
    return generate_finishing(spec, tool, machine, section, blank_radius_mm, strategies, modifications,
                              profile_tolerance_mm, **overrides)


def generate_finishing(spec: GearSpec, tool: Tool, machine: Machine, section: FinishingSection,
                       blank_radius_mm: float, strategies: Strategies = REGISTRY,
                       modifications: FlankModifications | None = None, profile_tolerance_mm: float = 0.001,
                       **overrides: Any) -> tuple[Toolpath, FinishingResult]:
    """Toolpath and result of the strategy named by `section.strategy`, with its parameters taken from
    the section (`overrides` replace some, e.g. the reference process's contact spacing), found in
    `strategies`, for a tool its `check_tool` has passed. Flank `modifications` are cut by the strategies that
    declare `follows_modifications` (refused for the others)."""
    strategy = get_strategy(section.strategy, strategies)
    params = params_from_section(strategy, section, **overrides)
    if modifications is None:
        return strategy.generate(spec, tool, machine, params, blank_radius_mm)
    if not strategy.follows_modifications:
        following = " or ".join(f"'{name}'" for name, other in strategies.items() if other.follows_modifications)
        raise ToolError(f"[finishing] strategy = '{strategy.name}' does not cut flank modifications "
                        f"([gear.modifications]); use strategy = {following}", field="strategy",
                        section="finishing")
    return strategy.generate(spec, tool, machine, params, blank_radius_mm, modifications, profile_tolerance_mm)


def finishing_toolpath(spec: GearSpec, tool: Tool, machine: Machine, section: FinishingSection,
                       blank_radius_mm: float) -> Toolpath:
    """The finishing operation as IR (pure function)."""
    return plan_finishing(spec, tool, machine, section, blank_radius_mm)[0]
