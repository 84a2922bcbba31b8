"""Chordal-tolerance sampling with a proven bound, and the full gear outline.

Each segment supplies a rigorous upper bound of the distance between its exact arc and the
chord over a parameter interval; intervals are split until every bound is within the
tolerance, so the polyline never strays further than the tolerance from the exact curve.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from spur_cad.errors import WorkLimitError, require_instance
from spur_cad.geometry.profile import SEGMENT_LABELS, Segment, ToothSpaceProfile
from spur_cad.geometry.spec import GearSpec

DEFAULT_TOLERANCE_MM = 0.001
_MAX_REFINEMENTS = 80
MAX_POINTS_PER_SEGMENT = 1_000_000
"""Chordal sampling refuses (WorkLimitError) rather than build more points than this on one segment."""


@dataclass(frozen=True)
class ProfileSamples:
    """Ordered samples of a profile: points (N, 2), unit normals into the space (N, 2),
    signed curvature radii (N,), segment label index per point (N,) into SEGMENT_LABELS,
    and the segment parameter of each point (N,)."""

    points: np.ndarray
    normals: np.ndarray
    curvature_radii: np.ndarray
    labels: np.ndarray
    parameters: np.ndarray

    def label_names(self) -> list[str]:
        return [SEGMENT_LABELS[i] for i in self.labels]

    def __len__(self) -> int:
        return len(self.points)


def even_arc_length_parameters(segment: Segment, spacing_mm: float) -> np.ndarray:
    """Parameters of a segment at even arc length (at most about `spacing_mm` apart), both ends
    included; arc length from a 4000-chord polyline, for fixed-spacing sampling (not tolerance-driven)."""
    dense = np.linspace(segment.start, segment.end, 4001)
    pts = segment.points(dense)
    arc = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))])
    n = max(1, math.ceil(arc[-1] / spacing_mm))
    return np.interp(np.linspace(0.0, arc[-1], n + 1), arc, dense)


def segment_parameters(segment: Segment, tolerance_mm: float, extra_curvature: float = 0.0) -> np.ndarray:
    """Increasing parameters from segment.start to segment.end whose chords are within tolerance.

    With `extra_curvature` k > 0 the bound per interval grows by k l^2 / 8 (l: arc length): the
    CAM layer passes 1 / r_t so that the cusp between two tool-corner circles of radius r_t
    touching consecutive points is within the tolerance ((curvature + 1/r_t) l^2 / 8 bounds it).
    """
    if not (math.isfinite(tolerance_mm) and tolerance_mm > 0.0):
        raise ValueError(f"chordal tolerance must be a positive number, got {tolerance_mm}")
    if segment.end <= segment.start:
        return np.array([segment.start, segment.end])
    pending_a = np.array([segment.start])
    pending_b = np.array([segment.end])
    accepted: list[np.ndarray] = []
    for _ in range(_MAX_REFINEMENTS):
        bound = segment.chord_error_bound(pending_a, pending_b)
        if extra_curvature > 0.0:
            bound = bound + extra_curvature * segment.arc_length_bound(pending_a, pending_b) ** 2 / 8.0
        ok = bound <= tolerance_mm
        accepted.append(pending_a[ok])
        if ok.all():
            break
        a, b, bound = pending_a[~ok], pending_b[~ok], bound[~ok]
        # The bound shrinks like the square of the interval: split into enough pieces at once.
        pieces = np.where(np.isfinite(bound), np.ceil(np.sqrt(bound / tolerance_mm) * 1.05), 2.0)
        pieces = np.clip(pieces, 2, 8).astype(int)
        if sum(len(p) for p in accepted) + int(pieces.sum()) > MAX_POINTS_PER_SEGMENT:
            raise WorkLimitError(f"a chordal tolerance of {tolerance_mm:.3g} mm would need more than "
                                 f"{MAX_POINTS_PER_SEGMENT:,} points on the {segment.label}; use a larger tolerance")
        new_a, new_b = [], []
        for lo, hi, n in zip(a, b, pieces):
            edges = np.linspace(lo, hi, n + 1)
            new_a.append(edges[:-1])
            new_b.append(edges[1:])
        pending_a, pending_b = np.concatenate(new_a), np.concatenate(new_b)
    else:  # pragma: no cover - the bounds shrink quadratically; this is a safety net
        raise RuntimeError(f"chordal sampling of the {segment.label} did not converge")
    starts = np.sort(np.concatenate(accepted))
    return np.append(starts, segment.end)


def sample_profile(profile: ToothSpaceProfile, tolerance_mm: float = DEFAULT_TOLERANCE_MM) -> ProfileSamples:
    """Sample the right half of the tooth space, root to tip; shared segment ends appear once.

    At a junction the point keeps the label, normal and curvature of the segment that ends
    there (for a tangent junction the normals agree anyway).
    """
    require_instance(profile, ToothSpaceProfile, "profile")
    require_instance(tolerance_mm, (int, float), "tolerance_mm")
    pts, nrm, rad, lab, par = [], [], [], [], []
    for index, segment in enumerate(profile.segments):
        params = segment_parameters(segment, tolerance_mm)
        if index > 0:
            params = params[1:]
        pts.append(segment.points(params))
        nrm.append(segment.normals(params))
        rad.append(segment.curvature_radii(params))
        lab.append(np.full(len(params), SEGMENT_LABELS.index(segment.label)))
        par.append(params)
    return ProfileSamples(np.concatenate(pts), np.concatenate(nrm), np.concatenate(rad),
                          np.concatenate(lab), np.concatenate(par))


def tooth_space_samples(spec: GearSpec, tolerance_mm: float = DEFAULT_TOLERANCE_MM) -> ProfileSamples:
    """Convenience: sampled right half of a tooth space of `spec`."""
    return sample_profile(spec.tooth_space_profile(), tolerance_mm)


def full_space_points(samples: ProfileSamples) -> np.ndarray:
    """Whole boundary of one space, counter-clockwise: right half tip->root, then its mirror root->tip.

    Starts on the tooth centre line right of the space (polar angle +pi/z) and ends on the one
    to the left (-pi/z).
    """
    right = samples.points[::-1]
    left = samples.points[1:] * np.array([-1.0, 1.0])
    return np.concatenate([right, left])


def gear_outline(spec: GearSpec, tolerance_mm: float = DEFAULT_TOLERANCE_MM) -> np.ndarray:
    """Closed outline of the whole gear (all teeth), counter-clockwise, first point not repeated.

    Space k is space 0 turned counter-clockwise by k * 360/z degrees in the gap frame.
    """
    space = full_space_points(sample_profile(spec.tooth_space_profile(), tolerance_mm))[:-1]
    pitch_angle = 2.0 * math.pi / spec.teeth
    chunks = []
    for k in range(spec.teeth):
        c, s = math.cos(k * pitch_angle), math.sin(k * pitch_angle)
        chunks.append(space @ np.array([[c, s], [-s, c]]))
    return np.concatenate(chunks)


def polygon_area(points: np.ndarray) -> float:
    """Signed shoelace area of a closed polygon (positive when counter-clockwise)."""
    x, y = points[:, 0], points[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
