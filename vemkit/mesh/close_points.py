"""Pairs of points closer than a radius, in numpy: what ``scipy.spatial.cKDTree.query_pairs`` gives,
without importing scipy.spatial (with scipy.special: 0.1-0.3 s of every command's start-up).

The points are binned on a grid of cells of side at least the radius (and at least 2^-19 of the
extent, so that a cell's key fits in an int64 in 3D); two points within the radius lie in the same
or in adjacent cells, so only those pairs are measured. A valid mesh has about one vertex per cell:
the work is a sort and a few searches, linear in the number of points.
"""

from __future__ import annotations

import itertools

import numpy as np

#: the finest grid: cells per axis (the keys of 3D cells, with one cell of margin each side, fit in an int64)
MAX_CELLS_PER_AXIS = 2**19


def close_pairs(points: np.ndarray, radius: float) -> np.ndarray:
    """``(P, 2)`` index pairs ``i < j`` of the rows of ``points`` (N, d) at most ``radius`` apart
    (Euclidean), in no particular order: the pairs of ``cKDTree(points).query_pairs(radius)``."""
    points = np.asarray(points, dtype=float)
    n, dimension = points.shape
    if n < 2:
        return np.zeros((0, 2), dtype=np.int64)
    low = points.min(axis=0)
    extent = max(float(np.max(np.ptp(points, axis=0))), np.finfo(float).tiny)
    side = max(float(radius), extent / MAX_CELLS_PER_AXIS)
    cells = np.floor((points - low) / side).astype(np.int64) + 1  # 1 ... MAX_CELLS_PER_AXIS + 1
    base = MAX_CELLS_PER_AXIS + 3
    weights = base ** np.arange(dimension - 1, -1, -1, dtype=np.int64)
    keys = cells @ weights
    order = np.argsort(keys, kind="stable")
    keys = keys[order]
    candidates = [_same_cell_pairs(keys)]
    for shift in _forward_neighbours(dimension):
        candidates.append(_shifted_cell_pairs(keys, int(np.dot(shift, weights))))
    a, b = (order[c] for c in np.concatenate(candidates, axis=1))
    near = np.einsum("ij,ij->i", points[a] - points[b], points[a] - points[b]) <= float(radius) ** 2
    return np.stack([np.minimum(a[near], b[near]), np.maximum(a[near], b[near])], axis=1)


def _forward_neighbours(dimension: int):
    """The neighbour cell offsets in {-1, 0, 1}^d that come after 0 (each pair of cells once)."""
    return [s for s in itertools.product((-1, 0, 1), repeat=dimension) if s > (0,) * dimension]


def _expand(first: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """(2, sum counts): position p paired with first[p], first[p] + 1, ..., first[p] + counts[p] - 1."""
    rows = np.repeat(np.arange(counts.size, dtype=np.int64), counts)
    starts = np.repeat(np.cumsum(counts) - counts, counts)
    return np.stack([rows, first[rows] + np.arange(rows.size, dtype=np.int64) - starts])


def _same_cell_pairs(keys: np.ndarray) -> np.ndarray:
    """Positions in ``keys`` (sorted) paired with the earlier positions of the same key."""
    group_start = np.searchsorted(keys, keys, side="left")
    positions = np.arange(keys.size, dtype=np.int64)
    return _expand(group_start, positions - group_start)


def _shifted_cell_pairs(keys: np.ndarray, shift: int) -> np.ndarray:
    """Positions in ``keys`` (sorted) paired with the positions of key + ``shift``."""
    first = np.searchsorted(keys, keys + shift, side="left")
    last = np.searchsorted(keys, keys + shift, side="right")
    return _expand(first, last - first)
