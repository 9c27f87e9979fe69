"""Lowest-order (k = 1) virtual element for 3D elasticity: one polyhedron at a time.

Degrees of freedom are the displacements at the cell's vertices, interleaved
``(u1(x_1), u2(x_1), u3(x_1), u1(x_2), ...)`` (dof = 3 i + component). As in 2D (Section 3, (3.8)),
the strain of the projection Pi v is the cell average of eps(v), computed from boundary values
(Gain, Talischi & Paulino 2014):

    |K| eps(Pi v) = int_dK sym(v (x) n) ds = sum_F sym((int_F v ds) (x) n_F).

The face integrals are those of the k = 1 face space in its enhanced form (Ahmad, Alsaedi, Brezzi,
Marini & Russo 2013): there int_F v ds = int_F Pi^F v ds by the definition of the space, Pi^F the
face's own k = 1 projection (the gradient from the face boundary, the vertex mean fixing the
constant). So the integral is exact -- not a quadrature -- for every function of the face space,
linear ones included, and it is a linear form of the vertex values with the weights

    w_i = |F| / m + 1/2 ((p_{i+1} - p_{i-1}) x n_F) . (x_F - xbar_F)

(m vertices, xbar_F their mean, x_F the area centroid): |F| times the vertex mean plus the gradient
of Pi^F phi_i, (1/2|F|) (|e_{i-1}| nu_{i-1} + |e_i| nu_i), dotted with x_F - xbar_F. On a triangle
x_F = xbar_F and w_i = |F| / 3 (P1, hence the equality with P1 finite elements on tetrahedra).

The rigid part of Pi v = c + (E + W)(x - xbar) (xbar the cell's vertex mean) is fixed by the
paper's two vertex constraints in 3D: the vertex mean of Pi v is that of v (c), and the vertex mean
of (x - xbar) x Pi v is that of (x - xbar) x v -- a 3 x 3 system M omega = mean(d x v) - mean(d x E d)
with the vertex inertia M = mean(|d|^2 I - d d^T) for the axial vector omega of W. Both hold for
every linear v, so Pi reproduces linear fields, rigid motions included.

The local form (3.9) is a_h^K = |K| B^T D B + alpha_K (I - Pi)^T (I - Pi) (dofi-dofi S_K). The
scalings are those of 2D times h_K^(d - 2) = h_K (the cell's diameter; half the height of a right
prism along z, ``k1_3d.stabilization_lengths``): alpha_K = h_K (dofi),
2 mu h_K (dofi-2mu), tr(|K| B^T D B) / 3n (trace, which scales by itself). The dofi-dofi form must
scale like a_K(phi_i, phi_i) ~ |K| / h_K^2 ~ h_K^(d - 2): in 2D that is 1 (the paper's alpha_K),
in 3D without the factor h_K the stabilization outgrows the consistency as h -> 0 and the
convergence is lost (measured on the manufactured solution of the tests: L2 rate 1.44 instead of 2). Strains in Voigt form (eps11, eps22, eps33, 2 eps12, 2 eps13, 2 eps23).
The numpy twin solving (3.8) literally is ``k1_3d_reference``.
"""

from __future__ import annotations

import numba
import numpy as np

from vemkit.vem.elements.k1_kernel import add_stabilization, stiffness_workspace


