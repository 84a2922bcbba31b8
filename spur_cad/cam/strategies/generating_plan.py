"""Finishing by generation, its plan: the parameters ([finishing] keys) and the passes of one tooth space in
cutting order, spur (spur_cad.cam.strategies.generating_geometry) or helical
(spur_cad.cam.strategies.generating_helical), with what they leave."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from spur_cad.cam.ir import Feature
from spur_cad.cam.strategies.base import TargetScallopParams
from spur_cad.cam.strategies.generating_flat import flat_leftover_mm
from spur_cad.cam.strategies.generating_geometry import (
    CUTTING_DIRECTIONS,
    FLANK_TOOL_ENDS,
    GOUGE_TOLERANCE_MM,
    MAX_PASSES_PER_SPACE,
    TIP_MODE_SAFETY,
    TIP_SAFETY_HELICAL,
    GeneratingPass,
    design_points,
    fillet_pose,
    flank_poses,
    flank_rolls,
    generating_tool_limits,
    gouges,
    land_angles,
    land_pose,
    root_pose,
    rough_passes_per_space,
    tip_rolls,
)
from spur_cad.cam.strategies.generating_helical import (
    CORNER_GAP_SHARE,
    CORNER_MATCH_MM,
    face_turn_range,
    flank_roll_step,
    helical_pass_count,
    helical_passes,
    helical_passes_estimate,
)
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.errors import WorkLimitError
from spur_cad.geometry.kinds import EXTERNAL_HELICAL, EXTERNAL_SPUR, INTERNAL_SPUR, GearKind
from spur_cad.geometry.spec import GearSpec
from spur_cad.keys import key


def cutting_direction_key() -> Any:
    """generating's [finishing] key cutting_direction, declared here once (GeneratingParams and the default
    registry's section, strategies.FinishingParams, take their field from here)."""
    return key("climb", label="CuttingDirection", group="Finishing strategy", choices=CUTTING_DIRECTIONS,
               meaning="generating: climb or conventional milling (spindle clockwise, M3)")


def flank_tool_end_key() -> Any:
    """generating's [finishing] key flank_tool_end, declared here once."""
    return key("rack", label="FlankToolEnd", group="Finishing strategy", choices=FLANK_TOOL_ENDS,
               meaning="generating: tool end on the rack's tip round (rack) or raised per pass (raised)")


@dataclass(frozen=True)
class GeneratingParams(TargetScallopParams):
    """[finishing] keys the generating strategy uses.

    cutting_direction: "climb" (default: the finished side is left by the thinnest chip, the
    usual choice for finishing on a rigid machine) or "conventional", for a spindle turning
    clockwise (M3), see the module docstring. flank_tool_end: "rack" (default: the corner
    tangent to the flank at the rack's point T, the same place relative to the rack for every
    pass) or "raised" (per pass, just low enough for the straight side to cut the whole flat).
    """

    cutting_direction: str = cutting_direction_key()
    flank_tool_end: str = flank_tool_end_key()


@dataclass(frozen=True)
class GeneratingPlan:
    """The passes of one tooth space in cutting order, and what they leave."""

    passes: tuple[GeneratingPass, ...]
    flank_rolls_rad: np.ndarray  # involute rolls t, form circle -> tip (each flank)
    fillet_betas_rad: np.ndarray  # contact angles on the rack round, junction -> 0 (each fillet)
    root_rolls_rad: np.ndarray  # rack rolls phi of the root passes, v -> -v
    land_angles_rad: np.ndarray  # part directions psi of the land passes (empty: blank at the tip diameter)
    flat_height_mm: float  # largest generating-flat deviation left on the involute (closed form)
    tip_leftover_mm: float  # largest sampled leftover on fillet, root and lands (helical: the bound the rolls keep)

    @property
    def passes_per_space(self) -> int:
        return len(self.passes)

    @property
    def flank_passes_per_flank(self) -> int:
        return len(self.flank_rolls_rad)

    @property
    def tip_passes_per_space(self) -> int:
        return sum(1 for p in self.passes if p.mode == "tip")

    @property
    def land_passes_per_space(self) -> int:
        return sum(1 for p in self.passes if p.mode == "land")


def _refuse_gouging_passes(spec: GearSpec, tool: Tool, params: GeneratingParams, poses: dict) -> None:
    """ToolError naming the largest tools that fit when a pass of `poses` (name -> (A rad, Y, Z)) reaches
    into the dense exact design points beyond GOUGE_TOLERANCE_MM."""
    design = design_points(spec)
    for name, (a, y, z) in poses.items():
        if len(a) == 0:
            continue
        depth = gouges(design, a, y, z, tool)
        if depth.max() > GOUGE_TOLERANCE_MM:
            limits = generating_tool_limits(spec, tool.effective_corner_radius_mm, params.target_scallop_mm,
                                            spec.tip_radius_mm)
            best = (limits.flank_mode_max_diameter_mm if params.flank_tool_end == "rack"
                    else limits.flank_mode_max_diameter_raised_mm)
            raise ToolError(f"finishing strategy generating: a {name} pass of the {tool.diameter_mm:g} mm tool "
                            f"reaches {1000 * depth.max():.2f} um into the gear; largest diameter for flank mode "
                            f"with r_t = {tool.effective_corner_radius_mm:g} mm and flank_tool_end = "
                            f"'{params.flank_tool_end}': {best:.3f} mm, for tip mode: "
                            f"{limits.tip_mode_max_diameter_mm:.3f} mm")


