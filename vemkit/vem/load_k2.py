"""The load vector <f_h, v_h> of Section 3.3 for k = 2, over the nodes of ``vemkit.vem.assembly_k2``.

- Body force: <f1_h, v_h> = sum_K int_K P_{k-2} f1 . v_h dx with k - 2 = 0: P_0 f1 is the cell
  average of f1 (``vemkit.vem.load.cell_averages``) and int_K v_h dx = |K| (cell mean of v_h), the
  interior degree of freedom. So the whole body-force load sits on the cell nodes: |K| P_0 f1.
- Tractions: int_e f2 . v_h ds on every edge of a Neumann part by Gauss-Legendre quadrature with
  the quadratic trace v_h = v_a (L0 - Lh/4) + v_b (L1 - Lh/4) + mean_e (3/2) Lh (L0, Lh, L1 the
  Lagrange quadratics at t = 0, 1/2, 1): exact for polynomial tractions of moderate degree.
All vectors are (n_nodes, 2); restrict with ``NodeMapK2.restrict``.
"""

from __future__ import annotations

import numba
import numpy as np

from vemkit.mesh.mesh import Mesh
from vemkit.vem.assembly_k2 import cell_nodes, edge_indices
from vemkit.vem.element_k2 import (N_BASIS, cell_frame, cell_projection, cell_vertex_coordinates, largest_cell,
                                    projection_workspace)
from vemkit.vem.load import pressure_traction, traction_samples


def n_nodes(mesh: Mesh) -> int:
    return mesh.n_vertices + mesh.edges.shape[0] + mesh.n_cells


def trace_weights(t: np.ndarray) -> np.ndarray:
    """(P, 3): the quadratic trace's weights on (v_a, v_b, mean_e) at the edge parameters t in [0, 1]."""
    L0, Lh, L1 = 2 * (t - 0.5) * (t - 1), 4 * t * (1 - t), 2 * t * (t - 0.5)
    return np.stack([L0 - Lh / 4, L1 - Lh / 4, 1.5 * Lh], axis=1)


def traction_load_k2(mesh: Mesh, edges: np.ndarray, traction, points: int = 5) -> np.ndarray:
    """(n_nodes, 2) loads of int_e f2 . phi ds over ``edges`` (k, 2); traction(x, y) -> (f1, f2)."""
    out = np.zeros((n_nodes(mesh), 2))
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if edges.size == 0:
        return out
    t, weight, f = traction_samples(mesh, edges, traction, points)
    to_node = np.einsum("eq,qk,eqc->kec", weight, trace_weights(t), f)  # (3, k, 2)
    targets = (edges[:, 0], edges[:, 1], mesh.n_vertices + edge_indices(mesh, edges))
    for node, contribution in zip(targets, to_node):
        for comp in range(2):
            out[:, comp] += np.bincount(node, contribution[:, comp], out.shape[0])
    return out


def pressure_load_k2(mesh: Mesh, edges: np.ndarray, pressure, points: int = 5) -> np.ndarray:
    """(n_nodes, 2) loads of a normal pressure p (``vemkit.vem.load.pressure_traction``)."""
    edges, traction = pressure_traction(mesh, edges, pressure)
    return traction_load_k2(mesh, edges, traction, points)


def body_force_load_k2(mesh: Mesh, cell_force: np.ndarray) -> np.ndarray:
    """(n_nodes, 2) loads of int_K P_0 f1 . v_h dx = |K| P_0 f1 . (cell mean of v_h), given P_0 f1 (M, 2)."""
    out = np.zeros((n_nodes(mesh), 2))
    first_cell = mesh.n_vertices + mesh.edges.shape[0]
    out[first_cell:] = mesh.cell_areas[:, None] * np.asarray(cell_force, dtype=float).reshape(-1, 2)
    return out


def body_force_k2(mesh: Mesh, body_force) -> np.ndarray:
    """(n_nodes, 2): the body-force load of a field body_force(x, y) -> (f1, f2) (its P_0 projection)."""
    from vemkit.mesh.triangulate import triangulate_cells
    from vemkit.vem.load import cell_averages

    triangles, parent = triangulate_cells(mesh)
    return body_force_load_k2(mesh, cell_averages(mesh, body_force, triangles, parent))


