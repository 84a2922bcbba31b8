"""Independent references for the tests: textbook / ISO 21771 formulas and the generating rack's
kinematics written from scratch here (not imported from spur_cad), so the tests compare the
engine with an independent derivation rather than with itself."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq


def inv(a: float) -> float:
    return math.tan(a) - a


def inv_inverse(value: float) -> float:
    return brentq(lambda a: inv(a) - value, 0.0, math.pi / 2 - 1e-9, xtol=1e-16, rtol=1e-15, maxiter=500)


@dataclass(frozen=True)
class Textbook:
    """A spur gear's textbook quantities (ISO 21771 symbols in the field names' comments)."""

    z: int
    m: float
    alpha_deg: float
    x: float = 0.0
    ha: float = 1.0
    hf: float = 1.25
    rho: float = 0.0
    allowance_fraction: float = 0.0
    allowance_mm: float = 0.0

    @property
    def alpha(self) -> float:
        return math.radians(self.alpha_deg)

    @property
    def r(self) -> float:  # reference radius d/2
        return self.m * self.z / 2

    @property
    def rb(self) -> float:  # base radius
        return self.r * math.cos(self.alpha)

    @property
    def ra(self) -> float:
        return self.r + (self.ha + self.x) * self.m

    @property
    def rf(self) -> float:
        return self.r - (self.hf - self.x) * self.m

    @property
    def s_nominal(self) -> float:
        return self.m * (math.pi / 2 + 2 * self.x * math.tan(self.alpha))

    @property
    def delta_s(self) -> float:  # thickness reduction on the reference circle
        return self.allowance_fraction * self.s_nominal + self.allowance_mm

    @property
    def s(self) -> float:
        return self.s_nominal - self.delta_s

    @property
    def e(self) -> float:
        return math.pi * self.m - self.s

    @property
    def theta_b(self) -> float:
        """Polar angle (from the space axis) of the right flank's involute at the base circle."""
        return math.pi / self.z - self.s / (2 * self.r) - inv(self.alpha)

    def thickness_at(self, ry: float) -> float:
        """docs/method.md: s_y = 2 r_y (s/(2r) + inv(alpha) - inv(alpha_y))."""
        ay = math.acos(self.rb / ry)
        return 2 * ry * (self.s / (2 * self.r) + inv(self.alpha) - inv(ay))

    # --- the generating rack, rolling on the reference circle ------------------------------
    @property
    def corner_depth(self) -> float:  # B
        return self.r - self.rf - self.rho

    @property
    def corner_offset(self) -> float:  # d_1
        return self.e / 2 - self.corner_depth * math.tan(self.alpha) - self.rho / math.cos(self.alpha)

    def to_gear(self, phi: float, q: np.ndarray) -> np.ndarray:
        """Rack point q (rolling-line coordinates at phi = 0) in the gear frame after rolling by phi."""
        q = np.atleast_2d(q) - np.array([self.r * phi, 0.0])
        c, s = math.cos(phi), math.sin(phi)
        return np.stack([q[:, 0] * c + q[:, 1] * s, -q[:, 0] * s + q[:, 1] * c], axis=-1)

    def pitch_point(self, phi: float) -> np.ndarray:
        """The fixed rolling contact (0, r) of the machine frame, seen from the gear turned by phi.

        In the rack's own coordinates it is (r phi, r): the rack has moved by r phi."""
        return self.to_gear(phi, np.array([[self.r * phi, self.r]]))[0]

    def corner_centre(self, phi: float) -> np.ndarray:
        return self.to_gear(phi, np.array([[self.corner_offset, self.r - self.corner_depth]]))[0]

    def rack_tooth_outline(self, height: float, corner_points: int = 64) -> np.ndarray:
        """Closed outline of one rack tooth (rolling-line coordinates), tip down, `height` above the rolling line."""
        a = self.alpha
        d1, B, rho = self.corner_offset, self.corner_depth, self.rho
        yc = self.r - B
        pts = []
        # right corner arc from the bottom (angle -90 deg) to the flank tangent (-alpha)
        for ang in np.linspace(-math.pi / 2, -a, corner_points):
            pts.append((d1 + rho * math.cos(ang), yc + rho * math.sin(ang)))
        top = self.r + height
        pts.append((self.e / 2 + height * math.tan(a), top))
        pts.append((-(self.e / 2 + height * math.tan(a)), top))
        for ang in np.linspace(math.pi + a, 1.5 * math.pi, corner_points):
            pts.append((-d1 + rho * math.cos(ang), yc + rho * math.sin(ang)))
        return np.array(pts)


def span_iso(g: Textbook, k: int) -> float:
    """ISO 21771 base tangent length for the nominal tooth, minus the allowance projected on the base tangent."""
    nominal = g.m * math.cos(g.alpha) * ((k - 0.5) * math.pi + g.z * inv(g.alpha)) + 2 * g.x * g.m * math.sin(g.alpha)
    return nominal - g.delta_s * math.cos(g.alpha)


