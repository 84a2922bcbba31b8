"""The machine's physical limits ([machine] max_part_diameter_mm, max_part_weight_kg, max_overhang_mm,
spindle_nose_top_mm, smallest_end_mill_mm) checked against the blank and the tools before any work.

Errors are MachineError naming the [machine] key; the smallest end mill gives warnings (a shop may
own a smaller one). Pure functions of the job's sections.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from spur_cad.cad.specs import StockSpec
from spur_cad.cam.common import safe_height_mm
from spur_cad.cam.machine import Machine, MachineError
from spur_cad.cam.tools import Tool
from spur_cad.geometry.spec import GearSpec


@dataclass(frozen=True)
class BlankFigures:
    """What the rotary table carries: the blank's diameter, weight and overhang from the chuck face."""

    diameter_mm: float
    weight_kg: float
    overhang_mm: float


def blank_figures(spec: GearSpec, stock: StockSpec) -> BlankFigures:
    """The blank before cutting: a cylinder of the blank radius from the front margin to the back margin plus the
    holding stub; the chuck face is at the stub's shoulder (X = b + back margin), so the overhang is the
    blank's length."""
    radius = stock.blank_radius_mm(spec)
    x_front, x_back = stock.blank_x_range_mm(spec)
    length = x_back - x_front
    volume_mm3 = math.pi * radius**2 * length + math.pi * (stock.stub_diameter_mm / 2.0) ** 2 * stock.stub_length_mm
    return BlankFigures(2.0 * radius, volume_mm3 * 1e-6 * stock.density_kg_dm3, length)


def check_machine_limits(spec: GearSpec, stock: StockSpec, machine: Machine,
                         tools: dict[str, Tool]) -> tuple[str, ...]:
    """Raise MachineError naming the [machine] key a blank or a tool exceeds (keys at 0 are not checked);
    return warnings for tools below the smallest end mill. `tools`: role -> Tool of the tools the job has."""
    blank = blank_figures(spec, stock)
    limits = (("max_part_diameter_mm", blank.diameter_mm, "mm", "the blank's diameter"),
              ("max_part_weight_kg", blank.weight_kg, "kg", f"the blank's weight (density {stock.density_kg_dm3:g} "
                                                            "kg/dm^3, before cutting)"),
              ("max_overhang_mm", blank.overhang_mm, "mm", "the blank's overhang from the chuck face to its far face"))
    for name, value, unit, what in limits:
        limit = getattr(machine, name)
        if limit > 0.0 and value > limit:
            raise MachineError(f"[machine] {name} = {limit:g} {unit}: {what} is {value:.3f} {unit}", field=name,
                               section="machine")
    top = safe_height_mm(stock.blank_radius_mm(spec), machine)
    for role, tool in tools.items():
        length = tool.gauge_length_mm or tool.stick_out_mm
        if machine.spindle_nose_top_mm > 0.0 and length > 0.0 and top + length > machine.spindle_nose_top_mm:
            which = "gauge length" if tool.gauge_length_mm else "stick-out"
            raise MachineError(f"[machine] spindle_nose_top_mm = {machine.spindle_nose_top_mm:g} mm: the {role} tool's "
                               f"{which} {length:g} mm over the safe height {top:.3f} mm (blank radius + clearance) "
                               f"needs {top + length:.3f} mm of Z travel above the rotary axis",
                               field="spindle_nose_top_mm", section="machine")
    return tuple(f"the {role} tool's diameter {tool.diameter_mm:g} mm is below the smallest end mill "
                 f"([machine] smallest_end_mill_mm = {machine.smallest_end_mill_mm:g} mm): check that it can be bought"
                 for role, tool in tools.items() if tool.diameter_mm < machine.smallest_end_mill_mm)