@numba.njit(cache=True)
def cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@numba.njit(cache=True)
def face_frame(p, ids, lo, hi):
    """(|F|, n_F, x_F - xbar_F, xbar_F) of the planar face with vertices p[ids[lo:hi]] (in order):
    the vector area and the centroid by the fan of signed triangles from the vertex mean (scalar
    arithmetic: no temporary arrays in the loops)."""
    m = hi - lo
    x0 = x1 = x2 = 0.0
    for t in range(lo, hi):
        x0 += p[ids[t], 0]
        x1 += p[ids[t], 1]
        x2 += p[ids[t], 2]
    x0, x1, x2 = x0 / m, x1 / m, x2 / m
    a0 = a1 = a2 = 0.0
    for t in range(lo, hi):
        i, j = ids[t], ids[lo + (t - lo + 1) % m]
        c0, c1, c2 = cross(p[i, 0] - x0, p[i, 1] - x1, p[i, 2] - x2, p[j, 0] - x0, p[j, 1] - x1, p[j, 2] - x2)
        a0 += 0.5 * c0
        a1 += 0.5 * c1
        a2 += 0.5 * c2
    area = np.sqrt(a0 * a0 + a1 * a1 + a2 * a2)
    n0, n1, n2 = a0 / area, a1 / area, a2 / area
    # fan triangle t: signed area s_t = (q x r) . n / 2, centroid offset (q + r) / 3
    s0 = s1 = s2 = 0.0
    for t in range(lo, hi):
        i, j = ids[t], ids[lo + (t - lo + 1) % m]
        q0, q1, q2 = p[i, 0] - x0, p[i, 1] - x1, p[i, 2] - x2
        r0, r1, r2 = p[j, 0] - x0, p[j, 1] - x1, p[j, 2] - x2
        c0, c1, c2 = cross(q0, q1, q2, r0, r1, r2)
        s = 0.5 * (c0 * n0 + c1 * n1 + c2 * n2)
        s0 += s * (q0 + r0) / 3.0
        s1 += s * (q1 + r1) / 3.0
        s2 += s * (q2 + r2) / 3.0
    return area, (n0, n1, n2), (s0 / area, s1 / area, s2 / area), (x0, x1, x2)


@numba.njit(cache=True)
def face_weights(p, ids, lo, hi, w):
    """w[0:m] the weights of int_F v ds = sum_i w_i v(p_i) of the enhanced k = 1 face space (module
    doc); returns the unit normal n_F (orientation of the vertex order), a tuple."""
    m = hi - lo
    area, n, shift, xb = face_frame(p, ids, lo, hi)
    for t in range(m):
        nxt = ids[lo + (t + 1) % m]
        prv = ids[lo + (t - 1 + m) % m]
        e0, e1, e2 = cross(p[nxt, 0] - p[prv, 0], p[nxt, 1] - p[prv, 1], p[nxt, 2] - p[prv, 2], n[0], n[1], n[2])
        w[t] = area / m + 0.5 * (e0 * shift[0] + e1 * shift[1] + e2 * shift[2])
    return n


@numba.njit(cache=True)
def boundary_vectors(p, face_ptr, face_local, f_lo, f_hi, q, w):
    """q (n, 3): q_i = sum_F w_{F,i} n_F = int_dK phi_i n ds; returns |K| = 1/3 int_dK x . n ds
    (about the vertex mean: x - xbar is linear, so the face weights integrate it exactly)."""
    n_v = p.shape[0]
    q[:n_v] = 0.0
    x0 = x1 = x2 = 0.0
    for i in range(n_v):
        x0 += p[i, 0]
        x1 += p[i, 1]
        x2 += p[i, 2]
    xb = (x0 / n_v, x1 / n_v, x2 / n_v)
    volume = 0.0
    for f in range(f_lo, f_hi):
        lo = face_ptr[f]
        hi = face_ptr[f + 1]
        n = face_weights(p, face_local, lo, hi, w)
        for t in range(hi - lo):
            i = face_local[lo + t]
            for k in range(3):
                q[i, k] += w[t] * n[k]
                volume += w[t] * n[k] * (p[i, k] - xb[k]) / 3.0
    return volume


@numba.njit(cache=True)
def strain_operator(q, volume, B):
    """B (6 x 3n): cell-average strain (eps11, eps22, eps33, 2 eps12, 2 eps13, 2 eps23) from the
    vertex values: |K| eps(Pi v) = sum_i sym(v_i (x) q_i)."""
    n = q.shape[0]
    B[:, : 3 * n] = 0.0
    for i in range(n):
        a = q[i, 0] / volume
        b = q[i, 1] / volume
        c = q[i, 2] / volume
        B[0, 3 * i] = a
        B[1, 3 * i + 1] = b
        B[2, 3 * i + 2] = c
        B[3, 3 * i] = b
        B[3, 3 * i + 1] = a
        B[4, 3 * i] = c
        B[4, 3 * i + 2] = a
        B[5, 3 * i + 1] = c
        B[5, 3 * i + 2] = b


