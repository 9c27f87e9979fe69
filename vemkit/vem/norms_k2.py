"""Pi_2 u_h of a k = 2 solution (3.8) and its errors against an exact solution.

``projected_solution_k2(mesh, u_nodes, lam, mu)`` gives, per cell, the coefficients of Pi_2 u_h in
the element kernel's basis (rigid motions about the centroid x_K and nine non-rigid fields in
(xi, eta) = (x - x_K) / h_K; see ``vemkit.vem.element_k2``). Pi_2 depends on the material: it is
the energy projection of a_K. ``exact_errors_k2`` integrates |u - Pi_2 u_h|^2 and
|grad(u - Pi_2 u_h)|^2 with the degree-5 rule on a triangulation of every cell
(``vemkit.vem.norms.reference_quadrature``): exact for the polynomial part, O(h^6) for the rest.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from vemkit.mesh.mesh import Mesh
from vemkit.vem.assembly_k2 import cell_nodes
from vemkit.vem.element_k2 import N_BASIS, cell_projection, largest_cell, projection_workspace


@numba.njit(cache=True)
def _cell_projections(vertices, offsets, nodes, u, lam, mu, coef, frame):
    Pi, rhs, G, sig = projection_workspace(largest_cell(offsets))
    for c in range(offsets.shape[0] - 1):
        start = offsets[c]
        size, area, xc, yc, h, m20, m11, m02 = cell_projection(vertices, offsets, nodes, c, lam, mu, Pi, rhs, G, sig)
        frame[c, 0] = xc
        frame[c, 1] = yc
        frame[c, 2] = h
        for b in range(N_BASIS):
            acc = 0.0
            for i in range(size):
                acc += Pi[b, 2 * i] * u[nodes[start + i], 0] + Pi[b, 2 * i + 1] * u[nodes[start + i], 1]
            coef[c, b] = acc


@dataclass(frozen=True)
class ProjectedSolutionK2:
    """Pi_2 u on every cell: coefficients (M, 12) in the kernel's basis; frame (M, 3) = (x_K, y_K, h_K)."""

    coef: np.ndarray
    frame: np.ndarray

    def _scaled(self, cells, points):
        f = self.frame[cells]
        return (points[:, 0] - f[:, 0]) / f[:, 2], (points[:, 1] - f[:, 1]) / f[:, 2], f[:, 2]

    def evaluate(self, cells: np.ndarray, points: np.ndarray) -> np.ndarray:
        """(P, 2) values of Pi_2 u at points, each in the given cell."""
        xi, eta, _ = self._scaled(cells, points)
        c = self.coef[cells].T
        u1 = c[0] - c[2] * eta + c[3] * xi + c[5] * eta + c[6] * xi**2 + c[7] * xi * eta + c[8] * eta**2
        u2 = c[1] + c[2] * xi + c[4] * eta + c[5] * xi + c[9] * xi**2 + c[10] * xi * eta + c[11] * eta**2
        return np.stack([u1, u2], axis=1)

    def gradient(self, cells: np.ndarray, points: np.ndarray) -> np.ndarray:
        """(P, 2, 2) gradient of Pi_2 u at points: [i, j] = d u_i / d x_j."""
        xi, eta, h = self._scaled(cells, points)
        c = self.coef[cells].T
        g = np.empty((points.shape[0], 2, 2))
        g[:, 0, 0] = c[3] + 2 * c[6] * xi + c[7] * eta
        g[:, 0, 1] = -c[2] + c[5] + c[7] * xi + 2 * c[8] * eta
        g[:, 1, 0] = c[2] + c[5] + 2 * c[9] * xi + c[10] * eta
        g[:, 1, 1] = c[4] + c[10] * xi + 2 * c[11] * eta
        return g / h[:, None, None]


def projected_solution_k2(mesh: Mesh, u_nodes: np.ndarray, lam: float, mu: float) -> ProjectedSolutionK2:
    """Pi_2 of the k = 2 node values ``u_nodes`` (n_nodes, 2) on every cell."""
    offsets, nodes = cell_nodes(mesh)
    u = np.ascontiguousarray(u_nodes, dtype=float).reshape(-1, 2)
    coef = np.empty((mesh.n_cells, N_BASIS))
    frame = np.empty((mesh.n_cells, 3))
    _cell_projections(mesh.vertices, offsets, nodes, u, float(lam), float(mu), coef, frame)
    return ProjectedSolutionK2(coef, frame)


def exact_errors_k2(mesh: Mesh, proj: ProjectedSolutionK2, u_exact, grad_exact, quadrature=None) -> dict:
    """Absolute L2 and H1-seminorm errors of Pi_2 u_h against an exact solution.

    u_exact(x, y) -> (u1, u2); grad_exact(x, y) -> ((du1/dx, du1/dy), (du2/dx, du2/dy)).
    """
    from vemkit.vem.norms import reference_quadrature

    points, weights, cells = quadrature if quadrature is not None else reference_quadrature(mesh, degree=5)
    ue = np.stack(np.broadcast_arrays(*u_exact(points[:, 0], points[:, 1])), axis=1)
    ge = np.moveaxis(np.asarray(grad_exact(points[:, 0], points[:, 1]), dtype=float), -1, 0)
    diff = proj.evaluate(cells, points) - ue
    grad = proj.gradient(cells, points) - ge
    return {
        "l2": float(np.sqrt(np.sum(weights * np.sum(diff**2, axis=1)))),
        "h1_semi": float(np.sqrt(np.sum(weights * np.sum(grad**2, axis=(1, 2))))),
    }
