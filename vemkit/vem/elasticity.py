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


def _rotations_2d(offsets: np.ndarray) -> np.ndarray:
    """(2N, 1) the infinitesimal rotation (-y, x) about the centroid (``offsets`` (N, 2) from it)."""
    rotation = np.empty_like(offsets)
    rotation[:, 0] = -offsets[:, 1]
    rotation[:, 1] = offsets[:, 0]
    return rotation.reshape(-1, 1)


def _rotations_3d(offsets: np.ndarray) -> np.ndarray:
    """(3N, 3) the rotations omega_k x (x - xbar) about the three axes (``offsets`` (N, 3) = x - xbar)."""
    return np.stack([np.cross(np.eye(3)[k], offsets).ravel() for k in range(3)], axis=1)


#: dimension -> the infinitesimal rotations of a body, node-major (dof = d node + component)
ROTATIONS = {2: _rotations_2d, 3: _rotations_3d}


def rigid_body_modes(coords: np.ndarray) -> np.ndarray:
    """The rigid-body motions at node coordinates (N, d): the d translations, then the rotations
    (``ROTATIONS``): (2N, 3) for d = 2, (3N, 6) for d = 3 (dof = d node + component)."""
    coords = np.asarray(coords, dtype=float)
    n, dimension = coords.shape
    rotations = ROTATIONS[dimension](coords - coords.mean(axis=0))
    modes = np.zeros((dimension * n, dimension + rotations.shape[1]))
    for k in range(dimension):
        modes[k::dimension, k] = 1.0
    modes[:, dimension:] = rotations
    return modes