@numba.njit(cache=True)
def inverse3(M):
    """The inverse of a 3 x 3 matrix (cofactors)."""
    inv = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            a, b = (j + 1) % 3, (j + 2) % 3
            c, d = (i + 1) % 3, (i + 2) % 3
            inv[i, j] = M[a, c] * M[b, d] - M[a, d] * M[b, c]
    det = M[0, 0] * inv[0, 0] + M[0, 1] * inv[1, 0] + M[0, 2] * inv[2, 0]
    return inv / det


@numba.njit(cache=True)
def vertex_moments(p):
    """(xbar, S, M^-1): the vertex mean, S = mean(d d^T), and the inverse of the vertex inertia
    M = mean(|d|^2) I - S (d = x_i - xbar) of the rotation constraint."""
    n = p.shape[0]
    xb = np.zeros(3)
    for i in range(n):
        xb += p[i]
    xb /= n
    S = np.zeros((3, 3))
    for i in range(n):
        for a in range(3):
            for b in range(3):
                S[a, b] += (p[i, a] - xb[a]) * (p[i, b] - xb[b]) / n
    M = -S.copy()
    tr = S[0, 0] + S[1, 1] + S[2, 2]
    for a in range(3):
        M[a, a] += tr
    return xb, S, inverse3(M)


@numba.njit(cache=True)
def projection_coefficients(p, B, P):
    """P (12 x 3n): Pi phi_j = c + E (x - xbar) + omega x (x - xbar) for every dof j. Rows: c (3),
    omega (3), E11, E22, E33, E12, E13, E23. Returns xbar (the constraints: module doc)."""
    n = p.shape[0]
    xb, S, Minv = vertex_moments(p)
    E = np.empty((3, 3))
    T = np.empty((3, 3))
    d = np.empty(3)
    e = np.zeros(3)
    g = np.empty(3)
    for j in range(3 * n):
        i, comp = j // 3, j % 3
        for r in range(3):
            P[r, j] = 1.0 / n if r == comp else 0.0
            P[6 + r, j] = B[r, j]
            P[9 + r, j] = 0.5 * B[3 + r, j]
        E[0, 0], E[1, 1], E[2, 2] = P[6, j], P[7, j], P[8, j]
        E[0, 1] = E[1, 0] = P[9, j]
        E[0, 2] = E[2, 0] = P[10, j]
        E[1, 2] = E[2, 1] = P[11, j]
        for a in range(3):  # T = E S: mean(d x E d)_a = eps_abc (E S)_cb
            for b in range(3):
                T[a, b] = E[a, 0] * S[0, b] + E[a, 1] * S[1, b] + E[a, 2] * S[2, b]
            d[a] = p[i, a] - xb[a]
            e[a] = 1.0 / n if a == comp else 0.0
        v0, v1, v2 = cross(d[0], d[1], d[2], e[0], e[1], e[2])  # mean(d x phi_j)
        g[0] = v0 - (T[2, 1] - T[1, 2])
        g[1] = v1 - (T[0, 2] - T[2, 0])
        g[2] = v2 - (T[1, 0] - T[0, 1])
        for r in range(3):
            P[3 + r, j] = Minv[r, 0] * g[0] + Minv[r, 1] * g[1] + Minv[r, 2] * g[2]
    return xb


@numba.njit(cache=True)
def residual_transpose(p, xb, P, R):
    """R (3n x 3n), row j: the vertex values of phi_j - Pi phi_j ((I - Pi)^T, contiguous rows)."""
    n = p.shape[0]
    for j in range(3 * n):
        for k in range(n):
            d0, d1, d2 = p[k, 0] - xb[0], p[k, 1] - xb[1], p[k, 2] - xb[2]
            w0, w1, w2 = cross(P[3, j], P[4, j], P[5, j], d0, d1, d2)
            R[j, 3 * k] = -(P[0, j] + P[6, j] * d0 + P[9, j] * d1 + P[10, j] * d2 + w0)
            R[j, 3 * k + 1] = -(P[1, j] + P[9, j] * d0 + P[7, j] * d1 + P[11, j] * d2 + w1)
            R[j, 3 * k + 2] = -(P[2, j] + P[10, j] * d0 + P[11, j] * d1 + P[8, j] * d2 + w2)
        R[j, j] += 1.0


