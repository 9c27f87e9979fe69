"""Lowest-order (k = 1) virtual element for plane elasticity: one polygon at a time.

Degrees of freedom are the displacements at the vertices, interleaved
``(u1(x_1), u2(x_1), u1(x_2), ...)``. For k = 1 the strain of the projection Pi v (3.8) is the
element average of eps(v), computable from the boundary values:

    |K| eps(Pi v) = int_dK sym(v (x) n) ds = sum_i sym(v_i (x) q_i) |K|,
    q_i = (y_{i+1} - y_{i-1}, x_{i-1} - x_{i+1}) / (2 |K|).

The rigid part of Pi v is fixed by the paper's two vertex constraints (after (3.8)): the vertex
mean of Pi v equals that of v, and the vertex mean of x x Pi v equals that of x x v.

The local form (3.9) is a_h^K = |K| B^T D B + alpha_K (I - Pi)^T (I - Pi), with the dofi-dofi
stabilization S_K of the paper and the scaling alpha_K named by ``stabilization``.

The Numba kernel ``element_stiffness`` is used by the assembly; its plain-numpy twin, which solves
(3.8) literally with boundary integrals and a 6 x 6 system, is ``k1_reference.element_stiffness_reference``
(the tests pin the kernel against it).
"""

from __future__ import annotations

import numba
import numpy as np

from vemkit.mesh.geometry import polygon_area


@numba.njit(cache=True)
def polygon_coordinates(vertices, ids, start, n):
    """(px, py) of the n vertices ids[start:start + n]."""
    px = np.empty(n)
    py = np.empty(n)
    for i in range(n):
        px[i] = vertices[ids[start + i], 0]
        py[i] = vertices[ids[start + i], 1]
    return px, py


@numba.njit(cache=True)
def cell_coordinates(vertices, offsets, cell_vertices, c):
    """(px, py): the vertex coordinates of cell c, in its (counter-clockwise) order."""
    return polygon_coordinates(vertices, cell_vertices, offsets[c], offsets[c + 1] - offsets[c])


@numba.njit(cache=True)
def strain_operator(px, py, area, B):
    """B (3 x 2n): element-average strain (eps11, eps22, 2 eps12) from vertex values."""
    n = px.shape[0]
    inv = 1.0 / (2.0 * area)
    for i in range(n):
        ip = (i + 1) % n
        im = (i - 1 + n) % n
        qx = (py[ip] - py[im]) * inv
        qy = (px[im] - px[ip]) * inv
        B[0, 2 * i] = qx
        B[0, 2 * i + 1] = 0.0
        B[1, 2 * i] = 0.0
        B[1, 2 * i + 1] = qy
        B[2, 2 * i] = qy
        B[2, 2 * i + 1] = qx


@numba.njit(cache=True)
def projection_coefficients(px, py, B, P):
    """P (6 x 2n): coefficients of Pi v = c + (E + omega J)(x - xbar) from the vertex values.

    Rows: c1, c2, omega, eps11, eps22, eps12 (tensor component). xbar is the vertex mean.
    """
    n = px.shape[0]
    xb = 0.0
    yb = 0.0
    for i in range(n):
        xb += px[i]
        yb += py[i]
    xb /= n
    yb /= n
    s = 0.0
    for i in range(n):
        s += (px[i] - xb) ** 2 + (py[i] - yb) ** 2
    s /= n
    for j in range(2 * n):
        P[0, j] = 0.0
        P[1, j] = 0.0
        P[3, j] = B[0, j]
        P[4, j] = B[1, j]
        P[5, j] = 0.5 * B[2, j]
    for i in range(n):
        P[0, 2 * i] = 1.0 / n
        P[1, 2 * i + 1] = 1.0 / n
    # omega * mean|d|^2 = mean(d x v) - mean(d x E d),  d x E d = E12 (d1^2 - d2^2) + d1 d2 (E22 - E11)
    a = 0.0
    b = 0.0
    for i in range(n):
        d1 = px[i] - xb
        d2 = py[i] - yb
        a += d1 * d1 - d2 * d2
        b += d1 * d2
    a /= n
    b /= n
    for j in range(2 * n):
        P[2, j] = -(a * P[5, j] + b * (P[4, j] - P[3, j])) / s
    for i in range(n):
        P[2, 2 * i] += -(py[i] - yb) / (n * s)
        P[2, 2 * i + 1] += (px[i] - xb) / (n * s)
    return xb, yb