def plan_generating(spec: GearSpec, tool: Tool, params: GeneratingParams, *, lands: bool = True,
                    check: bool = True, kink_rolls_rad: tuple[float, ...] = ()) -> GeneratingPlan:
    """The passes of tooth space 0 (the land beside it when `lands`, both flanks, fillets and root), in
    cutting order. `kink_rolls_rad`: involute rolls where a modified flank has a kink (a relief's start), each
    given a flank pass of its own so the kink is cut exactly (spur gears; a helical pass meets a roll at one X).
    The tool is one `check_generating_tool` has passed (the strategy's check_tool, run by the plan)."""
    return PLANNERS[spec.kind](spec, tool, params, lands, check, kink_rolls_rad)


def _plan_spur(spec: GearSpec, tool: Tool, params: GeneratingParams, lands: bool, check: bool,
               kink_rolls_rad: tuple[float, ...]) -> GeneratingPlan:
    """A spur gear's passes (its section is the same at every X: one pose per roll, placed in the section)."""
    profile = spec.tooth_space_profile()
    target = params.target_scallop_mm
    rough = rough_passes_per_space(spec, tool, target)
    if rough > MAX_PASSES_PER_SPACE:
        raise WorkLimitError(f"generating finishing would need about {rough:.3g} passes per tooth space (limit "
                             f"{MAX_PASSES_PER_SPACE:,}) for target_scallop_mm = {target:.3g}; raise [finishing] "
                             "target_scallop_mm", field="target_scallop_mm", section="finishing")
    t_rolls, flat_height = flank_rolls(spec, target)
    t_rolls = np.union1d(t_rolls, [t for t in kink_rolls_rad if t_rolls[0] < t < t_rolls[-1]])
    betas, roots, tip_leftover = tip_rolls(spec, tool, TIP_MODE_SAFETY * target)
    fa, fy, fz = flank_poses(spec, tool, t_rolls, params.flank_tool_end)
    ba, by, bz = fillet_pose(spec, tool, betas)
    ra, ry, rz = root_pose(spec, tool, roots)
    psis, land_leftover = land_angles(spec, tool, TIP_MODE_SAFETY * target) if lands else (np.zeros(0), 0.0)
    la, ly, lz = land_pose(spec, psis)
    if check:
        _refuse_gouging_passes(spec, tool, params, {"flank": (fa, fy, fz), "fillet": (ba, by, bz),
                                                    "root": (ra, ry, rz), "land": (la, ly, lz)})
    rb = spec.base_radius_mm
    fillet = profile.fillet
    passes: list[GeneratingPass] = []

    def add(mode, feature, roll, beta, a, y, z, side, radius):
        passes.append(GeneratingPass(mode, feature, float(roll), float(beta), math.degrees(float(a)), float(y),
                                     float(z), side, float(radius)))

    flank_radius = rb * np.sqrt(1.0 + t_rolls**2)
    fillet_radius = (np.hypot(*fillet.points(betas).T) if fillet is not None and len(betas) > 1
                     else np.full(len(betas), spec.root_radius_mm))
    # land of the tooth on the +Y side, then right flank, tip -> root
    for i in range(len(psis)):
        add("land", Feature.TIP, psis[i], math.nan, la[i], ly[i], lz[i], 1, spec.tip_radius_mm)
    for i in range(len(t_rolls) - 1, -1, -1):
        add("flank", Feature.RIGHT_FLANK, t_rolls[i], math.nan, fa[i], fy[i], fz[i], 1, flank_radius[i])
    # right fillet, junction -> root (its last pose, beta = 0, is the root's first)
    for i in range(len(betas) - 1):
        add("tip", Feature.RIGHT_FLANK, ba[i], betas[i], ba[i], by[i], bz[i], 1, fillet_radius[i])
    # root, v -> -v
    for i in range(len(roots)):
        add("tip", Feature.ROOT, ra[i], math.nan, ra[i], ry[i], rz[i], 1, spec.root_radius_mm)
    for i in range(len(roots) - 2, -1, -1):
        add("tip", Feature.ROOT, -ra[i], math.nan, -ra[i], -ry[i], rz[i], -1, spec.root_radius_mm)
    # left fillet, root -> junction
    for i in range(len(betas) - 2, -1, -1):
        add("tip", Feature.LEFT_FLANK, -ba[i], betas[i], -ba[i], -by[i], bz[i], -1, fillet_radius[i])
    # left flank, root -> tip
    for i in range(len(t_rolls)):
        add("flank", Feature.LEFT_FLANK, t_rolls[i], math.nan, -fa[i], -fy[i], fz[i], -1, flank_radius[i])
    return GeneratingPlan(tuple(passes), t_rolls, betas, np.concatenate([roots, -roots[-2::-1]]), psis,
                          flat_height, max(tip_leftover, land_leftover))


