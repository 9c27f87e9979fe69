"""Plane geometry shared by the mesh and the VEM layers.

- the shoelace formula, once: ``polygon_area_centroid`` / ``polygon_area`` for one polygon (Numba,
  callable from other Numba kernels: the element stiffness uses it) and ``areas_centroids`` /
  ``polygon_areas`` for many polygons in CSR form (the same formula summed in numpy's order: a
  Numba kernel with the bits of its vectorized twin ``areas_centroids_numpy``; its per-polygon parts
  ``area_centroid_few`` / ``area_centroid_many`` serve other kernels), and ``counter_clockwise``
  which reverses the clockwise ones;
- ``bounds``: the lowest and highest coordinate of a point set per axis, a column at a time
  (numpy's ``min(axis=0)`` of an (N, 2) array runs 25x slower than a column's ``min()``);
- ``bin_boxes``: items binned on a uniform g x g grid by their bounding boxes, for point location
  and segment-intersection searches (``vemkit.vem.norms``, ``vemkit.mesh.checks``).
"""

from __future__ import annotations

import numba
import numpy as np


def bounds(points: np.ndarray):
    """(low, high): ``points.min(axis=0)`` and ``points.max(axis=0)`` of a non-empty (N, d) array,
    one contiguous column at a time (the same values)."""
    low = np.array([points[:, k].min() for k in range(points.shape[1])])
    high = np.array([points[:, k].max() for k in range(points.shape[1])])
    return low, high


def extents(points: np.ndarray) -> np.ndarray:
    """``np.ptp(points, axis=0)`` of a non-empty (N, d) array (by ``bounds``)."""
    low, high = bounds(points)
    return high - low


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
    """Signed areas ``(M,)`` and centroids ``(M, 2)`` of M polygons in CSR form.

    Polygon k has the points ``coords[offsets[k]:offsets[k + 1]]``. The formula of
    ``polygon_area_centroid``; the sums run in numpy's order (``np.add.reduceat``: pairwise), so
    results may differ from ``polygon_area_centroid``'s in the last bits. Every mesh family depends
    on these exact bits: keep them. A Numba kernel repeats numpy's summation order (bit for bit
    ``areas_centroids_numpy``, the vectorized twin; tests compare them); offsets that are not a plain
    CSR of all of ``coords`` (empty polygons, a tail) and polygons of over 129 points go to the twin.
    """
    coords = np.ascontiguousarray(coords, dtype=np.float64).reshape(-1, 2)
    offsets = np.ascontiguousarray(offsets, dtype=np.int64)
    if offsets.size < 2:
        return np.zeros(0), np.zeros((0, 2))
    area, centroid, plain = _areas_centroids_kernel(coords, offsets)
    return (area, centroid) if plain else areas_centroids_numpy(coords, offsets)


def areas_centroids_numpy(coords: np.ndarray, offsets: np.ndarray):
    """``areas_centroids`` vectorized with numpy (its twin, and the reference of its bits)."""
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


@numba.njit(cache=True, error_model="numpy")
def _areas_centroids_kernel(coords, offsets):
    """``areas_centroids_numpy`` polygon by polygon; ``plain`` False (results unused) unless the
    offsets start at 0, increase strictly and end at len(coords), and no polygon has more than
    129 points (numpy then sums by halves; recursion would not survive Numba's cache)."""
    m = offsets.shape[0] - 1
    area, centroid = np.empty(m), np.empty((m, 2))
    plain = offsets[0] == 0 and offsets[m] == coords.shape[0]
    longest = 0
    for k in range(m):
        plain = plain and offsets[k + 1] > offsets[k]
        longest = max(longest, offsets[k + 1] - offsets[k])
    if not plain or longest > 129:
        return area, centroid, False
    work = np.empty((3, longest))
    for k in range(m):
        if offsets[k + 1] - offsets[k] <= 8:  # two kernels: one with both paths runs 3x slower
            area[k], centroid[k, 0], centroid[k, 1] = area_centroid_few(coords, None, offsets[k], offsets[k + 1])
        else:
            area[k], centroid[k, 0], centroid[k, 1] = area_centroid_many(coords, None, offsets[k], offsets[k + 1], work)
    return area, centroid, True


@numba.njit(cache=True, error_model="numpy", inline="always")
def area_centroid_few(points, refs, start, stop):
    """Signed area and centroid of the polygon ``points[refs[start:stop]]`` (``points[start:stop]``
    if refs is None) of at most 8 points, with the bits of ``areas_centroids_numpy``: numpy's
    ``reduceat`` adds to a polygon's first term the sum of the others, in order."""
    n = stop - start
    c0, x0, y0 = _shoelace_terms(points, refs, start, n, 0)
    sc = sx = sy = 0.0
    for i in range(1, n):
        c, cx, cy = _shoelace_terms(points, refs, start, n, i)
        sc, sx, sy = sc + c, sx + cx, sy + cy
    area = 0.5 * (c0 + sc)
    return area, (x0 + sx) / (6 * area), (y0 + sy) / (6 * area)


