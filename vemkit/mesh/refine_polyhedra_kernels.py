"""Numba kernels of the refinement of polyhedra (``refine_boxes``, ``refine_tetrahedra``), one loop
over the marked cells each.

``rectangle_rings`` collects, per axis-aligned rectangle of a marked box, the box's pool vertices on
its perimeter sorted by angle about its centre (numpy twin: ``refine_boxes.rectangle_rings_numpy``).
``tetrahedra_sides`` splits the whole sides of the marked tetrahedra into 4 triangles and
``tetrahedra_children`` makes their 8 children's faces (twins: ``refine_tetrahedra.whole_sides`` and
``tetrahedron_children``, cell by cell); ``refine_prisms_kernels`` does the same for prisms.
``tests/mesh3d/test_refine_polyhedra.py`` pins them to the twins.
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


@numba.njit(cache=True)
def grown(a, need):
    """``a``, or a copy with room for ``need`` entries."""
    if need <= a.shape[0]:
        return a
    out = np.empty(max(need, 2 * a.shape[0]), dtype=a.dtype)
    out[: a.shape[0]] = a
    return out


@numba.njit(cache=True)
def insert_on_edges(corners, pool, x, tol, out, k):
    """Write at out[k:] the cycle of the ``corners`` with the ``pool`` vertices inside its edges
    inserted in order; return the new end."""
    s = np.empty(pool.shape[0])
    ids = np.empty(pool.shape[0], dtype=np.int64)
    for e in range(corners.shape[0]):
        a, b = corners[e], corners[(e + 1) % corners.shape[0]]
        d0, d1, d2 = x[b, 0] - x[a, 0], x[b, 1] - x[a, 1], x[b, 2] - x[a, 2]
        length2 = d0 * d0 + d1 * d1 + d2 * d2
        out[k] = a
        k += 1
        n = 0
        for p in pool:
            r0, r1, r2 = x[p, 0] - x[a, 0], x[p, 1] - x[a, 1], x[p, 2] - x[a, 2]
            t = (r0 * d0 + r1 * d1 + r2 * d2) / length2
            off = (r0 - t * d0) ** 2 + (r1 - t * d1) ** 2 + (r2 - t * d2) ** 2
            if t > tol and t < 1 - tol and off < tol * tol * length2:
                j = n
                while j > 0 and s[j - 1] > t:
                    s[j], ids[j] = s[j - 1], ids[j - 1]
                    j -= 1
                s[j], ids[j] = t, p
                n += 1
        out[k : k + n] = ids[:n]
        k += n
    return k


@numba.njit(cache=True)
def _barycentric_centres(cycle_offsets, cycle_vertices, c0, c1, corners, x):
    """(cycles, 4): the barycentric coordinates (of the tetrahedron ``corners``) of the vertex means
    of the cycles c0 ... c1 - 1."""
    matrix = np.ones((4, 4))
    for j in range(4):
        matrix[:3, j] = x[corners[j]]
    to_bary = np.linalg.inv(matrix)
    out = np.empty((c1 - c0, 4))
    point = np.ones(4)
    for c in range(c0, c1):
        s, n = cycle_offsets[c], cycle_offsets[c + 1] - cycle_offsets[c]
        point[:3] = 0.0
        for i in range(s, s + n):
            point[:3] += x[cycle_vertices[i]]
        point[:3] /= n
        out[c - c0] = to_bary @ point
    return out


@numba.njit(cache=True)
def _outward(ids, child, x):
    """The triangle ``ids`` turned to face away from the mean of the ``child``'s corners."""
    u, v = x[ids[1]] - x[ids[0]], x[ids[2]] - x[ids[0]]
    normal = np.array([u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]])
    away = (x[ids[0]] + x[ids[1]] + x[ids[2]]) / 3.0 - (x[child[0]] + x[child[1]] + x[child[2]] + x[child[3]]) / 4.0
    return ids if normal @ away > 0 else ids[::-1].copy()


