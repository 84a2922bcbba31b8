"""A job's tools (spur_cad.job): the [tools.*] sections with their default numbers (no two different end mills
under one number), two-stage roughing's larger tool checked against the roughing tool, and the tool keys a file
may give as "auto" (the suggestion for the gear, spur_cad.cam.suggest, takes their place)."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

from spur_cad.cad.specs import StockSpec
from spur_cad.cam.machine import Machine, RoughingParams
from spur_cad.cam.strategies import Strategies, finishing_section_type
from spur_cad.cam.tools import Tool
from spur_cad.errors import (
    JobFileError,
    shown,
)
from spur_cad.geometry.spec import GearSpec
from spur_cad.job_sections import ToolsSection

TOOL_ROLES = ("roughing", "finishing", "bottom", "roughing_top")


DEFAULT_FINISHING_TOOL_NUMBER = 2
"""The finishing tool's number when its section gives none (the roughing tool's default is 1)."""
DEFAULT_BOTTOM_TOOL_NUMBER = 3
"""The bottom roughing tool's number when its section gives none."""
DEFAULT_ROUGHING_TOP_TOOL_NUMBER = 4
"""The larger roughing tool's number ([tools.roughing_top]) when its section gives none."""


def _tool_label(tool: Tool) -> str:
    corner = f" r {tool.effective_corner_radius_mm:g} mm" if tool.effective_corner_radius_mm else ""
    return f"{tool.kind} D {tool.diameter_mm:g} mm{corner}, {tool.flutes} flutes"


def _check_tool_numbers(first_role: str, first: Tool, role: str, tool: Tool, where: str, blamed: str) -> None:
    """Two different end mills under one tool number would make the machine load the wrong one for one of the
    programs: refuse (the same end mill may serve both, with its own cutting data)."""
    def shape(tool: Tool) -> tuple:
        return (tool.kind, tool.diameter_mm, tool.effective_corner_radius_mm, tool.flutes, tool.flute_length_mm,
                tool.stick_out_mm, tool.gauge_length_mm)

    if first.tool_number == tool.tool_number and shape(first) != shape(tool):
        raise JobFileError(f"{where}: [tools.{role}] tool_number = {tool.tool_number} is also the {first_role} "
                           f"tool's number, but the tools differ ({first_role} {_tool_label(first)}; {role} "
                           f"{_tool_label(tool)}): the machine would load the wrong end mill; give each tool "
                           "its own number", section=f"tools.{blamed}", field="tool_number")


def tools_section(sections: dict, tables: dict, where: Callable[[str, str | None], str]) -> ToolsSection:
    """The tools, with the default numbers of tools whose sections give none (T2 finishing, T3 bottom, T4
    roughing_top), and no two different tools under one number."""
    for role, number in (("finishing", DEFAULT_FINISHING_TOOL_NUMBER), ("bottom", DEFAULT_BOTTOM_TOOL_NUMBER),
                         ("roughing_top", DEFAULT_ROUGHING_TOP_TOOL_NUMBER)):
        if f"tools.{role}" in sections and "tool_number" not in tables[f"tools.{role}"]:
            sections[f"tools.{role}"] = dataclasses.replace(sections[f"tools.{role}"], tool_number=number)
    tools = ToolsSection(**{role: sections.get(f"tools.{role}") for role in TOOL_ROLES})
    present = [role for role in TOOL_ROLES if getattr(tools, role) is not None]
    for i, first_role in enumerate(present):
        for role in present[i + 1:]:
            given = "tool_number" in tables[f"tools.{role}"]  # else blame the other tool's number (the default given)
            blamed = role if given else first_role
            _check_tool_numbers(first_role, getattr(tools, first_role), role, getattr(tools, role),
                                where(f"tools.{blamed}", "tool_number"), blamed)
    return tools


