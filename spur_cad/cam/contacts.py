"""Finishing contacts in the transverse plane (docs/method.md, perimeter finishing): where the tool
touches each flank with its corner, the root arc and the tip land with its flat bottom, and the
X stations across the face width. The finishing strategies (spur_cad.cam.strategies) arrange
these poses into toolpaths.

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

from spur_cad.cam.tools import Tool, ToolError
from spur_cad.geometry.frames import turn_point, turn_points
from spur_cad.geometry.modifications import SIDES, FlankModifications, modified_tooth_space_profile
from spur_cad.geometry.profile import ToothSpaceProfile
from spur_cad.geometry.sampling import (
    even_arc_length_parameters,
    full_space_points,
    sample_profile,
    segment_parameters,
)
from spur_cad.geometry.spec import GearSpec


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

    def joined(self, following: "TransversePoses") -> "TransversePoses":
        """These poses, then `following`'s without its first (shared) pose."""
        return TransversePoses(np.concatenate([self.y, following.y[1:]]), np.concatenate([self.z, following.z[1:]]),
                               np.concatenate([self.a, following.a[1:]]),
                               np.concatenate([self.contact_radius, following.contact_radius[1:]]))


GOUGE_TOLERANCE_MM = 1e-5
ROTATION_CANDIDATES = 181


def tool_signed_distance(points: np.ndarray, tip_y: float, tip_z: float, tool: Tool) -> np.ndarray:
    """Signed distance of points (machine Y, Z) from the tool's section (negative inside).

    The section (bottom corners rounded by r_t, sides going up for ever) is the Minkowski sum
    of the strip |Y - tip_y| <= d/2, Z >= tip_z + r_t with a disc of radius r_t, so outside
    that strip the distance is exact: hypot(dy, dz) - r_t.
    """
    r_t, d = tool.effective_corner_radius_mm, tool.flat_width_mm
    dy = np.abs(points[:, 0] - tip_y) - d / 2.0
    dz = tip_z + r_t - points[:, 1]
    outside = np.hypot(np.maximum(dy, 0.0), np.maximum(dz, 0.0))
    inside = np.minimum(np.maximum(dy, dz), 0.0)
    return outside + inside - r_t


def _pose_for_turn(point: np.ndarray, normal: np.ndarray, turn: float, tool: Tool) -> tuple[float, float]:
    """Tip centre (Y, Z) touching `point` with the right corner when the part is turned by `turn`."""
    p_y, p_z = turn_point(point[0], point[1], turn)
    n_y, n_z = turn_point(normal[0], normal[1], turn)
    r_t = tool.effective_corner_radius_mm
    return p_y + r_t * n_y - tool.flat_width_mm / 2.0, p_z + r_t * n_z - r_t


def _gouge(design: np.ndarray, turn: float, tip: tuple[float, float], tool: Tool) -> float:
    """How deep the tool at `tip` reaches into the design points turned by `turn` (0 if not at all)."""
    turned = turn_points(design, turn)
    return max(0.0, -float(tool_signed_distance(turned, tip[0], tip[1], tool).min()))


def _corner_poses(points: np.ndarray, normals: np.ndarray, tool: Tool, design: np.ndarray) -> TransversePoses:
    """Cutter locations touching right-flank contact points with the tool's right corner.

    The part is turned by the contact's polar angle (docs/method.md) when that puts the contact on
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
                                "corner radius", field="diameter_mm", section="tools.finishing")
        turns[i], (ys[i], zs[i]) = preferred, tip
    return TransversePoses(ys, zs, np.degrees(turns), radius)


def _flat_sweep_steps(radius: float, angle: float, scallop: float) -> int:
    """Poses - 1 of a flat sweep over `angle`: leftover r (1/cos(step/2) - 1) = scallop between poses."""
    step = 2.0 * math.acos(1.0 / (1.0 + scallop / radius))
    return max(1, math.ceil(abs(angle) / step))


def _flat_sweep(radius: float, theta_start: float, theta_end: float, y_start: float, y_end: float,
                scallop: float) -> TransversePoses:
    """Flat bottom tangent to a circle about the axis at its top while the part turns (root or tip)."""
    n = _flat_sweep_steps(radius, theta_end - theta_start, scallop)
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


@dataclass(frozen=True)
class ContactCounts:
    """How many poses `space_poses` makes per feature, counted without computing the poses."""

    flank: int
    root: int
    tip: int

    @property
    def per_space(self) -> int:
        """Poses of one whole space (both flanks, root, tip land)."""
        return 2 * self.flank + self.root + self.tip


def contact_counts(spec: GearSpec, tool: Tool, scallop_mm: float,
                   contact_spacing_mm: float | None = None) -> ContactCounts:
    """The numbers of poses space_poses would make (cheap: parameters only, no tool placement)."""
    profile = spec.tooth_space_profile()
    flank = 0
    for label in ("involute", "fillet"):
        segment = profile.segment(label)
        if segment is None or segment.end <= segment.start:
            continue
        if contact_spacing_mm is None:
            params = segment_parameters(segment, scallop_mm, extra_curvature=1.0 / tool.effective_corner_radius_mm)
        else:
            params = even_arc_length_parameters(segment, contact_spacing_mm)
        flank += len(params) - (1 if flank else 0)
    v = profile.root_arc_half_angle_rad
    tip_edge = profile.tip.start
    tip_angle = 2.0 * tip_edge - 2.0 * math.pi / spec.teeth
    return ContactCounts(flank, _flat_sweep_steps(spec.root_radius_mm, 2.0 * v, scallop_mm) + 1,
                         _flat_sweep_steps(spec.tip_radius_mm, tip_angle, scallop_mm) + 1)


def space_poses(spec: GearSpec, tool: Tool, scallop_mm: float,
                contact_spacing_mm: float | None = None) -> SpacePoses:
    """All transverse poses of one space. `contact_spacing_mm` (fixed arc-length spacing) reproduces
    the reference process's sampling for comparison; by default the scallop bound decides."""
    profile = spec.tooth_space_profile()
    right = flank_poses(spec, profile, tool, scallop_mm, contact_spacing_mm)
    return _with_root_and_tip(spec, profile, tool, scallop_mm, right, right.mirrored(), profile)


