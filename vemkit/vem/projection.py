"""What follows from a projected displacement for every element: stress (docs/reference/mathematics.md) and the shear
energy density of the paper's Fig. 6. The projections Pi u_h themselves belong to the elements
(``VirtualElementSpace.project``)."""

from __future__ import annotations

import numpy as np

#: the strain and stress components of a 3D body, in the solution file's order (docs/reference/files.md)
COMPONENTS_3D = ("11", "22", "33", "12", "13", "23")
#: dimension -> the (i, j) of the strain and stress components, the d normal ones first (Voigt order)
VOIGT_PAIRS = {2: ((0, 0), (1, 1), (0, 1)), 3: ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))}
_DIMENSION_OF_COMPONENTS = {len(pairs): dimension for dimension, pairs in VOIGT_PAIRS.items()}


def strain_of(gradient: np.ndarray) -> np.ndarray:
    """(P, 3) eps11, eps22, eps12 of displacement gradients (P, 2, 2) [i, j] = d u_i / d x_j; in 3D
    (P, 3, 3) -> (P, 6) eps11, eps22, eps33, eps12, eps13, eps23 (``COMPONENTS_3D``)."""
    g = gradient
    return np.stack([0.5 * (g[:, i, j] + g[:, j, i]) for i, j in VOIGT_PAIRS[g.shape[1]]], axis=1)


def stress(strain: np.ndarray, lam: float, mu: float) -> np.ndarray:
    """sigma = C eps = lam tr(eps) I + 2 mu eps (docs/reference/mathematics.md): (M, 3) sigma11, sigma22, sigma12 from
    (eps11, eps22, eps12), or in 3D (M, 6) from (M, 6) in the order of ``COMPONENTS_3D``."""
    diagonal = _DIMENSION_OF_COMPONENTS[strain.shape[1]]  # the normal components come first
    tr = strain[:, :diagonal].sum(axis=1)
    sigma = 2 * mu * strain
    sigma[:, :diagonal] += lam * tr[:, None]
    return sigma


def von_mises(sig: np.ndarray) -> np.ndarray:
    """(M,) the von Mises stress sqrt(3/2 |dev sigma|^2) of 3D stresses (M, 6) (``COMPONENTS_3D``)."""
    s11, s22, s33, s12, s13, s23 = sig.T
    return np.sqrt(0.5 * ((s11 - s22) ** 2 + (s22 - s33) ** 2 + (s33 - s11) ** 2) + 3.0 * (s12**2 + s13**2 + s23**2))


def shear_energy_density(sig: np.ndarray, lam: float, mu: float, model: str = "plane_stress") -> np.ndarray:
    """|dev sigma|^2 / (4 mu). Plane stress: the formula printed under the paper's Fig. 6,

    |dev sigma|^2 = (mu^2 / (6 (mu + lam)^2) + 1/2) (s11 + s22)^2 + 2 (s12^2 - s11 s22),

    lam being the lambda* of the paper's C (docs/reference/mathematics.md). Plane strain: the deviator of the 3D stress with
    s33 = nu (s11 + s22), nu = lam / (2 (lam + mu)): |dev sigma|^2 = sum s_ii^2 + 2 s12^2 - (sum s_ii)^2 / 3.
    """
    s11, s22, s12 = sig[:, 0], sig[:, 1], sig[:, 2]
    if model == "plane_strain":
        s33 = lam / (2.0 * (lam + mu)) * (s11 + s22)
        trace = s11 + s22 + s33
        return (s11**2 + s22**2 + s33**2 + 2.0 * s12**2 - trace**2 / 3.0) / (4.0 * mu)
    dev2 = (mu**2 / (6.0 * (mu + lam) ** 2) + 0.5) * (s11 + s22) ** 2 + 2.0 * (s12**2 - s11 * s22)
    return dev2 / (4.0 * mu)
