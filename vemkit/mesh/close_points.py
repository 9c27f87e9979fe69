"""Pairs of points closer than a radius, in numpy: what ``scipy.spatial.cKDTree.query_pairs`` gives,
without importing scipy.spatial (with scipy.special: 0.1-0.3 s of every command's start-up).

The points are binned on a grid of cells of side at least the radius (and at least 2^-19 of the
extent, so that a cell's key fits in an int64 in 3D); two points within the radius lie in the same
or in adjacent cells, so only those pairs are measured. A valid mesh has about one vertex per cell:
the work is a sort and a few searches, linear in the number of points. ``has_close_pair`` only
screens (one merge walk, no candidate arrays: a valid mesh's check costs a sort).
"""

from __future__ import annotations

import itertools

import numba
import numpy as np

from vemkit.mesh.geometry import bounds

#: the finest grid: cells per axis (the keys of 3D cells, with one cell of margin each side, fit in an int64)
MAX_CELLS_PER_AXIS = 2**19


def close_pairs(points: np.ndarray, radius: float) -> np.ndarray:
    """``(P, 2)`` index pairs ``i < j`` of the rows of ``points`` (N, d) at most ``radius`` apart
    (Euclidean), in no particular order: the pairs of ``cKDTree(points).query_pairs(radius)``."""
    points = np.asarray(points, dtype=float)
    n, dimension = points.shape
    if n < 2:
        return np.zeros((0, 2), dtype=np.int64)
    keys, weights = _cell_keys(points, radius)
    order = np.argsort(keys, kind="stable")
    keys = keys[order]
    candidates = [_same_cell_pairs(keys)]
    for shift in _forward_neighbours(dimension):
        candidates.append(_shifted_cell_pairs(keys, int(np.dot(shift, weights))))
    a, b = (order[c] for c in np.concatenate(candidates, axis=1))
    near = np.einsum("ij,ij->i", points[a] - points[b], points[a] - points[b]) <= float(radius) ** 2
    return np.stack([np.minimum(a[near], b[near]), np.maximum(a[near], b[near])], axis=1)


def has_close_pair(points: np.ndarray, radius: float) -> bool:
    """True whenever ``close_pairs(points, radius)`` has a pair, without forming the candidate pairs
    (the same cells, the points sorted by cell, every cell met with its forward neighbours by one
    merge walk): a screen, true also for pairs up to (1 + 1e-12) x radius apart (a sum's rounding
    apart from ``close_pairs``), so a check runs ``close_pairs`` only when it says True."""
    points = np.asarray(points, dtype=float)
    n, dimension = points.shape
    if n < 2:
        return False
    keys, weights = _cell_keys(points, radius)
    order = np.argsort(keys)
    shifts = np.array([int(np.dot(shift, weights)) for shift in _forward_neighbours(dimension)], dtype=np.int64)
    return bool(
        _any_close_pair(np.ascontiguousarray(points), keys[order], order, shifts, float(radius) ** 2 * (1 + 1e-12))
    )


def _cell_keys(points: np.ndarray, radius: float):
    """(key of every point's grid cell, the key's weight per axis): cells of side at least radius
    and 2^-19 of the extent, numbered from 1 so that a neighbour's key is the key plus a shift."""
    low, high = bounds(points)
    extent = max(float(np.max(high - low)), np.finfo(float).tiny)
    side = max(float(radius), extent / MAX_CELLS_PER_AXIS)
    cells = np.floor((points - low) / side).astype(np.int64) + 1  # 1 ... MAX_CELLS_PER_AXIS + 1
    base = MAX_CELLS_PER_AXIS + 3
    weights = base ** np.arange(points.shape[1] - 1, -1, -1, dtype=np.int64)
    return cells @ weights, weights


@numba.njit(cache=True)
def _squared_distance(points, i, j):
    total = 0.0
    for k in range(points.shape[1]):
        d = points[i, k] - points[j, k]
        total += d * d
    return total


@numba.njit(cache=True)
def _any_close_pair(points, keys, order, shifts, radius2):
    """Is any pair of points (sorted by cell key: ``keys`` and ``order``) in the same cell, or in a
    cell and its neighbour at key + shift, within squared distance radius2? Linear in the points
    (for about one point per cell): the neighbours of increasing keys have increasing keys."""
    n = keys.shape[0]
    for p in range(n):
        q = p + 1
        while q < n and keys[q] == keys[p]:
            if _squared_distance(points, order[p], order[q]) <= radius2:
                return True
            q += 1
    for shift in shifts:
        q = 0
        for p in range(n):
            target = keys[p] + shift
            while q < n and keys[q] < target:
                q += 1
            r = q
            while r < n and keys[r] == target:
                if _squared_distance(points, order[p], order[r]) <= radius2:
                    return True
                r += 1
    return False


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
