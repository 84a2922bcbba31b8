"""Tool recommendations and limits (docs/method.md), and the tooth space's width at a height.

Heights are measured along the space's symmetry axis in the gap frame (y), as the tool sees
them when the space axis points up the tool axis.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np

from spur_cad.cam.allowances import (  # noqa: F401  (re-exported: the names callers know from here)
    LAND_PASS_DEPTH_FRACTION,
    PLUNGE_CAPACITY_FRACTION,
    BottomAllowance,
    ToolRecommendations,
    generating_bottom_allowance,
    generating_pass_allowance,
    plunge_allowance,
)
from spur_cad.cam.fillet_reach import applies, fillet_reach, refusal_text
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.geometry.kinds import EXTERNAL_HELICAL, EXTERNAL_SPUR, INTERNAL_SPUR, GearKind
from spur_cad.geometry.mate import GearPair
from spur_cad.geometry.profile import rack_corner
from spur_cad.geometry.sampling import sample_profile
from spur_cad.geometry.spec import GearSpec


def flank_polyline(spec: GearSpec, tolerance_mm: float | None = None) -> np.ndarray:
    """Right flank of a space (root arc, fillet, involute; no tip land), gap frame, root to tip edge."""
    samples = sample_profile(spec.tooth_space_profile(), tolerance_mm or 1e-6 * spec.module_mm)
    return samples.points[np.array(samples.label_names()) != "tip"]


def space_half_width_mm(flank: np.ndarray, height_mm: float) -> float:
    """Half-width a straight-sided tool can use at `height_mm` in a space whose right flank is the
    polyline `flank` (gap frame; the left flank is its mirror).

    A tool coming down the axis passes every height above too, so this is the smallest x of the
    flank at or above that height (an undercut flank can bulge inward higher up); above the tip
    edge it is the tip edge's x.
    """
    x, y = flank[:, 0], flank[:, 1]
    candidates = list(x[y >= height_mm])
    crossing = (y[:-1] - height_mm) * (y[1:] - height_mm) < 0.0
    for i in np.nonzero(crossing)[0]:
        t = (height_mm - y[i]) / (y[i + 1] - y[i])
        candidates.append(x[i] + t * (x[i + 1] - x[i]))
    return float(min(candidates)) if candidates else float(x[-1])


def generating_max_diameter_mm(spec: GearSpec, corner_radius_mm: float, target_scallop_mm: float,
                               blank_radius_mm: float) -> float:
    """Largest finishing tool with this corner radius that finishes the gear by generation (either flank tool
    end): the smaller of the tip-mode limit (flat within the rack's tip flat) and the flank-mode limit (no flank
    pass reaches into the design); 0.0 when none fits. Helical gears: any corner 0 < r_t <= rho (a flat end mill
    only for a sharp rack), the diameter within the normal tip flat 2 d_n + 2 r_t."""
    if corner_radius_mm > spec.rack_tip_radius_mm + 1e-12:
        return 0.0
    return GENERATING_MAX_DIAMETER[spec.kind](spec, corner_radius_mm, target_scallop_mm, blank_radius_mm)


def _helical_generating_max_diameter_mm(spec: GearSpec, corner_radius_mm: float, target_scallop_mm: float,
                                        blank_radius_mm: float) -> float:
    """A helical gear: any corner 0 < r_t <= rho (a flat end mill only for a sharp rack), within 2 d_n + 2 r_t."""
    if corner_radius_mm == 0.0 and spec.rack_tip_radius_mm > 0.0:
        return 0.0
    return max(2.0 * rack_corner(spec).normal_corner_offset_mm + 2.0 * corner_radius_mm, 0.0)


def _spur_generating_max_diameter_mm(spec: GearSpec, corner_radius_mm: float, target_scallop_mm: float,
                                     blank_radius_mm: float) -> float:
    """A spur gear: the smaller of the tip-mode and the (either tool end's) flank-mode limit."""
    from spur_cad.cam.strategies.generating_geometry import generating_tool_limits

    limits = generating_tool_limits(spec, corner_radius_mm, target_scallop_mm, blank_radius_mm)
    flank = max(limits.flank_mode_max_diameter_mm, limits.flank_mode_max_diameter_raised_mm)
    largest = min(limits.tip_mode_max_diameter_mm, flank)
    return float(largest) if largest > 2.0 * corner_radius_mm else 0.0


GENERATING_MAX_DIAMETER: dict[GearKind, Callable[[GearSpec, float, float, float], float]] = {
    EXTERNAL_SPUR: _spur_generating_max_diameter_mm, EXTERNAL_HELICAL: _helical_generating_max_diameter_mm,
    INTERNAL_SPUR: _spur_generating_max_diameter_mm}
"""generating_max_diameter_mm for each gear kind (spec, corner radius, target scallop, blank radius)."""


def recommend_tools(spec: GearSpec, blank_radius_mm: float, clearance_mm: float,
                    finishing_tool: Tool | None = None, target_scallop_mm: float = 0.005,
                    strategy=None) -> ToolRecommendations:
    """docs/method.md; what roughing may leave above the root is the finishing `strategy`'s bottom allowance
    (FinishingStrategy.bottom_allowance; None: the job file's default strategy, generating) for the chosen
    finishing tool, else for the largest allowed. The generating limits (docs/cam.md) use the target scallop's
    flank rolls."""
    from spur_cad.cam.strategies.base import TargetScallopParams
    from spur_cad.keys import key_of

    profile = spec.tooth_space_profile()
    max_flat = 2.0 * profile.root_arc_half_angle_rad * spec.root_radius_mm
    max_corner = profile.min_fillet_curvature_radius_mm
    if not np.isfinite(max_corner):  # no fillet (sharp rack on the rolling line): the root corner is sharp
        max_corner = 0.0
    flute = blank_radius_mm - spec.root_radius_mm
    scallop = key_of(TargetScallopParams, "target_scallop_mm")  # advice within the key's range (not a check)
    low, high = scallop.low, scallop.high
    if not (isinstance(low, (int, float)) and isinstance(high, (int, float))):
        raise TypeError("[finishing] target_scallop_mm is bounded by numbers")
    target = min(max(target_scallop_mm, low), high)
    generating = generating_max_diameter_mm(spec, spec.rack_tip_radius_mm, target, blank_radius_mm)
    flat_end_mill = generating_max_diameter_mm(spec, 0.0, target, blank_radius_mm)
    # the finishing limits first (the strategy's allowance without a finishing tool is its largest tool's); the
    # roughing fields follow from the allowance
    limits = ToolRecommendations(max_flat, max_corner, 0.0, 0.0, flute, flute + clearance_mm, generating,
                                 flat_end_mill)
    allowance = (strategy.bottom_allowance(finishing_tool, limits) if strategy is not None
                 else generating_bottom_allowance(finishing_tool, limits))  # the default strategy's rule
    roughing_max = 2.0 * space_half_width_mm(flank_polyline(spec), spec.root_radius_mm + allowance.allowance_mm)
    return dataclasses.replace(limits, plunge_allowance_mm=allowance.allowance_mm,
                               roughing_max_diameter_mm=roughing_max, bottom_allowance_rule=allowance.rule)


def check_tools(spec: GearSpec, recommendations: ToolRecommendations, roughing: Tool | None,
                finishing: Tool | None, pair: GearPair | None = None) -> None:
    """Raise ToolError naming the violated limit and its value (the finishing strategy's own tool rule,
    e.g. the flat width, is its `check_tool`), for tools already checked in themselves (Tool.validate, run once
    when the plan's inputs are made). With the gear's `pair` (its [mate]) a finishing corner above the fillet's
    tightest curvature is accepted when what it leaves in the fillet is below the mate's SAP and clear of the mate's
    tip path (cam.fillet_reach)."""
    rec = recommendations
    if finishing is not None:
        if finishing.kind == "flat":
            _check_flat_finishing(spec, finishing, rec)
        corner = finishing.effective_corner_radius_mm
        if corner > rec.finishing_max_corner_radius_mm + 1e-9 and pair is not None and applies(spec, pair):
            reach = fillet_reach(spec, pair, corner)
            if reach is None or not reach.fits:
                raise ToolError(refusal_text(spec, pair, corner, reach), field="corner_radius_mm",
                                section="tools.finishing")
        elif corner > rec.finishing_max_corner_radius_mm + 1e-9:
            raise ToolError(f"finishing tool corner radius {finishing.effective_corner_radius_mm:.4f} mm exceeds "
                            f"finishing_max_corner_radius_mm = {rec.finishing_max_corner_radius_mm:.4f} mm "
                            "(smallest curvature radius of the root fillet)", field="corner_radius_mm",
                            section="tools.finishing")
        _check_lengths(finishing, "finishing", rec)
    if roughing is not None:
        if roughing.kind != "flat":
            raise ToolError(f"roughing tool kind '{roughing.kind}': roughing uses a flat end mill (docs/method.md)",
                            field="kind", section="tools.roughing")
        if roughing.diameter_mm > rec.roughing_max_diameter_mm + 1e-9:
            raise ToolError(f"roughing tool diameter {roughing.diameter_mm:.4f} mm exceeds roughing_max_diameter_mm = "
                            f"{rec.roughing_max_diameter_mm:.4f} mm (space width at root radius + what "
                            f"{rec.bottom_allowance_rule})", field="diameter_mm", section="tools.roughing")
        _check_lengths(roughing, "roughing", rec)


def _check_flat_finishing(spec: GearSpec, tool: Tool, rec: ToolRecommendations) -> None:
    """A flat end mill finishes only by generation, up to finishing_flat_end_mill_max_diameter_mm (the
    strategies' own checks say why a strategy cannot take it)."""
    largest = rec.finishing_flat_end_mill_max_diameter_mm
    if largest <= 0.0:
        raise ToolError(f"finishing tool is a flat end mill, but no flat end mill can finish this gear "
                        f"(finishing_flat_end_mill_max_diameter_mm = 0: {NO_FLAT_END_MILL[spec.kind](spec)}); the "
                        "finishing tool must have a corner radius (bull_nose or ball)", field="kind",
                        section="tools.finishing")
    if tool.diameter_mm > largest + 1e-9:
        raise ToolError(f"finishing tool is a flat end mill of diameter {tool.diameter_mm:g} mm, above "
                        f"finishing_flat_end_mill_max_diameter_mm = {largest:.4f} mm (the largest flat end mill that "
                        "finishes this gear, by [finishing] strategy = \"generating\": its flat within the rack's tip "
                        "flat and its flank passes clear of the gear); a wider finishing tool must have a corner "
                        "radius (bull_nose or ball)", field="diameter_mm", section="tools.finishing")


def _helical_no_flat_end_mill(spec: GearSpec) -> str:
    return (f"a helical gear is finished by generation with a corner radius 0 < r_t <= the rack tip radius "
            f"rho = {spec.rack_tip_radius_mm:g} mm")


def _spur_no_flat_end_mill(spec: GearSpec) -> str:
    return "by generation its flat finds no room in the rack's tip flat and the flank passes"


NO_FLAT_END_MILL: dict[GearKind, Callable[[GearSpec], str]] = {
    EXTERNAL_SPUR: _spur_no_flat_end_mill, EXTERNAL_HELICAL: _helical_no_flat_end_mill,
    INTERNAL_SPUR: _spur_no_flat_end_mill}
"""Why no flat end mill finishes a gear of each kind (_check_flat_finishing's message)."""


def small_tool_warnings(rec: ToolRecommendations, smallest_end_mill_mm: float, strategy: str,
                        finishing: tuple[str, float], finishing_kind: str | None = None) -> tuple[str, ...]:
    """Warnings for recommended largest tools below [machine] smallest_end_mill_mm (no catalogue tool of that
    kind fits this gear): roughing, finishing for `strategy` (`finishing`: the strategy's own largest tool, its
    name and diameter, FinishingStrategy.largest_tool) and the flat end mill's, unless the job finishes with a
    tool that has a corner (`finishing_kind` bull_nose or ball: the flat end mill's limit is not its concern).
    Limits at 0 (no such tool at all) are errors elsewhere, not warnings."""
    limits: tuple[tuple[str, str, float], ...] = (
              ("roughing tool", "roughing_max_diameter_mm", rec.roughing_max_diameter_mm),
              (f"finishing tool for strategy {strategy}", *finishing))
    if finishing_kind in (None, "flat"):
        limits += (("flat end mill for finishing by generation", "finishing_flat_end_mill_max_diameter_mm",
                    rec.finishing_flat_end_mill_max_diameter_mm),)
    return tuple(f"this gear's largest {what} ({name} = {value:.3f} mm) is below the smallest end mill "
                 f"([machine] smallest_end_mill_mm = {smallest_end_mill_mm:g} mm): check that such a tool can be "
                 "bought" for what, name, value in limits if 0.0 < value < smallest_end_mill_mm)


def check_roughing_reach(roughing: Tool, lowest_level_above_root_mm: float, rec: ToolRecommendations) -> None:
    """The material roughing leaves above the root must be within the finishing strategy's bottom allowance
    (rec.plunge_allowance_mm, the rule in rec.bottom_allowance_rule; docs/method.md); raise ToolError otherwise."""
    if lowest_level_above_root_mm > rec.plunge_allowance_mm + 1e-9:
        raise ToolError(f"roughing tool diameter {roughing.diameter_mm:g} mm leaves "
                        f"{lowest_level_above_root_mm:.3f} mm above the root, more than "
                        f"{rec.bottom_allowance_rule}; use a smaller roughing tool", field="diameter_mm",
                        section="tools.roughing")


def _check_lengths(tool: Tool, role: str, rec: ToolRecommendations) -> None:
    if tool.flute_length_mm and tool.flute_length_mm < rec.required_flute_length_mm:
        raise ToolError(f"{role} tool flute_length_mm = {tool.flute_length_mm:g} is shorter than the "
                        f"required_flute_length_mm = {rec.required_flute_length_mm:.3f} mm", field="flute_length_mm",
                        section=f"tools.{role}")
    if tool.stick_out_mm and tool.stick_out_mm < rec.required_stick_out_mm:
        raise ToolError(f"{role} tool stick_out_mm = {tool.stick_out_mm:g} is shorter than the "
                        f"required_stick_out_mm = {rec.required_stick_out_mm:.3f} mm", field="stick_out_mm",
                        section=f"tools.{role}")
