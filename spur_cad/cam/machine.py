"""The machining centre with its rotary table, and the strategy parameters."""

from __future__ import annotations

import re
from dataclasses import dataclass

from spur_cad.cam.setups import ROTARY_TABLE, MachineSetup, setup_for_axes
from spur_cad.errors import SpurCadError, shown
from spur_cad.keys import check_section, key


class MachineError(SpurCadError, ValueError):
    """A machine or strategy setting that cannot work; the message names it."""


@dataclass(frozen=True)
class Machine:
    """[machine]: limits and habits of the machining centre and its rotary table (4th axis A)."""

    axes: int = key(4, choices=(4, 3), label="MachineAxes", group="Machine",
                    meaning="4: the gear on the rotary table (axis = X = A); 3: the blank clamped flat, gear axis = "
                            "Z, Z0 on its top face, the outline cut by the end mill's side with arcs (spur gears "
                            "only; docs/cam.md)")
    name: str = key("generic 4-axis VMC", label="MachineName", group="Machine",
                    meaning="machine name (summary, program headers)")
    max_spindle_rpm: float = key(7000.0, unit="1/min", low=100.0, high=100000.0, label="MaxSpindleRpm",
                                 group="Machine", meaning="spindle speed limit")
    max_feed_mm_min: float = key(5000.0, unit="mm/min", low=10.0, high=100000.0, label="MaxFeed", group="Machine",
                                 meaning="linear feed limit")
    rapid_feed_mm_min: float = key(15000.0, unit="mm/min", low=10.0, high=200000.0, label="RapidFeed",
                                   group="Machine", meaning="rapid traverse rate (cycle-time estimate)")
    max_rotary_speed_deg_min: float = key(3600.0, unit="deg/min", low=1.0, high=500000.0, label="MaxRotarySpeed",
                                          group="Machine", meaning="rotary axis speed limit")
    clearance_mm: float = key(1.0, unit="mm", low=0.0, high=100.0, label="Clearance", group="Machine",
                              meaning="clearance of non-cutting moves from the stock")
    block_time_s: float = key(0.004, unit="s", low=0.0, high=1.0, label="BlockTime", group="Machine",
                              meaning="the control's block processing time (cycle-time estimate)")
    rotary_simultaneous: bool = key(True, label="RotarySimultaneous", group="Machine",
                                    meaning="A can move together with X/Y/Z while cutting (false: the table only "
                                            "indexes; strategies that need simultaneous A are refused)")
    rotary_continuous: bool = key(True, label="RotaryContinuous", group="Machine",
                                  meaning="A turns without limits (false: finishing unwinds A after every station)")
    a_min_deg: float = key(-99999.0, unit="deg", low=-99999.0, high=99999.0, label="AMin", group="Machine",
                           meaning="A travel limit, low (used when rotary_continuous = false)")
    a_max_deg: float = key(99999.0, unit="deg", low=-99999.0, high=99999.0, label="AMax", group="Machine",
                           meaning="A travel limit, high (used when rotary_continuous = false)")
    x_min_mm: float = key(-1000.0, unit="mm", low=-10000.0, high=10000.0, label="XMin", group="Machine",
                          meaning="X travel limit, low")
    x_max_mm: float = key(1000.0, unit="mm", low=-10000.0, high=10000.0, label="XMax", group="Machine",
                          meaning="X travel limit, high")
    y_min_mm: float = key(-1000.0, unit="mm", low=-10000.0, high=10000.0, label="YMin", group="Machine",
                          meaning="Y travel limit, low")
    y_max_mm: float = key(1000.0, unit="mm", low=-10000.0, high=10000.0, label="YMax", group="Machine",
                          meaning="Y travel limit, high")
    z_min_mm: float = key(-1000.0, unit="mm", low=-10000.0, high=10000.0, label="ZMin", group="Machine",
                          meaning="Z travel limit, low")
    z_max_mm: float = key(1000.0, unit="mm", low=-10000.0, high=10000.0, label="ZMax", group="Machine",
                          meaning="Z travel limit, high")
    x_acceleration_mm_s2: float = key(1000.0, unit="mm/s^2", low=10.0, high=100000.0, label="XAcceleration",
                                      group="Machine", meaning="X axis acceleration limit (cycle-time estimate)")
    y_acceleration_mm_s2: float = key(1000.0, unit="mm/s^2", low=10.0, high=100000.0, label="YAcceleration",
                                      group="Machine", meaning="Y axis acceleration limit (cycle-time estimate)")
    z_acceleration_mm_s2: float = key(1000.0, unit="mm/s^2", low=10.0, high=100000.0, label="ZAcceleration",
                                      group="Machine", meaning="Z axis acceleration limit (cycle-time estimate)")
    a_acceleration_deg_s2: float = key(1500.0, unit="deg/s^2", low=1.0, high=1000000.0, label="AAcceleration",
                                       group="Machine", meaning="A axis acceleration limit (cycle-time estimate)")
    path_tolerance_mm: float = key(0.005, unit="mm", low=0.0, high=1.0, label="PathTolerance", group="Machine",
                                   meaning="how far the control may round a corner between moves (G64 P; "
                                           "cycle-time estimate)")
    max_part_diameter_mm: float = key(0.0, unit="mm", low=0.0, high=10000.0, label="MaxPartDiameter",
                                      group="Machine limits",
                                      meaning="largest part diameter the rotary table swings, 0: not checked")
    max_part_weight_kg: float = key(0.0, unit="kg", low=0.0, high=100000.0, label="MaxPartWeight",
                                    group="Machine limits",
                                    meaning="heaviest part the rotary table carries (the blank, before cutting), "
                                            "0: not checked")
    max_overhang_mm: float = key(0.0, unit="mm", low=0.0, high=10000.0, label="MaxOverhang", group="Machine limits",
                                 meaning="longest overhang from the chuck face (the stub's shoulder) to the far face "
                                         "of the blank, 0: not checked")
    spindle_nose_top_mm: float = key(0.0, unit="mm", low=0.0, high=10000.0, label="SpindleNoseTop",
                                     group="Machine limits",
                                     meaning="height of the spindle nose above the rotary axis at the top of the Z "
                                             "travel: a tool's gauge length plus the safe height must fit under it, "
                                             "0: not checked")
    smallest_end_mill_mm: float = key(1.0, unit="mm", low=0.1, high=100.0, label="SmallestEndMill",
                                      group="Machine limits",
                                      meaning="smallest end mill the shop buys (catalogue: 1 mm); a smaller tool or "
                                              "a job needing one is warned about")
    rotary_accuracy_arcsec: float = key(15.0, unit="arcsec", low=0.0, high=3600.0, label="RotaryAccuracy",
                                        group="Machine accuracy",
                                        meaning="error budget: the rotary table's positioning accuracy +- (datasheets "
                                                "of worm-driven tables: 10 to 20); applied as a once-per-turn sine "
                                                "of this amplitude unless rotary_calibration_file is given")
    rotary_repeatability_arcsec: float = key(10.0, unit="arcsec", low=0.0, high=3600.0,
                                             label="RotaryRepeatability", group="Machine accuracy",
                                             meaning="error budget: the rotary table's repeatability (datasheets: 4 "
                                                     "to 10); a seeded draw per space in +- half of it")
    rotary_calibration_file: str = key("", label="RotaryCalibrationFile", group="Machine accuracy",
                                       meaning="error budget: the rotary table's measured error, a file relative to "
                                               "the job file (in its folder or a --side-files folder) of lines "
                                               "'A_deg error_arcsec' as compensation tables hold it (empty: the "
                                               "accuracy's sine)")
    spindle_runout_um: float = key(2.0, unit="um", low=0.0, high=100.0, label="SpindleRunout",
                                   group="Machine accuracy",
                                   meaning="error budget: the spindle's runout, total indicated (datasheets: 1 to 3)")
    tool_runout_um: float = key(5.0, unit="um", low=0.0, high=200.0, label="ToolRunout", group="Machine accuracy",
                                meaning="error budget: the finishing tool's runout in its holder, total indicated "
                                        "(collet chucks 5 to 10, shrink fit about 3)")
    tool_radius_error_um: float = key(0.0, unit="um", low=-500.0, high=500.0, label="ToolRadiusError",
                                      group="Machine accuracy",
                                      meaning="error budget: the finishing tool's radius above the one the program "
                                              "assumes (measured on a presetter; + cuts deeper)")
    linear_accuracy_um: float = key(5.0, unit="um", low=0.0, high=500.0, label="LinearAccuracy",
                                    group="Machine accuracy",
                                    meaning="error budget: the linear axes' positioning accuracy (ISO 230-2; "
                                            "datasheets of machining centres: 5 to 10); half of it taken into the "
                                            "material on every flank")
    rotary_clamp_code: str = key("", label="RotaryClampCode", group="Machine",
                                 meaning="M code clamping A (needed by [roughing] clamp_rotary; "
                                         "generating clamps for every pass when both codes are given)")
    rotary_unclamp_code: str = key("", label="RotaryUnclampCode", group="Machine",
                                   meaning="M code unclamping A (needed by [roughing] clamp_rotary)")

    @property
    def setup(self) -> MachineSetup:
        """The set-up `axes` chooses (spur_cad.cam.setups): code asks it, never `axes`."""
        return setup_for_axes(self.axes)

    def __post_init__(self) -> None:
        """Every key in its range, each axis's travel limits in order and the clamp codes single M codes, checked
        once when the section is made (MachineError naming the key): the CAM trusts it."""
        check_section(self, "machine", MachineError)
        for low, high in (("a_min_deg", "a_max_deg"), ("x_min_mm", "x_max_mm"), ("y_min_mm", "y_max_mm"),
                          ("z_min_mm", "z_max_mm")):
            if not getattr(self, low) < getattr(self, high):
                raise MachineError(f"[machine] {low} must be below {high}", field=low)
        check_rotary_code(self.rotary_clamp_code, "rotary_clamp_code")
        check_rotary_code(self.rotary_unclamp_code, "rotary_unclamp_code")