@numba.njit(cache=True)
def tetrahedra_children(
    lattice, diagonal, children, to_child, new_face, row_start, cycle_offsets, cycle_vertices, x, tol
):
    """The children of the marked tetrahedra (``refine_tetrahedra``): per face of a child, child by
    child, (row, child, the parent's cycle it is, or -1 for a new face), and the new faces' (sizes,
    flat vertices). Per row: ``lattice`` (10 ids), ``diagonal`` (0, 1, 2: the octahedron's cut) and
    its cycles row_start[r] ... (``cycle_offsets``, ``cycle_vertices``: outward, its whole sides
    split); per diagonal and child: ``children`` (4 lattice positions), ``to_child`` (the parent's
    barycentric coordinates to the child's) and ``new_face`` (per left-out corner, whether the face
    opposite it is a new one, inside the parent)."""
    m = lattice.shape[0]
    rows, kids, sources = np.empty(0, np.int64), np.empty(0, np.int64), np.empty(0, np.int64)
    sizes, flat = np.empty(0, np.int64), np.empty(0, np.int64)
    n_app, n_new, n_flat = 0, 0, 0
    for r in range(m):
        c0, c1 = row_start[r], row_start[r + 1]
        pool = np.unique(np.concatenate((cycle_vertices[cycle_offsets[c0] : cycle_offsets[c1]], lattice[r])))
        bary = _barycentric_centres(cycle_offsets, cycle_vertices, c0, c1, lattice[r, :4], x)
        need = n_app + 8 * (c1 - c0 + 4)
        rows, kids, sources = grown(rows, need), grown(kids, need), grown(sources, need)
        sizes = grown(sizes, n_new + 32)
        flat = grown(flat, n_flat + 32 * (3 + pool.shape[0]))
        d = diagonal[r]
        for k in range(8):
            child = lattice[r][children[d, k]]
            for c in range(c1 - c0):
                inside = to_child[d, k] @ bary[c]
                if (inside > -tol).all():
                    rows[n_app], kids[n_app], sources[n_app] = r, k, c0 + c
                    n_app += 1
            for skip in range(4):
                if not new_face[d, k, skip]:
                    continue
                ids = np.array([child[q] for q in range(4) if q != skip])
                end = insert_on_edges(_outward(ids, child, x), pool, x, tol, flat, n_flat)
                sizes[n_new] = end - n_flat
                n_flat, n_new = end, n_new + 1
                rows[n_app], kids[n_app], sources[n_app] = r, k, -1
                n_app += 1
    return rows[:n_app], kids[:n_app], sources[:n_app], sizes[:n_new], flat[:n_flat]


@numba.njit(cache=True)
def tetrahedra_sides(lattice, mid, cell_start, faces, face_offsets, face_vertices, face_normals, x, tol):
    """The whole sides of the marked tetrahedra (faces with 3 of its corners; ``refine_tetrahedra``):
    per side found (row, face), row after row, and its 4 triangles' (sizes, flat vertices), as stored
    (turned along ``face_normals``) with the vertices of the cell inside their edges. Per row r: its
    ``lattice`` (10 ids) and faces cell_start[r] ...; ``mid[i, j]``: the lattice position of the
    midpoint of corners i and j."""
    m = lattice.shape[0]
    rows, found = np.empty(0, np.int64), np.empty(0, np.int64)
    sizes, flat = np.empty(0, np.int64), np.empty(0, np.int64)
    n_side, n_flat = 0, 0
    for r in range(m):
        f0, f1 = cell_start[r], cell_start[r + 1]
        total = 10
        for f in faces[f0:f1]:
            total += face_offsets[f + 1] - face_offsets[f]
        gathered = np.empty(total, np.int64)
        gathered[:10] = lattice[r]
        k = 10
        for f in faces[f0:f1]:
            n = face_offsets[f + 1] - face_offsets[f]
            gathered[k : k + n] = face_vertices[face_offsets[f] : face_offsets[f + 1]]
            k += n
        pool = np.unique(gathered)
        rows, found = grown(rows, n_side + f1 - f0), grown(found, n_side + f1 - f0)
        sizes = grown(sizes, 4 * (n_side + f1 - f0))
        flat = grown(flat, n_flat + 4 * (f1 - f0) * (3 + pool.shape[0]))
        for f in faces[f0:f1]:
            p = np.empty(4, np.int64)
            n = 0
            for v in face_vertices[face_offsets[f] : face_offsets[f + 1]]:
                for q in range(4):
                    if lattice[r, q] == v and n < 4:
                        p[n] = q
                        n += 1
            if n < 3:
                continue
            a, b, c = p[0], p[1], p[2]
            triangles = np.array(
                [
                    [a, mid[a, b], mid[a, c]],
                    [b, mid[b, c], mid[b, a]],
                    [c, mid[c, a], mid[c, b]],
                    [mid[a, b], mid[b, c], mid[c, a]],
                ]
            )
            for t in range(4):
                ids = lattice[r][triangles[t]]
                u, w = x[ids[1]] - x[ids[0]], x[ids[2]] - x[ids[0]]
                normal = np.array([u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]])
                if not normal @ face_normals[f] > 0:
                    ids = ids[::-1].copy()
                end = insert_on_edges(ids, pool, x, tol, flat, n_flat)
                sizes[4 * n_side + t] = end - n_flat
                n_flat = end
            rows[n_side], found[n_side] = r, f
            n_side += 1
    return rows[:n_side], found[:n_side], sizes[: 4 * n_side], flat[:n_flat]
