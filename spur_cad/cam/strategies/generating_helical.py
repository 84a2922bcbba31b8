"""Finishing by generation for helical gears (docs/cam.md, "Helical gears"): A clamped, one straight 3-D pass per
rack position, along the rack tooth.

The generating rack of a helical gear is a prism along the tooth direction d, inclined at the
helix angle beta in the pitch plane. With A = phi (the roll) the machine sees it with its tooth
axis vertical; in the transverse section at X it is the transverse rack moved by -r phi - X h tan(beta)
(h = +1 right hand, -1 left), because section X of the part is section 0 turned by
X h tan(beta) / r: section X sees the rack at roll phi + X h tan(beta) / r ("effective roll").
A pass turned by a further gamma about X runs along d turned by gamma:
dY/dX = -h tan(beta) cos(gamma), dZ/dX = -h tan(beta) sin(gamma).

- **No gouge, in 3-D.** A tool swept along the prism's direction stays inside the prism when the
  tool does at one point of the pass: its projection along d must lie inside the rack's *normal*
  section (flanks at alpha_n, tip rounds of radius rho). Every pass is checked that way against
  the rack tooth it plays (`rack_clearance_mm`, exact signed distance to the rounded wedge).
  The rack at any roll lies outside the gear, so such a pass cannot cut into the gear anywhere.
- **Flank mode.** gamma = +-alpha_t (transverse pressure angle) makes the rack's flank plane
  vertical; its trace in the XY plane runs at the base helix angle (dY/dX = -h tan(beta_b)) through
  Y = -+r_b t at X = 0, so every transverse section sees the spur flank pass at roll t shifted by
  its turn. The tool's side lies on that plane (axis R sqrt(1 + tan^2 beta_b) from the trace along
  Y) and its end is the lowest at which the tool still lies inside the rack tooth (bisection on
  the clearance). Rolls are evenly spaced so that the generating flats leave at most the target
  at the largest roll any section sees (the flat deviation grows with the roll).
- **Tip mode (fillets and root)** with A = phi and the pass along d (gamma = 0): the tool's projection
  along d is its own profile, so in the normal section it plays a rack round of radius r_t <= rho.
  With r_t = rho its corner *is* the rack's round over the whole pass. Per roll: the tool's right
  corner on the right round, its left corner on the left round, and, where the tip flat generates
  the root somewhere over the face width, flat passes between them. Rolls are evenly spaced so that
  the cusps left by the elliptic transverse round stay within the target.
  A smaller corner (0 < r_t < rho) is placed as for spur gears, internally tangent to the round at a
  normal-section angle b (from straight down toward the flank): corner centre at the round's centre
  + (rho - r_t)(sin b, -cos b), so the tool stays inside the rack tooth over the whole pass. A pass
  along d touches the round along one line only, while the rack's contact line crosses the round:
  section X at roll phi touches it at the angle b with r phi_e = d_1 + rho sin(b) (1/cos(beta) -
  cos(beta)) - B cos(beta) tan(b), phi_e = phi + X h tan(beta) / r. So each roll gets one pass per
  contact of a fixed grid (`corner_contacts`: angles over [0, 90 deg - alpha_n], then a few points
  of the flank line just above T, where the smaller corner falls away from the line faster than the
  round) that some section sees within a roll spacing of that roll, the grid spaced so that the
  tool leaves at most `CORNER_GAP_SHARE` of the target between its contacts, the rolls spaced for
  the rest.
  A sharp rack (rho = 0) is played by a flat end mill; its corner leaves wedge-shaped cusps, so the
  rolls are spaced for the target / sqrt(2) measured to the outline (thicker along the normal).
- Rolls (and land angles) cover what every section needs: the spur ranges widened by the turn of
  the face width, b tan(beta) / r.
- **Lands**: passes along X at fixed A with the flat bottom on the tip cylinder's tangent plane,
  as for spur gears, over the land angles widened by the turn.
"""

from __future__ import annotations

import math

import numpy as np

from spur_cad.cam.ir import Feature
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.errors import WorkLimitError
from spur_cad.geometry.frames import turn_points
from spur_cad.geometry.profile import rack_corner
from spur_cad.geometry.spec import GearSpec

