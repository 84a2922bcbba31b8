"""Along-X finishing: one pass along the face width per transverse contact pose (A fixed during
each pass), zig-zag, stepping between poses beside the part.

The order in which a space's pass groups are cut is a parameter (`pass_order`, `along_x_passes`), so that a
strategy cutting the same passes in another order (say the tip land first) is a subclass naming its order,
and every message names the strategy actually used.
"""

from __future__ import annotations

from dataclasses import dataclass

from spur_cad.cam.common import PLUNGE_FEED_FRACTION, apply_inverse_time, safe_height_mm
from spur_cad.cam.contacts import (
    SpacePoses,
    TransversePoses,
    contact_counts,
    space_poses,
    station_positions,
    station_step_mm,
)
from spur_cad.cam.estimate import Estimate
from spur_cad.cam.ir import Feature, MoveKind, Toolpath, ToolpathBuilder
from spur_cad.cam.machine import Machine
from spur_cad.cam.strategies.base import (
    ContactStrategy,
    FinishingResult,
    ScallopParams,
    check_flat_fits_root_arc,
    estimate_by_generating,
    finishing_builder,
)
from spur_cad.cam.tools import Tool
from spur_cad.geometry.modifications import FlankModifications
from spur_cad.geometry.spec import GearSpec

PassOrder = tuple[Feature, ...]
"""The order of a space's pass groups: each of Feature.RIGHT_FLANK (the right flank, then the root after it),
Feature.LEFT_FLANK and Feature.TIP (the tip land) once."""

ALONG_X_ORDER: PassOrder = (Feature.RIGHT_FLANK, Feature.LEFT_FLANK, Feature.TIP)
"""along_x's order: the right flank and the root, the left flank, the tip land."""


def along_x_warning(strategy: str) -> str:
    """The warning every along-X toolpath carries, naming the strategy that made it."""
    return (f"finishing strategy {strategy}: each contact line is cut by one pass along the face width; "
            "expect feed marks parallel to the contact lines")


@dataclass(frozen=True)
class AlongXParams(ScallopParams):
    """[finishing] keys the along-X strategy uses (step_over_mm only for the reported station step)."""


class AlongXStrategy(ContactStrategy):
    """See the module docstring. A subclass with another `name` and `pass_order` cuts the same passes in its
    own order."""

    name = "along_x"
    description = "one pass along X per contact pose, A fixed during each pass"
    params_type = AlongXParams
    simultaneous_rotary = True  # the steps between poses beside the part turn A at feed
    helical = False  # transverse contacts of a spur gear
    follows_modifications = False  # its contacts lie on the design flank
    corrects_slopes = False
    lying_flat = False
    pass_order: PassOrder = ALONG_X_ORDER

    def check_tool(self, spec: GearSpec, tool: Tool) -> None:
        check_flat_fits_root_arc(spec, tool, self.name)

    def estimate_moves(self, spec: GearSpec, tool: Tool, params: AlongXParams) -> int:
        counts = contact_counts(spec, tool, params.target_scallop_mm)
        poses = (counts.flank + counts.root - 1) + counts.flank + counts.tip
        return spec.teeth * (2 * poses + 6)

    def estimate(self, spec: GearSpec, tool: Tool, machine: Machine, params: AlongXParams,
                 blank_radius_mm: float) -> Estimate:
        return estimate_by_generating(self, spec, tool, machine, params, blank_radius_mm)

    def generate(self, spec: GearSpec, tool: Tool, machine: Machine, params: AlongXParams, blank_radius_mm: float,
                 modifications: FlankModifications | None = None,
                 profile_tolerance_mm: float = 0.001) -> tuple[Toolpath, FinishingResult]:
        """The passes on the design flanks (`modifications` are never given: follows_modifications is False)."""
        return along_x_passes(self.name, self.pass_order, spec, tool, machine, params, blank_radius_mm)


def along_x_passes(strategy: str, order: PassOrder, spec: GearSpec, tool: Tool, machine: Machine,
                   params: AlongXParams, blank_radius_mm: float) -> tuple[Toolpath, FinishingResult]:
    """The along-X toolpath and result of `strategy` (its name in the result and the warning), the pass groups of
    each space cut in `order`."""
    builder = finishing_builder(tool, machine)
    poses = space_poses(spec, tool, params.target_scallop_mm)
    _passes(builder, spec, tool, machine, pass_groups(poses, order), tool.feed_mm_min(machine),
            safe_height_mm(blank_radius_mm, machine))
    builder.warnings.append(along_x_warning(strategy))
    stations = station_positions(spec.face_width_mm,
                                 station_step_mm(tool, params.target_scallop_mm, params.step_over_mm))
    step = float(stations[1] - stations[0]) if len(stations) > 1 else 0.0
    result = FinishingResult(strategy, params, poses, 1, step, stations[:0])
    return apply_inverse_time(builder.build(), machine), result


def pass_groups(poses: SpacePoses, order: PassOrder) -> tuple[tuple[Feature, TransversePoses], ...]:
    """A space's pass groups in `order` (see PassOrder): (feature, poses), the root joined to the right flank."""
    groups = {Feature.RIGHT_FLANK: poses.right_flank.joined(poses.root), Feature.LEFT_FLANK: poses.left_flank,
              Feature.TIP: poses.tip}
    if sorted(order) != sorted(groups):
        raise ValueError(f"a pass order names each of {', '.join(f.name for f in groups)} once, got "
                         f"{', '.join(f.name for f in order)}")
    return tuple((feature, groups[feature]) for feature in order)


def _passes(builder: ToolpathBuilder, spec: GearSpec, tool: Tool, machine: Machine,
            groups: tuple[tuple[Feature, TransversePoses], ...], feed: float, safe_z: float) -> None:
    """One pass along X per contact pose, zig-zag, stepping between poses off the part, group by group."""
    x_front = -(tool.diameter_mm / 2.0 + machine.clearance_mm)
    x_back = spec.face_width_mm + tool.diameter_mm / 2.0 + machine.clearance_mm
    pitch_deg = 360.0 / spec.teeth
    for k in range(spec.teeth):
        base = -k * pitch_deg
        x_here = x_front
        for feature, p in groups:
            builder.move(MoveKind.RAPID, x_here, p.y[0], safe_z, base + p.a[0], space=k)
            builder.move(MoveKind.LINEAR, x_here, p.y[0], p.z[0], base + p.a[0], PLUNGE_FEED_FRACTION * feed,
                         space=k)
            for i, (y, z, a) in enumerate(zip(p.y, p.z, p.a)):
                if i > 0:  # step to the next contact pose beside the part
                    builder.move(MoveKind.LINEAR, x_here, y, z, base + a, feed, space=k, feature=feature)
                x_here = x_back if x_here == x_front else x_front
                builder.move(MoveKind.LINEAR, x_here, y, z, base + a, feed, space=k, feature=feature)
            builder.move(MoveKind.LINEAR, x_here, p.y[-1], safe_z, base + p.a[-1], feed, space=k)
