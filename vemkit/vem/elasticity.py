"""The material law of the paper (SPEC §1) and the rigid-body motions it leaves free."""

from __future__ import annotations

import numpy as np


def lame_parameters(E: float, nu: float):
    """(lambda*, mu) of the paper's (plane stress) C: lambda* = E nu / (1 - nu^2), mu = E / (2 (1 + nu))."""
    return E * nu / (1.0 - nu * nu), E / (2.0 * (1.0 + nu))


def elasticity_matrix(lam: float, mu: float) -> np.ndarray:
    """Voigt matrix D of C (SPEC §1) for the strain vector (eps11, eps22, 2 eps12)."""
    return np.array([[lam + 2 * mu, lam, 0.0], [lam, lam + 2 * mu, 0.0], [0.0, 0.0, mu]])


def rigid_body_modes(coords: np.ndarray) -> np.ndarray:
    """(2N, 3) translations and the infinitesimal rotation at vertex coordinates (N, 2)."""
    n = coords.shape[0]
    B = np.zeros((2 * n, 3))
    B[0::2, 0] = 1.0
    B[1::2, 1] = 1.0
    c = coords - coords.mean(axis=0)
    B[0::2, 2] = -c[:, 1]
    B[1::2, 2] = c[:, 0]
    return B
