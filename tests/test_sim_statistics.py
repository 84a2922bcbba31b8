"""The simulation's statistics in bounded memory equal numpy's on the whole array: exact percentiles by
narrowing (ties, zeros, one value, blocks of several spaces), means and per-feature extremes."""

from __future__ import annotations

import numpy as np
import pytest

from spur_cad.sim import statistics
from spur_cad.sim.statistics import (
    feature_statistics,
    kth_smallest,
    linear_percentile,
    scallop_statistics,
    space_blocks,
)


def _deviation(seed: int, spaces: int = 13, points: int = 57, rows: int = 31) -> np.ndarray:
    """Deviations as a simulation leaves them: gouges, a cloud of leftovers with many exact ties, uncut points."""
    rng = np.random.default_rng(seed)
    values = rng.gamma(2.0, 0.002, (spaces, points, rows)) - 0.001
    values[rng.random(values.shape) < 0.2] = 0.0035  # ties
    values[rng.random(values.shape) < 0.05] = 1.0  # never cut (the blade's outer end)
    return values


@pytest.mark.parametrize("seed", range(4))
def test_order_statistics_found_by_narrowing_equal_a_full_sort(seed):
    values = _deviation(seed).ravel()
    ordered = np.sort(values)

    def blocks():
        return iter(np.array_split(values, 7))

    for k in (0, 1, 17, len(values) // 2, len(values) - 2, len(values) - 1):
        assert kth_smallest(blocks, k, gather_limit=50) == ordered[k]
    for q in (0.0, 5.0, 50.0, 95.0, 99.0, 100.0):
        assert linear_percentile(blocks, len(values), q) == np.percentile(values, q)


def test_a_single_repeated_value_needs_no_histogram():
    def blocks():
        return iter([np.full(100, 0.25), np.full(50, 0.25)])

    assert kth_smallest(blocks, 120, gather_limit=10) == 0.25


def test_blocks_hold_whole_spaces_and_cover_the_gear():
    deviation = _deviation(1)
    blocks = list(space_blocks(deviation, max_values=3 * 57 * 31 + 5))
    assert [b.shape[0] for b in blocks] == [3, 3, 3, 3, 1]
    assert all(np.shares_memory(b, deviation) for b in blocks)  # views, not copies
    assert [b.shape[0] for b in space_blocks(deviation, max_values=10)] == [1] * 13  # one space at least


@pytest.mark.parametrize("gather_limit", [10**9, 100])
def test_scallop_statistics_equal_numpys_on_the_finished_points(monkeypatch, gather_limit):
    deviation = _deviation(7)
    monkeypatch.setattr(statistics, "BLOCK_VALUES", 4 * 57 * 31)  # four spaces a block
    monkeypatch.setattr(statistics, "GATHER_LIMIT", gather_limit)  # gathered whole, or narrowed
    finished = deviation[deviation < 1.0 - 1e-9]
    finished = np.maximum(finished, 0.0)
    result = scallop_statistics(deviation, 1.0 - 1e-9)
    assert result.points == finished.size
    assert result.p95_mm == np.percentile(finished, 95) and result.p99_mm == np.percentile(finished, 99)
    assert result.mean_mm == pytest.approx(finished.mean(), rel=1e-12)


def test_feature_statistics_equal_numpys_on_the_selected_points(monkeypatch):
    deviation = _deviation(3)
    monkeypatch.setattr(statistics, "BLOCK_VALUES", 2 * 57 * 31)
    mask = np.zeros(57, bool)
    mask[10:20] = True
    values = deviation[:, mask, :]
    result = feature_statistics(deviation, mask)
    assert result.max_gouge_mm == max(0.0, -values.min()) and result.max_leftover_mm == values.max()
    assert result.mean_mm == pytest.approx(values.mean(), rel=1e-12)


def test_nothing_finished_gives_zeros():
    assert scallop_statistics(np.ones((2, 3, 4)), 1.0 - 1e-9) == statistics.ScallopStatistics(0.0, 0.0, 0.0, 0)
