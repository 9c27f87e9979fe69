"""The k = 2 element's nodes, loads, interpolation and projected fields (Section 3, Fig. 1 right).

Nodes: every vertex (node v), every edge (node N_v + e, e the index in ``mesh.edges``) and every
cell (node N_v + N_e + c); each node carries the two components of its degree of freedom (vertex
value, edge mean, cell mean; see ``k2_kernel``). Cell c lists its 2n + 1 nodes as its n vertices
(CCW), its n edges (edge i from vertex i to i + 1: ``mesh.half_edge_edge``) and itself, which is the
local order of the element kernel (``cell_nodes``).

The load vector <f_h, v_h> of Section 3.3:

- Body force: <f1_h, v_h> = sum_K int_K P_{k-2} f1 . v_h dx with k - 2 = 0: P_0 f1 is the cell
  average of f1 (``vemkit.vem.quadrature.cell_averages``) and int_K v_h dx = |K| (cell mean of v_h), the
  interior degree of freedom. So the whole body-force load sits on the cell nodes: |K| P_0 f1.
- Tractions: int_e f2 . v_h ds on every edge of a Neumann part by Gauss-Legendre quadrature with
  the quadratic trace v_h = v_a (L0 - Lh/4) + v_b (L1 - Lh/4) + mean_e (3/2) Lh (L0, Lh, L1 the
  Lagrange quadratics at t = 0, 1/2, 1): exact for polynomial tractions of moderate degree.
All vectors are (n_nodes, 2).

Dirichlet data (``dirichlet_components``): a prescribed component gives the value at the side's
vertices (the side listed first wins at a shared vertex, as for k = 1) and the edge MEAN of the
prescribed value at its edges (5-point Gauss-Legendre), so a prescribed quadratic is reproduced.
``projected_solution`` gives Pi_2 u_h per cell in the kernel's basis (rigid motions about the
centroid and nine non-rigid fields in (xi, eta) = (x - x_K) / h_K).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numba
import numpy as np

from vemkit.mesh.mesh import Mesh, edge_indices
from vemkit.vem.elements.k1_fields import component_values
from vemkit.vem.elements.k1_fields import dirichlet_components as vertex_dirichlet_components
from vemkit.vem.elements.k2_kernel import (
    N_BASIS,
    cell_frame,
    cell_projection,
    cell_vertex_coordinates,
    largest_cell,
    projection_workspace,
)
from vemkit.vem.elements.k2_load_kernel import p1_basis_moments, scaled_points_and_p1_sums
from vemkit.vem.projection import strain_of
from vemkit.vem.quadrature import body_force_averages, edge_quadrature, reference_quadrature, traction_samples

CELL_CHUNKS = 8  # threads' shares of the cells in the per-cell projections (as vemkit.vem.condensation)

_CELL_NODES: "weakref.WeakKeyDictionary[Mesh, tuple]" = weakref.WeakKeyDictionary()


def cell_nodes(mesh: Mesh) -> tuple[np.ndarray, np.ndarray]:
    """CSR (offsets, nodes) of the 2n + 1 nodes of every cell in the kernel's local order (cached
    per mesh, read-only)."""
    if mesh not in _CELL_NODES:
        nv, ne = mesh.n_vertices, mesh.edges.shape[0]
        sizes = mesh.cell_sizes
        offsets = np.concatenate([[0], np.cumsum(2 * sizes + 1)]).astype(np.int64)
        nodes = np.empty(offsets[-1], dtype=np.int64)
        # position of half-edge p (cell c, local i) in the node list: offsets[c] + i and + n + i
        cell_of = mesh.half_edge_cells
        local = np.arange(mesh.cell_vertices.size) - mesh.cell_offsets[cell_of]
        nodes[offsets[cell_of] + local] = mesh.cell_vertices
        nodes[offsets[cell_of] + sizes[cell_of] + local] = nv + mesh.half_edge_edge
        nodes[offsets[1:] - 1] = nv + ne + np.arange(mesh.n_cells)
        offsets.flags.writeable = False
        nodes.flags.writeable = False
        _CELL_NODES[mesh] = (offsets, nodes)
    return _CELL_NODES[mesh]


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


def body_force_load_k2(mesh: Mesh, cell_force: np.ndarray) -> np.ndarray:
    """(n_nodes, 2) loads of int_K P_0 f1 . v_h dx = |K| P_0 f1 . (cell mean of v_h), given P_0 f1 (M, 2)."""
    out = np.zeros((n_nodes(mesh), 2))
    first_cell = mesh.n_vertices + mesh.edges.shape[0]
    out[first_cell:] = mesh.cell_areas[:, None] * np.asarray(cell_force, dtype=float).reshape(-1, 2)
    return out


def body_force_k2(mesh: Mesh, body_force) -> np.ndarray:
    """(n_nodes, 2): the body-force load of a field body_force(x, y) -> (f1, f2) (its P_0 projection)."""
    return body_force_load_k2(mesh, body_force_averages(mesh, body_force))


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


def _scatter_projected(vertices, offsets, nodes, lam, mu, moments, out):
    """out[node_j] += sum_b Pi[b, j] moments[c, b] over the cells in order (``_cell_projections``, then
    one ordered np.add.at: the sums of a serial loop over the cells)."""
    parts = np.empty(2 * offsets[-1])
    frame = np.empty((offsets.shape[0] - 1, 3))
    no_values, no_coef = np.empty((0, 2)), np.empty((0, N_BASIS))
    _cell_projections(vertices, offsets, nodes, lam, mu, no_values, moments, no_coef, frame, parts)
    np.add.at(out, (np.repeat(nodes, 2), np.tile(np.arange(2), nodes.size)), parts)


def cell_frames(mesh: Mesh) -> np.ndarray:
    """(M, 3): centroid (x_K, y_K) and scale h_K of every cell, as the element kernel uses them."""
    offsets, nodes = cell_nodes(mesh)
    frame = np.empty((mesh.n_cells, 3))
    _frames(mesh.vertices, offsets, nodes, frame)
    return frame


def _basis_components(xi, eta, zero, one):
    """The kernel's 12 basis fields at scaled points: (first components, second components), with
    ``zero`` and ``one`` as the constant entries (arrays; basis_moments passes None and 1.0)."""
    first = [one, zero, -eta, xi, zero, eta, xi * xi, xi * eta, eta * eta, zero, zero, zero]
    second = [zero, one, xi, zero, eta, xi, zero, zero, zero, xi * xi, xi * eta, eta * eta]
    return first, second


def _basis_at(xi, eta):
    """(P, 12, 2): the kernel's basis fields at scaled points."""
    first, second = _basis_components(xi, eta, np.zeros_like(xi), np.ones_like(xi))
    return np.stack([np.stack(first, axis=1), np.stack(second, axis=1)], axis=2)


