"""The material law (docs/reference/mathematics.md and docs/reference/files.md: ``vemkit.config.material``) and the rigid-body motions it leaves free."""

from __future__ import annotations

import numpy as np

from vemkit.config.material import lame_parameters  # noqa: F401  (the formulas' one home; re-exported)


def elasticity_matrix(lam: float, mu: float) -> np.ndarray:
    """Voigt matrix D of C (docs/reference/mathematics.md) for the strain vector (eps11, eps22, 2 eps12)."""
    return np.array([[lam + 2 * mu, lam, 0.0], [lam, lam + 2 * mu, 0.0], [0.0, 0.0, mu]])


def elasticity_matrix_3d(lam: float, mu: float) -> np.ndarray:
    """Voigt matrix D of the isotropic 3D C for (eps11, eps22, eps33, 2 eps12, 2 eps13, 2 eps23)."""
    D = np.zeros((6, 6))
    D[:3, :3] = lam
    D[np.arange(3), np.arange(3)] += 2 * mu
    D[np.arange(3, 6), np.arange(3, 6)] = mu
    return D


def rigid_body_modes(coords: np.ndarray) -> np.ndarray:
    """The rigid-body motions at node coordinates (N, d): (2N, 3) for d = 2, two translations and
    the infinitesimal rotation; (3N, 6) for d = 3, three translations and three rotations
    omega_k x (x - xbar) (dof = d node + component)."""
    coords = np.asarray(coords, dtype=float)
    if coords.shape[1] == 3:
        return _rigid_body_modes_3d(coords)
    n = coords.shape[0]
    B = np.zeros((2 * n, 3))
    B[0::2, 0] = 1.0
    B[1::2, 1] = 1.0
    c = coords - coords.mean(axis=0)
    B[0::2, 2] = -c[:, 1]
    B[1::2, 2] = c[:, 0]
    return B


def _rigid_body_modes_3d(coords: np.ndarray) -> np.ndarray:
    n = coords.shape[0]
    B = np.zeros((3 * n, 6))
    d = coords - coords.mean(axis=0)
    for k in range(3):
        B[k::3, k] = 1.0
        B[:, 3 + k] = np.cross(np.eye(3)[k], d).ravel()
    return B
