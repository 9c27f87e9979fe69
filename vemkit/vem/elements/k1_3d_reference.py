"""Plain-numpy twin of the 3D k = 1 element (``k1_3d_kernel``): the projection (3.8) solved literally
as a 12 x 12 system (six rows a_K(Pi v - v, q) = 0 for the strain modes q, with
a_K(v, q) = int_dK (C eps(q) n) . v ds; the paper's vertex constraints for the translations and
rotations), every face integral int_F v ds taken as int_F Pi^F v ds of the face's own k = 1
projection, built in the face's plane. The tests pin the Numba kernel against it."""

from __future__ import annotations

import numpy as np

_SKEW = [
    np.array([[0, 0, 0], [0, 0, -1], [0, 1, 0]]),
    np.array([[0, 0, 1], [0, 0, 0], [-1, 0, 0]]),
    np.array([[0, -1, 0], [1, 0, 0], [0, 0, 0]]),
]  # omega_k x d as a matrix
_STRAIN = []
for a, b in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)):
    e = np.zeros((3, 3))
    e[a, b] = e[b, a] = 1.0
    _STRAIN.append(e)


def face_integral_weights(p):
    """(m,) weights of int_F Pi^F v ds from the vertex values, p (m, 3) a planar face: Pi^F v = the
    vertex mean + grad (x - xbar), grad = (1/|F|) int_dF v nu ds (trapezoid, exact: v is linear on edges)."""
    m = p.shape[0]
    xb = p.mean(axis=0)
    area_vector = 0.5 * sum(np.cross(p[i] - xb, p[(i + 1) % m] - xb) for i in range(m))
    area = np.linalg.norm(area_vector)
    normal = area_vector / area
    t1 = (p[1] - p[0]) / np.linalg.norm(p[1] - p[0])
    t2 = np.cross(normal, t1)
    xy = np.stack([(p - xb) @ t1, (p - xb) @ t2], axis=1)  # face coordinates, counter-clockwise
    tri = [(xy[i], xy[(i + 1) % m]) for i in range(m)]
    signed = np.array([0.5 * (a[0] * b[1] - a[1] * b[0]) for a, b in tri])
    centroid = sum(s * (a + b) / 3.0 for s, (a, b) in zip(signed, tri)) / signed.sum()
    grad = np.zeros((m, 2))  # gradient of Pi^F phi_i
    for i in range(m):
        j = (i + 1) % m
        e = xy[j] - xy[i]
        nu_len = np.array([e[1], -e[0]])  # |e| times the outward normal in the plane
        grad[i] += 0.5 * nu_len / area
        grad[j] += 0.5 * nu_len / area
    return area / m + area * grad @ centroid, normal


def element_stiffness_reference(coords, faces, lam, mu, stabilization="dofi-2mu"):
    """(K, Pi_D) of the polyhedron with vertices ``coords`` (n, 3) and outward ``faces`` (lists of
    local vertex numbers)."""
    coords = np.asarray(coords, float)
    n = coords.shape[0]
    xb = coords.mean(axis=0)
    d = coords - xb
    # boundary integrals int_dK phi_i n ds, per vertex
    flux = np.zeros((n, 3))
    for face in faces:
        w, normal = face_integral_weights(coords[list(face)])
        flux[list(face)] += w[:, None] * normal
    volume = np.einsum("ik,ik->", flux, d) / 3.0
    mats = [np.zeros((3, 3))] * 3 + _SKEW + _STRAIN
    consts = [np.eye(3)[k] for k in range(3)] + [np.zeros(3)] * 9  # q(x) = A (x - xbar) + c
    C = lambda e: lam * np.trace(e) * np.eye(3) + 2 * mu * e  # noqa: E731
    sym = lambda A: 0.5 * (A + A.T)  # noqa: E731
    G = np.array([[volume * np.tensordot(sym(A), C(sym(Bm))) for Bm in mats] for A in mats])
    values = [d @ A.T + c for A, c in zip(mats, consts)]  # (n, 3) vertex values of each q
    system = np.zeros((12, 12))
    rhs = np.zeros((12, 3 * n))
    for alpha, vals in enumerate(values):
        system[0:3, alpha] = vals.mean(axis=0)
        system[3:6, alpha] = np.cross(d, vals).mean(axis=0)
        system[6:, alpha] = G[6:, alpha]
    for i in range(n):
        for k in range(3):
            e = np.eye(3)[k]
            rhs[k, 3 * i + k] = 1.0 / n
            rhs[3:6, 3 * i + k] = np.cross(d[i], e) / n
            for beta in range(6):  # a_K(q_beta, phi) = int_dK (C eps(q_beta) n) . phi ds
                rhs[6 + beta, 3 * i + k] = (C(_STRAIN[beta]) @ flux[i])[k]
    coef = np.linalg.solve(system, rhs)
    D = np.stack([v.ravel() for v in values], axis=1)
    Pi = D @ coef
    Kc = coef.T @ G @ coef
    h = max(np.linalg.norm(a - b) for a in coords for b in coords)  # h_K^(d - 2), d = 3 (``k1_3d_kernel``)
    alpha_K = {"dofi": h, "dofi-2mu": 2 * mu * h, "trace": np.trace(Kc) / (3 * n)}[stabilization]
    R = np.eye(3 * n) - Pi
    return Kc + alpha_K * R.T @ R, Pi
