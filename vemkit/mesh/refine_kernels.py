"""Numba kernels of ``vemkit.mesh.refine`` over the CSR polygon arrays (one loop per cell).

``corner_flags`` marks the slots (positions in ``cell_vertices``) where a polygon turns;
``midpoint_requests`` finds, for every geometric edge of the cells to refine, the old edge and the
parameter t at which its midpoint lies (or nothing when an old vertex is there already);
``augmented_rings`` inserts the split points into every polygon; ``children`` cuts the refined
polygons from the midpoints to a centre; ``max_inner_vertices`` counts, per polygon, the most
vertices inside one geometric edge. ``tests/mesh/test_refine.py`` pins them through the results.
"""

from __future__ import annotations

import numba
import numpy as np

from vemkit.mesh.geometry import turn

COLLINEAR = 1e-10  # |sin| of the turning angle below which a vertex is not a corner
SAME_POINT = 1e-9  # relative length along an edge below which two points coincide


@numba.njit(cache=True)
def corner_flags(points, offsets, ring):
    """True at the slots of ``ring`` (CSR polygons over ``points``) where the polygon turns."""
    out = np.zeros(ring.shape[0], dtype=np.bool_)
    for c in range(offsets.shape[0] - 1):
        s, n = offsets[c], offsets[c + 1] - offsets[c]
        for i in range(n):
            cross, scale, dot = turn(points, ring[s + (i - 1 + n) % n], ring[s + i], ring[s + (i + 1) % n])
            out[s + i] = not (abs(cross) <= COLLINEAR * scale and dot > 0.0)
    return out


@numba.njit(cache=True)
def _first_corner(corner, s, n):
    for i in range(n):
        if corner[s + i]:
            return i
    return 0


@numba.njit(cache=True)
def _run(corner, s, n, start):
    """Slots in the geometric edge that starts at corner slot ``start``: start, start + 1, … up to
    (not including) the next corner."""
    run = 1
    while run < n and not corner[s + (start + run) % n]:
        run += 1
    return run


@numba.njit(cache=True)
def _segment(points, ring, s, n, k):
    """Length of the polygon edge from slot k to slot k + 1 (cyclic)."""
    u, v = ring[s + k % n], ring[s + (k + 1) % n]
    return np.hypot(points[v, 0] - points[u, 0], points[v, 1] - points[u, 1])


@numba.njit(cache=True)
def _run_length(points, ring, s, n, start, run):
    total = 0.0
    for j in range(run):
        total += _segment(points, ring, s, n, start + j)
    return total


@numba.njit(cache=True)
def midpoint_requests(points, offsets, ring, corner, cells):
    """(a, b, t) per geometric edge of ``cells`` whose midpoint is not a vertex: the midpoint lies
    on the old edge a -> b at a + t (b - a)."""
    a_out = np.empty(ring.shape[0], dtype=np.int64)
    b_out = np.empty(ring.shape[0], dtype=np.int64)
    t_out = np.empty(ring.shape[0])
    count = 0
    for c in cells:
        s, n = offsets[c], offsets[c + 1] - offsets[c]
        first = _first_corner(corner, s, n)
        i = 0
        while i < n:
            start = (first + i) % n
            run = _run(corner, s, n, start)
            total = _run_length(points, ring, s, n, start, run)
            half, walked = 0.5 * total, 0.0
            for j in range(run):
                length = _segment(points, ring, s, n, start + j)
                if abs(walked - half) <= SAME_POINT * total:
                    break  # an old vertex at the midpoint
                if walked + length > half + SAME_POINT * total:
                    a_out[count], b_out[count] = ring[s + (start + j) % n], ring[s + (start + j + 1) % n]
                    t_out[count] = (half - walked) / length
                    count += 1
                    break
                walked += length
            i += run
    return a_out[:count], b_out[:count], t_out[:count]