def modified_space_poses(spec: GearSpec, tool: Tool, scallop_mm: float, modifications: FlankModifications,
                         x_face_mm: float, contact_spacing_mm: float | None = None) -> SpacePoses:
    """The poses of one space touching the flanks modified by `modifications` at face position X: each side's
    contacts on its modified tooth-space profile (geometry.modifications.modified_tooth_space_profile: the involute
    moved along its normal by the removal at its roll length and X, the fillet faded as the generating strategy's
    tip passes cut it), the left side's mirrored. The root arc is unchanged; the tip sweep spans the land between
    the two modified flanks' tip edges."""
    design = spec.tooth_space_profile()
    profiles = {side: modified_tooth_space_profile(design, modifications.side(side), x_face_mm) for side in SIDES}
    right = flank_poses(spec, profiles["right"], tool, scallop_mm, contact_spacing_mm)
    left = flank_poses(spec, profiles["left"], tool, scallop_mm, contact_spacing_mm).mirrored()
    return _with_root_and_tip(spec, design, tool, scallop_mm, right, left, profiles["left"], profiles["right"])


def flank_poses(spec: GearSpec, profile: ToothSpaceProfile, tool: Tool, scallop_mm: float,
                contact_spacing_mm: float | None = None) -> TransversePoses:
    """Right-flank poses (tip edge -> root) on the involute and fillet segments of `profile` (the design's, or a
    modified one whose involute is split at the reliefs' starts); a junction of two segments appears once (at a
    linear relief's kink with the upper segment's normal: a pose with each normal there changed the simulated
    leftover near it by 0.02 um)."""
    r_t = tool.effective_corner_radius_mm
    points: list[np.ndarray] = []
    normals: list[np.ndarray] = []
    for segment in reversed(profile.segments):  # tip -> root
        if segment.label not in ("involute", "fillet") or segment.end <= segment.start:
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
    return _corner_poses(np.concatenate(points), np.concatenate(normals), tool,
                         _space_design_points(profile, spec.module_mm))


def _with_root_and_tip(spec: GearSpec, profile: ToothSpaceProfile, tool: Tool, scallop_mm: float,
                       right: TransversePoses, left: TransversePoses, left_profile: ToothSpaceProfile,
                       right_profile: ToothSpaceProfile | None = None) -> SpacePoses:
    """The space's poses: the flanks' and the flat sweeps of the root arc and of the tip land between this space's
    left tip edge and the next space's right one (each side's profile gives its tip edge)."""
    d = tool.flat_width_mm
    v = profile.root_arc_half_angle_rad
    root = _flat_sweep(spec.root_radius_mm, v, -v, -d / 2.0, d / 2.0, scallop_mm)
    left_edge = left_profile.tip.start  # clockwise polar angle of the flank's tip edge
    right_edge = (right_profile or left_profile).tip.start
    pitch = 2.0 * math.pi / spec.teeth
    tip = _flat_sweep(spec.tip_radius_mm, -left_edge, right_edge - pitch, -d / 2.0, d / 2.0, scallop_mm)
    return SpacePoses(right, root, left, tip)


def _space_design_points(profile: ToothSpaceProfile, module_mm: float) -> np.ndarray:
    """Dense exact points of a tooth space of `profile` (both halves, tip lands to the tooth centres)."""
    return full_space_points(sample_profile(profile, 2e-5 * module_mm))


def station_step_mm(tool: Tool, target_scallop_mm: float, step_over_mm: float = 0.0) -> float:
    """X step between stations: the given step-over, else from the target scallop h with the flat
    width at the root (h = d/2 - sqrt((d/2)^2 - (dx/2)^2)) and the corner radius elsewhere."""
    if step_over_mm > 0.0:
        return step_over_mm
    h = target_scallop_mm
    candidates = [2.0 * math.sqrt(h * (2.0 * tool.effective_corner_radius_mm - h))]
    if tool.flat_width_mm > 2.0 * h:
        candidates.append(2.0 * math.sqrt(h * (tool.flat_width_mm - h)))
    return min(candidates)


def station_positions(face_width_mm: float, step_mm: float) -> np.ndarray:
    """Stations from the front face (X = 0) to the back face (X = b), evenly spaced, step <= step_mm."""
    n = max(1, math.ceil(face_width_mm / step_mm - 1e-12))
    return np.linspace(0.0, face_width_mm, n + 1)
