"""Numba kernels of the 3D k = 1 loads and projected fields (``k1_3d_fields``; their numpy twins, the
cell-by-cell originals, are ``k1_3d_fields_reference``): one pass over the cells or faces each, no
Python loop, no per-cell arrays.

- ``fan_quadrature``: the signed tetrahedral fan of cells [lo, hi) (cell vertex mean, face vertex
  mean, one face edge) with a reference rule on each tetrahedron;
- ``projection_table``: the Pi coefficients (3.8) of every cell packed in one (12, 3 sum n) table;
- ``body_force_scatter``: int_K P_0 f . Pi phi_j dx = |K| f_K . (Pi phi_j)(x_K) (Section 3.3);
- ``projected_fields``: c_K and G_K = E + W of Pi u on every cell;
- ``face_fan_points`` / ``face_trace_scatter``: the traction int_F g . Pi^F phi_i ds by the signed fan
  triangles of each face from its vertex mean.
"""

from __future__ import annotations

import numba
import numpy as np

from vemkit.vem.elements.k1_3d_kernel import boundary_vectors, cross, projection_coefficients, strain_operator


@numba.njit(cache=True)
def fan_tetrahedra_count(cell_offsets, cell_faces, face_offsets, lo, hi):
    """The number of fan tetrahedra of cells [lo, hi): one per face edge."""
    count = 0
    for t in range(cell_offsets[lo], cell_offsets[hi]):
        s = cell_faces[t]
        f = s if s >= 0 else -s - 1
        count += face_offsets[f + 1] - face_offsets[f]
    return count


@numba.njit(cache=True)
def fan_quadrature(
    vertices, cell_offsets, cell_faces, face_offsets, face_vertices, v_offsets, v_ids, lo, hi, ref, ref_w
):
    """(x (T Q, 3), w (T Q,), cell (T Q,)) of cells lo <= c < hi: on each fan tetrahedron (centre, face
    mean, p_i, p_i+1), J its edges from the centre, x = centre + J r, w = det(J) w_r (signed)."""
    q = ref.shape[0]
    total = fan_tetrahedra_count(cell_offsets, cell_faces, face_offsets, lo, hi) * q
    x = np.empty((total, 3))
    w = np.empty(total)
    cell = np.empty(total, dtype=np.int64)
    centre, mean, J = np.empty(3), np.empty(3), np.empty((3, 3))
    k = 0
    for c in range(lo, hi):
        centre[:] = 0.0
        for i in range(v_offsets[c], v_offsets[c + 1]):
            centre += vertices[v_ids[i]]
        centre /= v_offsets[c + 1] - v_offsets[c]
        for t in range(cell_offsets[c], cell_offsets[c + 1]):
            s = cell_faces[t]
            f = s if s >= 0 else -s - 1
            f_lo, m = face_offsets[f], face_offsets[f + 1] - face_offsets[f]
            mean[:] = 0.0
            for i in range(m):
                mean += vertices[face_vertices[f_lo + i]]
            mean /= m
            for i in range(m):
                a = face_vertices[f_lo + (i if s >= 0 else m - 1 - i)]
                b = face_vertices[f_lo + ((i + 1) % m if s >= 0 else (2 * m - 2 - i) % m)]
                for r in range(3):
                    J[r, 0] = mean[r] - centre[r]
                    J[r, 1] = vertices[a, r] - centre[r]
                    J[r, 2] = vertices[b, r] - centre[r]
                det = (
                    J[0, 0] * (J[1, 1] * J[2, 2] - J[1, 2] * J[2, 1])
                    - J[0, 1] * (J[1, 0] * J[2, 2] - J[1, 2] * J[2, 0])
                    + J[0, 2] * (J[1, 0] * J[2, 1] - J[1, 1] * J[2, 0])
                )
                for g in range(q):
                    for r in range(3):
                        x[k, r] = centre[r] + J[r, 0] * ref[g, 0] + J[r, 1] * ref[g, 1] + J[r, 2] * ref[g, 2]
                    w[k] = det * ref_w[g]
                    cell[k] = c
                    k += 1
    return x, w, cell


@numba.njit(cache=True)
def cell_moments(cell, w, x, f, cells):
    """(|K|, P_0 f, x_K) of every cell from a rule (x, w) with point values f (Q, 3): the sums of w,
    w f and w x over each cell's points (in their order), divided by |K|."""
    volume, mean_f, centroid = np.zeros(cells), np.zeros((cells, 3)), np.zeros((cells, 3))
    for k in range(w.shape[0]):
        c = cell[k]
        volume[c] += w[k]
        for a in range(3):
            mean_f[c, a] += w[k] * f[k, a]
            centroid[c, a] += w[k] * x[k, a]
    for c in range(cells):
        for a in range(3):
            mean_f[c, a] /= volume[c]
            centroid[c, a] /= volume[c]
    return volume, mean_f, centroid