@numba.njit(cache=True)
def element_stiffness(px, py, lam, mu, stab, K, B, P, R):
    """Local VEM stiffness (3.9) into K (2n x 2n). B (3 x 2n), P (6 x 2n), R (2n x 2n) are work.

    stab: 0 = dofi (alpha = 1), 1 = dofi-2mu (alpha = 2 mu), 2 = trace (alpha = tr(Kc) / 2n).
    """
    n = px.shape[0]
    m = 2 * n
    area = polygon_area(px, py)
    strain_operator(px, py, area, B)
    xb, yb = projection_coefficients(px, py, B, P)
    d11 = lam + 2.0 * mu
    # consistency |K| B^T D B
    tr = 0.0
    for i in range(m):
        b0 = B[0, i]
        b1 = B[1, i]
        b2 = B[2, i]
        t0 = area * (d11 * b0 + lam * b1)
        t1 = area * (lam * b0 + d11 * b1)
        t2 = area * mu * b2
        for j in range(m):
            K[i, j] = t0 * B[0, j] + t1 * B[1, j] + t2 * B[2, j]
        tr += K[i, i]
    if stab == 0:
        alpha = 1.0
    elif stab == 1:
        alpha = 2.0 * mu
    else:
        alpha = tr / m
    # R holds (I - Pi_D)^T: row j is the vertex values of phi_j - Pi phi_j (contiguous for the product)
    for j in range(m):
        c1 = P[0, j]
        c2 = P[1, j]
        om = P[2, j]
        e11 = P[3, j]
        e22 = P[4, j]
        e12 = P[5, j]
        for i in range(n):
            d1 = px[i] - xb
            d2 = py[i] - yb
            R[j, 2 * i] = -(c1 + e11 * d1 + (e12 - om) * d2)
            R[j, 2 * i + 1] = -(c2 + (e12 + om) * d1 + e22 * d2)
        R[j, j] += 1.0
    add_stabilization(R, alpha, K)
    return area


@numba.njit(cache=True)
def add_stabilization(R, alpha, K):
    """K += alpha (I - Pi)^T (I - Pi) (the dofi-dofi S_K of (3.9)), R = (I - Pi)^T (any dimension)."""
    m = R.shape[0]
    for i in range(m):
        for j in range(i, m):
            acc = 0.0
            for k in range(m):
                acc += R[i, k] * R[j, k]
            acc *= alpha
            K[i, j] += acc
            if j != i:
                K[j, i] += acc


# --------------------------------------------------------------------------------------------
# the element's hooks for the one assembly of ``vemkit.vem.assembly`` (``vemkit.vem.elements``)
# --------------------------------------------------------------------------------------------
@numba.njit(cache=True)
def stiffness_workspace(dim, max_nodes):
    """(K, B, P, R): the k = 1 element's matrices in dimension ``dim`` for cells of up to max_nodes
    vertices (m = dim max_nodes scalars): the stiffness K and R = (I - Pi)^T (m x m), the strain
    operator B (one row per Voigt strain, dim (dim + 1) / 2) and the projection's P (dim (dim + 1))."""
    m = dim * max_nodes
    strains = dim * (dim + 1) // 2
    return np.empty((m, m)), np.empty((strains, m)), np.empty((2 * strains, m)), np.empty((m, m))


@numba.njit(cache=True)
def workspace(max_nodes):
    """(K, B, P, R, px, py): the work arrays of ``cell_matrix`` for cells of up to max_nodes vertices."""
    return stiffness_workspace(2, max_nodes) + (np.empty(max_nodes), np.empty(max_nodes))


@numba.njit(cache=True)
def cell_matrix(c, vertices, offsets, nodes, lam, mu, stab, work):
    """The local stiffness (3.9) of cell c in its vertex order, in the leading 2n x 2n block of the
    returned work matrix."""
    K, B, P, R, px, py = work
    start = offsets[c]
    n = offsets[c + 1] - start
    for i in range(n):
        px[i] = vertices[nodes[start + i], 0]
        py[i] = vertices[nodes[start + i], 1]
    m = 2 * n
    element_stiffness(px[:n], py[:n], lam, mu, stab, K[:m, :m], B[:, :m], P[:, :m], R[:m, :m])
    return K
