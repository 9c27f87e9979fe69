"""What follows from a projected displacement for every element: stress (SPEC §1) and the shear
energy density of the paper's Fig. 6. The projections Pi u_h themselves belong to the elements
(``VirtualElementSpace.project``)."""

from __future__ import annotations

import numpy as np


def strain_of(gradient: np.ndarray) -> np.ndarray:
    """(P, 3) eps11, eps22, eps12 of displacement gradients (P, 2, 2) [i, j] = d u_i / d x_j."""
    g = gradient
    return np.stack([g[:, 0, 0], g[:, 1, 1], 0.5 * (g[:, 0, 1] + g[:, 1, 0])], axis=1)


def stress(strain: np.ndarray, lam: float, mu: float) -> np.ndarray:
    """(M, 3) sigma11, sigma22, sigma12 = C eps (SPEC §1) from (eps11, eps22, eps12)."""
    tr = strain[:, 0] + strain[:, 1]
    return np.stack([lam * tr + 2 * mu * strain[:, 0], lam * tr + 2 * mu * strain[:, 1], 2 * mu * strain[:, 2]], axis=1)


def shear_energy_density(sig: np.ndarray, lam: float, mu: float, model: str = "plane_stress") -> np.ndarray:
    """|dev sigma|^2 / (4 mu). Plane stress: the formula printed under the paper's Fig. 6,

    |dev sigma|^2 = (mu^2 / (6 (mu + lam)^2) + 1/2) (s11 + s22)^2 + 2 (s12^2 - s11 s22),

    lam being the lambda* of the paper's C (SPEC §1). Plane strain: the deviator of the 3D stress with
    s33 = nu (s11 + s22), nu = lam / (2 (lam + mu)): |dev sigma|^2 = sum s_ii^2 + 2 s12^2 - (sum s_ii)^2 / 3.
    """
    s11, s22, s12 = sig[:, 0], sig[:, 1], sig[:, 2]
    if model == "plane_strain":
        s33 = lam / (2.0 * (lam + mu)) * (s11 + s22)
        trace = s11 + s22 + s33
        return (s11**2 + s22**2 + s33**2 + 2.0 * s12**2 - trace**2 / 3.0) / (4.0 * mu)
    dev2 = (mu**2 / (6.0 * (mu + lam) ** 2) + 0.5) * (s11 + s22) ** 2 + 2.0 * (s12**2 - s11 * s22)
    return dev2 / (4.0 * mu)