@numba.njit(cache=True)
def _cell_projection(vertices, v_offsets, v_ids, cell_face_ptr, face_ptr, face_local, c, p, q, w, B, P):
    """Pi (3.8) of cell c into P[:, :3n] (``k1_3d_kernel.projection_coefficients``); returns (xbar, |K|, n)."""
    start, n = v_offsets[c], v_offsets[c + 1] - v_offsets[c]
    for i in range(n):
        p[i] = vertices[v_ids[start + i]]
    volume = boundary_vectors(p[:n], face_ptr, face_local, cell_face_ptr[c], cell_face_ptr[c + 1], q[:n], w)
    strain_operator(q[:n], volume, B[:, : 3 * n])
    xb = projection_coefficients(p[:n], B[:, : 3 * n], P[:, : 3 * n])
    return xb, volume, n


@numba.njit(cache=True)
def _work(v_offsets):
    size = 0
    for c in range(v_offsets.shape[0] - 1):
        size = max(size, v_offsets[c + 1] - v_offsets[c])
    return np.empty((size, 3)), np.empty((size, 3)), np.empty(size), np.empty((6, 3 * size)), np.empty((12, 3 * size))


@numba.njit(cache=True)
def projection_table(vertices, v_offsets, v_ids, cell_face_ptr, face_ptr, face_local):
    """(xbar (M, 3), P (12, 3 sum n), |K| (M,)): cell c's Pi coefficients in the columns
    3 v_offsets[c] ... 3 v_offsets[c + 1] of P (rows: c, omega, E11 E22 E33 E12 E13 E23)."""
    cells = v_offsets.shape[0] - 1
    p, q, w, B, Pc = _work(v_offsets)
    xbar, volumes = np.empty((cells, 3)), np.empty(cells)
    table = np.empty((12, 3 * v_offsets[-1]))
    for c in range(cells):
        xb, volumes[c], n = _cell_projection(
            vertices, v_offsets, v_ids, cell_face_ptr, face_ptr, face_local, c, p, q, w, B, Pc
        )
        xbar[c] = xb
        table[:, 3 * v_offsets[c] : 3 * v_offsets[c + 1]] = Pc[:, : 3 * n]
    return xbar, table, volumes


@numba.njit(cache=True)
def gradient_of(P, j, G):
    """G (3, 3) = E + W of Pi phi_j, column j of P (``k1_3d_fields._gradients``)."""
    G[0, 0], G[1, 1], G[2, 2] = P[6, j], P[7, j], P[8, j]
    G[0, 1] = P[9, j] - P[5, j]
    G[1, 0] = P[9, j] + P[5, j]
    G[0, 2] = P[10, j] + P[4, j]
    G[2, 0] = P[10, j] - P[4, j]
    G[1, 2] = P[11, j] - P[3, j]
    G[2, 1] = P[11, j] + P[3, j]


