"""Second-order (k = 2) virtual element for plane elasticity: one polygon at a time (Section 3, Fig. 1 right).

Local degrees of freedom of a polygon with n vertices (m = 4n + 2 scalars), node-interleaved:

- vertex i (0 <= i < n): the value v(x_i), scalars 2i, 2i + 1;
- edge i (from vertex i to i + 1): the moment int_e v ds for q in [P0(e)]^2 scaled as the edge MEAN
  (1/|e|) int_e v ds, scalars 2n + 2i, 2n + 2i + 1;
- the interior moment int_K v dx for q in [P0(K)]^2 scaled as the cell MEAN (1/|K|) int_K v dx,
  scalars 4n, 4n + 1.

Scaling the paper's moments as means gives every degree of freedom the units of a displacement (a
vertex value, an edge mean and a cell mean of a smooth field agree to O(h)), so the dofi-dofi form
S_K of (3.9) weighs them alike; the three scalings alpha_K of docs/reference/mathematics.md are then used unchanged.
The quadratic trace on edge e is v(t) = v_a L0(t) + v_mid Lh(t) + v_b L1(t) with the midpoint value
v_mid = (6 mean_e - v_a - v_b) / 4 (Simpson's rule is exact for quadratics).

Projection Pi_2 (3.8): a_K(Pi v - v, q) = 0 for q in [P2]^2, with
a_K(v, q) = int_dK v . sigma(q) n ds - int_K v . div sigma(q) dx; sigma(q) n is linear on each edge
(Simpson, using the vertex values and the edge mean, is exact) and div sigma(q) is constant (the
interior mean gives the volume term). The rigid part (kernel of (3.8)) is fixed by

    (1/|K|) int_K Pi v dx = (1/|K|) int_K v dx        (the interior moment: P_0 of v),
    int_K rot Pi v dx     = int_dK v . t ds            (the mean rotation, from the edge means).

For k >= 2 these are the natural replacements of the paper's vertex-mean constraints (written for
k = 1): both are exact functionals of v computable from its degrees of freedom, both are
invariant under relabelling of the vertices, and with the centroid as origin they decouple: the
translation comes from the interior mean, the rotation from the edge means alone.

The kernel works in the basis of [P2]^2 made of the rigid motions (1,0), (0,1), (-eta, xi) and nine
non-rigid fields (xi, 0), (0, eta), (eta, xi), (xi^2, 0), (xi eta, 0), (eta^2, 0), (0, xi^2),
(0, xi eta), (0, eta^2), with (xi, eta) = (x - x_K) / h, x_K the centroid and h the largest
centroid-vertex distance. The local stiffness (3.9) built on this projection is in
``vemkit.vem.elements.k2_stiffness``. The plain-numpy twin ``vemkit.vem.elements.k2_reference`` solves (3.8) and the
constraints literally as one saddle-point system; the tests pin the kernels against it.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from vemkit.vem.elements.k1_kernel import polygon_coordinates

N_BASIS = 12
# strain of the 9 non-rigid fields times h: STRAIN[b, (eps11, eps22, eps12), (1, xi, eta)]
STRAIN = np.zeros((9, 3, 3))
STRAIN[0, 0, 0] = 1.0  # (xi, 0)
STRAIN[1, 1, 0] = 1.0  # (0, eta)
STRAIN[2, 2, 0] = 1.0  # (eta, xi)
STRAIN[3, 0, 1] = 2.0  # (xi^2, 0)
STRAIN[4, 0, 2] = 1.0  # (xi eta, 0)
STRAIN[4, 2, 1] = 0.5
STRAIN[5, 2, 2] = 1.0  # (eta^2, 0)
STRAIN[6, 2, 1] = 1.0  # (0, xi^2)
STRAIN[7, 1, 1] = 1.0  # (0, xi eta)
STRAIN[7, 2, 2] = 0.5
STRAIN[8, 1, 2] = 2.0  # (0, eta^2)


@numba.njit(cache=True)
def cell_frame(px, py):
    """(area, xc, yc, h, M20, M11, M02): M_ab = int_K xi^a eta^b dx about the centroid (shoelace forms).

    The shoelace sums run in coordinates relative to the first vertex: in absolute coordinates a
    small cell far from the origin loses its centroid to cancellation, and the kernel relies on
    int_K xi = int_K eta = 0 about it.
    """
    n = px.shape[0]
    x0 = px[0]
    y0 = py[0]
    a2 = 0.0
    sx = 0.0
    sy = 0.0
    for i in range(n):
        j = (i + 1) % n
        cr = (px[i] - x0) * (py[j] - y0) - (px[j] - x0) * (py[i] - y0)
        a2 += cr
        sx += (px[i] + px[j] - 2.0 * x0) * cr
        sy += (py[i] + py[j] - 2.0 * y0) * cr
    area = 0.5 * a2
    xc = x0 + sx / (3.0 * a2)
    yc = y0 + sy / (3.0 * a2)
    h = 0.0
    for i in range(n):
        h = max(h, math.sqrt((px[i] - xc) ** 2 + (py[i] - yc) ** 2))
    m20 = 0.0
    m11 = 0.0
    m02 = 0.0
    for i in range(n):
        j = (i + 1) % n
        xi, yi = (px[i] - xc) / h, (py[i] - yc) / h
        xj, yj = (px[j] - xc) / h, (py[j] - yc) / h
        cr = xi * yj - xj * yi
        m20 += cr * (xi * xi + xi * xj + xj * xj)
        m02 += cr * (yi * yi + yi * yj + yj * yj)
        m11 += cr * (xi * yj + 2.0 * xi * yi + 2.0 * xj * yj + xj * yi)
    s = h * h
    return area, xc, yc, h, m20 * s / 12.0, m11 * s / 24.0, m02 * s / 12.0


@numba.njit(cache=True)
def stress_table(lam, mu, h, sig):
    """sig (9, 3, 3): sigma(q_b) = C eps(q_b) as (sigma11, sigma22, sigma12) x (1, xi, eta), docs/reference/mathematics.md."""
    for b in range(9):
        for t in range(3):
            e11 = STRAIN[b, 0, t] / h
            e22 = STRAIN[b, 1, t] / h
            e12 = STRAIN[b, 2, t] / h
            sig[b, 0, t] = lam * (e11 + e22) + 2.0 * mu * e11
            sig[b, 1, t] = lam * (e11 + e22) + 2.0 * mu * e22
            sig[b, 2, t] = 2.0 * mu * e12


@numba.njit(cache=True)
def energy_matrix(sig, h, area, m20, m11, m02, G):
    """G (9 x 9): a_K(q_a, q_b) = int_K sigma(q_a) : eps(q_b) dx, integrands linear x linear:
    int_K (f0 + f1 xi + f2 eta)(g0 + g1 xi + g2 eta) dx = f0 g0 |K| + f1 g1 M20 + (f1 g2 + f2 g1) M11 + f2 g2 M02."""
    for a in range(9):
        for b in range(a, 9):
            if a < 3 <= b:  # int_K const * (xi or eta) dx = 0 about the centroid
                G[a, b] = 0.0
                G[b, a] = 0.0
                continue
            acc = 0.0
            for c in range(3):
                g0, g1, g2 = STRAIN[b, c, 0], STRAIN[b, c, 1], STRAIN[b, c, 2]
                if g0 == 0.0 and g1 == 0.0 and g2 == 0.0:
                    continue
                f0, f1, f2 = sig[a, c, 0], sig[a, c, 1], sig[a, c, 2]
                w = 2.0 if c == 2 else 1.0
                acc += w * (f0 * g0 * area + f1 * g1 * m20 + (f1 * g2 + f2 * g1) * m11 + f2 * g2 * m02)
            G[a, b] = acc / h
            G[b, a] = acc / h


@numba.njit(cache=True)
def boundary_rhs(px, py, xc, yc, h, area, sig, rhs):
    """rhs (9 x m): a_K(phi_j, q_b) = int_dK phi_j . sigma(q_b) n ds - int_K phi_j . div sigma(q_b) dx.

    On edge (a, b), |e| sigma n = sigma (dy, -dx) is linear; Simpson with v_mid = (6 mean - v_a - v_b)/4
    gives the weights (T_a - T_b)/12 on v_a, (T_b - T_a)/12 on v_b and (T_a + T_b)/2 on the edge mean.
    """
    n = px.shape[0]
    for b in range(9):  # (loops, not a slice: no view to build in the per-cell path)
        for j in range(4 * n + 2):
            rhs[b, j] = 0.0
    for i in range(n):
        j = (i + 1) % n
        dx = px[j] - px[i]
        dy = py[j] - py[i]
        xa, ya = (px[i] - xc) / h, (py[i] - yc) / h
        xb, yb = (px[j] - xc) / h, (py[j] - yc) / h
        for b in range(9):
            s11a = sig[b, 0, 0] + sig[b, 0, 1] * xa + sig[b, 0, 2] * ya
            s22a = sig[b, 1, 0] + sig[b, 1, 1] * xa + sig[b, 1, 2] * ya
            s12a = sig[b, 2, 0] + sig[b, 2, 1] * xa + sig[b, 2, 2] * ya
            s11b = sig[b, 0, 0] + sig[b, 0, 1] * xb + sig[b, 0, 2] * yb
            s22b = sig[b, 1, 0] + sig[b, 1, 1] * xb + sig[b, 1, 2] * yb
            s12b = sig[b, 2, 0] + sig[b, 2, 1] * xb + sig[b, 2, 2] * yb
            ta1, ta2 = s11a * dy - s12a * dx, s12a * dy - s22a * dx
            tb1, tb2 = s11b * dy - s12b * dx, s12b * dy - s22b * dx
            rhs[b, 2 * i] += (ta1 - tb1) / 12.0
            rhs[b, 2 * i + 1] += (ta2 - tb2) / 12.0
            rhs[b, 2 * j] += (tb1 - ta1) / 12.0
            rhs[b, 2 * j + 1] += (tb2 - ta2) / 12.0
            rhs[b, 2 * n + 2 * i] += 0.5 * (ta1 + tb1)
            rhs[b, 2 * n + 2 * i + 1] += 0.5 * (ta2 + tb2)
    for b in range(9):  # div sigma(q_b) = d sigma / d(xi, eta) / h, constant
        rhs[b, 4 * n] -= area * (sig[b, 0, 1] + sig[b, 2, 2]) / h
        rhs[b, 4 * n + 1] -= area * (sig[b, 2, 1] + sig[b, 1, 2]) / h


@numba.njit(cache=True)
def cholesky_factor(G, lo, hi):
    """G[lo:hi, lo:hi] = L L^T in place for an SPD diagonal block of G: the lower triangle keeps L,
    its diagonal the reciprocals 1 / L_jj."""
    for j in range(lo, hi):
        s = G[j, j]
        for p in range(lo, j):
            s -= G[j, p] * G[j, p]
        G[j, j] = 1.0 / math.sqrt(s)
        for i in range(j + 1, hi):
            s = G[i, j]
            for p in range(lo, j):
                s -= G[i, p] * G[j, p]
            G[i, j] = s * G[j, j]


@numba.njit(cache=True)
def cholesky_solve(G, rhs, m, out, lo, hi):
    """out[lo:hi, :m] = G[lo:hi, lo:hi]^-1 rhs[lo:hi, :m] (G factored by ``cholesky_factor``). The
    substitutions run row by row over all m right-hand sides at once."""
    for i in range(lo, hi):
        for c in range(m):
            out[i, c] = rhs[i, c]
        for p in range(lo, i):
            g = G[i, p]
            for c in range(m):
                out[i, c] -= g * out[p, c]
        for c in range(m):
            out[i, c] *= G[i, i]
    for i in range(hi - 1, lo - 1, -1):
        for p in range(i + 1, hi):
            g = G[p, i]
            for c in range(m):
                out[i, c] -= g * out[p, c]
        for c in range(m):
            out[i, c] *= G[i, i]


@numba.njit(cache=True)
def largest_cell(offsets):
    """The most vertices of a cell in a k = 2 node list (n vertices, n edges, 1 cell node per cell)."""
    nmax = 0
    for c in range(offsets.shape[0] - 1):
        nmax = max(nmax, (offsets[c + 1] - offsets[c] - 1) // 2)
    return nmax


@numba.njit(cache=True)
def cell_vertex_coordinates(vertices, offsets, nodes, c):
    """(px, py) of the vertices of cell c from its k = 2 node list (the vertices come first)."""
    return polygon_coordinates(vertices, nodes, offsets[c], (offsets[c + 1] - offsets[c] - 1) // 2)


@numba.njit(cache=True)
def cell_projection(vertices, offsets, nodes, c, lam, mu, Pi, rhs, G, sig):
    """``projection_k2`` of cell c into the first 4n + 2 columns of the work arrays Pi, rhs;
    returns (number of nodes of the cell, area, xc, yc, h, m20, m11, m02)."""
    size = offsets[c + 1] - offsets[c]
    px, py = cell_vertex_coordinates(vertices, offsets, nodes, c)
    m = 2 * size
    area, xc, yc, h, m20, m11, m02 = projection_k2(px, py, lam, mu, Pi[:, :m], rhs[:, :m], G, sig)
    return size, area, xc, yc, h, m20, m11, m02


@numba.njit(cache=True)
def projection_workspace(nmax):
    """(Pi, rhs, G, sig) work arrays of ``projection_k2`` for cells of up to nmax vertices."""
    return np.empty((N_BASIS, 4 * nmax + 2)), np.empty((9, 4 * nmax + 2)), np.empty((9, 9)), np.empty((9, 3, 3))


@numba.njit(cache=True)
def projection_system(px, py, lam, mu, rhs, G, sig):
    """The system (3.8) of a polygon: G (9 x 9, factored by ``cholesky_factor``) and rhs (9 x m)
    (``energy_matrix``, ``boundary_rhs``); returns the frame (area, xc, yc, h, M20, M11, M02)."""
    area, xc, yc, h, m20, m11, m02 = cell_frame(px, py)
    stress_table(lam, mu, h, sig)
    energy_matrix(sig, h, area, m20, m11, m02, G)
    boundary_rhs(px, py, xc, yc, h, area, sig, rhs)
    # about the centroid the constant strains (fields 0-2) and the zero-mean linear strains of the
    # quadratic fields (3-8) are a_K-orthogonal: G is block diagonal, factored block by block
    cholesky_factor(G, 0, 3)
    cholesky_factor(G, 3, 9)
    return area, xc, yc, h, m20, m11, m02


@numba.njit(cache=True)
def projection_k2(px, py, lam, mu, Pi, rhs, G, sig):
    """Pi (12 x m): the coefficients of Pi_2 phi_j (3.8) in the kernel's basis; rhs (9 x m) keeps
    a_K(phi_j, q_b). Returns the frame (area, xc, yc, h, M20, M11, M02)."""
    n = px.shape[0]
    m = 4 * n + 2
    area, xc, yc, h, m20, m11, m02 = projection_system(px, py, lam, mu, rhs, G, sig)
    cholesky_solve(G, rhs, m, Pi[3:, :], 0, 3)
    cholesky_solve(G, rhs, m, Pi[3:, :], 3, 9)
    for j in range(m):
        Pi[0, j] = -(Pi[6, j] * m20 + Pi[7, j] * m11 + Pi[8, j] * m02) / area
        Pi[1, j] = -(Pi[9, j] * m20 + Pi[10, j] * m11 + Pi[11, j] * m02) / area
        Pi[2, j] = 0.0
    Pi[0, 4 * n] += 1.0  # interior mean of Pi v = interior mean of v
    Pi[1, 4 * n + 1] += 1.0
    for i in range(n):  # int_K rot Pi v = 2 |K| omega / h = sum_e (x_b - x_a) . mean_e v
        j = (i + 1) % n
        Pi[2, 2 * n + 2 * i] = h * (px[j] - px[i]) / (2.0 * area)
        Pi[2, 2 * n + 2 * i + 1] = h * (py[j] - py[i]) / (2.0 * area)
    return area, xc, yc, h, m20, m11, m02
