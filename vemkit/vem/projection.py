"""What follows from a projected displacement for every element: stress (SPEC §1) and the shear
energy density of the paper's Fig. 6. The projections Pi u_h themselves belong to the elements
(``VirtualElementSpace.project``)."""

from __future__ import annotations

import numpy as np


def stress(strain: np.ndarray, lam: float, mu: float) -> np.ndarray:
    """(M, 3) sigma11, sigma22, sigma12 = C eps (SPEC §1) from (eps11, eps22, eps12)."""
    tr = strain[:, 0] + strain[:, 1]
    return np.stack([lam * tr + 2 * mu * strain[:, 0], lam * tr + 2 * mu * strain[:, 1], 2 * mu * strain[:, 2]], axis=1)


def shear_energy_density(sig: np.ndarray, lam: float, mu: float) -> np.ndarray:
    """|dev sigma|^2 / (4 mu) with the formula printed under the paper's Fig. 6:

    |dev sigma|^2 = (mu^2 / (6 (mu + lam)^2) + 1/2) (s11 + s22)^2 + 2 (s12^2 - s11 s22),

    lam being the lambda* of the paper's C (SPEC §1).
    """
    s11, s22, s12 = sig[:, 0], sig[:, 1], sig[:, 2]
    dev2 = (mu**2 / (6.0 * (mu + lam) ** 2) + 0.5) * (s11 + s22) ** 2 + 2.0 * (s12**2 - s11 * s22)
    return dev2 / (4.0 * mu)