def planned_passes_per_space(spec: GearSpec, tool: Tool, params: GeneratingParams, *, lands: bool = True) -> int:
    """plan_generating(...).passes_per_space (without kink passes), refused as it would be; a helical gear's
    passes are counted, not placed (their ends take a bisection each), so the work bound does not plan them twice."""
    return PASS_COUNTS[spec.kind](spec, tool, params, lands)


def _spur_pass_count(spec: GearSpec, tool: Tool, params: GeneratingParams, lands: bool) -> int:
    return plan_generating(spec, tool, params, lands=lands, check=False).passes_per_space


def _helical_pass_count(spec: GearSpec, tool: Tool, params: GeneratingParams, lands: bool) -> int:
    _check_helical_work(spec, tool, params.target_scallop_mm)
    return helical_pass_count(spec, tool, params.target_scallop_mm, lands)


def _check_helical_work(spec: GearSpec, tool: Tool, target: float) -> None:
    """WorkLimitError when the closed-form count of a helical gear's passes exceeds MAX_PASSES_PER_SPACE."""
    rough = helical_passes_estimate(spec, target, tool)
    if rough > MAX_PASSES_PER_SPACE:
        raise WorkLimitError(f"generating finishing would need about {rough:.3g} passes per tooth space (limit "
                             f"{MAX_PASSES_PER_SPACE:,}) for target_scallop_mm = {target:.3g}; raise [finishing] "
                             "target_scallop_mm", field="target_scallop_mm", section="finishing")


def _plan_helical(spec: GearSpec, tool: Tool, params: GeneratingParams, lands: bool, check: bool,
                  kink_rolls_rad: tuple[float, ...]) -> GeneratingPlan:
    """The helical gear's passes (spur_cad.cam.strategies.generating_helical) as a plan: their ends are placed clear
    of the design by construction (no `check`), and a pass meets a roll at one X only (no kink passes)."""
    target = params.target_scallop_mm
    _check_helical_work(spec, tool, target)
    lo, hi = face_turn_range(spec)
    rows = helical_passes(spec, tool, target, spec.tip_radius_mm + tool.diameter_mm, lands)
    rb = spec.base_radius_mm
    passes = []
    for mode, feature, roll, a, y0, z0, sy, sz, side in rows:
        radius = {"flank": rb * math.sqrt(1.0 + roll * roll), "land": spec.tip_radius_mm}.get(mode,
                                                                                                spec.root_radius_mm)
        passes.append(GeneratingPass(mode, feature, roll, math.nan, math.degrees(a), y0, z0, side, radius, sy, sz))
    flank = np.array(sorted(p.roll_rad for p in passes if p.feature == Feature.RIGHT_FLANK and p.mode == "flank"))
    tips = np.array(sorted({p.roll_rad for p in passes if p.mode == "tip"}, reverse=True))
    land = np.array([p.roll_rad for p in passes if p.mode == "land"])
    step = flank_roll_step(spec, target)
    t_worst = spec.tooth_space_profile().involute.end + hi - lo
    tip_bound = TIP_SAFETY_HELICAL * target
    if tool.effective_corner_radius_mm < spec.rack_tip_radius_mm - CORNER_MATCH_MM:
        # rolls spaced for the rest of the target, plus what the corner leaves between its contact angles
        tip_bound = (TIP_SAFETY_HELICAL * (1.0 - CORNER_GAP_SHARE) + CORNER_GAP_SHARE) * target
    return GeneratingPlan(tuple(passes), flank, np.zeros(0), tips, land,
                          flat_leftover_mm(rb, t_worst - step, t_worst), tip_bound)


_Planner = Callable[[GearSpec, Tool, GeneratingParams, bool, bool, tuple[float, ...]], GeneratingPlan]
PLANNERS: dict[GearKind, _Planner] = {
    EXTERNAL_SPUR: _plan_spur, EXTERNAL_HELICAL: _plan_helical, INTERNAL_SPUR: _plan_spur}
"""plan_generating's planner for each gear kind (spec, tool, params, lands, check, kink_rolls_rad)."""
PASS_COUNTS: dict[GearKind, Callable[[GearSpec, Tool, GeneratingParams, bool], int]] = {
    EXTERNAL_SPUR: _spur_pass_count, EXTERNAL_HELICAL: _helical_pass_count, INTERNAL_SPUR: _spur_pass_count}
"""planned_passes_per_space's count for each gear kind (spec, tool, params, lands)."""
