"""The machining centre with its rotary table, and the strategy parameters."""

from __future__ import annotations

from dataclasses import dataclass

from spur_cad.errors import SpurCadError


class MachineError(SpurCadError, ValueError):
    """A machine or strategy setting that cannot work; the message names it."""


@dataclass(frozen=True)
class Machine:
    """[machine]: limits and habits of the machining centre and its rotary table (4th axis A)."""

    name: str = "generic 4-axis VMC"
    max_spindle_rpm: float = 7000.0
    max_feed_mm_min: float = 5000.0
    rapid_feed_mm_min: float = 15000.0
    max_rotary_speed_deg_min: float = 3600.0
    clearance_mm: float = 1.0
    block_time_s: float = 0.004
    rotary_continuous: bool = True
    a_min_deg: float = -99999.0
    a_max_deg: float = 99999.0
    x_min_mm: float = -1000.0
    x_max_mm: float = 1000.0
    y_min_mm: float = -1000.0
    y_max_mm: float = 1000.0
    z_min_mm: float = -1000.0
    z_max_mm: float = 1000.0
    rotary_clamp_code: str = ""
    rotary_unclamp_code: str = ""

    def validate(self) -> None:
        for name in ("max_spindle_rpm", "max_feed_mm_min", "rapid_feed_mm_min", "max_rotary_speed_deg_min"):
            if not getattr(self, name) > 0.0:
                raise MachineError(f"[machine] {name} = {getattr(self, name):g} must be positive")
        if self.clearance_mm < 0.0 or self.block_time_s < 0.0:
            raise MachineError("[machine] clearance_mm and block_time_s must not be negative")
        for low, high in (("a_min_deg", "a_max_deg"), ("x_min_mm", "x_max_mm"), ("y_min_mm", "y_max_mm"),
                          ("z_min_mm", "z_max_mm")):
            if not getattr(self, low) < getattr(self, high):
                raise MachineError(f"[machine] {low} must be below {high}")


def check_travel(machine: Machine, x, y, z, a, operation: str) -> None:
    """Raise MachineError naming the axis and the value when a pose leaves the machine's travel
    (A only when the table is not continuous)."""
    import numpy as np

    axes = [("X", x, machine.x_min_mm, machine.x_max_mm, "mm"), ("Y", y, machine.y_min_mm, machine.y_max_mm, "mm"),
            ("Z", z, machine.z_min_mm, machine.z_max_mm, "mm")]
    if not machine.rotary_continuous:
        axes.append(("A", a, machine.a_min_deg, machine.a_max_deg, "deg"))
    for name, values, low, high, unit in axes:
        values = np.asarray(values)
        if len(values) and (values.min() < low or values.max() > high):
            worst = values.min() if values.min() < low else values.max()
            raise MachineError(f"{operation} needs {name} = {worst:.3f} {unit}, outside the machine's travel "
                               f"[{low:g}, {high:g}] {unit}")


@dataclass(frozen=True)
class RoughingParams:
    """[roughing]: METHOD.md 4. Allowances are measured from the designed flank."""

    flank_allowance_mm: float = 0.1  # largest staircase left on the flanks (ofst)
    finish_stock_mm: float = 0.02  # roughing never comes closer than this to the design
    step_over_fraction: float = 0.5  # Y step between passes of a level, x D
    max_level_depth_fraction: float = 0.5  # slotting depth limit per level, x D
    clamp_rotary: bool = False  # clamp A around each space (needs the machine's codes)

    def validate(self) -> None:
        if not 0.0 <= self.finish_stock_mm < self.flank_allowance_mm:
            raise MachineError(f"[roughing] finish_stock_mm = {self.finish_stock_mm:g} must be at least 0 and below "
                               f"flank_allowance_mm = {self.flank_allowance_mm:g}")
        if not 0.0 < self.step_over_fraction <= 1.0:
            raise MachineError(f"[roughing] step_over_fraction = {self.step_over_fraction:g} must be in (0, 1]")
        if not 0.0 < self.max_level_depth_fraction <= 2.0:
            raise MachineError(f"[roughing] max_level_depth_fraction = {self.max_level_depth_fraction:g} "
                               "must be in (0, 2]")


@dataclass(frozen=True)
class FinishingParams:
    """[finishing]: METHOD.md 5."""

    strategy: str = "perimeter"  # a name in spur_cad.cam.strategies.REGISTRY
    target_scallop_mm: float = 0.005
    step_over_mm: float = 0.0  # X step between stations; 0: derived from the target scallop
    cutting_direction: str = "climb"  # generating: "climb" or "conventional" (spindle clockwise, M3)
    flank_tool_end: str = "rack"  # generating: "rack" (corner at the rack's point T) or "raised" (per pass)

    def validate(self) -> None:
        from spur_cad.cam.strategies import get_strategy  # the registry imports this module

        get_strategy(self.strategy)
        if self.cutting_direction not in ("climb", "conventional"):
            raise MachineError(f"[finishing] cutting_direction = {self.cutting_direction!r} is unknown "
                               "(use one of climb, conventional)")
        if self.flank_tool_end not in ("rack", "raised"):
            raise MachineError(f"[finishing] flank_tool_end = {self.flank_tool_end!r} is unknown "
                               "(use one of rack, raised)")
        if not 0.0 < self.target_scallop_mm <= 0.1:
            raise MachineError(f"[finishing] target_scallop_mm = {self.target_scallop_mm:g} must be in (0, 0.1]")
        if self.step_over_mm < 0.0:
            raise MachineError(f"[finishing] step_over_mm = {self.step_over_mm:g} must not be negative")