ROTARY_CODE = re.compile(r"M[0-9]{1,4}")
"""A rotary clamp/unclamp code is one M code and nothing else (the post writes it as its own block)."""


RESERVED_M_CODES = frozenset({0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 30, 60, 96, 97, 98, 99, 198})
"""M codes that stop, end or call programs, or drive the spindle, tool or coolant: never a clamp code."""


def check_rotary_code(code: str, key: str) -> None:
    """Refuse a clamp/unclamp code that is anything but a single M code ("" means none), or an M code that
    stops, ends or calls a program or drives the spindle, tool or coolant."""
    if code and ROTARY_CODE.fullmatch(code) and int(code[1:]) in RESERVED_M_CODES:
        raise MachineError(f"[machine] {key} = {shown(code)} is an M code that stops, ends or calls a program or "
                           "drives the spindle, tool or coolant; use the machine's rotary clamp code (e.g. M10)",
                           field=key, section="machine")
    if code and not ROTARY_CODE.fullmatch(code):
        raise MachineError(f"[machine] {key} = {shown(code, 20)} must be a single M code such as 'M10' (the programs "
                           "write it as a block of its own)", field=key, section="machine")


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
            bound = ("x", "y", "z", "a")["XYZA".index(name)] + ("_min" if worst < low else "_max") + \
                ("_deg" if name == "A" else "_mm")
            raise MachineError(f"{operation} needs {name} = {worst:.3f} {unit}, outside the machine's travel "
                               f"[{low:g}, {high:g}] {unit}", field=bound, section="machine")


