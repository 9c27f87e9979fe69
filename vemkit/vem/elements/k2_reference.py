"""Plain-numpy twin of the k = 2 element (``vemkit.vem.elements.k2_kernel``): the projection (3.8) solved literally.

Independent of the kernel on purpose: scaled monomials about the vertex mean with h = diam(K),
integrals over K by a degree-5 rule on the signed triangles (vertex mean, x_i, x_{i+1}) (exact for
polynomials on any simple polygon, convex or not), edge integrals of the quadratic traces by
3-point Gauss-Legendre, and (3.8) with the rigid-motion constraints solved as one saddle-point
system [[G, C^T], [C, 0]] with the full 12 x 12 Gram matrix G (rank 9) and the three constraints

    (1/|K|) int_K Pi v dx = interior mean of v,    int_K rot Pi v dx = sum_e |e| t_e . mean_e v.

The degrees of freedom are ordered as in the kernel: vertex values, edge means, the cell mean,
each a pair (x, y) of scalars.
"""

from __future__ import annotations

import numpy as np

from vemkit.vem.quadrature import TRIANGLE_RULE

EXPONENTS = [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)]


def _fields(points, center, h):
    """Values (P, 12, 2), gradients (P, 12, 2, 2) and div sigma-ready Hessians (12, 2, 2) of the basis
    m_s e_c (s over EXPONENTS, c over components; field index 2 s + c)."""
    xi = (points[:, 0] - center[0]) / h
    eta = (points[:, 1] - center[1]) / h
    values = np.zeros((len(points), 12, 2))
    grads = np.zeros((len(points), 12, 2, 2))
    hess = np.zeros((12, 2, 2))
    for s, (a, b) in enumerate(EXPONENTS):
        mono = xi**a * eta**b
        dx = a * xi ** max(a - 1, 0) * eta**b / h
        dy = b * xi**a * eta ** max(b - 1, 0) / h
        H = np.array([[a * (a - 1), a * b], [a * b, b * (b - 1)]], float) / h**2 if a + b == 2 else np.zeros((2, 2))
        for c in range(2):
            values[:, 2 * s + c, c] = mono
            grads[:, 2 * s + c, c, 0] = dx
            grads[:, 2 * s + c, c, 1] = dy
            hess[2 * s + c] = H  # Hessian of the single nonzero component c
    return values, grads, hess


def _cell_quadrature(coords):
    """Points (P, 2) and signed weights (P,) exact to degree 5 on the polygon."""
    x0 = coords.mean(axis=0)
    pts, wts = [], []
    for i in range(len(coords)):
        a, b = coords[i], coords[(i + 1) % len(coords)]
        area = 0.5 * ((a[0] - x0[0]) * (b[1] - x0[1]) - (b[0] - x0[0]) * (a[1] - x0[1]))
        pts.append(TRIANGLE_RULE[:, :3] @ np.array([x0, a, b]))
        wts.append(TRIANGLE_RULE[:, 3] * area)
    return np.concatenate(pts), np.concatenate(wts)


def _edge_trace_basis(t):
    """The quadratic trace from (v_a, v_b, mean_e): weights (P, 3) at the edge parameters t in [0, 1]."""
    L0, Lh, L1 = 2 * (t - 0.5) * (t - 1), 4 * t * (1 - t), 2 * t * (t - 0.5)
    return np.stack([L0 - Lh / 4, L1 - Lh / 4, 1.5 * Lh], axis=1)


def _div_stress(hess, lam, mu):
    """(12, 2): div sigma(q) = (lam + mu) grad div q + mu Laplacian q, constant for q in [P2]^2."""
    out = np.zeros((12, 2))
    for f in range(12):
        c = f % 2
        out[f] = (lam + mu) * hess[f][c] + mu * np.trace(hess[f]) * np.eye(2)[c]
    return out


