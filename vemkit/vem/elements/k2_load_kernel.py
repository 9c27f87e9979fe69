"""The k = 2 body-force load's point sums (``k2_fields.body_force_p1_k2``), one pass over the points each.

The P_1 load needs, per cell, sums over the points of a degree-5 rule on a triangulation of the
cells: the mass matrix of the monomials (1, xi, eta) and their moments against f1 (for P_1 f1), then
the moments of the kernel's 12 basis fields against the weighted P_1 f1 - P_0 f1. Written in numpy
(``k2_fields.cell_sums``, ``k2_fields.basis_moments``, the plain-numpy twin kept for the tests) these
are 27 bincounts over (P, ...) temporaries; here they are two loops over the points. Every product
and every sum is the numpy one in the numpy order (a point's terms as numpy forms them, the points
of a cell added in increasing order, as ``np.bincount`` does), so the two agree bit for bit (the
tests pin it).
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def scaled_points_and_p1_sums(points, weights, cells, frame, f, xi, eta, mass, moments):
    """xi, eta (P,) = (point - x_K) / h_K; mass (M, 3, 3) += w m_a m_b and moments (M, 3, 2) += w m_a f
    summed over each cell's points, m = (1, xi, eta) (``mass``, ``moments`` zero on entry)."""
    m = np.empty(3)
    m[0] = 1.0
    for p in range(points.shape[0]):
        c = cells[p]
        x = (points[p, 0] - frame[c, 0]) / frame[c, 2]
        y = (points[p, 1] - frame[c, 1]) / frame[c, 2]
        xi[p], eta[p] = x, y
        m[1], m[2] = x, y
        w = weights[p]
        for a in range(3):
            wm = w * m[a]
            for b in range(3):
                mass[c, a, b] += wm * m[b]
            moments[c, a, 0] += wm * f[p, 0]
            moments[c, a, 1] += wm * f[p, 1]


@numba.njit(cache=True)
def p1_basis_moments(xi, eta, weights, cells, p1, out):
    """out (M, 12) += sum over each cell's points of q_b(xi, eta) . w g, g = P_1 f1 - P_0 f1 =
    xi p1[c, 1] + eta p1[c, 2], for the 12 basis fields of ``k2_fields._basis_components`` (``out``
    zero on entry)."""
    for p in range(xi.shape[0]):
        c = cells[p]
        x, y, w = xi[p], eta[p], weights[p]
        g0 = w * (x * p1[c, 1, 0] + y * p1[c, 2, 0])
        g1 = w * (x * p1[c, 1, 1] + y * p1[c, 2, 1])
        xx, xy, yy = x * x, x * y, y * y
        out[c, 0] += g0
        out[c, 1] += g1
        out[c, 2] += (-y) * g0 + x * g1
        out[c, 3] += x * g0
        out[c, 4] += y * g1
        out[c, 5] += y * g0 + x * g1
        out[c, 6] += xx * g0
        out[c, 7] += xy * g0
        out[c, 8] += yy * g0
        out[c, 9] += xx * g1
        out[c, 10] += xy * g1
        out[c, 11] += yy * g1