def cell_sums(cells, values, n_cells: int) -> np.ndarray:
    """(M, ...): the sum of ``values`` (P, ...) over each cell's points (np.add.at, by bincount)."""
    flat = values.reshape(values.shape[0], -1)
    sums = [np.bincount(cells, flat[:, j], n_cells) for j in range(flat.shape[1])]
    return np.stack(sums, axis=1).reshape((n_cells,) + values.shape[1:])


def basis_moments(xi, eta, wg, cells, n_cells: int) -> np.ndarray:
    """(M, 12): sum over each cell's points of q_b(xi, eta) . wg for the 12 fields of ``_basis_at``,
    field by field (no (P, 12, 2) array, no products with a constant component) and summed per cell
    with bincount."""
    g0, g1 = wg[:, 0], wg[:, 1]
    first, second = _basis_components(xi, eta, None, 1.0)
    columns = [_times(a, g0, _times(b, g1)) for a, b in zip(first, second, strict=True)]
    return np.stack([np.bincount(cells, column, n_cells) for column in columns], axis=1)


def _times(component, g, plus=None):
    """component * g (+ plus): a component None is zero, the scalar 1.0 is one (no array products)."""
    if component is None:
        return plus
    term = g if isinstance(component, float) else component * g
    return term if plus is None else term + plus