CLEARANCE_TOLERANCE_MM = 1e-6
"""A pass may touch its rack tooth's boundary within this (the flank side lies on it by design)."""
CORNER_MATCH_MM = 1e-6
"""A tool corner radius within this of the rack tip radius plays the round itself (one tip pass per side)."""
CORNER_GAP_SHARE = 0.3
"""With r_t < rho: the share of the target left to the tool between its contacts on the rack."""
"""With r_t < rho: the share of the target left to the tool between its contacts on the rack."""
_SAFETY = 0.95
MAX_TIP_ROLLS = 1000
"""Most tip-mode rolls whose leftover `tip_roll_step` checks (the helical example needs about 60 at 5 um and
450 at 1 um); beyond, the target is refused rather than checked for minutes."""


def pass_slopes(spec: GearSpec, gamma_rad: float) -> tuple[float, float]:
    """(dY/dX, dZ/dX) of a pass along the rack tooth turned by gamma about X."""
    tan_h = spec.hand_sign * math.tan(spec.helix_angle_rad)
    return -tan_h * math.cos(gamma_rad), -tan_h * math.sin(gamma_rad)


def face_turn_range(spec: GearSpec) -> tuple[float, float]:
    """(lowest, highest) turn of a transverse section over the face width (rad): 0 and b h tan(beta) / r."""
    turn = spec.section_turn_rad(spec.face_width_mm)
    return min(0.0, turn), max(0.0, turn)


