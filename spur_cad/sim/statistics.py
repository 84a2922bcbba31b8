"""Statistics of a simulated gear's deviations in memory bounded by a block of tooth spaces, not the whole gear.

A big gear holds tens of millions of (space, point, row) deviations; the summary's scallop mean and
percentiles and its per-feature figures are computed block by block (whole tooth spaces, at most
BLOCK_VALUES values each), where one copy of all of them would double the run's peak memory. The
percentiles are exact: numpy's linear interpolation between the two order statistics around the rank, the
order statistics found by narrowing a value range with histograms until few enough values remain to gather.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Iterator

import numpy as np

BLOCK_VALUES = 2_000_000
"""Deviations per block (whole tooth spaces, at least one): 16 MB of float64."""
GATHER_LIMIT = 4_000_000
"""Values gathered into one array at most (32 MB); above it, order statistics are found by narrowing."""
_BINS = 4096


@dataclass(frozen=True)
class ScallopStatistics:
    """The leftover of the finished design points (gouges count as 0; points never cut are left out): mean and
    95th / 99th percentiles (mm), and how many points they cover."""

    mean_mm: float
    p95_mm: float
    p99_mm: float
    points: int


@dataclass(frozen=True)
class FeatureStatistics:
    """Largest gouge and leftover (mm, 0 when none) and the mean deviation of one feature's design points."""

    max_gouge_mm: float
    max_leftover_mm: float
    mean_mm: float


def space_blocks(deviation: np.ndarray, max_values: int | None = None) -> Iterator[np.ndarray]:
    """Views of `deviation` (space, point, row) holding whole tooth spaces, at most max_values (default
    BLOCK_VALUES) each, but one space at least."""
    per_space = max(1, int(np.prod(deviation.shape[1:])))
    step = max(1, (BLOCK_VALUES if max_values is None else max_values) // per_space)
    for first in range(0, deviation.shape[0], step):
        yield deviation[first:first + step]


def _finished_leftover(block: np.ndarray, uncut_from_mm: float) -> np.ndarray:
    """The block's finished values (below uncut_from_mm), gouges set to 0: a new array."""
    values = block[block < uncut_from_mm]
    np.maximum(values, 0.0, out=values)
    return values


def scallop_statistics(deviation: np.ndarray, uncut_from_mm: float) -> ScallopStatistics:
    """Mean and percentiles of the finished points' leftover, block by block (see the module docstring)."""

    def blocks() -> Iterator[np.ndarray]:
        return (_finished_leftover(block, uncut_from_mm) for block in space_blocks(deviation))

    count, total = 0, 0.0
    for values in blocks():
        count += values.size
        total += float(values.sum())
    if count == 0:
        return ScallopStatistics(0.0, 0.0, 0.0, 0)
    if count <= GATHER_LIMIT:
        values = np.concatenate(list(blocks()))
        p95, p99 = (float(v) for v in np.percentile(values, [95, 99]))
        return ScallopStatistics(float(values.mean()), p95, p99, count)
    p95, p99 = (linear_percentile(blocks, count, q) for q in (95.0, 99.0))
    return ScallopStatistics(total / count, p95, p99, count)


def linear_percentile(blocks: Callable[[], Iterator[np.ndarray]], count: int, q: float) -> float:
    """numpy's default ('linear') percentile q of the `count` values that blocks() yields, without holding them
    all: the order statistics at floor and ceil of q/100 * (count - 1), interpolated as numpy does."""
    virtual = np.true_divide(q, 100.0) * (count - 1)
    previous = int(np.floor(virtual))
    gamma = float(virtual - previous)
    below = kth_smallest(blocks, previous)
    above = kth_smallest(blocks, min(previous + 1, count - 1))
    difference = above - below
    return above - difference * (1.0 - gamma) if gamma >= 0.5 else below + difference * gamma


def kth_smallest(blocks: Callable[[], Iterator[np.ndarray]], k: int, gather_limit: int | None = None) -> float:
    """The k-th smallest (from 0) of the values blocks() yields: the range holding it is narrowed by histograms
    over the values inside it until at most gather_limit (default GATHER_LIMIT) remain, which are gathered and
    partitioned."""
    gather_limit = GATHER_LIMIT if gather_limit is None else gather_limit
    low, high, high_closed, below = -np.inf, np.inf, True, 0

    def inside(values: np.ndarray) -> np.ndarray:
        keep = (values >= low) & ((values <= high) if high_closed else (values < high))
        return values[keep]

    while True:
        count, smallest, largest = 0, np.inf, -np.inf
        for values in blocks():
            chosen = inside(values)
            if chosen.size:
                count += chosen.size
                smallest, largest = min(smallest, float(chosen.min())), max(largest, float(chosen.max()))
        if smallest == largest or count <= gather_limit:
            break
        edges = np.linspace(smallest, largest, _BINS + 1)
        counts = np.zeros(_BINS, np.int64)
        for values in blocks():
            chosen = inside(values)
            counts += np.bincount(np.minimum(np.searchsorted(edges, chosen, side="right") - 1, _BINS - 1),
                                  minlength=_BINS)
        cumulative = np.cumsum(counts)
        j = int(np.searchsorted(cumulative, k - below, side="right"))
        below += int(cumulative[j - 1]) if j else 0
        low, high, high_closed = float(edges[j]), float(edges[j + 1]), j == _BINS - 1
    if smallest == largest:
        return smallest
    gathered = np.concatenate([inside(values) for values in blocks()])
    return float(np.partition(gathered, k - below)[k - below])


def feature_statistics(deviation: np.ndarray, points: np.ndarray) -> FeatureStatistics:
    """Largest gouge, largest leftover and mean over the design points selected by `points` (a mask over the
    points axis), every space and row, block by block."""
    smallest, largest, total, count = np.inf, -np.inf, 0.0, 0
    for block in space_blocks(deviation):
        values = block[:, points, :]
        smallest, largest = min(smallest, float(values.min())), max(largest, float(values.max()))
        total += float(values.sum())
        count += values.size
    return FeatureStatistics(max(0.0, -smallest), max(0.0, largest), total / count)