@numba.njit(cache=True)
def augmented_rings(offsets, ring, edge_keys, split_ptr, split_vertices, n_old):
    """Every polygon with the split points of its edges inserted (new CSR offsets and ring).

    ``edge_keys`` sorted keys min * n_old + max of the split edges; ``split_vertices[split_ptr[k]:
    split_ptr[k + 1]]`` the new vertices on edge k in the direction min -> max.
    """
    n_cells = offsets.shape[0] - 1
    new_offsets = np.zeros(n_cells + 1, dtype=np.int64)
    out = np.empty(ring.shape[0] + 2 * split_vertices.shape[0], dtype=np.int64)
    m = 0
    for c in range(n_cells):
        s, n = offsets[c], offsets[c + 1] - offsets[c]
        for i in range(n):
            a, b = ring[s + i], ring[s + (i + 1) % n]
            out[m] = a
            m += 1
            key = min(a, b) * n_old + max(a, b)
            k = np.searchsorted(edge_keys, key)
            if k < edge_keys.shape[0] and edge_keys[k] == key:
                lo, hi = split_ptr[k], split_ptr[k + 1]
                for j in range(hi - lo):
                    out[m] = split_vertices[lo + j] if a < b else split_vertices[hi - 1 - j]
                    m += 1
        new_offsets[c + 1] = m
    return new_offsets, out[:m]


@numba.njit(cache=True)
def max_inner_vertices(offsets, ring, corner):
    """Per polygon: the most vertices strictly inside one of its geometric edges."""
    n_cells = offsets.shape[0] - 1
    out = np.zeros(n_cells, dtype=np.int64)
    for c in range(n_cells):
        s, n = offsets[c], offsets[c + 1] - offsets[c]
        first = _first_corner(corner, s, n)
        inner = 0
        for i in range(1, n + 1):
            if corner[s + (first + i) % n]:
                out[c] = max(out[c], inner)
                inner = 0
            else:
                inner += 1
    return out


@numba.njit(cache=True)
def _kernel_point(points, ring, s, n, zx, zy):
    """(zx, zy) strictly left of every edge of the counter-clockwise polygon ring[s:s + n]."""
    for i in range(n):
        u, v = ring[s + i], ring[s + (i + 1) % n]
        ex, ey = points[v, 0] - points[u, 0], points[v, 1] - points[u, 1]
        if ex * (zy - points[u, 1]) - ey * (zx - points[u, 0]) <= 1e-12 * (ex * ex + ey * ey):
            return False
    return True


@numba.njit(cache=True)
def _clip(poly, m, ax, ay, ex, ey, out):
    """Sutherland-Hodgman: the convex polygon poly[:m] cut to the left of the line a + s e; out its
    vertices, the count returned."""
    k = 0
    for i in range(m):
        px, py, qx, qy = poly[i, 0], poly[i, 1], poly[(i + 1) % m, 0], poly[(i + 1) % m, 1]
        dp = ex * (py - ay) - ey * (px - ax)
        dq = ex * (qy - ay) - ey * (qx - ax)
        if dp >= 0.0:
            out[k, 0], out[k, 1] = px, py
            k += 1
        if (dp >= 0.0) != (dq >= 0.0):
            w = dp / (dp - dq)
            out[k, 0], out[k, 1] = px + w * (qx - px), py + w * (qy - py)
            k += 1
    return k


@numba.njit(cache=True)
def kernel_centroid(points, ring, s, n):
    """Centroid of the kernel of the counter-clockwise polygon ring[s:s + n] (the points that see
    every edge: the cell's bounding box cut by the left half-plane of each edge); (nan, nan) if the
    kernel has no area."""
    poly, out = np.empty((n + 4, 2)), np.empty((n + 4, 2))
    lo_x, lo_y, hi_x, hi_y = np.inf, np.inf, -np.inf, -np.inf
    for i in range(n):
        x, y = points[ring[s + i], 0], points[ring[s + i], 1]
        lo_x, lo_y, hi_x, hi_y = min(lo_x, x), min(lo_y, y), max(hi_x, x), max(hi_y, y)
    poly[0, 0], poly[0, 1], poly[1, 0], poly[1, 1] = lo_x, lo_y, hi_x, lo_y
    poly[2, 0], poly[2, 1], poly[3, 0], poly[3, 1] = hi_x, hi_y, lo_x, hi_y
    m = 4
    for i in range(n):
        u, v = ring[s + i], ring[s + (i + 1) % n]
        m = _clip(poly, m, points[u, 0], points[u, 1], points[v, 0] - points[u, 0], points[v, 1] - points[u, 1], out)
        poly, out = out, poly
        if m < 3:
            return np.nan, np.nan
    area, sx, sy = 0.0, 0.0, 0.0
    for i in range(m):
        cross = poly[i, 0] * poly[(i + 1) % m, 1] - poly[(i + 1) % m, 0] * poly[i, 1]
        area += cross
        sx += (poly[i, 0] + poly[(i + 1) % m, 0]) * cross
        sy += (poly[i, 1] + poly[(i + 1) % m, 1]) * cross
    if area <= 1e-14 * (hi_x - lo_x) * (hi_y - lo_y):
        return np.nan, np.nan
    return sx / (3 * area), sy / (3 * area)