DEFAULT_ROUGHING_STRATEGY = ROTARY_TABLE.default_roughing_strategy
"""[roughing] strategy where a job leaves it out, in job files and the workbench alike: roughing by flanks
(constant engagement, docs/method.md 4.1), about three times faster than levels with the same tool and cutting
data. It needs the rotary table, to turn A to each flank segment: on 3 axes the default is levels
(default_roughing_strategy)."""


def default_roughing_strategy(setup: MachineSetup) -> str:
    """The [roughing] strategy of a job that leaves it out, in machine set-up `setup` (Machine.setup):
    DEFAULT_ROUGHING_STRATEGY on the rotary table (spur and helical gears), "levels" lying flat (3 axes: no table
    turns a flank to the tool, and the 3-axis roughing is by levels, each a series of passes offset from the
    outline)."""
    return setup.default_roughing_strategy


@dataclass(frozen=True)
class RoughingParams:
    """[roughing]: roughing by levels or by flanks (docs/method.md); allowances are measured from the designed
    flank."""

    strategy: str = key(DEFAULT_ROUGHING_STRATEGY, choices=("levels", "flank"), label="RoughingStrategy",
                        group="Roughing strategy",
                        meaning="flank: A turned to each flank segment, the tool's side at full depth (constant "
                                "engagement); levels: horizontal levels of zig-zag passes (left out: levels on 3 "
                                "axes, and where flank roughing cannot take the gear or tools, with a note)")
    flank_allowance_mm: float = key(0.1, unit="mm", low=0.0, high=5.0, low_open=True, label="FlankAllowance",
                                    group="Roughing strategy",
                                    meaning="largest staircase roughing leaves on the flanks (ofst)")
    finish_stock_mm: float = key(0.02, unit="mm", low=0.0, high=2.0, label="FinishStock", group="Roughing strategy",
                                 meaning="roughing never comes closer than this to the design "
                                         "(below flank_allowance_mm)")
    step_over_fraction: float = key(0.5, low=0.0, high=1.0, low_open=True, label="StepOverFraction",
                                    group="Roughing strategy",
                                    meaning="levels: Y step between passes of a level, x D")
    max_level_depth_fraction: float = key(0.5, low=0.0, high=2.0, low_open=True, label="MaxLevelDepthFraction",
                                          group="Roughing strategy",
                                          meaning="slotting depth limit per level (flank strategy: of a pass "
                                                  "engaged wider than its radial engagement), x D")
    max_radial_engagement_fraction: float = key(0.2, low=0.0, high=0.5, low_open=True,
                                                label="MaxRadialEngagementFraction", group="Roughing strategy",
                                                meaning="flank strategy: largest radial engagement of a pass deeper "
                                                        "than a slot, x D")
    max_axial_depth_mm: float = key(0.0, unit="mm", low=0.0, high=200.0, label="MaxAxialDepth",
                                    group="Roughing strategy",
                                    meaning="flank strategy: largest axial depth of a pass; 0: the flute length, "
                                            "at most 3 D")
    max_feed_factor: float = key(2.0, low=1.0, high=4.0, label="MaxFeedFactor", group="Roughing strategy",
                                 meaning="flank strategy: largest chip-thinning raise of the feed")
    bottom_tool_above_root_mm: float = key(0.0, unit="mm", low=0.0, high=1000.0, label="BottomToolAboveRoot",
                                           group="Roughing strategy",
                                           meaning="two-stage roughing ([tools.bottom]): the roughing tool's levels "
                                                   "reach down to this height above the root circle, the bottom "
                                                   "tool's below it; 0: the split with the shortest estimated time")
    clamp_rotary: bool = key(False, label="ClampRotary", group="Roughing strategy",
                             meaning="clamp A around each tooth space (needs the machine's clamp codes)")

    def __post_init__(self) -> None:
        """Every key in its range and the finish stock below the allowance, checked once when the section is made
        (MachineError naming the key)."""
        check_section(self, "roughing", MachineError)
        if not self.finish_stock_mm < self.flank_allowance_mm:
            raise MachineError(f"[roughing] finish_stock_mm = {self.finish_stock_mm:g} must be below "
                               f"flank_allowance_mm = {self.flank_allowance_mm:g}", field="finish_stock_mm")