def over_pins_iso(g: Textbook, pin_d: float) -> float:
    """Dimension over pins (textbook): inv(a_M) = inv(a) + D/(m z cos a) - pi/(2z) + 2 x tan(a)/z - ds/(m z)."""
    inv_am = (inv(g.alpha) + pin_d / (g.m * g.z * math.cos(g.alpha)) - math.pi / (2 * g.z)
              + 2 * g.x * math.tan(g.alpha) / g.z - g.delta_s / (g.m * g.z))
    am = inv_inverse(inv_am)
    dm = g.m * g.z * math.cos(g.alpha) / math.cos(am)
    if g.z % 2 == 0:
        return dm + pin_d
    return dm * math.cos(math.pi / (2 * g.z)) + pin_d


def point_polyline_distance(points: np.ndarray, polyline: np.ndarray) -> np.ndarray:
    """Distance of each point to an open polyline (vectorised over points, looped over segments in chunks)."""
    a = polyline[:-1]
    b = polyline[1:]
    ab = b - a
    denom = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
    best = np.full(len(points), np.inf)
    for start in range(0, len(points), 2000):
        p = points[start:start + 2000, None, :]
        t = np.clip(np.einsum("pij,ij->pi", p - a[None], ab) / denom, 0.0, 1.0)
        proj = a[None] + t[..., None] * ab[None]
        best[start:start + 2000] = np.sqrt(((p - proj) ** 2).sum(-1)).min(axis=1)
    return best


@dataclass(frozen=True)
class HelicalTextbook:
    """A helical gear's textbook quantities from its normal-section (rack) values (ISO 21771), written
    here from scratch; the transverse rack is the normal rack stretched along the rolling line by
    1 / cos(beta) (so its tip rounds are ellipses)."""

    z: int
    mn: float
    alpha_n_deg: float
    beta_deg: float
    x: float = 0.0
    ha: float = 1.0
    hf: float = 1.25
    rho: float = 0.0
    allowance_fraction: float = 0.0

    @property
    def beta(self) -> float:
        return math.radians(self.beta_deg)

    @property
    def alpha_n(self) -> float:
        return math.radians(self.alpha_n_deg)

    @property
    def mt(self) -> float:
        return self.mn / math.cos(self.beta)

    @property
    def alpha_t(self) -> float:
        return math.atan(math.tan(self.alpha_n) / math.cos(self.beta))

    @property
    def r(self) -> float:
        return self.z * self.mt / 2

    @property
    def rb(self) -> float:
        return self.r * math.cos(self.alpha_t)

    @property
    def ra(self) -> float:
        return self.r + (self.ha + self.x) * self.mn

    @property
    def rf(self) -> float:
        return self.r - (self.hf - self.x) * self.mn

    @property
    def beta_b(self) -> float:
        return math.atan(math.tan(self.beta) * math.cos(self.alpha_t))

    @property
    def lead(self) -> float:
        return math.pi * self.z * self.mn / math.sin(self.beta)

    @property
    def st(self) -> float:  # transverse tooth thickness on the reference circle, allowance applied
        return (1 - self.allowance_fraction) * self.mt * (math.pi / 2 + 2 * self.x * math.tan(self.alpha_n))

    @property
    def delta_st(self) -> float:
        return self.allowance_fraction * self.mt * (math.pi / 2 + 2 * self.x * math.tan(self.alpha_n))

    def transverse_rack_outline(self, height: float, corner_points: int = 64) -> np.ndarray:
        """One tooth of the transverse rack (rolling-line coordinates, tip down): the normal rack tooth with
        circular tip corners, every x stretched by 1 / cos(beta)."""
        an, s = self.alpha_n, 1.0 / math.cos(self.beta)
        e_n = math.pi * self.mn - self.st * math.cos(self.beta)  # normal space width of the gear
        depth = self.r - self.rf - self.rho  # B, the same in both sections
        d_n = e_n / 2 - depth * math.tan(an) - self.rho / math.cos(an)
        yc = self.r - depth
        pts = []
        for ang in np.linspace(-math.pi / 2, -an, corner_points):
            pts.append((d_n + self.rho * math.cos(ang), yc + self.rho * math.sin(ang)))
        top = self.r + height
        pts.append((e_n / 2 + height * math.tan(an), top))
        pts.append((-(e_n / 2 + height * math.tan(an)), top))
        for ang in np.linspace(math.pi + an, 1.5 * math.pi, corner_points):
            pts.append((-d_n + self.rho * math.cos(ang), yc + self.rho * math.sin(ang)))
        out = np.array(pts)
        out[:, 0] *= s
        return out

    def to_gear(self, phi: float, q: np.ndarray) -> np.ndarray:
        """Transverse rack point q (rolling-line coordinates at phi = 0) in the gear frame after rolling by phi."""
        q = np.atleast_2d(q) - np.array([self.r * phi, 0.0])
        c, s = math.cos(phi), math.sin(phi)
        return np.stack([q[:, 0] * c + q[:, 1] * s, -q[:, 0] * s + q[:, 1] * c], axis=-1)