def element_stiffness_k2_reference(coords, lam, mu, stabilization="dofi-2mu"):
    """(K, Pi_D, coef): the local stiffness (3.9), the dofs of Pi phi_j (m x m), and the coefficients
    (12 x m) of Pi phi_j in the monomial basis about the vertex mean with h = diam(K)."""
    coords = np.asarray(coords, float)
    n = len(coords)
    m = 4 * n + 2
    center = coords.mean(axis=0)
    h = max(np.linalg.norm(p - q) for p in coords for q in coords)
    qp, qw = _cell_quadrature(coords)
    area = qw.sum()
    values, grads, hess = _fields(qp, center, h)
    eps = 0.5 * (grads + np.swapaxes(grads, 2, 3))
    sig = lam * np.einsum("pfii->pf", eps)[:, :, None, None] * np.eye(2) + 2 * mu * eps
    G = np.einsum("p,pfij,pgij->fg", qw, sig, eps)
    mean = np.einsum("p,pfc->fc", qw, values) / area  # (12, 2)
    rot = np.einsum("p,pf->f", qw, grads[:, :, 1, 0] - grads[:, :, 0, 1])
    rhs = np.zeros((12, m))
    tails = np.zeros((3, m))
    gt, gw = np.polynomial.legendre.leggauss(3)
    gt, gw = 0.5 * (gt + 1), 0.5 * gw
    trace_basis = _edge_trace_basis(gt)
    for i in range(n):
        a, b = coords[i], coords[(i + 1) % n]
        d = b - a
        pts = a + gt[:, None] * d
        _, gq, _ = _fields(pts, center, h)
        eq = 0.5 * (gq + np.swapaxes(gq, 2, 3))
        sq = lam * np.einsum("pfii->pf", eq)[:, :, None, None] * np.eye(2) + 2 * mu * eq
        traction = sq @ np.array([d[1], -d[0]])  # (P, 12, 2): |e| sigma(q) n
        for local, dof in enumerate((2 * i, 2 * ((i + 1) % n), 2 * n + 2 * i)):
            rhs[:, dof : dof + 2] += np.einsum("p,p,pfc->fc", gw, trace_basis[:, local], traction)
        tails[2, 2 * n + 2 * i : 2 * n + 2 * i + 2] = d  # int_e v . t ds = d . mean_e v
    rhs[:, 4 * n : 4 * n + 2] -= area * _div_stress(hess, lam, mu)
    tails[0, 4 * n] = 1.0
    tails[1, 4 * n + 1] = 1.0
    C = np.vstack([mean[:, 0], mean[:, 1], rot])
    saddle = np.block([[G, C.T], [C, np.zeros((3, 3))]])
    coef = np.linalg.solve(saddle, np.vstack([rhs, tails]))[:12]
    D = basis_dofs(coords, center, h, qp, qw)
    Pi_D = D @ coef
    K_consistency = coef.T @ G @ coef
    alpha = {"dofi": 1.0, "dofi-2mu": 2 * mu, "trace": np.trace(K_consistency) / m}[stabilization]
    R = np.eye(m) - Pi_D
    return K_consistency + alpha * R.T @ R, Pi_D, coef


def basis_dofs(coords, center, h, qp, qw):
    """(m, 12): the degrees of freedom of the 12 monomial fields."""
    return np.stack(
        [
            field_dofs(
                coords,
                lambda x, y, f=f: _fields(np.stack([x, y], -1).reshape(-1, 2), center, h)[0][:, f].reshape(
                    np.shape(x) + (2,)
                ),
                qp,
                qw,
            )
            for f in range(12)
        ],
        axis=1,
    )


def field_dofs(coords, field, qp=None, qw=None):
    """(m,) degrees of freedom of a vector field (x, y) -> (..., 2): vertex values, edge means
    (5-point Gauss-Legendre), cell mean (degree-5 rule on the signed triangles)."""
    coords = np.asarray(coords, float)
    n = len(coords)
    if qp is None:
        qp, qw = _cell_quadrature(coords)
    out = np.zeros(4 * n + 2)
    out[: 2 * n] = np.asarray(field(coords[:, 0], coords[:, 1])).reshape(n, 2).ravel()
    gt, gw = np.polynomial.legendre.leggauss(5)
    gt, gw = 0.5 * (gt + 1), 0.5 * gw
    for i in range(n):
        a, b = coords[i], coords[(i + 1) % n]
        pts = a + gt[:, None] * (b - a)
        out[2 * n + 2 * i : 2 * n + 2 * i + 2] = gw @ np.asarray(field(pts[:, 0], pts[:, 1])).reshape(-1, 2)
    out[4 * n :] = qw @ np.asarray(field(qp[:, 0], qp[:, 1])).reshape(-1, 2) / qw.sum()
    return out
