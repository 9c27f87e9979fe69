"""Plain-numpy twin of the k = 1 element (``k1_kernel``): the projection (3.8) solved literally, with
boundary integrals and the paper's two vertex constraints as a 6 x 6 system. The tests pin the
Numba kernel against it."""

from __future__ import annotations

import numpy as np

from vemkit.mesh.geometry import polygon_areas


def _p1_basis(xb, yb):
    """[P1]^2 basis: two translations, a rotation, three strain modes; each as (A, c): q(x) = A x + c."""
    mats = [
        np.zeros((2, 2)),
        np.zeros((2, 2)),
        np.array([[0.0, -1.0], [1.0, 0.0]]),
        np.array([[1.0, 0.0], [0.0, 0.0]]),
        np.array([[0.0, 0.0], [0.0, 1.0]]),
        np.array([[0.0, 1.0], [1.0, 0.0]]),
    ]
    consts = [np.array([1.0, 0.0]), np.array([0.0, 1.0])] + [-(A @ [xb, yb]) for A in mats[2:]]
    return mats, consts


def element_stiffness_reference(coords, lam, mu, stabilization="dofi-2mu"):
    """Local stiffness by solving (3.8) with the paper's constraints; returns (K, Pi_D)."""
    coords = np.asarray(coords, float)
    n = coords.shape[0]
    x, y = coords[:, 0], coords[:, 1]
    area = float(polygon_areas(coords, [0, n])[0])
    xb, yb = coords.mean(axis=0)
    mats, consts = _p1_basis(xb, yb)
    C = lambda e: lam * np.trace(e) * np.eye(2) + 2 * mu * e  # noqa: E731  (docs/reference/mathematics.md)
    sym = lambda A: 0.5 * (A + A.T)  # noqa: E731
    stress = [C(sym(A)) for A in mats]
    # a_K(phi_j, q) = int_dK (C eps(q) n) . phi_j ds, phi_j linear on each edge (trapezoid exact)
    rhs_strain = np.zeros((3, 2 * n))
    for e in range(n):
        a, b = e, (e + 1) % n
        t = coords[b] - coords[a]
        normal_len = np.array([t[1], -t[0]])  # |e| * outward normal (CCW polygon)
        for beta in range(3):
            traction = stress[3 + beta] @ normal_len
            for v in (a, b):
                rhs_strain[beta, 2 * v : 2 * v + 2] += 0.5 * traction
    G = np.array([[area * np.tensordot(sym(mats[a]), stress[b]) for b in range(6)] for a in range(6)])

    # constraint rows: vertex means of the two components, vertex mean of x x q
    def vertex_values(alpha):
        return coords @ mats[alpha].T + consts[alpha]

    system = np.zeros((6, 6))
    rhs = np.zeros((6, 2 * n))
    for alpha in range(6):
        vals = vertex_values(alpha)
        system[0, alpha] = vals[:, 0].mean()
        system[1, alpha] = vals[:, 1].mean()
        system[2, alpha] = np.mean(x * vals[:, 1] - y * vals[:, 0])
        system[3:, alpha] = G[3:, alpha]
    for i in range(n):
        rhs[0, 2 * i] = 1.0 / n
        rhs[1, 2 * i + 1] = 1.0 / n
        rhs[2, 2 * i] = -y[i] / n
        rhs[2, 2 * i + 1] = x[i] / n
    rhs[3:] = rhs_strain
    coef = np.linalg.solve(system, rhs)  # (6, 2n): Pi phi_j in the basis
    D = np.zeros((2 * n, 6))
    for alpha in range(6):
        D[:, alpha] = vertex_values(alpha).ravel()
    Pi = D @ coef
    K_consistency = coef.T @ G @ coef
    alpha_K = {"dofi": 1.0, "dofi-2mu": 2 * mu, "trace": np.trace(K_consistency) / (2 * n)}[stabilization]
    R = np.eye(2 * n) - Pi
    return K_consistency + alpha_K * R.T @ R, Pi