def body_force_p1_k2(mesh: Mesh, body_force, lam: float, mu: float) -> np.ndarray:
    """(n_nodes, 2): int_K P_0 f1 . v dx + int_K (P_1 f1 - P_0 f1) . Pi_2 v dx on every cell.

    Not the paper's choice (which is ``body_force_k2``, P_{k-2} f1 = P_0 f1): with it the L2 error
    is O(h^2) only (the body-force term contributes (h^2/12) int grad f1 : grad z for the dual z).
    In the enhanced virtual element space the moments of v against the zero-mean linear fields are
    those of Pi_2 v, so this is int_K P_1 f1 . v dx there, and the stiffness matrix is unchanged.
    """
    offsets, nodes = cell_nodes(mesh)
    frame = cell_frames(mesh)
    points, weights, cells = reference_quadrature(mesh, degree=5)
    f = np.empty_like(points)  # (P, 2): f1 at the points
    f[:, 0], f[:, 1] = body_force(points[:, 0], points[:, 1])
    xi, eta = np.empty(len(points)), np.empty(len(points))
    mass, moments_f = np.zeros((mesh.n_cells, 3, 3)), np.zeros((mesh.n_cells, 3, 2))
    scaled_points_and_p1_sums(points, weights, cells, frame, f, xi, eta, mass, moments_f)
    p1 = np.linalg.solve(mass, moments_f)  # (M, 3, 2): P_1 f1 = p1[0] + p1[1] xi + p1[2] eta
    moments = np.zeros((mesh.n_cells, N_BASIS))
    p1_basis_moments(xi, eta, weights, cells, p1, moments)  # P_1 f1 - P_0 f1 against the basis
    out = body_force_load_k2(mesh, p1[:, 0])
    _scatter_projected(mesh.vertices, offsets, nodes, float(lam), float(mu), moments, out)
    return out


