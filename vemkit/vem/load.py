"""The load vector <f_h, v_h> of Section 3.3 (k = 1).

- Body force: int_K P_0 f1 . v_h dx with P_0 f1 the cell average of f1 (Gauss quadrature on a
  triangulation of the cell) and int_K v_h dx computed as int_K Pi v_h dx = |K| (Pi v_h)(x_K),
  x_K the centroid: exact for linear v_h on any polygon, hence the patch test with body force.
- Tractions: int_e f2 . v_h ds on every edge of a Neumann part by Gauss-Legendre quadrature;
  v_h is linear on each edge, so this is exact for polynomial tractions of moderate degree. A
  normal pressure p is the traction -p nu with nu the outward normal of each edge (SPEC §7).
All vectors are over the vertices, shape (N, 2); restrict with ``DofMap.restrict``.
"""

from __future__ import annotations

import numba
import numpy as np

from vemkit.mesh.geometry import polygon_area_centroid
from vemkit.mesh.mesh import Mesh
from vemkit.vem.element import cell_coordinates, projection_coefficients, strain_operator

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


def pressure_traction(mesh: Mesh, edges: np.ndarray, pressure):
    """(edges as (E, 2) int64, traction(x, y) on (E, points) arrays): the traction -p nu of a normal
    pressure p on every edge (a, b), nu its outward normal (the body lies left of a -> b);
    pressure(x, y) -> p, or a number. Shared by the k = 1 and k = 2 loads."""
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    tangent = mesh.vertices[edges[:, 1]] - mesh.vertices[edges[:, 0]]
    normal = np.stack([tangent[:, 1], -tangent[:, 0]], axis=1)
    normal /= np.maximum(np.linalg.norm(normal, axis=1), np.finfo(float).tiny)[:, None]

    def traction(x, y):
        p = np.broadcast_to(pressure(x, y) if callable(pressure) else float(pressure), x.shape)
        return -p * normal[:, 0:1], -p * normal[:, 1:2]

    return edges, traction


def pressure_load(mesh: Mesh, edges: np.ndarray, pressure, points: int = 5) -> np.ndarray:
    """(N, 2) nodal loads of a normal pressure p (``pressure_traction``)."""
    edges, traction = pressure_traction(mesh, edges, pressure)
    return traction_load(mesh, edges, traction, points)


def cell_averages(mesh: Mesh, field, triangles: np.ndarray, parent: np.ndarray) -> np.ndarray:
    """(M, 2) cell averages P_0 f of a vector field f(x, y) -> (fx, fy), from a cell triangulation."""
    p = mesh.vertices[triangles]  # (T, 3, 2)
    area = 0.5 * ((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1]))
    x = np.einsum("qk,tkc->tqc", TRIANGLE_RULE[:, :3], p)
    fx, fy = field(x[..., 0], x[..., 1])
    w = TRIANGLE_RULE[:, 3][None, :] * area[:, None]
    integral = np.stack([np.sum(w * np.broadcast_to(fx, w.shape), axis=1), np.sum(w * np.broadcast_to(fy, w.shape), axis=1)], axis=1)
    out = np.zeros((mesh.n_cells, 2))
    for comp in range(2):
        out[:, comp] = np.bincount(parent, integral[:, comp], mesh.n_cells)
    return out / mesh.cell_areas[:, None]


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
