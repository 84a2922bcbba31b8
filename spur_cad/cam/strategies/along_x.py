"""Along-X finishing: one pass along the face width per transverse contact pose (A fixed during
each pass), zig-zag, stepping between poses beside the part."""

from __future__ import annotations

from dataclasses import dataclass

from spur_cad.cam.common import PLUNGE_FEED_FRACTION, apply_inverse_time, safe_height_mm
from spur_cad.cam.contacts import SpacePoses, contact_counts, space_poses, station_positions, station_step_mm
from spur_cad.cam.ir import Feature, MoveKind, Toolpath, ToolpathBuilder
from spur_cad.cam.machine import Machine
from spur_cad.cam.strategies.base import (
    ContactStrategy,
    FinishingResult,
    ScallopParams,
    check_flat_fits_root_arc,
    finishing_builder,
)
from spur_cad.cam.tools import Tool
from spur_cad.geometry.spec import GearSpec

ALONG_X_WARNING = ("finishing strategy along_x: each contact line is cut by one pass along the face width; "
                   "expect feed marks parallel to the contact lines")


@dataclass(frozen=True)
class AlongXParams(ScallopParams):
    """[finishing] keys the along-X strategy uses (step_over_mm only for the reported station step)."""


class AlongXStrategy(ContactStrategy):
    """See the module docstring."""

    name = "along_x"
    description = "one pass along X per contact pose, A fixed during each pass"
    params_type = AlongXParams
    simultaneous_rotary = True  # the steps between poses beside the part turn A at feed

    def check_tool(self, spec: GearSpec, tool: Tool) -> None:
        check_flat_fits_root_arc(spec, tool)

    def estimate_moves(self, spec: GearSpec, tool: Tool, params: AlongXParams) -> int:
        params.validate()
        counts = contact_counts(spec, tool, params.target_scallop_mm)
        poses = (counts.flank + counts.root - 1) + counts.flank + counts.tip
        return spec.teeth * (2 * poses + 6)

    def generate(self, spec: GearSpec, tool: Tool, machine: Machine, params: AlongXParams,
                 blank_radius_mm: float) -> tuple[Toolpath, FinishingResult]:
        builder = finishing_builder(tool, machine, params)
        poses = space_poses(spec, tool, params.target_scallop_mm)
        _passes(builder, spec, tool, machine, poses, tool.feed_mm_min(machine),
                safe_height_mm(blank_radius_mm, machine))
        builder.warnings.append(ALONG_X_WARNING)
        stations = station_positions(spec.face_width_mm,
                                     station_step_mm(tool, params.target_scallop_mm, params.step_over_mm))
        step = float(stations[1] - stations[0]) if len(stations) > 1 else 0.0
        result = FinishingResult(self.name, params, poses, 1, step, stations[:0])
        return apply_inverse_time(builder.build(), machine), result


def _passes(builder: ToolpathBuilder, spec: GearSpec, tool: Tool, machine: Machine, poses: SpacePoses,
            feed: float, safe_z: float) -> None:
    """One pass along X per contact pose, zig-zag, stepping between poses off the part."""
    x_front = -(tool.diameter_mm / 2.0 + machine.clearance_mm)
    x_back = spec.face_width_mm + tool.diameter_mm / 2.0 + machine.clearance_mm
    pitch_deg = 360.0 / spec.teeth
    for k in range(spec.teeth):
        base = -k * pitch_deg
        x_here = x_front
        for feature, p in ((Feature.RIGHT_FLANK, poses.right_flank.joined(poses.root)),
                           (Feature.LEFT_FLANK, poses.left_flank), (Feature.TIP, poses.tip)):
            builder.move(MoveKind.RAPID, x_here, p.y[0], safe_z, base + p.a[0], space=k)
            builder.move(MoveKind.LINEAR, x_here, p.y[0], p.z[0], base + p.a[0], PLUNGE_FEED_FRACTION * feed,
                         space=k)
            for i, (y, z, a) in enumerate(zip(p.y, p.z, p.a)):
                if i > 0:  # step to the next contact pose beside the part
                    builder.move(MoveKind.LINEAR, x_here, y, z, base + a, feed, space=k, feature=feature)
                x_here = x_back if x_here == x_front else x_front
                builder.move(MoveKind.LINEAR, x_here, y, z, base + a, feed, space=k, feature=feature)
            builder.move(MoveKind.LINEAR, x_here, p.y[-1], safe_z, base + p.a[-1], feed, space=k)