@numba.njit(cache=True, parallel=True)
def _cell_projections(vertices, offsets, nodes, lam, mu, u, moments, coef, frame, parts):
    """Pi_2 of every cell c (in parallel, CELL_CHUNKS shares), applied both ways: frame[c] = (x_K, y_K,
    h_K); where ``coef`` has rows, coef[c] = Pi_2 of the node values u on c; where ``parts`` has
    entries, parts[2 offsets[c] + j] = sum_b Pi[b, j] moments[c, b] (int_K g . Pi_2 phi_j dx given
    int_K g . q_b dx) for the 2 (2n + 1) local dofs j."""
    n_cells = offsets.shape[0] - 1
    nmax = largest_cell(offsets)
    for chunk in numba.prange(CELL_CHUNKS):
        Pi, rhs, G, sig = projection_workspace(nmax)
        for c in range(chunk * n_cells // CELL_CHUNKS, (chunk + 1) * n_cells // CELL_CHUNKS):
            start = offsets[c]
            size, area, xc, yc, h, m20, m11, m02 = cell_projection(
                vertices, offsets, nodes, c, lam, mu, Pi, rhs, G, sig
            )
            frame[c, 0] = xc
            frame[c, 1] = yc
            frame[c, 2] = h
            if coef.shape[0] > 0:
                for b in range(N_BASIS):
                    acc = 0.0
                    for i in range(size):
                        acc += Pi[b, 2 * i] * u[nodes[start + i], 0] + Pi[b, 2 * i + 1] * u[nodes[start + i], 1]
                    coef[c, b] = acc
            if parts.shape[0] > 0:
                for j in range(2 * size):
                    acc = 0.0
                    for b in range(N_BASIS):
                        acc += Pi[b, j] * moments[c, b]
                    parts[2 * start + j] = acc


@dataclass(frozen=True)
class ProjectedSolutionK2:
    """Pi_2 u on every cell: coefficients (M, 12) in the kernel's basis; frame (M, 3) = (x_K, y_K, h_K)."""

    coef: np.ndarray
    frame: np.ndarray
    degree = 2  # polynomial degree of Pi u on a cell

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

    def cell_mean_strain(self) -> np.ndarray:
        """(M, 3) eps11, eps22, eps12: the cell mean of eps(Pi_2 u_h) (linear: its value at the centroid)."""
        g = self.gradient_at(np.arange(self.frame.shape[0]), self.frame[:, :2])
        return strain_of(g)

    def gradient_at(self, cells: np.ndarray, points: np.ndarray) -> np.ndarray:
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
    no_moments, no_parts = np.empty((0, N_BASIS)), np.empty(0)
    _cell_projections(mesh.vertices, offsets, nodes, float(lam), float(mu), u, no_moments, coef, frame, no_parts)
    return ProjectedSolutionK2(coef, frame)


def interpolate_k2(mesh: Mesh, field, points: int = 5) -> np.ndarray:
    """(n_nodes, 2) degrees of freedom of a field(x, y) -> (f1, f2): vertex values, edge means
    (Gauss-Legendre, ``points`` per edge) and cell means (degree-5 rule on a cell triangulation)."""

    def stacked(x, y):
        f1, f2 = field(x, y)
        return np.stack([np.broadcast_to(f1, np.shape(x)), np.broadcast_to(f2, np.shape(x))], axis=-1)

    t, w = edge_quadrature(points)
    pa, pb = mesh.vertices[mesh.edges[:, 0]], mesh.vertices[mesh.edges[:, 1]]
    x = pa[:, None, :] * (1 - t)[None, :, None] + pb[:, None, :] * t[None, :, None]
    edge_means = np.einsum("q,eqc->ec", w, stacked(x[..., 0], x[..., 1]))
    cell_means = body_force_averages(mesh, field)
    return np.concatenate([stacked(mesh.vertices[:, 0], mesh.vertices[:, 1]), edge_means, cell_means])


def _edge_means(mesh: Mesh, edges: np.ndarray, component, points: int = 5) -> np.ndarray:
    """(k,) the mean over every edge (a, b) of a number or a function of (x, y)."""
    if not callable(component):
        return np.full(edges.shape[0], float(component))
    t, w = edge_quadrature(points)
    pa, pb = mesh.vertices[edges[:, 0]], mesh.vertices[edges[:, 1]]
    x = pa[:, None, :] * (1 - t)[None, :, None] + pb[:, None, :] * t[None, :, None]
    return component_values(component, x[..., 0], x[..., 1]) @ w


def dirichlet_components(mesh: Mesh, dirichlet) -> tuple[np.ndarray, np.ndarray]:
    """(prescribed (n_nodes, 2) bool, values (n_nodes, 2)) of ``dirichlet`` (side names, u = 0, or
    a mapping side -> (u1, u2), each None, a number or a function of (x, y)) on the k = 2 nodes."""
    nv, ne = mesh.n_vertices, mesh.edges.shape[0]
    n_nodes = nv + ne + mesh.n_cells
    prescribed = np.zeros((n_nodes, 2), dtype=bool)
    values = np.zeros((n_nodes, 2))
    prescribed[:nv], values[:nv] = vertex_dirichlet_components(mesh, dirichlet)
    entries = dirichlet.items() if isinstance(dirichlet, dict) else ((side, (0.0, 0.0)) for side in dirichlet)
    for side, components in entries:
        edges = np.asarray(mesh.boundary[side], dtype=np.int64).reshape(-1, 2)
        node = nv + edge_indices(mesh, edges)
        for c, component in enumerate(components):
            if component is None:
                continue
            new = ~prescribed[node, c]
            values[node[new], c] = _edge_means(mesh, edges[new], component)
            prescribed[node[new], c] = True
    return prescribed, values


def node_coordinates(mesh: Mesh) -> np.ndarray:
    """(n_nodes, 2): vertices, edge midpoints and cell centroids (the node order). A rigid motion is
    linear, so its vertex values, edge means and cell means are its values there."""
    mid = 0.5 * (mesh.vertices[mesh.edges[:, 0]] + mesh.vertices[mesh.edges[:, 1]])
    return np.concatenate([mesh.vertices, mid, cell_frames(mesh)[:, :2]])
