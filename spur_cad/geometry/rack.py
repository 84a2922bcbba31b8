"""The generating rack of an external gear (docs/method.md, docs/geometry.md): its right tip corner relative to
the rolling line, and the root fillet its round generates, for each gear kind the rack generates.

A spur gear's rack is its own transverse section (flank at alpha, a circular round: a trochoidal fillet); a helical
gear's is given in the normal section (flank at alpha_n, round rho), so in the transverse section its flank is at
alpha_t and its round an ellipse (an elliptic fillet). `generating_rack(spec)` gives a kind's rack by the kind
object (`_RACKS`), so geometry/profile.py builds the profile without asking which kind it is.

Frame and rolling as in geometry/profile.py's module doc. numpy only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from spur_cad.geometry.frames import turned_clockwise
from spur_cad.geometry.kinds import EXTERNAL_HELICAL, EXTERNAL_SPUR, INTERNAL_SPUR, GearKind


class RackGear(Protocol):
    """What the rack reads of a gear (GearSpec provides it; geometry/profile.py's GeneratedGear includes it)."""

    @property
    def kind(self) -> GearKind: ...
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
    def root_radius_mm(self) -> float: ...
    @property
    def space_width_mm(self) -> float: ...


@dataclass(frozen=True)
class TrochoidalFillet:
    """Root fillet: envelope of the rack's tip-corner circle, parameter beta in [0, pi/2 - alpha].

    beta is the angle of the contact point on the corner circle, measured from straight down
    (beta = 0, the root circle) toward the rack flank (beta = pi/2 - alpha, the flank's
    tangent point). Willis/Camus: the contact normal passes through the pitch point, which
    fixes the roll angle at which the point is generated: phi(beta) = (d_1 - B tan beta) / r.
    Point: R(-phi) (B tan(beta) + rho sin(beta), r - B - rho cos(beta)).
    """

    label: str
    reference_radius_mm: float
    corner_offset_mm: float  # d_1: corner centre from the rack tooth axis
    corner_depth_mm: float  # B: corner centre below the rolling line
    corner_radius_mm: float  # rho
    start: float
    end: float

    def roll_angle(self, beta: np.ndarray) -> np.ndarray:
        """phi at which the rack generates the fillet point of parameter beta."""
        return (self.corner_offset_mm - self.corner_depth_mm * np.tan(beta)) / self.reference_radius_mm

    def points(self, beta: np.ndarray) -> np.ndarray:
        beta = np.asarray(beta, dtype=float)
        B, rho, r = self.corner_depth_mm, self.corner_radius_mm, self.reference_radius_mm
        return turned_clockwise(self.roll_angle(beta), B * np.tan(beta) + rho * np.sin(beta),
                                 r - B - rho * np.cos(beta))

    def normals(self, beta: np.ndarray) -> np.ndarray:
        """Into the space, i.e. into the rack tooth: from the contact point toward the corner centre."""
        beta = np.asarray(beta, dtype=float)
        return turned_clockwise(self.roll_angle(beta), -np.sin(beta), np.cos(beta))

    def _speed_terms(self, beta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The two beta-dependent terms of |dP/dbeta| = rho + (B^2 sec^3 + B rho sec^2) / r."""
        sec = 1.0 / np.cos(beta)
        B, rho = self.corner_depth_mm, self.corner_radius_mm
        return B * B * sec**3, B * rho * sec**2

    def speeds(self, beta: np.ndarray) -> np.ndarray:
        """|dP/dbeta|; zero would mean a cusp of the envelope."""
        t1, t2 = self._speed_terms(np.asarray(beta, dtype=float))
        return self.corner_radius_mm + (t1 + t2) / self.reference_radius_mm

    def turning_rates(self, beta: np.ndarray) -> np.ndarray:
        """d(tangent angle)/dbeta = 1 + B sec^2(beta) / r (tangent angle is beta - phi)."""
        beta = np.asarray(beta, dtype=float)
        return 1.0 + self.corner_depth_mm / (np.cos(beta) ** 2 * self.reference_radius_mm)

    def curvature_radii(self, beta: np.ndarray) -> np.ndarray:
        """rho + B^2 sec^3 / (r + B sec^2): offset of the corner-centre trochoid by rho."""
        beta = np.asarray(beta, dtype=float)
        with np.errstate(divide="ignore"):
            return self.speeds(beta) / self.turning_rates(beta)

    def chord_error_bound(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """K l^2 / 8 with interval bounds of curvature K and arc length l from monotone terms."""
        r = self.reference_radius_mm
        ta1, ta2 = self._speed_terms(a)
        tb1, tb2 = self._speed_terms(b)
        # sec is increasing on [0, pi/2): B^2 sec^3 increases, B rho sec^2 is monotone.
        speed_low = self.corner_radius_mm + (ta1 + np.minimum(ta2, tb2)) / r
        speed_high = self.corner_radius_mm + (tb1 + np.maximum(ta2, tb2)) / r
        turning_high = np.maximum(np.abs(self.turning_rates(a)), np.abs(self.turning_rates(b)))
        length = speed_high * (b - a)
        with np.errstate(divide="ignore", invalid="ignore"):
            curvature = np.where(speed_low > 0.0, turning_high / speed_low, np.inf)
            bound = curvature * length * length / 8.0
        return np.where(length == 0.0, 0.0, bound)

    def arc_length_bound(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        ta1, ta2 = self._speed_terms(a)
        tb1, tb2 = self._speed_terms(b)
        speed_high = self.corner_radius_mm + (tb1 + np.maximum(ta2, tb2)) / self.reference_radius_mm
        return speed_high * (b - a)


@dataclass(frozen=True)
class EllipticFillet:
    """Root fillet of a helical gear's transverse section: envelope of the rack tip round's transverse
    section, an ellipse with semi-axes rho / cos(beta_h) along the rolling line and rho radially
    (`stretch` s = 1 / cos(beta_h)); parameter beta as for TrochoidalFillet, the angle on the round in
    the rack's normal section. The rack point at beta is (s (d_n + rho sin b), r - B - rho cos b) with
    inward normal along (-sin b, s cos b); its normal meets the rolling line at
    x_0 = s d_n + (s - 1/s) rho sin b - (B / s) tan b, so it generates the fillet at phi = x_0 / r:
    P = R(-phi) (u, y), u = (B / s) tan b + (rho / s) sin b, y = r - B - rho cos b (s = 1: the
    trochoidal fillet). Derivatives are analytic; the chord-error bound samples curvature and speed
    at 9 points per interval with a 25 % margin (not an interval-arithmetic bound).
    """

    label: str
    reference_radius_mm: float
    corner_offset_mm: float  # d_n: the round's centre from the rack tooth axis, normal section
    corner_depth_mm: float  # B
    corner_radius_mm: float  # rho
    stretch: float  # s = 1 / cos(beta_h)
    start: float
    end: float

    def roll_angle(self, beta: np.ndarray) -> np.ndarray:
        beta = np.asarray(beta, dtype=float)
        s, d, B, rho = self.stretch, self.corner_offset_mm, self.corner_depth_mm, self.corner_radius_mm
        return (s * d + (s - 1.0 / s) * rho * np.sin(beta) - (B / s) * np.tan(beta)) / self.reference_radius_mm

    def _terms(self, beta: np.ndarray):
        """u, y, phi and their first and second derivatives in beta."""
        beta = np.asarray(beta, dtype=float)
        s, B, rho, r = self.stretch, self.corner_depth_mm, self.corner_radius_mm, self.reference_radius_mm
        sin, cos, tan = np.sin(beta), np.cos(beta), np.tan(beta)
        sec2 = 1.0 / cos**2
        u = (B / s) * tan + (rho / s) * sin
        du = (B / s) * sec2 + (rho / s) * cos
        ddu = (2.0 * B / s) * sec2 * tan - (rho / s) * sin
        y = r - B - rho * cos
        dy, ddy = rho * sin, rho * cos
        phi = self.roll_angle(beta)
        dphi = ((s - 1.0 / s) * rho * cos - (B / s) * sec2) / r
        ddphi = (-(s - 1.0 / s) * rho * sin - (2.0 * B / s) * sec2 * tan) / r
        return u, du, ddu, y, dy, ddy, phi, dphi, ddphi

    def points(self, beta: np.ndarray) -> np.ndarray:
        u, _, _, y, _, _, phi, _, _ = self._terms(beta)
        return turned_clockwise(phi, u, y)

    def normals(self, beta: np.ndarray) -> np.ndarray:
        """Into the space: the ellipse's inward normal (-sin b, s cos b), normalised, turned with the gear."""
        beta = np.asarray(beta, dtype=float)
        nx, ny = -np.sin(beta), self.stretch * np.cos(beta)
        length = np.hypot(nx, ny)
        return turned_clockwise(self.roll_angle(beta), nx / length, ny / length)

    def _velocity(self, beta: np.ndarray):
        """dP/dbeta in the turned frame, w = (u' + phi' y, y' - phi' u), and its derivative."""
        u, du, ddu, y, dy, ddy, _, dphi, ddphi = self._terms(beta)
        wx, wy = du + dphi * y, dy - dphi * u
        dwx = ddu + ddphi * y + dphi * dy
        dwy = ddy - ddphi * u - dphi * du
        return wx, wy, dwx, dwy, dphi

    def speeds(self, beta: np.ndarray) -> np.ndarray:
        wx, wy, *_ = self._velocity(beta)
        return np.hypot(wx, wy)

    def turning_rates(self, beta: np.ndarray) -> np.ndarray:
        """d(tangent angle)/dbeta: the turned velocity's angle rate minus phi'."""
        wx, wy, dwx, dwy, dphi = self._velocity(beta)
        with np.errstate(divide="ignore", invalid="ignore"):
            return (wx * dwy - wy * dwx) / (wx * wx + wy * wy) - dphi

    def curvature_radii(self, beta: np.ndarray) -> np.ndarray:
        with np.errstate(divide="ignore"):
            return self.speeds(beta) / self.turning_rates(beta)

    def _sampled(self, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        a, b = np.atleast_1d(np.asarray(a, float)), np.atleast_1d(np.asarray(b, float))
        grid = a[:, None] + (b - a)[:, None] * np.linspace(0.0, 1.0, 9)[None, :]
        speed = self.speeds(grid)
        turning = np.abs(self.turning_rates(grid))
        return speed, turning, b - a

    def chord_error_bound(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        speed, turning, width = self._sampled(a, b)
        speed_low, speed_high = 0.8 * speed.min(axis=1), 1.25 * speed.max(axis=1)
        length = speed_high * width
        with np.errstate(divide="ignore", invalid="ignore"):
            curvature = np.where(speed_low > 0.0, 1.25 * turning.max(axis=1) / speed_low, np.inf)
            bound = curvature * length * length / 8.0
        return np.where(length == 0.0, 0.0, bound)

    def arc_length_bound(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        speed, _, width = self._sampled(a, b)
        return 1.25 * speed.max(axis=1) * width


Fillet = TrochoidalFillet | EllipticFillet


@dataclass(frozen=True)
class RackCorner:
    """The generating rack's right tip corner relative to the rolling line (docs/method.md), transverse
    section; for a helical gear the round is an ellipse (`stretch` = 1 / cos(beta) along the rolling line)."""

    half_thickness_on_rolling_line_mm: float  # e / 2 (transverse)
    corner_offset_mm: float  # d_1 (transverse: the round's centre from the rack tooth axis)
    corner_depth_mm: float  # B
    corner_radius_mm: float  # rho
    stretch: float = 1.0  # 1 / cos(beta): 1 for a spur gear

    @property
    def normal_corner_offset_mm(self) -> float:
        """d_n = d_1 / s: the round's centre from the tooth axis in the rack's normal section."""
        return self.corner_offset_mm / self.stretch


@dataclass(frozen=True)
class _StraightRack:
    """The generating rack of straight teeth: its transverse section is the rack itself (flank at alpha, a
    circular round of radius rho; the fillet a trochoid's parallel curve)."""

    def corner(self, spec: RackGear) -> RackCorner:
        """d_1 = e/2 - B tan(a) - rho / cos(a)."""
        alpha = spec.pressure_angle_rad
        rho = spec.rack_tip_radius_mm
        half_e = spec.space_width_mm / 2.0
        depth = spec.reference_radius_mm - spec.root_radius_mm - rho
        return RackCorner(half_e, half_e - depth * math.tan(alpha) - rho / math.cos(alpha), depth, rho)

    def flank_point_t_distance(self, spec: RackGear, corner: RackCorner) -> float:
        """Where T, the rack flank's lowest straight point (the round's tangent point), generates: its distance
        from the pitch point along the line of action, B / sin(a) + rho."""
        return corner.corner_depth_mm / math.sin(spec.pressure_angle_rad) + corner.corner_radius_mm

    def fillet(self, spec: RackGear, corner: RackCorner, d1: float, end: float) -> Fillet:
        return TrochoidalFillet("fillet", spec.reference_radius_mm, d1, corner.corner_depth_mm,
                                corner.corner_radius_mm, 0.0, end)


@dataclass(frozen=True)
class _HelicalRack:
    """The generating rack of helical teeth, given in the normal section (flank at alpha_n, round rho): in the
    transverse section its flank is at alpha_t and its round an ellipse stretched by s = 1 / cos(beta) along the
    rolling line."""

    def corner(self, spec: RackGear) -> RackCorner:
        """Transverse e and alpha_t, and the elliptic round's offset s rho / cos(alpha_n) from the flank line."""
        alpha = spec.pressure_angle_rad
        rho = spec.rack_tip_radius_mm
        half_e = spec.space_width_mm / 2.0
        depth = spec.reference_radius_mm - spec.root_radius_mm - rho
        stretch = 1.0 / math.cos(spec.helix_angle_rad)
        offset = half_e - depth * math.tan(alpha) - stretch * rho / math.cos(spec.normal_pressure_angle_rad)
        return RackCorner(half_e, offset, depth, rho, stretch)

    def flank_point_t_distance(self, spec: RackGear, corner: RackCorner) -> float:
        """T lies B + rho sin(alpha_n) below the rolling line and the transverse flank is at alpha_t."""
        B, rho = corner.corner_depth_mm, corner.corner_radius_mm
        return (B + rho * math.sin(spec.normal_pressure_angle_rad)) / math.sin(spec.pressure_angle_rad)

    def fillet(self, spec: RackGear, corner: RackCorner, d1: float, end: float) -> Fillet:
        return EllipticFillet("fillet", spec.reference_radius_mm, d1 / corner.stretch, corner.corner_depth_mm,
                              corner.corner_radius_mm, corner.stretch, 0.0, end)


_RACKS: dict[GearKind, _StraightRack | _HelicalRack] = {
    EXTERNAL_SPUR: _StraightRack(), EXTERNAL_HELICAL: _HelicalRack(),
    INTERNAL_SPUR: _StraightRack(),  # a ring is shaped (geometry/internal.py); its rack_corner: the straight rack's
}
"""Each gear kind's generating rack, by the kind object: what differs between a spur and a helical gear's rack
generation (the corner, the flank's lowest straight point, the fillet's curve)."""


def generating_rack(spec: RackGear) -> _StraightRack | _HelicalRack:
    """The rack that generates `spec`'s kind (ValueError naming a kind no rack is known for)."""
    rack = _RACKS.get(spec.kind)
    if rack is None:
        raise ValueError(f"no generating rack is known for a {spec.kind.name} gear (geometry/rack.py, _RACKS)")
    return rack


def rack_corner(spec: RackGear) -> RackCorner:
    """d_1 and B of the generating rack: B = r - r_f - rho, d_1 = e/2 - B tan(a) - rho / cos(a); helical:
    transverse e and alpha_t, and the elliptic round's offset s rho / cos(alpha_n) from the flank line."""
    return generating_rack(spec).corner(spec)