@numba.njit(cache=True)
def body_force_scatter(
    vertices, v_offsets, v_ids, cell_face_ptr, face_ptr, face_local, lo, volume, mean_f, centroid, out
):
    """out[v] += |K| f_K . (Pi phi_j)(x_K) for the cells lo <= c < lo + len(volume) (row c - lo of
    ``volume``, ``mean_f``, ``centroid``); out (N, 3), dof j = 3 i + a of the cell's vertex i."""
    p, q, w, B, P = _work(v_offsets)
    G = np.empty((3, 3))
    for r in range(volume.shape[0]):
        c = lo + r
        xb, _, n = _cell_projection(vertices, v_offsets, v_ids, cell_face_ptr, face_ptr, face_local, c, p, q, w, B, P)
        d = centroid[r] - xb
        for j in range(3 * n):
            gradient_of(P, j, G)
            load = 0.0
            for a in range(3):
                value = P[a, j] + G[a, 0] * d[0] + G[a, 1] * d[1] + G[a, 2] * d[2]
                load += value * mean_f[r, a]
            out[v_ids[v_offsets[c] + j // 3], j % 3] += volume[r] * load


@numba.njit(cache=True)
def projected_fields(vertices, v_offsets, v_ids, cell_face_ptr, face_ptr, face_local, u):
    """(xbar (M, 3), c (M, 3), G (M, 3, 3)): Pi u = c + G (x - xbar) on every cell, u (N, 3)."""
    cells = v_offsets.shape[0] - 1
    p, q, w, B, P = _work(v_offsets)
    xbar, c_out, G_out = np.empty((cells, 3)), np.zeros((cells, 3)), np.zeros((cells, 3, 3))
    G = np.empty((3, 3))
    for c in range(cells):
        xb, _, n = _cell_projection(vertices, v_offsets, v_ids, cell_face_ptr, face_ptr, face_local, c, p, q, w, B, P)
        xbar[c] = xb
        for j in range(3 * n):
            v = u[v_ids[v_offsets[c] + j // 3], j % 3]
            gradient_of(P, j, G)
            for a in range(3):
                c_out[c, a] += P[a, j] * v
                for b in range(3):
                    G_out[c, a, b] += v * G[a, b]
    return xbar, c_out, G_out


@numba.njit(cache=True)
def face_fan_points(vertices, face_offsets, face_vertices, faces, ref, ref_w):
    """(x (sum m Q, 3), w): the rule (ref, ref_w) on the fan triangles (xbar_F, p_i, p_i+1) of every
    face, w = the signed 2 |T| (along the face's unit normal) times the reference weight."""
    q = ref.shape[0]
    total = 0
    for f in faces:
        total += (face_offsets[f + 1] - face_offsets[f]) * q
    x, w = np.empty((total, 3)), np.empty(total)
    xb, a = np.empty(3), np.empty(3)
    k = 0
    for f in faces:
        lo, m = face_offsets[f], face_offsets[f + 1] - face_offsets[f]
        _face_mean_and_area(vertices, face_vertices, lo, m, xb, a)
        norm = np.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
        for i in range(m):
            p, r = vertices[face_vertices[lo + i]] - xb, vertices[face_vertices[lo + (i + 1) % m]] - xb
            c0, c1, c2 = cross(p[0], p[1], p[2], r[0], r[1], r[2])
            twice = (c0 * a[0] + c1 * a[1] + c2 * a[2]) / norm
            for g in range(q):
                x[k] = xb + ref[g, 0] * p + ref[g, 1] * r
                w[k] = twice * ref_w[g]
                k += 1
    return x, w


@numba.njit(cache=True)
def _face_mean_and_area(vertices, face_vertices, lo, m, xb, a):
    """xb = the vertex mean of the face, a = its vector area sum_i (p_i - xb) x (p_i+1 - xb) (twice |F| n_F)."""
    xb[:] = 0.0
    for i in range(m):
        xb += vertices[face_vertices[lo + i]]
    xb /= m
    a[:] = 0.0
    for i in range(m):
        p, r = vertices[face_vertices[lo + i]] - xb, vertices[face_vertices[lo + (i + 1) % m]] - xb
        c0, c1, c2 = cross(p[0], p[1], p[2], r[0], r[1], r[2])
        a[0] += c0
        a[1] += c1
        a[2] += c2


@numba.njit(cache=True)
def face_trace_scatter(vertices, face_offsets, face_vertices, faces, points_per_face_vertex, x, wg, out):
    """out[v_i] += sum_q Pi^F phi_i (x_q) wg_q over every face's points (``face_fan_points`` order):
    Pi^F phi_i = 1/m + grad_i . (x - xbar_F), grad_i = ((p_i+1 - p_i-1) x n_F) / (2 |F|)."""
    xb, a, grad = np.empty(3), np.empty(3), np.empty((64, 3))
    k = 0
    for f in faces:
        lo, m = face_offsets[f], face_offsets[f + 1] - face_offsets[f]
        if m > grad.shape[0]:
            grad = np.empty((m, 3))
        _face_mean_and_area(vertices, face_vertices, lo, m, xb, a)
        area = 0.5 * np.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
        n = 0.5 * a / area
        for i in range(m):
            e = vertices[face_vertices[lo + (i + 1) % m]] - vertices[face_vertices[lo + (i - 1 + m) % m]]
            g0, g1, g2 = cross(e[0], e[1], e[2], n[0], n[1], n[2])
            grad[i, 0], grad[i, 1], grad[i, 2] = g0 / (2 * area), g1 / (2 * area), g2 / (2 * area)
        for _point in range(m * points_per_face_vertex):
            for i in range(m):
                phi = 1.0 / m + (
                    (x[k, 0] - xb[0]) * grad[i, 0] + (x[k, 1] - xb[1]) * grad[i, 1] + (x[k, 2] - xb[2]) * grad[i, 2]
                )
                for r in range(3):
                    out[face_vertices[lo + i], r] += phi * wg[k, r]
            k += 1