def check_roughing_top(tools: ToolsSection, where: Callable[[str, str | None], str]) -> None:
    """[tools.roughing_top] offers two-stage roughing with a larger flat end mill above [tools.roughing]: it needs
    that section, not [tools.bottom] as well (each makes a pair of roughing tools), and a larger diameter."""
    top, roughing = tools.roughing_top, tools.roughing
    if top is None:
        return
    name = "tools.roughing_top"
    if roughing is None:
        problem, key = ("needs [tools.roughing]: the larger tool roughs the upper part of the spaces, the roughing "
                        "tool what it leaves"), "diameter_mm"
    elif tools.bottom is not None:
        problem, key = ("and [tools.bottom] both make two-stage roughing: give one of them (roughing_top: a larger "
                        "tool above [tools.roughing]; bottom: a smaller one below it)"), "diameter_mm"
    elif top.kind != "flat":
        problem, key = f"kind = {shown(top.kind)}: roughing uses a flat end mill", "kind"
    elif top.diameter_mm <= roughing.diameter_mm:
        problem, key = (f"diameter_mm = {top.diameter_mm:g} must be larger than the roughing tool's "
                        f"{roughing.diameter_mm:g} mm (it roughs the upper part of the spaces)"), "diameter_mm"
    else:
        return
    raise JobFileError(f"{where(name, key)}: [{name}] {problem}", section=name, field=key)


AUTO = "auto"
AUTO_KEYS = ("diameter_mm", "corner_radius_mm")
"""Tool keys a job may give as "auto": the suggestion for the gear (spur_cad.cam.suggest) takes their place."""
_AUTO_ROLES = ("roughing", "finishing")
_PROVISIONAL = {"diameter_mm": 1.0, "corner_radius_mm": 0.0}  # stand-ins until the suggestion is known


def without_auto(tables: dict, where: Callable[[str, str | None], str]) -> tuple[dict, dict[str, set[str]]]:
    """The tables with every "auto" tool key replaced by a stand-in, and {role: its "auto" keys}; "auto"
    anywhere else is refused with one line."""
    autos: dict[str, set[str]] = {}
    tables = dict(tables)
    for name, table in list(tables.items()):
        if not isinstance(table, dict):
            continue
        for key_name, value in table.items():
            if value != AUTO:
                continue
            role = name.removeprefix("tools.")
            if not name.startswith("tools.") or role not in _AUTO_ROLES or key_name not in AUTO_KEYS:
                allowed = " and ".join(f"[tools.{r}]" for r in _AUTO_ROLES)
                raise JobFileError(f"{where(name, key_name)}: [{name}] {key_name} = \"auto\": only "
                                   f"{' and '.join(AUTO_KEYS)} of {allowed} may be \"auto\"",
                                   section=name, field=key_name)
            autos.setdefault(role, set()).add(key_name)
            tables[name] = {**tables[name], key_name: _PROVISIONAL[key_name]}
    return tables, autos


def resolve_auto(sections: dict, tables: dict, autos: dict[str, set[str]], spec: GearSpec, strategies: Strategies,
                  where: Callable[[str, str | None], str]) -> None:
    """Put the suggested tools' sizes (and kinds, where the table gives none) in place of the "auto" keys: the
    finishing tool first (the roughing limit depends on it and the finishing strategy), then the roughing tool."""
    from spur_cad.cam.strategies import get_strategy
    from spur_cad.cam.suggest import suggested_finishing, suggested_roughing

    stock, machine = sections.get("stock", StockSpec()), sections.get("machine", Machine())
    blank = stock.blank_radius_mm(spec)
    finishing_section = sections.get("finishing") or finishing_section_type(strategies)()
    for role in ("finishing", "roughing"):
        if role not in autos:
            continue
        name = f"tools.{role}"
        strategy = get_strategy(finishing_section.strategy, strategies)
        if role == "finishing":
            shape = suggested_finishing(spec, strategy, finishing_section.target_scallop_mm, blank,
                                        machine.clearance_mm)
        else:
            shape = suggested_roughing(spec, strategy, sections.get("tools.finishing"),
                                       sections.get("roughing", RoughingParams()), stock, machine.clearance_mm)
        first = sorted(autos[role])[0]
        if shape is None:
            raise JobFileError(f"{where(name, first)}: [{name}] {first} = \"auto\": no {role} tool fits this gear "
                               "within its limits; give the tool's size", section=name, field=first)
        chosen = {key_name: getattr(shape, key_name) for key_name in autos[role]}
        if "kind" not in tables[name]:
            chosen["kind"] = shape.kind
        sections[name] = dataclasses.replace(sections[name], **chosen)
