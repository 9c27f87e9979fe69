"""Numba passes over a polygon mesh's cells for ``vemkit.mesh.checks`` and ``read_mesh``'s precision
check: one loop each instead of numpy's (H, 2) temporaries over the H half-edges (at 1.6 M
half-edges the numpy forms took 0.16 s for the perimeters, 0.13 s for the angle sums and 0.15 s for
the precision ratio). Each computes what its numpy twin computes (the formulas are quoted in the
docstrings; tests/mesh/test_check_kernels.py compares them on random meshes); the kernels return
numbers, the checks decide and word the errors."""

from __future__ import annotations

import math

import numba
import numpy as np

#: above this many vertices a cell's repeated-vertex search sorts instead of comparing all pairs
PAIRWISE_REPEAT_MAX = 16


@numba.njit(cache=True)
def first_repeated_vertex(offsets, cell_vertices):
    """(cell, vertex): the first cell that lists a vertex twice and its smallest such vertex, or
    (-1, -1) (numpy: the smallest repeated key cell * N + vertex of the sorted keys)."""
    for k in range(offsets.size - 1):
        s, e = offsets[k], offsets[k + 1]
        smallest = -1
        if e - s <= PAIRWISE_REPEAT_MAX:
            for i in range(s, e):
                for j in range(i + 1, e):
                    if cell_vertices[i] == cell_vertices[j] and (smallest < 0 or cell_vertices[i] < smallest):
                        smallest = cell_vertices[i]
        else:
            ordered = np.sort(cell_vertices[s:e])
            for i in range(ordered.size - 1):
                if ordered[i] == ordered[i + 1]:
                    smallest = ordered[i]
                    break
        if smallest >= 0:
            return k, smallest
    return -1, -1


@numba.njit(cache=True)
def cell_perimeters(vertices, offsets, cell_vertices):
    """Perimeter of every cell: the lengths sqrt(dx^2 + dy^2) of its edges added in order
    (numpy: ``np.add.reduceat(np.linalg.norm(q - p, axis=1), offsets[:-1])``)."""
    m = offsets.size - 1
    out = np.zeros(m)
    for k in range(m):
        s, e = offsets[k], offsets[k + 1]
        total = 0.0
        for h in range(s, e):
            a, b = cell_vertices[h], cell_vertices[h + 1 if h + 1 < e else s]
            dx, dy = vertices[b, 0] - vertices[a, 0], vertices[b, 1] - vertices[a, 1]
            total += np.sqrt(dx * dx + dy * dy)
        out[k] = total
    return out


@numba.njit(cache=True)
def corner_angle(vertices, p, v, q):
    """Counter-clockwise angle at v from direction q - v to direction p - v, in [0, 2 pi)."""
    ax, ay = vertices[q, 0] - vertices[v, 0], vertices[q, 1] - vertices[v, 1]
    bx, by = vertices[p, 0] - vertices[v, 0], vertices[p, 1] - vertices[v, 1]
    angle = np.arctan2(ax * by - ay * bx, ax * bx + ay * by)
    return angle + 2 * np.pi if angle < 0 else angle


@numba.njit(cache=True)
def corner_angle_sums(vertices, offsets, cell_vertices):
    """Sum over the cells at every vertex of their corner angle there (``corner_angle`` of the
    previous and the next vertex of the cell), added in half-edge order (numpy: ``np.bincount``
    of the corner angles with the half-edges' start vertices)."""
    total = np.zeros(vertices.shape[0])
    for k in range(offsets.size - 1):
        s, e = offsets[k], offsets[k + 1]
        for h in range(s, e):
            p = cell_vertices[h - 1 if h > s else e - 1]
            q = cell_vertices[h + 1 if h + 1 < e else s]
            total[cell_vertices[h]] += corner_angle(vertices, p, cell_vertices[h], q)
    return total


@numba.njit(cache=True)
def worst_coordinate_over_edge(vertices, offsets, cell_vertices):
    """(half-edge, ratio, length, reach) of the half-edge (a, b) with the largest
    reach / length, reach = max_i |x_a,i| and length = |x_b - x_a| (hypot over the 2 or 3 coordinates;
    ratio 0 for length 0; the first of equal ratios; (-1, 0, 0, 0) for no half-edge). The cells are
    polygons: a 2D mesh's cells or a 3D mesh's faces."""
    worst, worst_ratio, worst_length, worst_reach = -1, 0.0, 0.0, 0.0
    for k in range(offsets.size - 1):
        s, e = offsets[k], offsets[k + 1]
        for h in range(s, e):
            a, b = cell_vertices[h], cell_vertices[h + 1 if h + 1 < e else s]
            length, reach = 0.0, 0.0
            for i in range(vertices.shape[1]):
                length = math.hypot(length, vertices[b, i] - vertices[a, i])
                reach = max(reach, abs(vertices[a, i]))
            ratio = reach / length if length > 0 else 0.0
            if worst < 0 or ratio > worst_ratio:
                worst, worst_ratio, worst_length, worst_reach = h, ratio, length, reach
    return worst, worst_ratio, worst_length, worst_reach


@numba.njit(cache=True)
def edges_shared_properly(half_edges, half_edge_edge, edge_first_half_edges):
    """True when every edge has at most two half-edges and a second one runs opposite to the first
    (``checks._check_edges`` passes): one pass over the half-edges."""
    count = np.zeros(edge_first_half_edges.shape[0], dtype=np.int64)
    for h in range(half_edges.shape[0]):
        e = half_edge_edge[h]
        count[e] += 1
        if count[e] > 2:
            return False
        first = edge_first_half_edges[e]
        if first != h and half_edges[first, 0] == half_edges[h, 0]:
            return False
    return True