# --------------------------------------------------------------------------------------------
# optional: P_1 f1 through Pi_2 (the "enhanced" space of Ahmad, Alsaedi, Brezzi, Marini, Russo 2013)
# --------------------------------------------------------------------------------------------
@numba.njit(cache=True)
def _frames(vertices, offsets, nodes, frame):
    """frame (M, 3): centroid and scale h of every cell, as the kernel's basis uses them."""
    for c in range(offsets.shape[0] - 1):
        px, py = cell_vertex_coordinates(vertices, offsets, nodes, c)
        area, xc, yc, h, m20, m11, m02 = cell_frame(px, py)
        frame[c, 0], frame[c, 1], frame[c, 2] = xc, yc, h


@numba.njit(cache=True)
def _scatter_projected(vertices, offsets, nodes, lam, mu, moments, out):
    """out[node_j] += sum_b Pi[b, j] moments[c, b]: int_K g . Pi_2 phi_j dx given int_K g . q_b dx."""
    Pi, rhs, G, sig = projection_workspace(largest_cell(offsets))
    for c in range(offsets.shape[0] - 1):
        start = offsets[c]
        size = cell_projection(vertices, offsets, nodes, c, lam, mu, Pi, rhs, G, sig)[0]
        for j in range(2 * size):
            acc = 0.0
            for b in range(N_BASIS):
                acc += Pi[b, j] * moments[c, b]
            out[nodes[start + j // 2], j % 2] += acc


def cell_frames(mesh: Mesh) -> np.ndarray:
    """(M, 3): centroid (x_K, y_K) and scale h_K of every cell, as the element kernel uses them."""
    offsets, nodes = cell_nodes(mesh)
    frame = np.empty((mesh.n_cells, 3))
    _frames(mesh.vertices, offsets, nodes, frame)
    return frame


def _basis_at(xi, eta):
    """(P, 12, 2): the kernel's basis fields at scaled points."""
    z, one = np.zeros_like(xi), np.ones_like(xi)
    first = [one, z, -eta, xi, z, eta, xi * xi, xi * eta, eta * eta, z, z, z]
    second = [z, one, xi, z, eta, xi, z, z, z, xi * xi, xi * eta, eta * eta]
    return np.stack([np.stack(first, axis=1), np.stack(second, axis=1)], axis=2)


def body_force_p1_k2(mesh: Mesh, body_force, lam: float, mu: float) -> np.ndarray:
    """(n_nodes, 2): int_K P_0 f1 . v dx + int_K (P_1 f1 - P_0 f1) . Pi_2 v dx on every cell.

    Not the paper's choice (which is ``body_force_k2``, P_{k-2} f1 = P_0 f1): with it the L2 error
    is O(h^2) only (the body-force term contributes (h^2/12) int grad f1 : grad z for the dual z).
    In the enhanced virtual element space the moments of v against the zero-mean linear fields are
    those of Pi_2 v, so this is int_K P_1 f1 . v dx there, and the stiffness matrix is unchanged.
    """
    from vemkit.vem.norms import reference_quadrature

    offsets, nodes = cell_nodes(mesh)
    frame = cell_frames(mesh)
    points, weights, cells = reference_quadrature(mesh, degree=5)
    f = np.stack(np.broadcast_arrays(*body_force(points[:, 0], points[:, 1])), axis=1)
    xi = (points[:, 0] - frame[cells, 0]) / frame[cells, 2]
    eta = (points[:, 1] - frame[cells, 1]) / frame[cells, 2]
    mono = np.stack([np.ones_like(xi), xi, eta], axis=1)  # (P, 3)
    mass = np.zeros((mesh.n_cells, 3, 3))
    np.add.at(mass, cells, weights[:, None, None] * mono[:, :, None] * mono[:, None, :])
    moments_f = np.zeros((mesh.n_cells, 3, 2))
    np.add.at(moments_f, cells, weights[:, None, None] * mono[:, :, None] * f[:, None, :])
    p1 = np.linalg.solve(mass, moments_f)  # (M, 3, 2): P_1 f1 = p1[0] + p1[1] xi + p1[2] eta
    g = xi[:, None] * p1[cells, 1] + eta[:, None] * p1[cells, 2]  # P_1 f1 - P_0 f1 at the points
    moments = np.zeros((mesh.n_cells, N_BASIS))
    np.add.at(moments, cells, weights[:, None] * np.einsum("pbc,pc->pb", _basis_at(xi, eta), g))
    out = body_force_load_k2(mesh, p1[:, 0])
    _scatter_projected(mesh.vertices, offsets, nodes, float(lam), float(mu), moments, out)
    return out
