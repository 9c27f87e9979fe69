"""The material law (SPEC §1, §10: ``vemkit.config.material``) and the rigid-body motions it leaves free."""

from __future__ import annotations

import numpy as np

from vemkit.config.material import lame_parameters  # noqa: F401  (the formulas' one home; re-exported)


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
