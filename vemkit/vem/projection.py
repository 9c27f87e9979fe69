"""Elementwise projection Pi_1 (3.8) of a discrete solution, and what follows from it.

``projected_solution(mesh, u)`` gives, per cell, the linear polynomial
Pi u = c + (E + omega J)(x - xbar) (xbar the vertex mean), stored as coefficients
(c1, c2, omega, eps11, eps22, eps12). Strain, stress and the shear energy density of Fig. 6
are constant per cell and computed from it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from vemkit.mesh.mesh import Mesh
from vemkit.vem.element import cell_coordinates, polygon_area, projection_coefficients, strain_operator


@numba.njit(cache=True)
def _cell_projections(vertices, offsets, cell_vertices, u, coef, center):
    n_cells = offsets.shape[0] - 1
    for c in range(n_cells):
        s = offsets[c]
        n = offsets[c + 1] - s
        px, py = cell_coordinates(vertices, offsets, cell_vertices, c)
        B = np.empty((3, 2 * n))
        P = np.empty((6, 2 * n))
        strain_operator(px, py, polygon_area(px, py), B)
        xb, yb = projection_coefficients(px, py, B, P)
        center[c, 0] = xb
        center[c, 1] = yb
        for r in range(6):
            acc = 0.0
            for i in range(n):
                v = cell_vertices[s + i]
                acc += P[r, 2 * i] * u[v, 0] + P[r, 2 * i + 1] * u[v, 1]
            coef[c, r] = acc


@dataclass(frozen=True)
class ProjectedSolution:
    """Pi_1 u on every cell: value c at xbar, rotation omega, strain (eps11, eps22, eps12)."""

    center: np.ndarray  # (M, 2) vertex mean xbar of each cell
    coef: np.ndarray  # (M, 6): c1, c2, omega, eps11, eps22, eps12

    @property
    def strain(self) -> np.ndarray:
        """(M, 3): eps11, eps22, eps12."""
        return self.coef[:, 3:]

    @property
    def gradient(self) -> np.ndarray:
        """(M, 2, 2) constant gradient E + omega J of Pi u per cell."""
        c = self.coef
        g = np.empty((c.shape[0], 2, 2))
        g[:, 0, 0] = c[:, 3]
        g[:, 1, 1] = c[:, 4]
        g[:, 0, 1] = c[:, 5] - c[:, 2]
        g[:, 1, 0] = c[:, 5] + c[:, 2]
        return g

    def evaluate(self, cells: np.ndarray, points: np.ndarray) -> np.ndarray:
        """(P, 2) values of Pi u at points, each in the given cell."""
        d = points - self.center[cells]
        return self.coef[cells, :2] + np.einsum("pij,pj->pi", self.gradient[cells], d)


def projected_solution(mesh: Mesh, u_vertices: np.ndarray) -> ProjectedSolution:
    u = np.ascontiguousarray(u_vertices, dtype=float).reshape(mesh.n_vertices, 2)
    coef = np.empty((mesh.n_cells, 6))
    center = np.empty((mesh.n_cells, 2))
    _cell_projections(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, u, coef, center)
    return ProjectedSolution(center, coef)


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
