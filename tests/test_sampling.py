"""Chordal-tolerance sampling: the polyline never strays from the dense exact curve by more than the tolerance."""

from __future__ import annotations

import numpy as np
import pytest

from spur_cad.geometry import sample_profile
from spur_cad.geometry.sampling import segment_parameters
from tests.gears import GEAR_CASES, spec_of
from tests.textbook import point_polyline_distance


@pytest.mark.parametrize("name", list(GEAR_CASES))
@pytest.mark.parametrize("tolerance", [1e-2, 1e-3, 1e-4, pytest.param(1e-5, marks=pytest.mark.slow)])
def test_polyline_within_tolerance_of_dense_exact_curve(name, tolerance):
    profile = spec_of(name).tooth_space_profile()
    worst = 0.0
    for segment in profile.segments:
        params = segment_parameters(segment, tolerance)
        assert params[0] == segment.start and params[-1] == segment.end
        assert np.all(np.diff(params) > 0)
        polyline = segment.points(params)
        # Dense exact points: 200 per sampled interval, so every chord is examined closely.
        dense = np.concatenate([np.linspace(a, b, 200, endpoint=False) for a, b in zip(params, params[1:])])
        distances = point_polyline_distance(segment.points(dense), polyline)
        worst = max(worst, float(distances.max()))
    assert worst <= tolerance * (1 + 1e-9)
    # The bound is not wildly pessimistic: the worst chord uses a fair part of the tolerance.
    assert worst > 0.05 * tolerance


def test_finer_tolerance_gives_more_points_and_ordered_labels():
    spec = spec_of("reference_z23_m4")
    coarse = sample_profile(spec.tooth_space_profile(), 1e-2)
    fine = sample_profile(spec.tooth_space_profile(), 1e-4)
    assert len(fine) > 2 * len(coarse)
    # Labels run root -> fillet -> involute -> tip, never back.
    assert np.all(np.diff(fine.labels) >= 0)
    assert fine.points[0] == pytest.approx([0.0, spec.root_radius_mm])
    assert np.hypot(*fine.points[-1]) == pytest.approx(spec.tip_radius_mm)


def test_rejects_non_positive_tolerance():
    spec = spec_of("reference_z23_m4")
    with pytest.raises(ValueError, match="tolerance"):
        sample_profile(spec.tooth_space_profile(), 0.0)
