"""Finishing (METHOD.md 5): both flanks cut downward with a bull-nose (or ball) corner, the root
arc and the tip land with the flat bottom, in transverse stations along X.

Cutter location for a contact point p with unit normal n (into the space, gap frame of the
space): turn the part so that p lies on the vertical through the rotary axis (A = polar angle
of p, relative to the space's index angle); there p' = (0, |p|) and n' = n turned by that
angle. The corner circle's centre is c = p' + r_t n'; the tip centre is d/2 from it toward
the space centre and r_t lower. The contact lies on the corner (not the flat or the side)
when -n' points down and outward; this is checked, not assumed.

Contact points are spaced so that the cusp between two consecutive corner circles is within
the target scallop ((curvature + 1/r_t) l^2 / 8, a proven bound); the flat-bottom sweeps of
root and tip leave r (1/cos(dtheta/2) - 1) between poses, also kept within the scallop.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from spur_cad.cam.ir import Feature, MoveKind, Operation, Toolpath, ToolpathBuilder, relative_path_lengths
from spur_cad.cam.machine import FinishingParams, Machine
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.geometry.sampling import (
    even_arc_length_parameters,
    full_space_points,
    sample_profile,
    segment_parameters,
)
from spur_cad.geometry.spec import GearSpec

PLUNGE_FEED_FRACTION = 0.5


@dataclass(frozen=True)
class TransversePoses:
    """Tool-tip poses of one feature in the transverse plane for space 0: Y, Z (mm), A (deg)."""

    y: np.ndarray
    z: np.ndarray
    a: np.ndarray
    contact_radius: np.ndarray

    def mirrored(self) -> "TransversePoses":
        """The same poses for the mirror-image feature (left flank from right flank)."""
        return TransversePoses(-self.y, self.z, -self.a, self.contact_radius)


GOUGE_TOLERANCE_MM = 1e-5
ROTATION_CANDIDATES = 181


def tool_signed_distance(points: np.ndarray, tip_y: float, tip_z: float, tool: Tool) -> np.ndarray:
    """Signed distance of points (machine Y, Z) from the tool's section (negative inside).

    The section (bottom corners rounded by r_t, sides going up for ever) is the Minkowski sum
    of the strip |Y - tip_y| <= d/2, Z >= tip_z + r_t with a disc of radius r_t, so outside
    that strip the distance is exact: hypot(dy, dz) - r_t.
    """
    r_t, d = tool.corner_radius, tool.flat_width_mm
    dy = np.abs(points[:, 0] - tip_y) - d / 2.0
    dz = tip_z + r_t - points[:, 1]
    outside = np.hypot(np.maximum(dy, 0.0), np.maximum(dz, 0.0))
    inside = np.minimum(np.maximum(dy, dz), 0.0)
    return outside + inside - r_t


def _pose_for_turn(point: np.ndarray, normal: np.ndarray, turn: float, tool: Tool) -> tuple[float, float]:
    """Tip centre (Y, Z) touching `point` with the right corner when the part is turned by `turn`."""
    c, s = math.cos(turn), math.sin(turn)
    p_y, p_z = point[0] * c - point[1] * s, point[0] * s + point[1] * c
    n_y, n_z = normal[0] * c - normal[1] * s, normal[0] * s + normal[1] * c
    r_t = tool.corner_radius
    return p_y + r_t * n_y - tool.flat_width_mm / 2.0, p_z + r_t * n_z - r_t


def _gouge(design: np.ndarray, turn: float, tip: tuple[float, float], tool: Tool) -> float:
    """How deep the tool at `tip` reaches into the design points turned by `turn` (0 if not at all)."""
    c, s = math.cos(turn), math.sin(turn)
    turned = np.stack([design[:, 0] * c - design[:, 1] * s, design[:, 0] * s + design[:, 1] * c], axis=-1)
    return max(0.0, -float(tool_signed_distance(turned, tip[0], tip[1], tool).min()))


def _corner_poses(points: np.ndarray, normals: np.ndarray, tool: Tool, design: np.ndarray) -> TransversePoses:
    """Cutter locations touching right-flank contact points with the tool's right corner.

    The part is turned by the contact's polar angle (METHOD.md 5) when that puts the contact on
    the corner (-n' pointing down and outward) and the tool clear of the rest of the space
    (`design`: dense exact points of the space and its tooth tips). Otherwise (overhanging
    undercut flanks) the turn is searched within the range where the corner touches, nearest
    first; a contact no turn can reach without gouging is an error.
    """
    radius = np.hypot(points[:, 0], points[:, 1])
    polar = np.arctan2(points[:, 0], points[:, 1])  # clockwise polar angle from the space axis
    normal_angle = np.arctan2(normals[:, 1], normals[:, 0])  # counter-clockwise from +x
    # Turning the part counter-clockwise by psi turns the normal to normal_angle + psi, which must
    # lie in [90, 180] deg (n' pointing up-left: the right corner touches).
    lowest = np.mod(np.pi / 2 - normal_angle + np.pi, 2 * np.pi) - np.pi
    highest = lowest + np.pi / 2
    turns, ys, zs = np.empty(len(points)), np.empty(len(points)), np.empty(len(points))
    for i, (p, n) in enumerate(zip(points, normals)):
        preferred = float(np.clip(polar[i], lowest[i], highest[i]))
        tip = _pose_for_turn(p, n, preferred, tool)
        if _gouge(design, preferred, tip, tool) > GOUGE_TOLERANCE_MM:
            candidates = np.linspace(lowest[i], highest[i], ROTATION_CANDIDATES)
            for turn in candidates[np.argsort(np.abs(candidates - preferred))]:
                tip = _pose_for_turn(p, n, float(turn), tool)
                if _gouge(design, float(turn), tip, tool) <= GOUGE_TOLERANCE_MM:
                    preferred = float(turn)
                    break
            else:
                raise ToolError(f"finishing: the flank point at radius {radius[i]:.4f} mm cannot be reached by the "
                                f"tool's corner without gouging (undercut); use a tool with a smaller diameter or "
                                "corner radius")
        turns[i], (ys[i], zs[i]) = preferred, tip
    return TransversePoses(ys, zs, np.degrees(turns), radius)


def _flat_sweep(radius: float, theta_start: float, theta_end: float, y_start: float, y_end: float,
                scallop: float) -> TransversePoses:
    """Flat bottom tangent to a circle about the axis at its top while the part turns (root or tip)."""
    step = 2.0 * math.acos(1.0 / (1.0 + scallop / radius))  # leftover r (1/cos(step/2) - 1) = scallop
    n = max(1, math.ceil(abs(theta_end - theta_start) / step))
    theta = np.linspace(theta_start, theta_end, n + 1)
    fraction = np.linspace(0.0, 1.0, n + 1)
    return TransversePoses(y_start + (y_end - y_start) * fraction, np.full(n + 1, radius), np.degrees(theta),
                           np.full(n + 1, radius))


@dataclass(frozen=True)
class SpacePoses:
    """The finishing poses of one tooth space (space 0), in cutting order within each feature."""

    right_flank: TransversePoses  # tip edge -> root, descending
    root: TransversePoses  # from the right fillet's end to the left's (Y and A together)
    left_flank: TransversePoses  # tip edge -> root, descending
    tip: TransversePoses  # tip land from this space's left edge to the next space's right edge

    @property
    def points_per_flank(self) -> int:
        return len(self.right_flank.y)


def space_poses(spec: GearSpec, tool: Tool, scallop_mm: float,
                contact_spacing_mm: float | None = None) -> SpacePoses:
    """All transverse poses of one space. `contact_spacing_mm` (fixed arc-length spacing) reproduces
    the reference process's sampling for comparison; by default the scallop bound decides."""
    profile = spec.tooth_space_profile()
    r_t, d = tool.corner_radius, tool.flat_width_mm
    points, normals = [], []
    for label in ("involute", "fillet"):  # tip -> root
        segment = profile.segment(label)
        if segment is None or segment.end <= segment.start:
            continue
        if contact_spacing_mm is None:
            params = segment_parameters(segment, scallop_mm, extra_curvature=1.0 / r_t)
        else:
            params = even_arc_length_parameters(segment, contact_spacing_mm)
        params = params[::-1]
        if points:  # the junction is shared with the previous segment
            params = params[1:]
        points.append(segment.points(params))
        normals.append(segment.normals(params))
    right = _corner_poses(np.concatenate(points), np.concatenate(normals), tool, _space_design_points(spec))
    v = profile.root_arc_half_angle_rad
    root = _flat_sweep(spec.root_radius_mm, v, -v, -d / 2.0, d / 2.0, scallop_mm)
    tip_edge = profile.segment("tip").start  # clockwise polar angle of the right flank's tip edge
    pitch = 2.0 * math.pi / spec.teeth
    tip = _flat_sweep(spec.tip_radius_mm, -tip_edge, tip_edge - pitch, -d / 2.0, d / 2.0, scallop_mm)
    return SpacePoses(right, root, right.mirrored(), tip)


def _space_design_points(spec: GearSpec) -> np.ndarray:
    """Dense exact points of tooth space 0 (both halves, tip lands to the tooth centres)."""
    return full_space_points(sample_profile(spec.tooth_space_profile(), 2e-5 * spec.module_mm))



def station_step_mm(tool: Tool, params: FinishingParams) -> float:
    """X step between stations: the given step-over, else from the target scallop h with the flat
    width at the root (h = d/2 - sqrt((d/2)^2 - (dx/2)^2)) and the corner radius elsewhere."""
    if params.step_over_mm > 0.0:
        return params.step_over_mm
    h = params.target_scallop_mm
    candidates = [2.0 * math.sqrt(h * (2.0 * tool.corner_radius - h))]
    if tool.flat_width_mm > 2.0 * h:
        candidates.append(2.0 * math.sqrt(h * (tool.flat_width_mm - h)))
    return min(candidates)


def station_positions(face_width_mm: float, step_mm: float) -> np.ndarray:
    """Stations from the front face (X = 0) to the back face (X = b), evenly spaced, step <= step_mm."""
    n = max(1, math.ceil(face_width_mm / step_mm - 1e-12))
    return np.linspace(0.0, face_width_mm, n + 1)


def safe_height_mm(blank_radius_mm: float, machine: Machine) -> float:
    """Z at which the tool may index A: above the blank by the clearance."""
    return blank_radius_mm + machine.clearance_mm


def finishing_toolpath(spec: GearSpec, tool: Tool, machine: Machine, params: FinishingParams,
                       blank_radius_mm: float, *, contact_spacing_mm: float | None = None) -> Toolpath:
    """The finishing operation as IR (pure function)."""
    params.validate()
    machine.validate()
    tool.validate("finishing")
    poses = space_poses(spec, tool, params.target_scallop_mm, contact_spacing_mm)
    feed = tool.feed_mm_min(machine)
    safe_z = safe_height_mm(blank_radius_mm, machine)
    stations = station_positions(spec.face_width_mm, station_step_mm(tool, params))
    builder = ToolpathBuilder(Operation.FINISHING, tool.tool_number, tool.spindle_rpm(machine))
    if params.strategy == "along_x":
        _along_x(builder, spec, tool, machine, poses, feed, safe_z)
        builder.warnings.append("finishing strategy along_x: each contact line is cut by one pass along the face "
                                "width; expect feed marks parallel to the contact lines")
    else:
        _perimeter(builder, spec, machine, poses, stations, feed, safe_z)
    return apply_inverse_time(builder.build(), machine)


def _space_sequence(poses: SpacePoses, safe_z: float):
    """(kind, y, z, a_rel, feature, plunge) rows of one space at one station, in cutting order."""
    rows = []

    def approach(p: TransversePoses, feature: Feature):
        rows.append((MoveKind.RAPID, p.y[0], safe_z, p.a[0], Feature.NONE, False))
        rows.append((MoveKind.LINEAR, p.y[0], p.z[0], p.a[0], Feature.NONE, True))
        for y, z, a in zip(p.y[1:], p.z[1:], p.a[1:]):
            rows.append((MoveKind.LINEAR, y, z, a, feature, False))

    def retract():
        _, y, _, a, _, _ = rows[-1]
        rows.append((MoveKind.LINEAR, y, safe_z, a, Feature.NONE, False))

    approach(poses.right_flank, Feature.RIGHT_FLANK)
    for y, z, a in zip(poses.root.y[1:], poses.root.z[1:], poses.root.a[1:]):
        rows.append((MoveKind.LINEAR, y, z, a, Feature.ROOT, False))
    retract()
    approach(poses.left_flank, Feature.LEFT_FLANK)
    retract()
    approach(poses.tip, Feature.TIP)
    retract()
    return rows


def _perimeter(builder: ToolpathBuilder, spec: GearSpec, machine: Machine, poses: SpacePoses,
               stations: np.ndarray, feed: float, safe_z: float) -> None:
    """Every station: once around the gear, space by space; stations tiled with numpy."""
    rows = _space_sequence(poses, safe_z)
    kind = np.array([r[0] for r in rows], dtype=np.int8)
    y = np.array([r[1] for r in rows])
    z = np.array([r[2] for r in rows])
    a_rel = np.array([r[3] for r in rows])
    feature = np.array([r[4] for r in rows], dtype=np.int8)
    plunge = np.array([r[5] for r in rows])
    teeth, pitch_deg = spec.teeth, 360.0 / spec.teeth
    per_space, per_station = len(rows), len(rows) * teeth
    n_total = per_station * len(stations)
    space_index = np.tile(np.repeat(np.arange(teeth), per_space), len(stations))
    station_index = np.repeat(np.arange(len(stations)), per_station)
    turns = station_index * teeth if machine.rotary_continuous else np.zeros(n_total, int)
    # Space k is brought up by A = -k * pitch; continuous tables keep turning the same way.
    a = np.tile(a_rel, teeth * len(stations)) - (space_index + turns) * pitch_deg
    feeds = np.where(np.tile(plunge, teeth * len(stations)), PLUNGE_FEED_FRACTION * feed, feed)
    feeds = np.where(np.tile(kind, teeth * len(stations)) == MoveKind.RAPID, np.nan, feeds)
    builder.extend(np.tile(kind, teeth * len(stations)), stations[station_index],
                   np.tile(y, teeth * len(stations)), np.tile(z, teeth * len(stations)), a, feeds, False,
                   space_index, station_index, np.tile(feature, teeth * len(stations)))


def _along_x(builder: ToolpathBuilder, spec: GearSpec, tool: Tool, machine: Machine, poses: SpacePoses,
             feed: float, safe_z: float) -> None:
    """Second strategy: one pass along X per contact pose, zig-zag, stepping between poses off the part."""
    x_front = -(tool.diameter_mm / 2.0 + machine.clearance_mm)
    x_back = spec.face_width_mm + tool.diameter_mm / 2.0 + machine.clearance_mm
    pitch_deg = 360.0 / spec.teeth
    for k in range(spec.teeth):
        base = -k * pitch_deg
        x_here = x_front
        for feature, p in ((Feature.RIGHT_FLANK, _join(poses.right_flank, poses.root)),
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


def _join(first: TransversePoses, second: TransversePoses) -> TransversePoses:
    return TransversePoses(np.concatenate([first.y, second.y[1:]]), np.concatenate([first.z, second.z[1:]]),
                           np.concatenate([first.a, second.a[1:]]),
                           np.concatenate([first.contact_radius, second.contact_radius[1:]]))


def apply_inverse_time(path: Toolpath, machine: Machine) -> Toolpath:
    """Convert linear moves that turn A into inverse-time feeds (1/min) from the relative path length,
    limited by the rotary axis's maximum speed."""
    if len(path) == 0:
        return path
    prev = lambda v: np.concatenate([[v[0]], v[:-1]])  # noqa: E731 - start pose of each move
    moving_a = (path.kind == MoveKind.LINEAR) & (np.abs(path.a - prev(path.a)) > 1e-12)
    if not moving_a.any():
        return path
    idx = np.nonzero(moving_a)[0]
    length = relative_path_lengths(prev(path.x)[idx], prev(path.y)[idx], prev(path.z)[idx], prev(path.a)[idx],
                                   path.x[idx], path.y[idx], path.z[idx], path.a[idx])
    minutes = np.maximum(length / path.feed[idx], np.abs(path.a[idx] - prev(path.a)[idx])
                         / machine.max_rotary_speed_deg_min)
    feed = path.feed.copy()
    feed[idx] = 1.0 / minutes
    inverse = path.inverse_time.copy()
    inverse[idx] = True
    return Toolpath(path.kind, path.x, path.y, path.z, path.a, feed, inverse, path.space, path.station,
                    path.feature, path.operation, path.tool_number, path.spindle_rpm, path.warnings)
