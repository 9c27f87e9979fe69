"""The k = 1 element's loads and projected fields (Section 3.3, (3.8)).

- Body force: int_K P_0 f1 . v_h dx with P_0 f1 the cell average of f1 and int_K v_h dx computed as
  int_K Pi v_h dx = |K| (Pi v_h)(x_K), x_K the centroid: exact for linear v_h on any polygon, hence
  the patch test with body force.
- Tractions: int_e f2 . v_h ds on every edge of a Neumann part by Gauss-Legendre quadrature; v_h is
  linear on each edge, so this is exact for polynomial tractions of moderate degree.
- ``projected_solution(mesh, u)``: per cell, the linear polynomial Pi u = c + (E + omega J)(x - xbar)
  (xbar the vertex mean), stored as coefficients (c1, c2, omega, eps11, eps22, eps12).
All vectors are over the vertices, shape (N, 2).
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from vemkit.mesh.geometry import polygon_area, polygon_area_centroid
from vemkit.mesh.mesh import Mesh
from vemkit.vem.elements.k1_kernel import cell_coordinates, projection_coefficients, strain_operator
from vemkit.vem.quadrature import traction_samples


def traction_load(mesh: Mesh, edges: np.ndarray, traction, points: int = 5) -> np.ndarray:
    """(N, 2) nodal loads of int_e f2 . phi ds over ``edges`` (k, 2); traction(x, y) -> (f1, f2)."""
    out = np.zeros((mesh.n_vertices, 2))
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if edges.size == 0:
        return out
    t, weight, f = traction_samples(mesh, edges, traction, points)
    to_a = np.einsum("eq,eqc->ec", weight * (1 - t)[None, :], f)
    to_b = np.einsum("eq,eqc->ec", weight * t[None, :], f)
    for comp in range(2):
        out[:, comp] += np.bincount(edges[:, 0], to_a[:, comp], mesh.n_vertices)
        out[:, comp] += np.bincount(edges[:, 1], to_b[:, comp], mesh.n_vertices)
    return out


@numba.njit(cache=True)
def _body_force_scatter(vertices, offsets, cell_vertices, force, out):
    """out[v] += |K| f_K * d(Pi v)(x_K)/d(v_j): int_K P0 f1 . Pi v dx for every cell."""
    n_cells = offsets.shape[0] - 1
    for c in range(n_cells):
        s = offsets[c]
        n = offsets[c + 1] - s
        px, py = cell_coordinates(vertices, offsets, cell_vertices, c)
        area, cx, cy = polygon_area_centroid(px, py)
        B = np.empty((3, 2 * n))
        P = np.empty((6, 2 * n))
        strain_operator(px, py, area, B)
        xb, yb = projection_coefficients(px, py, B, P)
        d1 = cx - xb
        d2 = cy - yb
        for j in range(2 * n):
            pi1 = P[0, j] + P[3, j] * d1 + P[5, j] * d2 - P[2, j] * d2
            pi2 = P[1, j] + P[5, j] * d1 + P[4, j] * d2 + P[2, j] * d1
            v = cell_vertices[s + j // 2]
            out[v, j % 2] += area * (force[c, 0] * pi1 + force[c, 1] * pi2)


def body_force_load(mesh: Mesh, cell_force: np.ndarray) -> np.ndarray:
    """(N, 2) nodal loads of int_K P_0 f1 . v_h dx given the cell averages (M, 2) of f1."""
    out = np.zeros((mesh.n_vertices, 2))
    cell_force = np.ascontiguousarray(cell_force, dtype=float)
    if np.any(cell_force):
        _body_force_scatter(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, cell_force, out)
    return out


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
    degree = 1  # polynomial degree of Pi u on a cell

    @property
    def strain(self) -> np.ndarray:
        """(M, 3): eps11, eps22, eps12."""
        return self.coef[:, 3:]

    def cell_mean_strain(self) -> np.ndarray:
        """(M, 3) the cell mean of eps(Pi u): its constant value."""
        return self.strain

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

    def gradient_at(self, cells: np.ndarray, points: np.ndarray) -> np.ndarray:
        """(P, 2, 2) the gradient of Pi u at points, each in the given cell (constant per cell)."""
        return self.gradient[cells]

    def evaluate(self, cells: np.ndarray, points: np.ndarray) -> np.ndarray:
        """(P, 2) values of Pi u at points, each in the given cell."""
        d = points - self.center[cells]
        return self.coef[cells, :2] + np.einsum("pij,pj->pi", self.gradient[cells], d)


def projected_solution(mesh: Mesh, u_vertices: np.ndarray) -> ProjectedSolution:
    """Pi_1 of the vertex values ``u_vertices`` (N, 2) on every cell."""
    u = np.ascontiguousarray(u_vertices, dtype=float).reshape(mesh.n_vertices, 2)
    coef = np.empty((mesh.n_cells, 6))
    center = np.empty((mesh.n_cells, 2))
    _cell_projections(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, u, coef, center)
    return ProjectedSolution(center, coef)


def component_values(component, x, y) -> np.ndarray:
    if callable(component):
        return np.broadcast_to(np.asarray(component(x, y), dtype=float), x.shape).copy()
    return np.full(x.shape, float(component))


def dirichlet_components(mesh: Mesh, dirichlet) -> tuple[np.ndarray, np.ndarray]:
    """(prescribed (n_vertices, 2) bool, values (n_vertices, 2)) of ``dirichlet``: a sequence of
    side names (u = 0) or a mapping side -> (u1, u2), each None, a number or a function of (x, y)."""
    entries = dirichlet.items() if isinstance(dirichlet, dict) else ((side, (0.0, 0.0)) for side in dirichlet)
    prescribed = np.zeros((mesh.n_vertices, 2), dtype=bool)
    values = np.zeros((mesh.n_vertices, 2))
    for side, components in entries:
        vertices = mesh.boundary_vertices(side)
        x, y = mesh.vertices[vertices, 0], mesh.vertices[vertices, 1]
        for c, component in enumerate(components):
            if component is None:
                continue
            new = vertices[~prescribed[vertices, c]]  # the first listed side wins
            values[new, c] = component_values(component, x, y)[~prescribed[vertices, c]]
            prescribed[new, c] = True
    return prescribed, values


def node_coordinates(mesh: Mesh) -> np.ndarray:
    """(N, 2): the nodes of k = 1 are the vertices."""
    return mesh.vertices
