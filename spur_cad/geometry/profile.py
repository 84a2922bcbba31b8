"""The exact rack-generated tooth-space profile (docs/method.md), numpy only.

Frame ("gap-symmetric"): origin at the gear centre, +y along the symmetry axis of a tooth
space, x to the right. Polar angles `theta` are measured from +y toward +x (clockwise).
The right half of the space boundary runs root -> tip: root arc, fillet, involute, tip arc.

Every segment gives points, unit normals pointing into the tooth space, and signed
curvature radii (positive when the centre of curvature lies on the space side, i.e. the
material is concave there, as in a root fillet; negative for convex material: root circle,
involute, tip circle), plus a rigorous upper bound of the chord error over a parameter
interval, which the chordal-tolerance sampler relies on.

Generating rack, in rolling-line coordinates at roll angle phi = 0: the rolling line is
y = r (tangent to the reference circle), the rack tooth is centred on x = 0 and points to
the gear centre; its half-thickness on the rolling line is e/2 (the gear's space width), its
tip line is the root circle's tangent y = r_f, and its right tip corner is a circle of
radius rho centred at (d_1, r - B). Rolling: the gear turns by phi while the rack moves by
r*phi; a rack point q is then at R(-phi) (q - (r*phi, 0)) in the gear frame and the pitch
point at R(-phi) (0, r). The rack's corner and the fillet its round generates, for each gear kind:
geometry/rack.py.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol, TypeVar

import numpy as np

from spur_cad.errors import GearSpecError
from spur_cad.geometry.frames import turned_clockwise
from spur_cad.geometry.involute import involute_function
from spur_cad.geometry.kinds import GearKind
from spur_cad.geometry.rack import Fillet, generating_rack
from spur_cad.geometry.rack import rack_corner as rack_corner  # callers import it from here too
from spur_cad.geometry.roots import brentq, minimize_bounded

SEGMENT_LABELS = ("root", "fillet", "involute", "tip")


class GeneratedGear(Protocol):
    """What the profile construction reads of a gear. GearSpec (spec.py) provides it and builds its profile
    with this module, so the profile names no spec type: within the geometry layer the spec sits above it."""

    @property
    def kind(self) -> GearKind: ...
    @property
    def teeth(self) -> int: ...
    @property
    def module_mm(self) -> float: ...
    @property
    def rack_tip_radius_mm(self) -> float: ...
    @property
    def pressure_angle_rad(self) -> float: ...
    @property
    def normal_pressure_angle_rad(self) -> float: ...
    @property
    def helix_angle_rad(self) -> float: ...
    @property
    def reference_radius_mm(self) -> float: ...
    @property
    def base_radius_mm(self) -> float: ...
    @property
    def tip_radius_mm(self) -> float: ...
    @property
    def root_radius_mm(self) -> float: ...
    @property
    def space_width_mm(self) -> float: ...
    @property
    def base_half_space_angle_rad(self) -> float: ...
    @property
    def tip_thickness_mm(self) -> float: ...


@dataclass(frozen=True)
class CircularArc:
    """Arc of a circle centred on the gear axis, from polar angle `start` to `end` (clockwise)."""

    label: str
    radius_mm: float
    start: float
    end: float

    def points(self, theta: np.ndarray) -> np.ndarray:
        theta = np.asarray(theta, dtype=float)
        return np.stack([self.radius_mm * np.sin(theta), self.radius_mm * np.cos(theta)], axis=-1)

    def normals(self, theta: np.ndarray) -> np.ndarray:
        """Outward radial: the space (root arc) or the outside (tip arc) lies outside the circle."""
        theta = np.asarray(theta, dtype=float)
        return np.stack([np.sin(theta), np.cos(theta)], axis=-1)

    def curvature_radii(self, theta: np.ndarray) -> np.ndarray:
        return np.full(np.shape(theta), -self.radius_mm)

    def chord_error_bound(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Exact sagitta R (1 - cos(dtheta / 2))."""
        return self.radius_mm * (1.0 - np.cos(np.abs(b - a) / 2.0))

    def arc_length_bound(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        return self.radius_mm * np.abs(b - a)


@dataclass(frozen=True)
class Involute:
    """Involute of the base circle, parameter t = roll angle = tan(pressure angle at the point).

    Point: R(-theta_b) r_b (sin t - t cos t, cos t + t sin t); the base point sits at polar
    angle theta_b. Tangent R(-theta_b)(sin t, cos t), normal into the space
    R(-theta_b)(-cos t, sin t), curvature radius r_b t (convex material: negative sign).
    """

    label: str
    base_radius_mm: float
    base_angle_rad: float
    start: float
    end: float

    def points(self, t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        rb = self.base_radius_mm
        return turned_clockwise(self.base_angle_rad, rb * (np.sin(t) - t * np.cos(t)),
                                 rb * (np.cos(t) + t * np.sin(t)))

    def normals(self, t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        return turned_clockwise(self.base_angle_rad, -np.cos(t), np.sin(t))

    def curvature_radii(self, t: np.ndarray) -> np.ndarray:
        return -self.base_radius_mm * np.asarray(t, dtype=float)

    def chord_error_bound(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """min(K l^2 / 8, (l/2) tan(turn/2)): curvature bound and convex-arc triangle bound.

        Arc length l = r_b (b^2 - a^2) / 2, curvature at most 1 / (r_b a), tangent turns by b - a.
        """
        rb = self.base_radius_mm
        length = rb * (b * b - a * a) / 2.0
        with np.errstate(divide="ignore"):
            curvature_bound = np.where(a > 0.0, length * length / (8.0 * rb * np.maximum(a, 1e-300)), np.inf)
        triangle_bound = 0.5 * length * np.tan(np.minimum(b - a, 3.0) / 2.0)
        return np.minimum(curvature_bound, triangle_bound)

    def arc_length_bound(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        return self.base_radius_mm * (b * b - a * a) / 2.0


_S = TypeVar("_S")


class Segment(Protocol):
    """What every segment of a tooth-space profile offers, whatever curve it is: the root and tip arcs, the
    involute, the rack's trochoid or ellipse fillet here, and the shaper cutter's fillet of an internal gear
    (geometry/internal.py). Its parameter runs from `start` to `end`, root side first."""

    @property
    def label(self) -> str: ...

    @property
    def start(self) -> float: ...

    @property
    def end(self) -> float: ...

    def points(self, parameter: np.ndarray) -> np.ndarray: ...

    def normals(self, parameter: np.ndarray) -> np.ndarray: ...

    def curvature_radii(self, parameter: np.ndarray) -> np.ndarray: ...

    def chord_error_bound(self, a: np.ndarray, b: np.ndarray) -> np.ndarray: ...

    def arc_length_bound(self, a: np.ndarray, b: np.ndarray) -> np.ndarray: ...


@dataclass(frozen=True)
class ToothSpaceProfile:
    """Right half of one tooth space, root to tip, as exact segments (see the module doc)."""

    segments: tuple[Segment, ...]
    teeth: int
    reference_radius_mm: float
    base_radius_mm: float
    root_radius_mm: float
    tip_radius_mm: float
    form_radius_mm: float
    root_arc_half_angle_rad: float
    undercut: bool
    undercut_depth_mm: float
    junction_is_tangent: bool
    min_fillet_curvature_radius_mm: float

    def segment(self, label: str) -> Segment | None:
        """The segment with this label, or None (the fillet is absent for a sharp rack on the rolling line)."""
        for seg in self.segments:
            if seg.label == label:
                return seg
        return None

    @property
    def involute(self) -> Involute:
        """The involute flank; every profile has one (GearSpec refuses a gear whose form circle reaches the tip)."""
        return self._required("involute", Involute)

    @property
    def tip(self) -> CircularArc:
        """The tip arc; every profile has one."""
        return self._required("tip", CircularArc)

    @property
    def fillet(self) -> Segment | None:
        """The fillet (a rack's or, for an internal gear, a shaper cutter's), or None for a sharp rack corner on the
        rolling line."""
        return self.segment("fillet")

    def _required(self, label: str, kind: type[_S]) -> _S:
        seg = self.segment(label)
        if not isinstance(seg, kind):
            raise ValueError(f"the tooth-space profile has no {label} segment")
        return seg


def build_tooth_space_profile(spec: GeneratedGear) -> ToothSpaceProfile:
    """Construct the exact profile of `spec`, raising GearSpecError where it cannot be cut."""
    alpha = spec.pressure_angle_rad
    r, rb, ra, rf = spec.reference_radius_mm, spec.base_radius_mm, spec.tip_radius_mm, spec.root_radius_mm
    z = spec.teeth
    half_tooth_angle = math.pi / z
    rack = generating_rack(spec)
    corner = rack.corner(spec)
    d1, B, rho = corner.corner_offset_mm, corner.corner_depth_mm, corner.corner_radius_mm
    if spec.space_width_mm <= 0.0:
        raise GearSpecError("the tooth thickness allowance leaves no space between teeth",
                            field="thickness_allowance_mm")
    if d1 < -1e-12:
        max_rho = (corner.half_thickness_on_rolling_line_mm - (r - rf) * math.tan(alpha)) / (
            corner.stretch / math.cos(spec.normal_pressure_angle_rad) - math.tan(alpha))
        raise GearSpecError(
            f"rack tip radius {rho:g} mm is too large for the rack tooth: the two tip corners overlap "
            f"(d_1 = {d1:.4f} mm < 0); at most {max(max_rho, 0.0):.4f} mm fits this module, pressure angle, "
            "dedendum and thickness allowance", field="rack_tip_radius_mm")
    d1 = max(d1, 0.0)
    theta_b = spec.base_half_space_angle_rad
    root_half_angle = d1 / r
    beta_max = math.pi / 2.0 - spec.normal_pressure_angle_rad

    t_dist = rack.flank_point_t_distance(spec, corner)
    undercut = t_dist > r * math.sin(alpha) + 1e-12
    generated: Fillet = rack.fillet(spec, corner, d1, beta_max)
    fillet: Fillet | None = generated
    if rho == 0.0 and abs(B) < 1e-12:
        fillet = None  # a sharp rack corner on the rolling line generates no fillet
    else:
        speeds = generated.speeds(np.linspace(0.0, beta_max, 2049))
        if speeds.min() <= 1e-9 * spec.module_mm:
            raise GearSpecError(
                f"rack tip radius {rho:g} mm: the fillet envelope has a cusp for this tooth count and profile "
                "shift (the rack corner circle lies above the rolling line and turns faster than it rolls); "
                "use a smaller rack tip radius or less profile shift", field="rack_tip_radius_mm")

    undercut_depth = 0.0
    if not undercut:
        # Tangent junction in closed form: the involute point generated by T (roll t_j).
        t_junction = (r * math.sin(alpha) - t_dist) / rb
        beta_junction = beta_max
        junction_is_tangent = True
    else:
        assert fillet is not None
        beta_junction, t_junction, undercut_depth = _undercut_junction(fillet, rb, theta_b, beta_max)
        junction_is_tangent = False
    form_radius = rb * math.sqrt(1.0 + t_junction * t_junction)

    if ra <= form_radius + 1e-9:
        raise GearSpecError(
            f"tip radius {ra:.4f} mm is not above the form radius {form_radius:.4f} mm (start of the involute): "
            "the tooth would have no involute flank; reduce the dedendum or rack tip radius, or increase the "
            "addendum or profile shift", field="addendum_coefficient")
    tip_thickness = spec.tip_thickness_mm
    if tip_thickness <= 0.0:
        raise GearSpecError(
            f"the tooth is pointed: tip thickness {tip_thickness:.4f} mm <= 0 at tip radius {ra:.4f} mm; "
            "reduce the addendum or the profile shift", field="profile_shift_coefficient")
    t_tip = math.sqrt((ra / rb) ** 2 - 1.0)
    theta_tip = theta_b + involute_function(math.atan(t_tip))

    segments: list[Segment] = []
    if root_half_angle > 0.0:
        segments.append(CircularArc("root", rf, 0.0, root_half_angle))
    min_fillet_radius = math.inf
    if fillet is not None and beta_junction > 0.0:
        fillet = rack.fillet(spec, corner, d1, beta_junction)
        _check_fillet_inside_tooth(fillet, half_tooth_angle)
        min_fillet_radius = float(np.min(np.abs(fillet.curvature_radii(np.linspace(0.0, beta_junction, 4097)))))
        segments.append(fillet)
    segments.append(Involute("involute", rb, theta_b, t_junction, t_tip))
    segments.append(CircularArc("tip", ra, theta_tip, half_tooth_angle))
    return ToothSpaceProfile(
        segments=tuple(segments), teeth=z, reference_radius_mm=r, base_radius_mm=rb, root_radius_mm=rf,
        tip_radius_mm=ra, form_radius_mm=form_radius, root_arc_half_angle_rad=root_half_angle,
        undercut=undercut, undercut_depth_mm=undercut_depth, junction_is_tangent=junction_is_tangent,
        min_fillet_curvature_radius_mm=min_fillet_radius,
    )


def _fillet_minus_involute_angle(fillet: Fillet, rb: float, theta_b: float, beta: float) -> float:
    """Polar angle of the fillet point minus that of the involute at the same radius (+inf inside r_b)."""
    x, y = fillet.points(np.array([beta]))[0]
    radius = math.hypot(x, y)
    if radius <= rb:
        return math.inf
    return math.atan2(x, y) - theta_b - involute_function(math.acos(rb / radius))


def _undercut_junction(fillet: Fillet, rb: float, theta_b: float,
                       beta_max: float) -> tuple[float, float, float]:
    """Transverse fillet/involute intersection of an undercut gear, by bracketing and Brent's method.

    Below the junction the fillet lies deeper in the tooth than the involute (angle difference
    > 0); the first sign change from the root is the junction. Returns (beta, t, undercut depth),
    the depth being the largest thickness the fillet removes from the involute flank, measured
    along the circle at that radius.
    """
    grid = np.linspace(0.0, beta_max, 2049)
    diff = np.array([_fillet_minus_involute_angle(fillet, rb, theta_b, b) for b in grid])
    crossings = np.nonzero((diff[:-1] > 0.0) & (diff[1:] <= 0.0))[0]
    if crossings.size == 0:
        raise GearSpecError("undercut: the root fillet does not meet the involute flank; this combination of "
                            "teeth, profile shift and rack tip radius cannot be generated", field="teeth")
    i = int(crossings[0])
    lo, hi = grid[i], grid[i + 1]
    if not math.isfinite(diff[i]):
        # The bracket starts inside the base circle: move its low end to the base circle crossing.
        lo = brentq(lambda b: float(np.hypot(*fillet.points(np.array([b]))[0])) - rb * (1 + 1e-12), lo, hi,
                    xtol=1e-15)
    beta_j = brentq(lambda b: _fillet_minus_involute_angle(fillet, rb, theta_b, b), lo, hi, xtol=1e-15,
                    rtol=1e-15, maxiter=200)
    x, y = fillet.points(np.array([beta_j]))[0]
    t_j = math.sqrt(max((x * x + y * y) / (rb * rb) - 1.0, 0.0))

    def neg_depth(beta: float) -> float:
        d = _fillet_minus_involute_angle(fillet, rb, theta_b, beta)
        return 0.0 if not math.isfinite(d) else -d * float(np.hypot(*fillet.points(np.array([beta]))[0]))

    finite = np.isfinite(diff[: i + 2]) & (grid[: i + 2] <= beta_j)
    depth = 0.0
    if finite.any():
        candidates = grid[: i + 2][finite]
        best = candidates[int(np.argmin([neg_depth(b) for b in candidates]))]
        step = grid[1] - grid[0]
        res = minimize_bounded(neg_depth, max(best - step, candidates[0]), min(best + step, beta_j), xatol=1e-12)
        depth = max(0.0, -float(res.fun), -neg_depth(best))
    return beta_j, t_j, depth


def _check_fillet_inside_tooth(fillet: Fillet, half_tooth_angle: float) -> None:
    """The fillet must stay between the space axis and the tooth's centre line."""
    pts = fillet.points(np.linspace(fillet.start, fillet.end, 2049))
    theta = np.arctan2(pts[:, 0], pts[:, 1])
    if theta.max() >= half_tooth_angle:
        raise GearSpecError("undercut cuts through the tooth root (the fillets of neighbouring spaces meet); "
                            "use more teeth, more profile shift or a smaller rack tip radius", field="teeth")
    if theta.min() < -1e-12:
        raise GearSpecError("the root fillets of one space cross its symmetry axis; use a smaller rack tip radius",
                            field="rack_tip_radius_mm")
