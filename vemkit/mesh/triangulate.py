"""Triangulation of every polygon of a mesh by ear clipping.

Works for non-convex polygons and for polygons with collinear vertices (hanging nodes): an ear is
a strictly convex corner whose triangle holds no other vertex of the remaining polygon, not even
on its sides, so no vertex ends up inside a triangle's side and no triangle is degenerate. Among
the ears the best-shaped one (largest area / sum of squared sides) is clipped first. If no such
ear exists (never for a simple polygon in exact arithmetic, possibly under round-off), corners
with other vertices on the triangle's sides are accepted, then failure is reported.

``triangulate_cells`` runs a small numba kernel over the CSR arrays; ``ear_clip_reference`` is the
same algorithm in plain Python, one polygon at a time, used by the tests to pin the kernel.
"""

from __future__ import annotations

import numba
import numpy as np

from vemkit.mesh.mesh import Mesh


def triangulate_cells(mesh: Mesh) -> tuple[np.ndarray, np.ndarray]:
    """Triangles ``(T, 3)`` (vertex indices, counter-clockwise) and their parent cell ``(T,)``.

    Cell ``K`` with ``m`` vertices gives ``m - 2`` triangles, stored contiguously in cell order.
    """
    sizes = mesh.cell_sizes
    triangles = np.empty((int(sizes.sum()) - 2 * mesh.n_cells, 3), dtype=np.int64)
    failed = _ear_clip_cells(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, triangles)
    if failed >= 0:
        raise ValueError(
            f"cell {failed} could not be triangulated: it is not a simple counter-clockwise polygon "
            "(run vemkit.mesh.checks.validate_mesh)"
        )
    parent = np.repeat(np.arange(mesh.n_cells, dtype=np.int64), sizes - 2)
    return triangles, parent


# -- numba kernel -----------------------------------------------------------------------------
@numba.njit(cache=True)
def _cross(ax, ay, bx, by, cx, cy):
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)


@numba.njit(cache=True)
def _ear_quality(xy, ring, n_left, i, strict):
    """Shape quality of the ear at ring position i, or -1 if the corner is not an ear."""
    p, c, q = ring[(i - 1) % n_left], ring[i], ring[(i + 1) % n_left]
    px, py, cx, cy, qx, qy = xy[p, 0], xy[p, 1], xy[c, 0], xy[c, 1], xy[q, 0], xy[q, 1]
    area2 = _cross(px, py, cx, cy, qx, qy)
    if area2 <= 0.0:
        return -1.0
    for t in range(n_left):
        r = ring[t]
        if r == p or r == c or r == q:
            continue
        rx, ry = xy[r, 0], xy[r, 1]
        d1 = _cross(px, py, cx, cy, rx, ry)
        d2 = _cross(cx, cy, qx, qy, rx, ry)
        d3 = _cross(qx, qy, px, py, rx, ry)
        if strict:
            if d1 >= 0.0 and d2 >= 0.0 and d3 >= 0.0:
                return -1.0
        elif d1 > 0.0 and d2 > 0.0 and d3 > 0.0:
            return -1.0
    sides = (cx - px) ** 2 + (cy - py) ** 2 + (qx - cx) ** 2 + (qy - cy) ** 2 + (px - qx) ** 2 + (py - qy) ** 2
    return area2 / sides


@numba.njit(cache=True)
def _ear_clip_polygon(xy, m, ring, out):
    """Triangulate the CCW polygon ``xy[:m]`` into ``out[:m - 2]`` (local indices); False on failure.

    ``ring`` is scratch space of length >= m.
    """
    for i in range(m):
        ring[i] = i
    n_left = m
    t = 0
    while n_left > 3:
        best, best_quality = -1, -1.0
        for strict in (True, False):
            for i in range(n_left):
                quality = _ear_quality(xy, ring, n_left, i, strict)
                if quality > best_quality:
                    best, best_quality = i, quality
            if best >= 0:
                break
        if best < 0:
            return False
        out[t, 0] = ring[(best - 1) % n_left]
        out[t, 1] = ring[best]
        out[t, 2] = ring[(best + 1) % n_left]
        t += 1
        for i in range(best, n_left - 1):
            ring[i] = ring[i + 1]
        n_left -= 1
    out[t, 0], out[t, 1], out[t, 2] = ring[0], ring[1], ring[2]
    return True


@numba.njit(cache=True)
def _ear_clip_cells(vertices, offsets, cell_vertices, triangles):
    """Fill ``triangles`` for every cell; the first cell that fails, or -1."""
    largest = 3
    for k in range(offsets.size - 1):
        largest = max(largest, offsets[k + 1] - offsets[k])
    xy = np.empty((largest, 2))
    ring = np.empty(largest, dtype=np.int64)
    local = np.empty((largest - 2, 3), dtype=np.int64)
    for k in range(offsets.size - 1):
        s, m = offsets[k], offsets[k + 1] - offsets[k]
        t0 = s - 2 * k
        if m == 3:
            for j in range(3):
                triangles[t0, j] = cell_vertices[s + j]
            continue
        for i in range(m):
            xy[i, 0] = vertices[cell_vertices[s + i], 0]
            xy[i, 1] = vertices[cell_vertices[s + i], 1]
        if not _ear_clip_polygon(xy, m, ring, local):
            return k
        for i in range(m - 2):
            for j in range(3):
                triangles[t0 + i, j] = cell_vertices[s + local[i, j]]
    return -1


# -- plain-Python twin ------------------------------------------------------------------------
def ear_clip_reference(xy) -> np.ndarray:
    """The kernel's algorithm in plain Python for one CCW polygon: ``(m - 2, 3)`` local indices."""
    xy = [(float(x), float(y)) for x, y in np.asarray(xy, dtype=float)]

    def cross(a, b, c):
        return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])

    def quality(ring, i, strict):
        p, c, q = ring[i - 1], ring[i], ring[(i + 1) % len(ring)]
        area2 = cross(xy[p], xy[c], xy[q])
        if area2 <= 0.0:
            return -1.0
        for r in ring:
            if r in (p, c, q):
                continue
            d = (cross(xy[p], xy[c], xy[r]), cross(xy[c], xy[q], xy[r]), cross(xy[q], xy[p], xy[r]))
            if (min(d) >= 0.0) if strict else (min(d) > 0.0):
                return -1.0
        (px, py), (cx, cy), (qx, qy) = xy[p], xy[c], xy[q]
        sides = (cx - px) ** 2 + (cy - py) ** 2 + (qx - cx) ** 2 + (qy - cy) ** 2 + (px - qx) ** 2 + (py - qy) ** 2
        return area2 / sides

    ring = list(range(len(xy)))
    out = []
    while len(ring) > 3:
        best, best_quality = -1, -1.0
        for strict in (True, False):
            for i in range(len(ring)):
                qual = quality(ring, i, strict)
                if qual > best_quality:
                    best, best_quality = i, qual
            if best >= 0:
                break
        if best < 0:
            raise ValueError("polygon could not be triangulated: not simple and counter-clockwise")
        out.append((ring[best - 1], ring[best], ring[(best + 1) % len(ring)]))
        del ring[best]
    out.append(tuple(ring))
    return np.array(out, dtype=np.int64).reshape(-1, 3)