def rack_tooth_signed_distance_mm(spec: GearSpec, n: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Signed distance (< 0 inside) to the rack tooth in its normal section: n from the tooth's centre
    plane, z machine height at A = phi. The tooth is the wedge of the round centres (z >= r_f + rho,
    |n| <= d_n + (z - r_f - rho) tan(alpha_n)) grown by rho."""
    corner = rack_corner(spec)
    rho, d_n = spec.rack_tip_radius_mm, corner.normal_corner_offset_mm
    alpha = spec.normal_pressure_angle_rad
    z_c = spec.root_radius_mm + rho
    m, dz = np.abs(n), np.asarray(z, float) - z_c
    side = (m - d_n) * math.cos(alpha) - dz * math.sin(alpha)
    inside = np.maximum(-dz, side)
    to_bottom = np.hypot(np.maximum(m - d_n, 0.0), np.minimum(dz, 0.0))
    along = np.maximum((m - d_n) * math.sin(alpha) + dz * math.cos(alpha), 0.0)
    to_flank = np.hypot(m - d_n - along * math.sin(alpha), dz - along * math.cos(alpha))
    outside = np.minimum(to_bottom, to_flank)
    return np.where(inside <= 0.0, inside, outside) - rho


def tool_hull_points(tool: Tool, height_mm: float, around: int = 180, corner: int = 12) -> np.ndarray:
    """(N, 3) points relative to the tool tip centre whose convex hull is the tool up to `height_mm`."""
    radius, r_t = tool.diameter_mm / 2.0, tool.effective_corner_radius_mm
    theta = np.linspace(0.0, 2.0 * math.pi, around, endpoint=False)
    psi = np.linspace(0.0, 0.5 * math.pi, corner) if r_t > 0.0 else np.array([0.5 * math.pi])
    ring_r = np.concatenate([radius - r_t + r_t * np.sin(psi), [radius]])
    ring_z = np.concatenate([r_t - r_t * np.cos(psi), [height_mm]])
    x = (ring_r[:, None] * np.cos(theta)[None, :]).ravel()
    y = (ring_r[:, None] * np.sin(theta)[None, :]).ravel()
    z = np.repeat(ring_z, around)
    return np.stack([x, y, z], axis=-1)


def rack_clearance_mm(spec: GearSpec, points: np.ndarray, a_rad: float, phi: float) -> float:
    """Largest signed distance of machine points (N, 3: X, Y, Z at A = a_rad) from the rack tooth at roll
    phi (<= 0: all inside the rack, which never enters the gear)."""
    return float(rack_distances_mm(spec, points, a_rad, phi).max())


def rack_distances_mm(spec: GearSpec, points: np.ndarray, a_rad: float, phi: float) -> np.ndarray:
    """Signed distance of each machine point (N, 3: X, Y, Z at A = a_rad) from the rack tooth at roll phi."""
    turn = phi - a_rad  # the same part point with A = phi
    x, (y, z) = points[:, 0], turn_points(points[:, 1:], turn).T
    tan_h = spec.hand_sign * math.tan(spec.helix_angle_rad)
    axis_y = -spec.reference_radius_mm * phi - tan_h * x
    n = (y - axis_y) * math.cos(spec.helix_angle_rad)
    return rack_tooth_signed_distance_mm(spec, n, z)


def check_helical_generating_tool(spec: GearSpec, tool: Tool) -> None:
    """ToolError unless the tool's corner fits inside the rack's round (0 < r_t <= rho; a flat end mill only for a
    sharp rack) and its flat fits the rack's tip flat."""
    rho, r_t = spec.rack_tip_radius_mm, tool.effective_corner_radius_mm
    if r_t > rho + CORNER_MATCH_MM:
        raise ToolError(f"finishing strategy generating for a helical gear: tool corner radius r_t = {r_t:g} mm is "
                        f"larger than the rack tip radius rho = {rho:g} mm; the tool's corner must fit inside the "
                        "rack's tip round: use r_t <= rho (r_t = rho needs the fewest passes)",
                        field="corner_radius_mm", section="tools.finishing")
    if r_t == 0.0 and rho > 0.0:
        raise ToolError(f"finishing strategy generating for a helical gear: a flat end mill (r_t = 0) plays only a "
                        f"sharp rack (rho = 0); this rack's tip radius is rho = {rho:g} mm: use a corner radius "
                        f"0 < r_t <= {rho:g} mm", field="corner_radius_mm", section="tools.finishing")
    d_n = rack_corner(spec).normal_corner_offset_mm
    if tool.flat_width_mm > 2.0 * d_n + 1e-12:
        raise ToolError(f"finishing strategy generating: tool flat width d = {tool.flat_width_mm:g} mm (D - 2 r_t) is "
                        f"wider than the rack's normal tip flat 2 d_n = {2 * d_n:.4f} mm; largest diameter: "
                        f"{2 * d_n + 2 * r_t:.4f} mm", field="diameter_mm", section="tools.finishing")


def _even(lo: float, hi: float, step: float) -> np.ndarray:
    """Evenly spaced values from lo to hi, at most `step` apart (both ends included)."""
    count = max(1, math.ceil((hi - lo) / step - 1e-12))
    return np.linspace(lo, hi, count + 1)


def flank_roll_step(spec: GearSpec, target_mm: float) -> float:
    """Even roll spacing whose generating flats leave at most `target` at the largest roll any section sees."""
    from spur_cad.cam.strategies.generating_flat import flat_leftover_mm as _flat_leftover

    involute = spec.tooth_space_profile().involute
    lo, hi = face_turn_range(spec)
    t_worst = involute.end + (hi - lo)
    rb, goal = spec.base_radius_mm, _SAFETY * target_mm
    step = math.sqrt(8.0 * goal / (rb * t_worst))
    while _flat_leftover(rb, t_worst - step, t_worst) > goal:
        step *= 0.9
    return step


def _rack_tip_boundary(spec: GearSpec, samples: int = 400) -> np.ndarray:
    """Transverse outline of the rack's right tip corner at roll 0 (gear frame, rolling line at Z = r): the
    elliptic round (semi-axes rho / cos(beta) along, rho across) from its bottom to T, and the tip line."""
    corner = rack_corner(spec)
    rho, s = corner.corner_radius_mm, corner.stretch
    centre = np.array([corner.corner_offset_mm, spec.reference_radius_mm - corner.corner_depth_mm])
    theta = np.linspace(-0.5 * math.pi, 0.0, samples)
    round_ = centre + np.stack([s * rho * np.cos(theta), rho * np.sin(theta)], axis=-1)
    line = np.array([[-centre[0], spec.root_radius_mm]])  # the tip line: one segment to the round's bottom
    return np.concatenate([line, round_])


def _tip_rolls_within(spec: GearSpec, rolls: np.ndarray, points: np.ndarray, outline: np.ndarray,
                      goal_mm: float) -> bool:
    """Whether every fillet/root point lies within goal_mm of the nearest of the rack outlines at `rolls`
    (transverse). A point once within is done (its nearest distance can only shrink), so each roll measures only
    the points not reached yet."""
    open_ = points
    r = spec.reference_radius_mm
    for phi in rolls:
        moved = outline - np.array([r * phi, 0.0])
        part = turn_points(moved, -phi)
        a, edge = part[:-1], np.diff(part, axis=0)  # distance to the outline's segments, not its vertices
        rel = open_[:, None, :] - a[None, :, :]
        u = np.clip((rel * edge[None]).sum(axis=-1) / np.maximum((edge * edge).sum(axis=-1), 1e-300), 0.0, 1.0)
        d = np.hypot(*(rel - u[..., None] * edge[None]).transpose(2, 0, 1)).min(axis=1)
        open_ = open_[d > goal_mm]
        if not len(open_):
            return True
    return False


def tip_roll_step(spec: GearSpec, target_mm: float) -> float:
    """Even rack-roll spacing for tip mode: the largest (from twice the closed-form spacing, shrunk by 10 %
    steps) whose rolls, at four phases, leave fillet and root points (right half, transverse) within 95 %
    of the target from the nearest rack outline -- each section sees the rolls shifted by its turn."""
    from spur_cad.geometry.sampling import sample_profile

    samples = sample_profile(spec.tooth_space_profile(), 1e-3 * spec.module_mm)
    keep = np.isin(samples.label_names(), ["fillet", "root"])
    points = samples.points[keep][:: max(1, int(keep.sum()) // 120)]
    outline = _rack_tip_boundary(spec)
    corner = rack_corner(spec)
    r = spec.reference_radius_mm
    phi_t = (corner.corner_offset_mm - corner.corner_depth_mm / math.tan(spec.pressure_angle_rad)) / r
    lo, hi = min(phi_t, -corner.corner_offset_mm / r) - 0.02, corner.corner_offset_mm / r + 0.02
    goal = _SAFETY * target_mm
    if spec.rack_tip_radius_mm == 0.0:
        # A sharp rack corner (played by a flat end mill) leaves wedge-shaped cusps: along the design normal up
        # to 2 sin(45 deg - alpha/2) / cos(alpha) (< sqrt(2)) times their distance to the outline, which is what
        # is measured here.
        goal /= math.sqrt(2.0)
    step = 2.0 * _first_tip_step(spec, goal)  # the closed form is conservative: start above it
    if (hi - lo) / step > MAX_TIP_ROLLS / 8.0:  # the spacing found is rarely below a third of the closed form
        step = (hi - lo) / MAX_TIP_ROLLS
    for _ in range(40):
        rolls = np.arange(lo, hi + step, step)
        if len(rolls) > MAX_TIP_ROLLS:
            break
        if all(_tip_rolls_within(spec, rolls + phase * step, points, outline, goal) for phase in (0.0, 0.25, 0.5,
                                                                                                0.75)):
            return step
        step *= 0.9
    raise WorkLimitError(f"generating finishing: no roll spacing above {step:.3g} rad keeps the fillet within "
                         f"target_scallop_mm = {target_mm:g} (checked up to {MAX_TIP_ROLLS} rolls); raise [finishing] "
                         "target_scallop_mm", field="target_scallop_mm", section="finishing")


def helical_passes_estimate(spec: GearSpec, target_mm: float, tool: Tool | None = None) -> float:
    """Passes per space from closed forms alone (before any planning, to bound the work): both flanks at the
    largest roll any section sees, tip mode at the root's spacing sqrt(8 target / r_f) / r_f over the widened
    fillet-to-fillet range with up to four passes per roll (a `tool` corner below rho: two more per contact
    angle, the rolls spaced for the rest of the target)."""
    involute = spec.tooth_space_profile().involute
    lo, hi = face_turn_range(spec)
    t_worst = involute.end + (hi - lo)
    goal = _SAFETY * target_mm
    flank = (involute.end - involute.start + hi - lo) / math.sqrt(8.0 * goal / (spec.base_radius_mm * t_worst))
    corner = rack_corner(spec)
    r = spec.reference_radius_mm
    tip_range = 2.0 * (corner.corner_offset_mm + corner.corner_depth_mm / math.tan(spec.pressure_angle_rad)) / r
    per_roll = 4.0
    if tool is not None and tool.effective_corner_radius_mm < spec.rack_tip_radius_mm - CORNER_MATCH_MM:
        per_roll += 2.0 * (len(corner_contacts(spec, tool, target_mm)[0]) - 1)
        goal *= 1.0 - CORNER_GAP_SHARE
    tip = (tip_range + hi - lo) / _first_tip_step(spec, goal)
    return 2.0 * flank + per_roll * tip


def _first_tip_step(spec: GearSpec, goal: float) -> float:
    """Closed-form tip-mode roll spacing: the root (radius r_f) leaves r_f dphi^2 / 8; the round (smallest
    transverse curvature radius rho cos(beta)) generates points s dphi apart, s the contact's distance from the
    pitch point, leaving about (s dphi)^2 / (8 rho cos(beta))."""
    corner = rack_corner(spec)
    rho = spec.rack_tip_radius_mm
    steps = [math.sqrt(8.0 * goal / spec.root_radius_mm)]
    if rho > 0.0:
        reach = math.hypot(corner.corner_offset_mm + corner.stretch * rho, corner.corner_depth_mm + rho)
        steps.append(math.sqrt(8.0 * rho * math.cos(spec.helix_angle_rad) * goal) / reach)
    return min(steps)


def _flank_rolls(spec: GearSpec, target_mm: float) -> tuple[tuple[int, Feature, np.ndarray], ...]:
    """(side, feature, rolls) of both flanks' passes: right tip -> root, left root -> tip, evenly spaced over the
    rolls any section sees."""
    involute = spec.tooth_space_profile().involute
    lo, hi = face_turn_range(spec)
    step = flank_roll_step(spec, target_mm)
    return ((1, Feature.RIGHT_FLANK, _even(involute.start - hi, involute.end - lo, step)[::-1]),
            (-1, Feature.LEFT_FLANK, _even(involute.start + lo, involute.end + hi, step)))


def _flank_passes(spec: GearSpec, tool: Tool, target_mm: float, points: np.ndarray) -> list[tuple]:
    """(mode, feature, roll, a rad, y0, z0, dy/dx, dz/dx, side) of both flanks' passes (right tip -> root, left
    root -> tip)."""
    rb, alpha_t = spec.base_radius_mm, spec.pressure_angle_rad
    theta_b = spec.tooth_space_profile().involute.base_angle_rad
    radius = tool.diameter_mm / 2.0
    out = []
    for side, feature, rolls in _flank_rolls(spec, target_mm):
        gamma = side * alpha_t
        sy, sz = pass_slopes(spec, gamma)
        for t in rolls:
            a = side * (theta_b + t)
            y0 = -side * (rb * t + radius * math.sqrt(1.0 + sy * sy))
            z0 = _lowest_end(spec, points, a, a - gamma, y0, side, tool)
            out.append(("flank", feature, float(t), a, y0, z0, sy, sz, side))
    return out


def _rack_point_t_z(spec: GearSpec, phi: float, gamma: float, side: int) -> float:
    """Machine Z at X = 0 of the rack's point T (flank/round tangency) on the `side` flank, the rack at roll phi
    turned further by gamma (transverse section: the rack round's T at r_f + rho (1 - sin alpha_n))."""
    corner = rack_corner(spec)
    rho, alpha_n = spec.rack_tip_radius_mm, spec.normal_pressure_angle_rad
    t_y = (corner.normal_corner_offset_mm + rho * math.cos(alpha_n)) / math.cos(spec.helix_angle_rad)
    t_z = spec.root_radius_mm + rho - rho * math.sin(alpha_n)
    y = side * t_y - spec.reference_radius_mm * phi
    return y * math.sin(gamma) + t_z * math.cos(gamma)


def _lowest_end(spec: GearSpec, points: np.ndarray, a: float, phi: float, y0: float, side: int,
                tool: Tool) -> float:
    """Lowest tip Z (at X = 0) with the tool inside the rack tooth at roll phi (bisection, bracketed around
    the rack's point T)."""
    def fits(z0: float) -> bool:
        return rack_clearance_mm(spec, points + np.array([0.0, y0, z0]), a, phi) <= CLEARANCE_TOLERANCE_MM

    near = _rack_point_t_z(spec, phi, a - phi, side) - tool.effective_corner_radius_mm
    span = tool.diameter_mm + spec.tip_radius_mm - spec.root_radius_mm
    high, low = near + span, near - span
    for _ in range(8):
        if fits(high):
            break
        high += span
    else:
        raise ToolError(f"finishing strategy generating: the {tool.diameter_mm:g} mm tool does not fit inside the "
                        "rack tooth of a flank pass of this helical gear; use a smaller diameter",
                        field="diameter_mm", section="tools.finishing")
    while fits(low):
        low -= span
    active = points  # the hull points that may still decide a step
    for _ in range(48):
        mid = 0.5 * (low + high)
        distance = rack_distances_mm(spec, active + np.array([0.0, y0, mid]), a, phi)
        low, high = (low, mid) if distance.max(initial=-math.inf) <= CLEARANCE_TOLERANCE_MM else (mid, high)
        # Moving the tool by dz moves a point's signed distance by at most |dz| (a distance is 1-Lipschitz; twice
        # that, and 1 nm, for safety): a point below the tolerance by more than that over the bracket left never
        # decides a step again, so dropping it leaves every step, and the result, as they were.
        active = active[distance + 2.0 * (high - low) + 1e-6 >= CLEARANCE_TOLERANCE_MM]
    return high


def contact_roll_rad(spec: GearSpec, b_rad: np.ndarray) -> np.ndarray:
    """Effective roll phi_e at which the right rack round touches the gear at normal-section angle b (from
    straight down toward the flank): r phi_e = d_1 + rho sin(b) (1/cos(beta) - cos(beta)) - B cos(beta) tan(b)
    (the round's normal there meets the pitch line; spur: d_1 - B tan(b))."""
    corner = rack_corner(spec)
    rho, cos_beta = spec.rack_tip_radius_mm, math.cos(spec.helix_angle_rad)
    b = np.asarray(b_rad, float)
    return (corner.corner_offset_mm + rho * np.sin(b) * (1.0 / cos_beta - cos_beta)
            - corner.corner_depth_mm * cos_beta * np.tan(b)) / spec.reference_radius_mm


def corner_contacts(spec: GearSpec, tool: Tool, target_mm: float) -> tuple[np.ndarray, ...]:
    """Where a corner r_t < rho touches the rack in tip mode, root -> flank: the corner centre's offset from the
    round's centre (normal section: across, up; mm) and the range of effective rolls (lowest, highest) at which
    the rack touches within half a spacing of each contact. Contacts: angles b on the round (0 -> 90 deg -
    alpha_n), spaced so that between them the tool leaves at most CORNER_GAP_SHARE of the target on the round,
    then contacts on the rack's flank line above T, as far apart, up to where a corner of radius rho tangent
    at T (the exact tool) leaves the target, sqrt(2 rho target) (a corner tangent to the line above T from
    inside stays inside the rack: the round bends away from the line below T)."""
    rho, r_t = spec.rack_tip_radius_mm, tool.effective_corner_radius_mm
    e, gap = rho - r_t, CORNER_GAP_SHARE * target_mm
    corner, alpha_n, cos_beta = rack_corner(spec), spec.normal_pressure_angle_rad, math.cos(spec.helix_angle_rad)
    # A round point Delta away from the tangency lies sqrt(rho^2 + e^2 - 2 rho e cos(Delta)) - r_t from the tool.
    cos_half = (rho * rho + e * e - (r_t + gap) ** 2) / (2.0 * rho * e)
    half = math.acos(min(max(cos_half, -1.0), 1.0))
    b_max = 0.5 * math.pi - alpha_n
    angles = _even(0.0, b_max, 2.0 * half)
    spacing = angles[1] - angles[0]
    cells = np.clip(angles[:, None] + np.linspace(-0.5, 0.5, 65)[None, :] * spacing, 0.0, b_max)
    rolls = contact_roll_rad(spec, cells)
    across, up = e * np.sin(angles), -e * np.cos(angles)
    # On the flank line, s above T: a line point u from the tangency lies u^2 / (2 r_t) from the tool.
    step_s = 2.0 * math.sqrt(2.0 * r_t * gap)
    s = step_s * np.arange(1, max(1, math.ceil(math.sqrt(2.0 * rho * target_mm) / step_s)) + 1)
    s_cells = np.maximum(s[:, None] + np.linspace(-0.5, 0.5, 65)[None, :] * step_s, 0.0)
    # the flank point's normal (angle b_max) meets the pitch line: as contact_roll_rad with the point moved by s
    t_across = rho * math.sin(b_max) + s_cells * math.sin(alpha_n)
    t_depth = rho * math.cos(b_max) - s_cells * math.cos(alpha_n)
    s_rolls = (corner.corner_offset_mm + t_across / cos_beta
               - (corner.corner_depth_mm + t_depth) * cos_beta * math.tan(b_max)) / spec.reference_radius_mm
    across = np.concatenate([across, e * math.sin(b_max) + s * math.sin(alpha_n)])
    up = np.concatenate([up, -e * math.cos(b_max) + s * math.cos(alpha_n)])
    low = np.concatenate([rolls.min(axis=1), s_rolls.min(axis=1)])
    high = np.concatenate([rolls.max(axis=1), s_rolls.max(axis=1)])
    return across, up, low, high


def _tip_passes(spec: GearSpec, tool: Tool, target_mm: float) -> list[tuple]:
    """Tip-mode passes (rolls descending: right fillet -> root -> left fillet)."""
    corner = rack_corner(spec)
    r, beta = spec.reference_radius_mm, spec.helix_angle_rad
    d1 = corner.corner_offset_mm
    d_n, rho = corner.normal_corner_offset_mm, spec.rack_tip_radius_mm
    alpha_n, alpha_t = spec.normal_pressure_angle_rad, spec.pressure_angle_rad
    r_f, r_t = spec.root_radius_mm, tool.effective_corner_radius_mm
    half_flat = tool.flat_width_mm / 2.0
    lo, hi = face_turn_range(spec)
    # Transverse point T (flank/round tangency) and the roll at which its normal passes the pitch point.
    t_y = (d_n + rho * math.cos(alpha_n)) / math.cos(beta)
    t_z = r_f + rho - rho * math.sin(alpha_n)
    phi_t = (t_y - (r - t_z) / math.tan(alpha_t)) / r
    phi_bottom = d1 / r
    sy, _ = pass_slopes(spec, 0.0)
    reach_n = math.sqrt(2.0 * max(r_t, 1e-9) * 0.5 * target_mm)  # corner drop
    spread = spec.hand_sign * spec.face_width_mm * math.sin(beta)  # the root contact's travel in n over the face
    inner = d_n - half_flat  # tool axis offset with a corner on a round
    exact = abs(r_t - rho) <= CORNER_MATCH_MM  # the corner is the round: one pass per side and roll
    first, last = min(phi_t, -phi_bottom) - hi, max(phi_bottom, -phi_t) - lo
    roll_target = target_mm
    if not exact:
        across, up, cell_low, cell_high = corner_contacts(spec, tool, target_mm)
        low, high = min(phi_t, phi_bottom, cell_low.min()), max(phi_t, phi_bottom, cell_high.max())
        first, last = min(low, -high) - hi, max(high, -low) - lo
        # Corner positions (tool axis n, tip Z) tangent to the rack at each contact, flank -> root.
        corners = [(d_n - half_flat + a, r_f + rho + u - r_t, lo_, hi_)
                   for a, u, lo_, hi_ in zip(across[::-1], up[::-1], cell_low[::-1], cell_high[::-1])]
        roll_target = (1.0 - CORNER_GAP_SHARE) * target_mm
    out = []
    step = tip_roll_step(spec, roll_target)
    for phi in _even(first, last, step)[::-1]:
        positions: list[tuple[float, float, Feature, int]] = []
        if exact:
            if phi_t - hi <= phi <= phi_bottom - lo:
                positions.append((inner, r_f, Feature.RIGHT_FLANK, 1))
        else:  # the angles some section sees at this roll (effective rolls phi + lo .. phi + hi)
            positions.extend((n, z, Feature.RIGHT_FLANK, 1) for n, z, low, high in corners
                             if low - hi - step <= phi <= high - lo + step)
        # The root contact (Y = 0 in every section) meets the rack's tip plane at n = r phi cos(beta) + X h sin(beta).
        n_a = max(r * phi * math.cos(beta) + min(0.0, spread), -d_n)
        n_b = min(r * phi * math.cos(beta) + max(0.0, spread), d_n)
        if n_a <= n_b:
            lo_axis = float(np.clip(min(n_a + half_flat, 0.5 * (n_a + n_b)), -inner, inner))
            hi_axis = float(np.clip(max(n_b - half_flat, 0.5 * (n_a + n_b)), -inner, inner))
            axes = [lo_axis] if hi_axis - lo_axis < 1e-9 else _even(lo_axis, hi_axis, 2.0 * (half_flat + reach_n))
            side = 1 if phi >= 0.0 else -1
            positions.extend((float(n), r_f, Feature.ROOT, side) for n in axes)
        if exact:
            if -phi_bottom - hi <= phi <= -phi_t - lo:
                positions.append((-inner, r_f, Feature.LEFT_FLANK, -1))
        else:  # the left round mirrors the right one: it touches at effective roll -phi_e(b)
            positions.extend((-n, z, Feature.LEFT_FLANK, -1) for n, z, low, high in corners[::-1]
                             if -high - hi - step <= phi <= -low - lo + step)
        for n, z, feature, side in positions:
            y0 = -r * phi + n / math.cos(beta)
            out.append(("tip", feature, float(phi), float(phi), y0, z, sy, 0.0, side))
    return out


def _land_passes(spec: GearSpec, tool: Tool, target_mm: float) -> list[tuple]:
    """Land passes along X over the tooth on the +Y side of space 0, angles widened by the face's turn."""
    tip = spec.tooth_space_profile().tip
    if tip is None:
        return []
    lo, hi = face_turn_range(spec)
    ra = spec.tip_radius_mm
    reach = tool.flat_width_mm / 2.0 + math.sqrt(2.0 * max(tool.effective_corner_radius_mm, 1e-9) * 0.5 * target_mm)
    first, last = tip.start, 2.0 * math.pi / spec.teeth - tip.start
    return [("land", Feature.TIP, float(a), float(a), 0.0, ra, 0.0, 0.0, 1)
            for a in _even(first - hi, last - lo, 2.0 * _SAFETY * reach / ra)]


def helical_passes(spec: GearSpec, tool: Tool, target_mm: float, blank_radius_mm: float,
                   lands: bool) -> list[tuple]:
    """Every pass of tooth space 0 in cutting order: (mode, feature, roll, a rad, y0, z0, dy/dx, dz/dx, side),
    each checked against the rack tooth it plays (ToolError when one would leave it)."""
    check_helical_generating_tool(spec, tool)
    points = tool_hull_points(tool, blank_radius_mm - spec.root_radius_mm + tool.diameter_mm)
    tip = _tip_passes(spec, tool, target_mm)  # first: its roll check refuses an absurd target at once
    flank = _flank_passes(spec, tool, target_mm, points)
    right = [p for p in flank if p[8] > 0]
    left = [p for p in flank if p[8] < 0]
    passes = (_land_passes(spec, tool, target_mm) if lands else []) + right + tip + left
    for mode, _, roll, a, y0, z0, _, _, side in passes:
        if mode == "land":
            continue
        phi = a - side * spec.pressure_angle_rad if mode == "flank" else roll
        clearance = rack_clearance_mm(spec, points + np.array([0.0, y0, z0]), a, phi)
        if clearance > 10.0 * CLEARANCE_TOLERANCE_MM:
            raise ToolError(f"finishing strategy generating: a {mode} pass of the {tool.diameter_mm:g} mm tool leaves "
                            f"its rack tooth by {1000 * clearance:.3f} um; use a smaller diameter",
                            field="diameter_mm", section="tools.finishing")
    return passes


def helical_pass_count(spec: GearSpec, tool: Tool, target_mm: float, lands: bool) -> int:
    """How many passes helical_passes plans for tooth space 0, counted without placing the flank passes' ends (a
    bisection each) or checking them against the rack: what the work bound needs before anything is built."""
    check_helical_generating_tool(spec, tool)
    flank = sum(len(rolls) for _, _, rolls in _flank_rolls(spec, target_mm))
    land = len(_land_passes(spec, tool, target_mm)) if lands else 0
    return len(_tip_passes(spec, tool, target_mm)) + flank + land


__all__ = ["check_helical_generating_tool", "face_turn_range", "flank_roll_step", "helical_passes",
           "contact_roll_rad", "corner_contacts", "helical_pass_count", "helical_passes_estimate", "pass_slopes",
           "rack_clearance_mm", "rack_distances_mm", "rack_tooth_signed_distance_mm", "tip_roll_step",
           "tool_hull_points"]