@numba.njit(cache=True, error_model="numpy")
def area_centroid_many(points, refs, start, stop, work):
    """``area_centroid_few`` for 9 to 129 points: numpy adds the others pairwise (8 running sums,
    then the rest in order). ``work``: (3, >= stop - start) scratch."""
    n = stop - start
    for i in range(n):
        work[0, i], work[1, i], work[2, i] = _shoelace_terms(points, refs, start, n, i)
    area = 0.5 * (work[0, 0] + _pairwise_sum(work[0], 1, n - 1))
    return (
        area,
        (work[1, 0] + _pairwise_sum(work[1], 1, n - 1)) / (6 * area),
        (work[2, 0] + _pairwise_sum(work[2], 1, n - 1)) / (6 * area),
    )


@numba.njit(cache=True, inline="always")
def _shoelace_terms(points, refs, start, n, i):
    """Point i's terms of ``areas_centroids_numpy``: cross, (x_i + x_i+1) cross, (y_i + y_i+1) cross."""
    j = i + 1 if i + 1 < n else 0
    if refs is None:
        a, b = start + i, start + j
    else:
        a, b = refs[start + i], refs[start + j]
    c = points[a, 0] * points[b, 1] - points[b, 0] * points[a, 1]
    return c, (points[a, 0] + points[b, 0]) * c, (points[a, 1] + points[b, 1]) * c


@numba.njit(cache=True)
def _pairwise_sum(a, lo, n):
    """numpy's pairwise sum of a[lo:lo + n], 8 <= n <= 128 (what ``np.add.reduceat`` adds to a
    segment's first element): 8 running sums, combined pairwise, then the rest in order."""
    r = a[lo : lo + 8].copy()
    i = 8
    while i < n - n % 8:
        for j in range(8):
            r[j] += a[lo + i + j]
        i += 8
    res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]))
    for i in range(n - n % 8, n):
        res += a[lo + i]
    return res


def polygon_areas(coords: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Signed areas of the polygons ``coords[offsets[k]:offsets[k + 1]]`` (CSR)."""
    return areas_centroids(coords, offsets)[0]


def indexed_polygon_areas(points: np.ndarray, offsets: np.ndarray, refs: np.ndarray) -> np.ndarray:
    """``polygon_areas(points[refs], offsets)`` (the same bits) without gathering the coordinates:
    the kernel reads ``points[refs[i]]`` in place (1.6 M references: 0.08 s of gather saved)."""
    points = np.ascontiguousarray(points, dtype=np.float64)
    offsets = np.ascontiguousarray(offsets, dtype=np.int64)
    refs = np.ascontiguousarray(refs, dtype=np.int64)
    if offsets.size < 2:
        return np.zeros(0)
    area, plain = _indexed_areas_kernel(points, offsets, refs)
    return area if plain else polygon_areas(points[refs], offsets)


@numba.njit(cache=True, error_model="numpy")
def _indexed_areas_kernel(points, offsets, refs):
    """The areas of ``_areas_centroids_kernel`` of the polygons points[refs[offsets[k]:offsets[k + 1]]];
    ``plain`` False (results unused) on the same conditions, or for a reference outside points."""
    m = offsets.shape[0] - 1
    area = np.empty(m)
    plain = offsets[0] == 0 and offsets[m] == refs.shape[0]
    longest = 0
    for k in range(m):
        plain = plain and offsets[k + 1] > offsets[k]
        longest = max(longest, offsets[k + 1] - offsets[k])
    for i in range(refs.shape[0]):
        plain = plain and 0 <= refs[i] < points.shape[0]
    if not plain or longest > 129:
        return area, False
    work = np.empty((3, longest))
    for k in range(m):
        if offsets[k + 1] - offsets[k] <= 8:
            area[k] = area_centroid_few(points, refs, offsets[k], offsets[k + 1])[0]
        else:
            area[k] = area_centroid_many(points, refs, offsets[k], offsets[k + 1], work)[0]
    return area, True


def ranges(sizes: np.ndarray) -> np.ndarray:
    """0..s-1 for every s in sizes, concatenated."""
    starts = np.repeat(np.cumsum(sizes) - sizes, sizes)
    return np.arange(int(sizes.sum()), dtype=np.int64) - starts


def counter_clockwise(pool: np.ndarray, offsets: np.ndarray, refs: np.ndarray) -> np.ndarray:
    """Reverse the vertex order of every clockwise cell."""
    area = indexed_polygon_areas(pool, offsets, refs)
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