@numba.njit(cache=True)
def split_centres(points, offsets, ring, cells):
    """Per cell: the centroid, else the vertex mean, else the kernel's centroid, if in the kernel;
    (nan, nan) if the cell has no kernel (it is not star-shaped)."""
    out = np.full((cells.shape[0], 2), np.nan)
    for k in range(cells.shape[0]):
        c = cells[k]
        s, n = offsets[c], offsets[c + 1] - offsets[c]
        area, sx, sy, mx, my = 0.0, 0.0, 0.0, 0.0, 0.0
        for i in range(n):
            u, v = ring[s + i], ring[s + (i + 1) % n]
            cross = points[u, 0] * points[v, 1] - points[v, 0] * points[u, 1]
            area += cross
            sx += (points[u, 0] + points[v, 0]) * cross
            sy += (points[u, 1] + points[v, 1]) * cross
            mx += points[u, 0] / n
            my += points[u, 1] / n
        if area != 0.0 and _kernel_point(points, ring, s, n, sx / (3 * area), sy / (3 * area)):
            out[k, 0], out[k, 1] = sx / (3 * area), sy / (3 * area)
        elif _kernel_point(points, ring, s, n, mx, my):
            out[k, 0], out[k, 1] = mx, my
        else:
            zx, zy = kernel_centroid(points, ring, s, n)
            if not np.isnan(zx) and _kernel_point(points, ring, s, n, zx, zy):
                out[k, 0], out[k, 1] = zx, zy
    return out


@numba.njit(cache=True)
def children(points, offsets, ring, corner, cells, centres):
    """CSR polygons of the children of ``cells`` (ring: augmented, corner: its flags), and the
    parent index into ``cells`` of each child. ``centres[k]`` is the new centre vertex of cell k."""
    child_offsets = [0]
    child_ring = []
    parent = []
    for k in range(cells.shape[0]):
        c = cells[k]
        s, n = offsets[c], offsets[c + 1] - offsets[c]
        first = _first_corner(corner, s, n)
        corners, splits = [], []
        i = 0
        while i < n:
            start = (first + i) % n
            run = _run(corner, s, n, start)
            total = _run_length(points, ring, s, n, start, run)
            best, walked, best_gap = 1, 0.0, np.inf
            for j in range(1, run):  # the inner vertex nearest half the edge length
                walked += _segment(points, ring, s, n, start + j - 1)
                if abs(walked - 0.5 * total) < best_gap:
                    best, best_gap = j, abs(walked - 0.5 * total)
            corners.append(start)
            splits.append((start + best) % n)
            i += run
        m = len(corners)
        for g in range(m):
            j = corners[g]
            while True:  # corner -> split of this edge
                child_ring.append(ring[s + j])
                if j == splits[g]:
                    break
                j = (j + 1) % n
            child_ring.append(centres[k])
            j = splits[g - 1]
            while j != corners[g]:  # split of the previous edge -> up to the corner
                child_ring.append(ring[s + j])
                j = (j + 1) % n
            child_offsets.append(len(child_ring))
            parent.append(k)
    return (
        np.array(child_offsets, dtype=np.int64),
        np.array(child_ring, dtype=np.int64),
        np.array(parent, dtype=np.int64),
    )
