"""Quadrature rules and the sampling of data on edges and cells, for every element.

- ``TRIANGLE_RULE``: the 7-point degree-5 rule on triangles; ``reference_quadrature``: a degree-2 or
  degree-5 rule on a triangulation of every cell (errors, projections of data);
- ``edge_quadrature``: Gauss-Legendre on [0, 1]; ``traction_samples``: a traction at the Gauss points
  of boundary edges; ``pressure_traction``: the traction -p nu of a normal pressure (docs/reference/files.md);
- ``cell_averages``: P_0 f of a vector field on every cell.
"""

from __future__ import annotations

import numpy as np

from vemkit.mesh.mesh import Mesh

# 7-point degree-5 rule on the reference triangle (barycentric a, b, c; weights sum to 1)
_A1, _B1 = 0.059715871789770, 0.470142064105115
_A2, _B2 = 0.797426985353087, 0.101286507323456
TRIANGLE_RULE = np.array(
    [
        [1 / 3, 1 / 3, 1 / 3, 0.225],
        [_A1, _B1, _B1, 0.132394152788506],
        [_B1, _A1, _B1, 0.132394152788506],
        [_B1, _B1, _A1, 0.132394152788506],
        [_A2, _B2, _B2, 0.125939180544827],
        [_B2, _A2, _B2, 0.125939180544827],
        [_B2, _B2, _A2, 0.125939180544827],
    ]
)
# degree-2 rule on triangles (barycentric coordinates, weights summing to 1)
_DEGREE2 = np.array([[2 / 3, 1 / 6, 1 / 6], [1 / 6, 2 / 3, 1 / 6], [1 / 6, 1 / 6, 2 / 3]])
_DEGREE2_WEIGHTS = np.full(3, 1 / 3)


def edge_quadrature(points: int = 5):
    """Gauss-Legendre nodes on [0, 1] and weights summing to 1."""
    t, w = np.polynomial.legendre.leggauss(points)
    return 0.5 * (t + 1.0), 0.5 * w


def traction_samples(mesh: Mesh, edges: np.ndarray, traction, points: int = 5):
    """(t (Q,), |e| w_q (E, Q), f2 (E, Q, 2)): Gauss points on [0, 1], weights and the traction at
    x = (1 - t) x_a + t x_b on every edge (a, b)."""
    t, w = edge_quadrature(points)
    pa, pb = mesh.vertices[edges[:, 0]], mesh.vertices[edges[:, 1]]
    length = np.linalg.norm(pb - pa, axis=1)
    x = pa[:, None, :] * (1 - t)[None, :, None] + pb[:, None, :] * t[None, :, None]
    fx, fy = traction(x[..., 0], x[..., 1])
    f = np.stack([np.broadcast_to(fx, x.shape[:2]), np.broadcast_to(fy, x.shape[:2])], axis=-1)
    return t, length[:, None] * w[None, :], f


def pressure_traction(mesh: Mesh, edges: np.ndarray, pressure):
    """(edges as (E, 2) int64, traction(x, y) on (E, points) arrays): the traction -p nu of a normal
    pressure p on every edge (a, b), nu its outward normal (the body lies left of a -> b);
    pressure(x, y) -> p, or a number. Shared by every element's loads."""
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    tangent = mesh.vertices[edges[:, 1]] - mesh.vertices[edges[:, 0]]
    normal = np.stack([tangent[:, 1], -tangent[:, 0]], axis=1)
    normal /= np.maximum(np.linalg.norm(normal, axis=1), np.finfo(float).tiny)[:, None]

    def traction(x, y):
        p = np.broadcast_to(pressure(x, y) if callable(pressure) else float(pressure), x.shape)
        return -p * normal[:, 0:1], -p * normal[:, 1:2]

    return edges, traction


def cell_averages(mesh: Mesh, field, triangles: np.ndarray, parent: np.ndarray) -> np.ndarray:
    """(M, 2) cell averages P_0 f of a vector field f(x, y) -> (fx, fy), from a cell triangulation."""
    p = mesh.vertices[triangles]  # (T, 3, 2)
    area = 0.5 * (
        (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1])
    )
    x = np.einsum("qk,tkc->tqc", TRIANGLE_RULE[:, :3], p)
    fx, fy = field(x[..., 0], x[..., 1])
    w = TRIANGLE_RULE[:, 3][None, :] * area[:, None]
    integral = np.stack(
        [np.sum(w * np.broadcast_to(fx, w.shape), axis=1), np.sum(w * np.broadcast_to(fy, w.shape), axis=1)], axis=1
    )
    out = np.zeros((mesh.n_cells, 2))
    for comp in range(2):
        out[:, comp] = np.bincount(parent, integral[:, comp], mesh.n_cells)
    return out / mesh.cell_areas[:, None]


def body_force_averages(mesh: Mesh, field) -> np.ndarray:
    """(M, 2) P_0 f1 of a body force field(x, y) on every cell (a triangulation of each cell)."""
    from vemkit.mesh.triangulate import triangulate_cells

    triangles, parent = triangulate_cells(mesh)
    return cell_averages(mesh, field, triangles, parent)


def reference_quadrature(mesh: Mesh, degree: int = 2):
    """Quadrature (degree 2 or 5) on a triangulation of the cells: points (P, 2), weights (P,), cell (P,)."""
    from vemkit.mesh.triangulate import triangulate_cells

    bary, w = (_DEGREE2, _DEGREE2_WEIGHTS) if degree <= 2 else (TRIANGLE_RULE[:, :3], TRIANGLE_RULE[:, 3])
    tri, parent = triangulate_cells(mesh)
    p = mesh.vertices[tri]
    area = 0.5 * np.abs(
        (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1])
    )
    points = np.einsum("qk,tkc->tqc", bary, p).reshape(-1, 2)
    weights = (area[:, None] * w[None, :]).ravel()
    cells = np.repeat(parent, bary.shape[0])
    return points, weights, cells
