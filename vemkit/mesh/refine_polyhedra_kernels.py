"""Numba kernels of the refinement of polyhedra (``vemkit.mesh.refine_boxes``, ``refine_polyhedra``).

``rectangle_rings`` collects, per axis-aligned rectangle of a marked box, the box's pool vertices on
its perimeter sorted by angle about its centre; its numpy twin is ``refine_boxes.rectangle_rings_numpy``
(``tests/mesh3d/test_refine_polyhedra.py`` pins the kernel to it).
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True)
def rectangle_rings(pool_start, t, pool_vertex, row, axis, level, low, high, outward, tol):
    """(sizes, flat vertices) per rectangle r: the pool entries pool_start[row_r] ... of its box with
    |t[axis_r] - level_r| < tol, inside [low_r, high_r] in the next two axes (b, d) and on its perimeter
    (within tol), sorted by angle about its centre (from -pi), reversed where outward_r <= 0."""
    n_rect = row.shape[0]
    bound, width = 0, 0
    for r in range(n_rect):
        size = pool_start[row[r] + 1] - pool_start[row[r]]
        bound += size
        width = max(width, size)
    flat = np.empty(bound, dtype=np.int64)
    sizes = np.zeros(n_rect, dtype=np.int64)
    angles = np.empty(width)
    ids = np.empty(width, dtype=np.int64)
    k = 0
    for r in range(n_rect):
        a = axis[r]
        b, d = (a + 1) % 3, (a + 2) % 3
        lb, ld, hb, hd = low[r, 0], low[r, 1], high[r, 0], high[r, 1]
        cb, cd = 0.5 * (lb + hb), 0.5 * (ld + hd)
        n = 0
        for e in range(pool_start[row[r]], pool_start[row[r] + 1]):
            tb, td = t[e, b], t[e, d]
            if not (abs(t[e, a] - level[r]) < tol and tb > lb - tol and tb < hb + tol and td > ld - tol):
                continue
            if not td < hd + tol:
                continue
            on_b = abs(tb - lb) < tol or abs(tb - hb) < tol
            if not (on_b or abs(td - ld) < tol or abs(td - hd) < tol):
                continue
            angle = math.atan2(td - cd, tb - cb)
            j = n
            while j > 0 and angles[j - 1] > angle:  # insertion: a ring has few vertices
                angles[j], ids[j] = angles[j - 1], ids[j - 1]
                j -= 1
            angles[j], ids[j] = angle, pool_vertex[e]
            n += 1
        for j in range(n):
            flat[k + j] = ids[j] if outward[r] > 0 else ids[n - 1 - j]
        sizes[r] = n
        k += n
    return sizes, flat[:k]
