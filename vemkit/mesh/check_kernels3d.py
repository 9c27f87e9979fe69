"""Numba screens of ``vemkit.mesh.checks3d``: one pass over the faces or cells that says a mesh
certainly passes a check. When a screen says False the check's numpy form runs and decides (and
words the error), so the screens never change what is refused; on a valid mesh they replace sorts
of every cell's edges and (entries x 3) temporaries (at 200 000 tetrahedra: 0.3 s of 0.8 s).
tests/mesh/test_check_kernels3d.py compares every screen with its check on broken meshes."""

from __future__ import annotations

import numba
import numpy as np

#: a cell with more signed face edges than this is left to the numpy check (pairwise work)
PAIRWISE_EDGES_MAX = 512
#: relative margin of the screens' float comparisons (their sums round apart from numpy's)
MARGIN = 1e-9


@numba.njit(cache=True)
def no_repeats(offsets, values):
    """True when no CSR segment lists a value twice (``checks3d._first_repeat`` is None); segments
    are compared pairwise, or screened False above ``PAIRWISE_EDGES_MAX`` entries."""
    for k in range(offsets.size - 1):
        s, e = offsets[k], offsets[k + 1]
        if e - s > PAIRWISE_EDGES_MAX:
            return False
        for i in range(s, e):
            for j in range(i + 1, e):
                if values[i] == values[j]:
                    return False
    return True


@numba.njit(cache=True)
def cells_closed(cell_offsets, cell_faces, face_offsets, face_vertices):
    """True when every cell's signed faces use each of its edges exactly twice, once in each
    direction (``checks3d._check_closed`` passes): per cell, its directed edges (a, b), faces taken
    with their signs, are counted pairwise."""
    longest = 0
    for c in range(cell_offsets.size - 1):
        total = 0
        for t in range(cell_offsets[c], cell_offsets[c + 1]):
            s = cell_faces[t]
            f = s if s >= 0 else -s - 1
            total += face_offsets[f + 1] - face_offsets[f]
        longest = max(longest, total)
    if longest > PAIRWISE_EDGES_MAX:
        return False
    a = np.empty(longest, dtype=np.int64)
    b = np.empty(longest, dtype=np.int64)
    for c in range(cell_offsets.size - 1):
        m = 0
        for t in range(cell_offsets[c], cell_offsets[c + 1]):
            s = cell_faces[t]
            f = s if s >= 0 else -s - 1
            lo, n = face_offsets[f], face_offsets[f + 1] - face_offsets[f]
            for i in range(n):
                p, q = face_vertices[lo + i], face_vertices[lo + (i + 1) % n]
                a[m], b[m] = (p, q) if s >= 0 else (q, p)
                m += 1
        for i in range(m):
            same = 0
            up = 0
            lo_i, hi_i = min(a[i], b[i]), max(a[i], b[i])
            for j in range(m):
                if min(a[j], b[j]) == lo_i and max(a[j], b[j]) == hi_i:
                    same += 1
                    up += a[j] > b[j]
            if same != 2 or up != 1:
                return False
    return True


@numba.njit(cache=True)
def faces_flat_and_planar(vertices, face_offsets, face_vertices, vector_areas, centroids, degenerate, planarity):
    """True when every face's area passes ``degenerate`` x diameter² and every vertex lies within
    ``planarity`` x diameter of its plane (``checks3d._check_faces`` passes), both by a margin of
    ``MARGIN``: the diameter is twice the largest vertex distance from the centroid, the distance
    off the plane |(p - centroid) . |F| n_F| / |F|."""
    for f in range(face_offsets.size - 1):
        c0, c1, c2 = centroids[f, 0], centroids[f, 1], centroids[f, 2]
        n0, n1, n2 = vector_areas[f, 0], vector_areas[f, 1], vector_areas[f, 2]
        area = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
        reach = 0.0
        off = 0.0
        for i in range(face_offsets[f], face_offsets[f + 1]):
            v = face_vertices[i]
            d0, d1, d2 = vertices[v, 0] - c0, vertices[v, 1] - c1, vertices[v, 2] - c2
            reach = max(reach, np.sqrt(d0 * d0 + d1 * d1 + d2 * d2))
            off = max(off, abs(d0 * n0 + d1 * n1 + d2 * n2))
        diameter = 2.0 * reach
        if not area > degenerate * diameter**2 * (1.0 + MARGIN):
            return False
        if not off < planarity * diameter * area * (1.0 - MARGIN):
            return False
    return True
