"""The local k = 2 stiffness (3.9) from the projection of ``vemkit.vem.elements.k2_kernel``, in low-rank form.

A[k, j] = dof k of Pi phi_j = E_k . C_j, with C_j the monomial coefficients of the two components
of Pi phi_j and E_k the dofs of the monomials (1, xi, eta, xi^2, xi eta, eta^2) at the place of
dof k (vertex value, edge or cell mean), in the block of its component. With G = L_G L_G^T (3.8),
Q = sum_k E_k E_k^T = L L^T (6 x 6 per component), Y = L_G^-1 rhs and F_k = L^-1 E_k:

    a_K(Pi phi_i, Pi phi_j) = Y_i . Y_j,
    S_K((I - Pi) phi_i, (I - Pi) phi_j) = delta_ij - A_ij - A_ji + sum_k A_ki A_kj
                                        = delta_ij + V_i . V_j - F_i . F_j,   V_j = L^T C_j - F_j.

So K_ij = W_i . W_j + alpha (delta_ij - H_ij), W_j = (Y_j, sqrt(alpha) V_j) (21 numbers) and
H_ij = F_i . F_j the hat matrix of the monomials' dofs (zero between the two components): one short
dot product per entry, no m x m x m product, no per-cell allocation. The tests pin the result
against the plain-numpy twin ``vemkit.vem.elements.k2_reference`` (the dense (I - Pi)^T (I - Pi) of (3.9)).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from vemkit.vem.elements.base import stabilization_code
from vemkit.vem.elements.k2_kernel import cholesky_factor, projection_system

N_ENERGY = 24  # length of the energy vectors W: Y (9), V (2 x 6), zero padding (3: three vector lanes)


@numba.njit(cache=True, fastmath={"contract"})
def strain_coordinates(G, rhs, m, W, P):
    """Per dof j, G factored by ``cholesky_factor``: Y_j = L_G^-1 a_K(phi_j, q_.) into W[j, :9] and
    P[j] = L_G^-T Y_j, the coefficients 3..11 of Pi phi_j (3.8); the operations of ``cholesky_solve``,
    one right-hand side at a time."""
    for j in range(m):
        for i in range(9):
            s = rhs[i, j]
            for p in range(0 if i < 3 else 3, i):
                s -= G[i, p] * W[j, p]
            W[j, i] = s * G[i, i]
        for i in range(8, -1, -1):
            s = W[j, i]
            for p in range(i + 1, 3 if i < 3 else 9):
                s -= G[p, i] * P[j, p]
            P[j, i] = s * G[i, i]


@numba.njit(cache=True)
def component_coefficients(px, py, h, area, m20, m11, m02, P, C):
    """C[j, :6], C[j, 6:]: the components u1, u2 of Pi phi_j in the monomials (1, xi, eta, xi^2,
    xi eta, eta^2), from its coefficients 3..11 P[j] and the rigid part of ``projection_k2``."""
    n = px.shape[0]
    for j in range(4 * n + 2):
        C[j, 0] = -(P[j, 3] * m20 + P[j, 4] * m11 + P[j, 5] * m02) / area  # zero interior mean
        C[j, 1] = P[j, 0]
        C[j, 2] = P[j, 2]
        C[j, 6] = -(P[j, 6] * m20 + P[j, 7] * m11 + P[j, 8] * m02) / area
        C[j, 7] = P[j, 2]
        C[j, 8] = P[j, 1]
        for s in range(3):
            C[j, 3 + s] = P[j, 3 + s]
            C[j, 9 + s] = P[j, 6 + s]
    C[4 * n, 0] += 1.0  # interior mean of Pi v = interior mean of v
    C[4 * n + 1, 6] += 1.0
    for i in range(n):  # rotation omega (-eta, xi): int_K rot Pi v = sum_e (x_b - x_a) . mean_e v
        k = (i + 1) % n
        wx = h * (px[k] - px[i]) / (2.0 * area)
        wy = h * (py[k] - py[i]) / (2.0 * area)
        C[2 * n + 2 * i, 2] -= wx
        C[2 * n + 2 * i, 7] += wx
        C[2 * n + 2 * i + 1, 2] -= wy
        C[2 * n + 2 * i + 1, 7] += wy


@numba.njit(cache=True)
def _monomials(Mo, row, x, y, weight):
    """Mo[row] += weight * (1, x, y, x^2, x y, y^2)."""
    Mo[row, 0] += weight
    Mo[row, 1] += weight * x
    Mo[row, 2] += weight * y
    Mo[row, 3] += weight * x * x
    Mo[row, 4] += weight * x * y
    Mo[row, 5] += weight * y * y


@numba.njit(cache=True)
def dof_monomials(px, py, xc, yc, h, area, m20, m11, m02, Mo):
    """Mo (2n + 1, 6): the degrees of freedom of the scaled monomials: values at the vertices, means
    on the edges (Simpson: exact for quadratics) and over the cell (about the centroid)."""
    n = px.shape[0]
    for loc in range(2 * n + 1):
        for s in range(6):
            Mo[loc, s] = 0.0
    for i in range(n):
        k = (i + 1) % n
        xa, ya = (px[i] - xc) / h, (py[i] - yc) / h
        xb, yb = (px[k] - xc) / h, (py[k] - yc) / h
        _monomials(Mo, i, xa, ya, 1.0)
        _monomials(Mo, n + i, xa, ya, 1.0 / 6.0)
        _monomials(Mo, n + i, 0.5 * (xa + xb), 0.5 * (ya + yb), 4.0 / 6.0)
        _monomials(Mo, n + i, xb, yb, 1.0 / 6.0)
    Mo[2 * n, 0] = 1.0
    Mo[2 * n, 3] = m20 / area
    Mo[2 * n, 4] = m11 / area
    Mo[2 * n, 5] = m02 / area


@numba.njit(cache=True, fastmath={"contract", "reassoc"})
def monomial_gram(n_loc, Mo, Q, F, H):
    """Q = Mo^T Mo = L L^T factored in place (the diagonal keeps L_rr), F[l] = L^-1 Mo[l] and the
    hat matrix H[l, l'] = F_l . F_l' of the monomials' dofs at the n_loc places."""
    for r in range(6):
        for s in range(r + 1):
            Q[r, s] = 0.0
    for loc in range(n_loc):
        for r in range(6):
            for s in range(r + 1):
                Q[r, s] += Mo[loc, r] * Mo[loc, s]
    cholesky_factor(Q, 0, 6)
    for loc in range(n_loc):
        for r in range(6):
            acc = Mo[loc, r]
            for p in range(r):
                acc -= Q[r, p] * F[loc, p]
            F[loc, r] = acc * Q[r, r]
    for r in range(6):
        Q[r, r] = 1.0 / Q[r, r]
    for loc in range(n_loc):
        for other in range(loc, n_loc):
            acc = 0.0
            for r in range(6):
                acc += F[loc, r] * F[other, r]
            H[loc, other] = acc
            H[other, loc] = acc


@numba.njit(cache=True, fastmath={"contract", "reassoc"})
def energy_vectors(m, mu, stab, C, Q, F, W):
    """W[j, 9:21] = sqrt(alpha) V_j (W[j, :9] = Y_j already; see the module docstring); returns alpha
    (``element_stiffness_k2``). ``reassoc``: the sums need not run one after the other."""
    tr = 0.0  # trace of the consistency part, sum_j |Y_j|^2
    for j in range(m):
        for b in range(9):
            tr += W[j, b] * W[j, b]
    alpha = 1.0 if stab == 0 else (2.0 * mu if stab == 1 else tr / m)
    scale = math.sqrt(alpha)
    for j in range(m):
        loc, comp = j // 2, j % 2  # dof j is component comp at vertex, edge or cell ``loc``
        for a in range(2):
            for r in range(6):
                acc = -F[loc, r] if a == comp else 0.0
                for s in range(r, 6):
                    acc += Q[s, r] * C[j, 6 * a + s]
                W[j, 9 + 6 * a + r] = scale * acc
    return alpha


@numba.njit(cache=True, fastmath={"contract", "reassoc"})
def local_stiffness(m, alpha, H, W, K):
    """K = a_K(Pi phi_i, Pi phi_j) + alpha S_K((I - Pi) phi_i, (I - Pi) phi_j) (3.9), S_K dofi-dofi,
    = W_i . W_j + alpha (delta_ij - H_ij). The dot products run over a length known only at run
    time, in 2 x 2 blocks (m is even): the loop vectorizer takes them into vector lanes."""
    width = W.shape[1]
    for i in range(0, m, 2):
        for j in range(i, m, 2):
            a00 = a01 = a10 = a11 = 0.0
            for t in range(width):
                a00 += W[i, t] * W[j, t]
                a01 += W[i, t] * W[j + 1, t]
                a10 += W[i + 1, t] * W[j, t]
                a11 += W[i + 1, t] * W[j + 1, t]
            K[i, j] = a00
            K[i, j + 1] = a01
            K[i + 1, j] = a10
            K[i + 1, j + 1] = a11
    for i in range(m):
        for j in range(i, m, 2):  # same component: F_i . F_j = H
            K[i, j] -= alpha * H[i // 2, j // 2]
        K[i, i] += alpha
    for i in range(m):
        for j in range(i):
            K[i, j] = K[j, i]


@numba.njit(cache=True)
def stiffness_workspace(nmax):
    """The work arrays of ``element_stiffness_k2`` for cells of up to nmax vertices (W zeroed: its
    padding stays zero)."""
    m = 4 * nmax + 2
    n_loc = 2 * nmax + 1
    return (
        np.empty((9, m)),
        np.empty((9, 9)),
        np.empty((9, 3, 3)),
        np.zeros((m, N_ENERGY)),
        np.empty((m, 9)),
        np.empty((m, 12)),
        np.empty((n_loc, 6)),
        np.empty((6, 6)),
        np.empty((n_loc, 6)),
        np.empty((n_loc, n_loc)),
    )


@numba.njit(cache=True)
def element_stiffness_k2(px, py, lam, mu, stab, K, work):
    """Local k = 2 stiffness (3.9) into K[:m, :m] (m = 4n + 2); ``work`` from ``stiffness_workspace``
    (K and the work arrays may be larger: only their leading rows / columns are used).

    stab: 0 = dofi (alpha = 1), 1 = dofi-2mu (alpha = 2 mu), 2 = trace (alpha = tr(Kc) / m).
    """
    rhs, G, sig, W, P, C, Mo, Q, F, H = work
    n = px.shape[0]
    m = 4 * n + 2
    area, xc, yc, h, m20, m11, m02 = projection_system(px, py, lam, mu, rhs, G, sig)
    strain_coordinates(G, rhs, m, W, P)
    component_coefficients(px, py, h, area, m20, m11, m02, P, C)
    dof_monomials(px, py, xc, yc, h, area, m20, m11, m02, Mo)
    monomial_gram(2 * n + 1, Mo, Q, F, H)
    alpha = energy_vectors(m, mu, stab, C, Q, F, W)
    local_stiffness(m, alpha, H, W, K)
    return area


def element_stiffness_k2_matrix(coords, lam, mu, stabilization="dofi-2mu"):
    """Convenience: the local k = 2 stiffness of one polygon (n, 2) from the Numba kernel."""
    c = np.asarray(coords, float)
    n = c.shape[0]
    m = 4 * n + 2
    K = np.empty((m, m))
    element_stiffness_k2(
        c[:, 0].copy(),
        c[:, 1].copy(),
        float(lam),
        float(mu),
        stabilization_code(stabilization),
        K,
        stiffness_workspace(n),
    )
    return K


# --------------------------------------------------------------------------------------------
# the element's hooks for the one assembly of ``vemkit.vem.assembly`` (``vemkit.vem.elements``)
# --------------------------------------------------------------------------------------------
@numba.njit(cache=True)
def workspace(max_nodes):
    """(K, stiffness work, px, py): the work arrays of ``cell_matrix`` for cells of up to max_nodes
    nodes (2n + 1 for n vertices)."""
    nmax = (max_nodes - 1) // 2
    mmax = 4 * nmax + 2
    return np.empty((mmax, mmax)), stiffness_workspace(nmax), np.empty(nmax), np.empty(nmax)


@numba.njit(cache=True)
def cell_matrix(c, vertices, offsets, nodes, lam, mu, stab, work):
    """The local stiffness (3.9) of cell c in its node order (vertices, edges, the cell), in the
    leading (4n + 2) x (4n + 2) block of the returned work matrix."""
    K, stiffness_work, px, py = work
    start = offsets[c]
    n = (offsets[c + 1] - start - 1) // 2
    for i in range(n):
        px[i] = vertices[nodes[start + i], 0]
        py[i] = vertices[nodes[start + i], 1]
    # the work arrays are passed whole (C-contiguous, faster loops); the kernel uses their leading part
    element_stiffness_k2(px[:n], py[:n], lam, mu, stab, K, stiffness_work)
    return K
