"""Plane geometry shared by the mesh and the VEM layers.

- the shoelace formula, once: ``polygon_area_centroid`` / ``polygon_area`` for one polygon (Numba,
  callable from other Numba kernels: the element stiffness uses it) and ``areas_centroids`` /
  ``polygon_areas`` for many polygons in CSR form (vectorized numpy, the same formula), and
  ``counter_clockwise`` which reverses the clockwise ones;
- ``bin_boxes``: items binned on a uniform g x g grid by their bounding boxes, for point location
  and segment-intersection searches (``vemkit.vem.norms``, ``vemkit.mesh.checks``).
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def bin_boxes(boxes, g):
    """CSR (ptr, items) of the items whose bin box (i0, i1, j0, j1) covers each bin j * g + i."""
    ptr = np.zeros(g * g + 1, dtype=np.int64)
    for t in range(boxes.shape[0]):
        for j in range(boxes[t, 2], boxes[t, 3] + 1):
            for i in range(boxes[t, 0], boxes[t, 1] + 1):
                ptr[j * g + i + 1] += 1
    for b in range(g * g):
        ptr[b + 1] += ptr[b]
    items = np.empty(ptr[g * g], dtype=np.int64)
    fill = ptr[:-1].copy()
    for t in range(boxes.shape[0]):
        for j in range(boxes[t, 2], boxes[t, 3] + 1):
            for i in range(boxes[t, 0], boxes[t, 1] + 1):
                items[fill[j * g + i]] = t
                fill[j * g + i] += 1
    return ptr, items


@numba.njit(cache=True)
def polygon_area_centroid(px, py):
    """Signed area and centroid (shoelace): |K| = ½ Σ (x_i y_{i+1} − x_{i+1} y_i), positive when CCW.

    The centroid is Σ (x_i + x_{i+1}) c_i / (6 |K|), c_i the cross term; (nan, nan) for zero area.
    """
    n = px.shape[0]
    a = 0.0
    sx = 0.0
    sy = 0.0
    for i in range(n):
        j = (i + 1) % n
        cross = px[i] * py[j] - px[j] * py[i]
        a += cross
        sx += (px[i] + px[j]) * cross
        sy += (py[i] + py[j]) * cross
    if a == 0.0:
        return 0.0, np.nan, np.nan
    return 0.5 * a, sx / (3.0 * a), sy / (3.0 * a)


@numba.njit(cache=True)
def polygon_area(px, py):
    """Signed (shoelace) area of the polygon (px, py): positive for counter-clockwise order."""
    return polygon_area_centroid(px, py)[0]


def areas_centroids(coords: np.ndarray, offsets: np.ndarray):
    """Signed areas ``(M,)`` and centroids ``(M, 2)`` of M polygons in CSR form, vectorized.

    Polygon k has the points ``coords[offsets[k]:offsets[k + 1]]``. The formula of
    ``polygon_area_centroid``; the sums run in numpy's order (pairwise), so results may differ from
    the kernel's in the last bits. Every mesh family depends on these exact bits: keep them.
    """
    coords = np.asarray(coords, dtype=np.float64).reshape(-1, 2)
    offsets = np.asarray(offsets, dtype=np.int64)
    if offsets.size < 2:
        return np.zeros(0), np.zeros((0, 2))
    nxt = np.arange(1, coords.shape[0] + 1)
    nxt[offsets[1:] - 1] = offsets[:-1]
    x, y = coords[:, 0], coords[:, 1]
    cross = x * y[nxt] - x[nxt] * y
    area = 0.5 * np.add.reduceat(cross, offsets[:-1])
    with np.errstate(divide="ignore", invalid="ignore"):
        cx = np.add.reduceat((x + x[nxt]) * cross, offsets[:-1]) / (6 * area)
        cy = np.add.reduceat((y + y[nxt]) * cross, offsets[:-1]) / (6 * area)
    return area, np.stack([cx, cy], axis=1)


def polygon_areas(coords: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Signed areas of the polygons ``coords[offsets[k]:offsets[k + 1]]`` (CSR)."""
    return areas_centroids(coords, offsets)[0]


def ranges(sizes: np.ndarray) -> np.ndarray:
    """0..s-1 for every s in sizes, concatenated."""
    starts = np.repeat(np.cumsum(sizes) - sizes, sizes)
    return np.arange(int(sizes.sum()), dtype=np.int64) - starts


def counter_clockwise(pool: np.ndarray, offsets: np.ndarray, refs: np.ndarray) -> np.ndarray:
    """Reverse the vertex order of every clockwise cell."""
    area = polygon_areas(pool[refs], offsets)
    sizes = np.diff(offsets)
    local = ranges(sizes)
    flip = np.repeat(area < 0, sizes)
    source = np.where(flip, np.repeat(offsets[1:], sizes) - 1 - local, np.repeat(offsets[:-1], sizes) + local)
    return refs[source]


@numba.njit(cache=True)
def turn(points, a, b, c):
    """How the path a -> b -> c turns at b: (cross, |ab| |bc|, dot) of ab and bc.

    cross > 0: a left (convex, counter-clockwise) turn; cross = 0 with dot > 0: b lies on a straight
    line (a hanging node, or no corner at all)."""
    e1x, e1y = points[b, 0] - points[a, 0], points[b, 1] - points[a, 1]
    e2x, e2y = points[c, 0] - points[b, 0], points[c, 1] - points[b, 1]
    return e1x * e2y - e1y * e2x, np.sqrt((e1x * e1x + e1y * e1y) * (e2x * e2x + e2y * e2y)), e1x * e2x + e1y * e2y
