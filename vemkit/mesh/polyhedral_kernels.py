"""Numba kernels of :class:`~vemkit.mesh.polyhedral.PolyhedralMesh`'s derived topology and face
geometry, and of the orientation test of ``polyhedral_build`` (the vertex after the smallest one of
every face): one pass over the cells or faces, no sort, no (entries x 3) temporaries. Their numpy
twins are ``polyhedral_reference``."""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def cell_vertex_lists(cell_offsets, cell_faces, face_offsets, face_vertices, n_vertices):
    """CSR (offsets, vertices): the distinct vertices of every cell in order of first appearance along
    its faces (faces as stored); a vertex is new to cell c when its stamp is not c."""
    cells = cell_offsets.shape[0] - 1
    stamp = np.full(n_vertices, -1, dtype=np.int64)
    total = 0
    for t in range(cell_faces.shape[0]):
        s = cell_faces[t]
        f = s if s >= 0 else -s - 1
        total += face_offsets[f + 1] - face_offsets[f]
    ids = np.empty(total, dtype=np.int64)
    offsets = np.zeros(cells + 1, dtype=np.int64)
    k = 0
    for c in range(cells):
        for t in range(cell_offsets[c], cell_offsets[c + 1]):
            s = cell_faces[t]
            f = s if s >= 0 else -s - 1
            for i in range(face_offsets[f], face_offsets[f + 1]):
                v = face_vertices[i]
                if stamp[v] != c:
                    stamp[v] = c
                    ids[k] = v
                    k += 1
        offsets[c + 1] = k
    return offsets, ids[:k].copy()


@numba.njit(cache=True)
def face_geometry(vertices, face_offsets, face_vertices):
    """((F, 3) |F| n_F, (F, 3) area centroids): per face the cross products q_i x q_i+1 about the
    vertex mean (q_i = p_i - mean) give |F| n_F = 1/2 sum; the fan triangle i has the signed (doubled)
    area a_i = (q_i x q_i+1) . n_F and centroid offset (q_i + q_i+1) / 3 (``polyhedral_reference``)."""
    n_faces = face_offsets.shape[0] - 1
    va = np.zeros((n_faces, 3))
    centroid = np.zeros((n_faces, 3))
    tiny = np.finfo(np.float64).tiny
    for f in range(n_faces):
        lo, m = face_offsets[f], face_offsets[f + 1] - face_offsets[f]
        if m == 0:
            continue
        x0 = x1 = x2 = 0.0
        for i in range(lo, lo + m):
            x0 += vertices[face_vertices[i], 0]
            x1 += vertices[face_vertices[i], 1]
            x2 += vertices[face_vertices[i], 2]
        x0, x1, x2 = x0 / m, x1 / m, x2 / m
        s0 = s1 = s2 = 0.0
        for i in range(m):
            a, b = face_vertices[lo + i], face_vertices[lo + (i + 1) % m]
            q0, q1, q2 = vertices[a, 0] - x0, vertices[a, 1] - x1, vertices[a, 2] - x2
            r0, r1, r2 = vertices[b, 0] - x0, vertices[b, 1] - x1, vertices[b, 2] - x2
            s0 += q1 * r2 - q2 * r1
            s1 += q2 * r0 - q0 * r2
            s2 += q0 * r1 - q1 * r0
        va[f, 0], va[f, 1], va[f, 2] = 0.5 * s0, 0.5 * s1, 0.5 * s2
        norm = max(np.sqrt(va[f, 0] ** 2 + va[f, 1] ** 2 + va[f, 2] ** 2), tiny)
        n0, n1, n2 = va[f, 0] / norm, va[f, 1] / norm, va[f, 2] / norm
        total = m0 = m1 = m2 = 0.0
        for i in range(m):
            a, b = face_vertices[lo + i], face_vertices[lo + (i + 1) % m]
            q0, q1, q2 = vertices[a, 0] - x0, vertices[a, 1] - x1, vertices[a, 2] - x2
            r0, r1, r2 = vertices[b, 0] - x0, vertices[b, 1] - x1, vertices[b, 2] - x2
            t = (q1 * r2 - q2 * r1) * n0 + (q2 * r0 - q0 * r2) * n1 + (q0 * r1 - q1 * r0) * n2
            total += t
            m0 += (q0 + r0) / 3.0 * t
            m1 += (q1 + r1) / 3.0 * t
            m2 += (q2 + r2) / 3.0 * t
        centroid[f, 0], centroid[f, 1], centroid[f, 2] = x0, x1, x2
        if abs(total) > 0:
            centroid[f, 0] += m0 / total
            centroid[f, 1] += m1 / total
            centroid[f, 2] += m2 / total
    return va, centroid


@numba.njit(cache=True)
def successor_of_min(offsets, vertices):
    """The vertex after the smallest one (its first place) in every CSR cycle."""
    out = np.empty(offsets.shape[0] - 1, dtype=np.int64)
    for c in range(out.shape[0]):
        s, n = offsets[c], offsets[c + 1] - offsets[c]
        if n == 0:
            out[c] = -1
            continue
        at = 0
        for i in range(1, n):
            if vertices[s + i] < vertices[s + at]:
                at = i
        out[c] = vertices[s + (at + 1) % n]
    return out