@numba.njit(cache=True)
def consistency(B, volume, lam, mu, K):
    """K = |K| B^T D B (the isotropic D: lam 1 1^T + 2 mu on the normal strains, mu on the
    engineering shears); returns its trace."""
    m = B.shape[1]
    tr = 0.0
    for i in range(m):
        s = lam * (B[0, i] + B[1, i] + B[2, i])
        t0 = volume * (s + 2.0 * mu * B[0, i])
        t1 = volume * (s + 2.0 * mu * B[1, i])
        t2 = volume * (s + 2.0 * mu * B[2, i])
        t3 = volume * mu * B[3, i]
        t4 = volume * mu * B[4, i]
        t5 = volume * mu * B[5, i]
        for j in range(m):
            K[i, j] = t0 * B[0, j] + t1 * B[1, j] + t2 * B[2, j] + t3 * B[3, j] + t4 * B[4, j] + t5 * B[5, j]
        tr += K[i, i]
    return tr


@numba.njit(cache=True)
def diameter(p):
    """h_K: the largest distance between two vertices."""
    h2 = 0.0
    for i in range(p.shape[0]):
        for j in range(i + 1, p.shape[0]):
            h2 = max(h2, (p[i, 0] - p[j, 0]) ** 2 + (p[i, 1] - p[j, 1]) ** 2 + (p[i, 2] - p[j, 2]) ** 2)
    return np.sqrt(h2)


@numba.njit(cache=True)
def element_stiffness(p, face_ptr, face_local, f_lo, f_hi, lam, mu, stab, length, K, B, P, R, q, w):
    """Local stiffness (3.9) of the polyhedron with vertices p (n, 3) and outward faces
    face_local[face_ptr[f]:face_ptr[f + 1]] (local vertex numbers), f_lo <= f < f_hi, into K (3n x 3n).
    stab: 0 dofi (alpha = h_K), 1 dofi-2mu (alpha = 2 mu h_K), 2 trace (alpha = tr(Kc) / 3n), h_K =
    ``length`` (``k1_3d.stabilization_lengths``: the diameter, half the height of a right prism along
    z); a negative ``length``: the diameter of p. Returns |K|."""
    m = 3 * p.shape[0]
    volume = boundary_vectors(p, face_ptr, face_local, f_lo, f_hi, q, w)
    strain_operator(q, volume, B)
    xb = projection_coefficients(p, B, P)
    tr = consistency(B, volume, lam, mu, K)
    h = length if length >= 0.0 else diameter(p)
    alpha = h if stab == 0 else (2.0 * mu * h if stab == 1 else tr / m)
    residual_transpose(p, xb, P, R)
    add_stabilization(R, alpha, K)
    return volume


# --------------------------------------------------------------------------------------------
# the element's hooks for the one assembly of ``vemkit.vem.assembly``; ``geometry`` is the tuple of
# ``FirstOrder3D.geometry``: (vertices, cell_face_ptr, face_ptr, face_local, stabilization lengths)
# --------------------------------------------------------------------------------------------
@numba.njit(cache=True)
def workspace(max_nodes):
    """(K, B, P, R, p, q, w): the work arrays of ``cell_matrix`` for cells of up to max_nodes vertices."""
    return stiffness_workspace(3, max_nodes) + (np.empty((max_nodes, 3)), np.empty((max_nodes, 3)), np.empty(max_nodes))


@numba.njit(cache=True)
def cell_matrix(c, geometry, offsets, nodes, lam, mu, stab, work):
    """The local stiffness (3.9) of cell c in its vertex order, in the leading 3n x 3n block of the
    returned work matrix."""
    vertices, cell_face_ptr, face_ptr, face_local, lengths = geometry
    K, B, P, R, p, q, w = work
    start = offsets[c]
    n = offsets[c + 1] - start
    for i in range(n):
        for k in range(3):
            p[i, k] = vertices[nodes[start + i], k]
    m = 3 * n
    element_stiffness(
        p[:n],
        face_ptr,
        face_local,
        cell_face_ptr[c],
        cell_face_ptr[c + 1],
        lam,
        mu,
        stab,
        lengths[c],
        K[:m, :m],
        B[:, :m],
        P[:, :m],
        R[:m, :m],
        q[:n],
        w,
    )
    return K
