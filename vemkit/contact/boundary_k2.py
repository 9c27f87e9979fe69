"""The contact boundary of a k = 2 problem: Simpson's rule on the quadratic traces of Gamma_C edges.

Quadrature. On a Gamma_C edge e = (a, b) the trace of v_h is quadratic (Section 3.1), and the
contact terms of (3.16) are integrated with the three-point Gauss-Lobatto (Simpson) rule:

    int_e g ds  ~  |e|/6 g(x_a) + 4|e|/6 g(x_m) + |e|/6 g(x_b),      x_m the midpoint of e,

for g = p_nu(u_nu - g_a) v_nu and g = p_tau(u_nu - g_a) lambda v_tau. It is the k = 2 counterpart of
the k = 1 nodal (trapezoid) rule of SPEC §3: its points are the nodes of the quadratic trace, so
the terms stay a sum of independent point contributions (a diagonal "lumped" contact operator, one
2 x 2 block per point); its weights are positive, so the discrete normal-compliance operator stays
monotone and the discrete friction functional sum_c w_c k_tau |v_tau(x_c)| stays convex (higher
Newton-Cotes rules have negative weights and lose both); and it is exact for cubics, one degree
more than the quadratic traces of k = 2 need for the linear terms. Each Gamma_C vertex gets |e|/6
from each adjacent contact edge, each edge midpoint 4|e|/6.

Where the multiplier lives: the friction multiplier lambda (5.2)-(5.3) lives at the same points,
the Gamma_C vertices and the Gamma_C edge midpoints, with |lambda_c| <= 1 and lambda_c u_tau(x_c)
= |u_tau(x_c)| point by point; the Uzawa update (5.5) and the semismooth Newton complementarity
function stay point-wise, exactly as at the k = 1 vertices.

Change of variables. The edge degree of freedom is the edge MEAN m_e, so the midpoint value is the
combination u(x_m) = (6 m_e - u_a - u_b) / 4 of three dofs (Simpson is exact for quadratics). The
problem therefore carries, on every Gamma_C edge with a contact midpoint, the midpoint value w_e
as its unknown instead of m_e:

    m_e = (4 w_e + u_a + u_b) / 6,     i.e. the Section 3.1 dofs are T u = u + E u,

with E = 0 except E[m, m] = -1/3, E[m, a] = E[m, b] = 1/6 (per component). The stiffness matrix and
the load become T^T K T and T^T f (the same sparsity: a, b and m belong to the one cell of the
boundary edge), and every contact point reads its (u1, u2) from two unknowns of its own. So
``vemkit.contact.boundary.ContactBoundary`` (nodal quadrature) is reused as it is, and with it
every solver and the independent check. ``ContactBoundary.vertices`` holds k = 2 node indices
here: a mesh vertex v, or n_vertices + e for the midpoint of edge e.

Dropped points: a vertex or an edge with a Dirichlet component (clamped, or a prescribed
component) is not a contact point, as for k = 1: it belongs to the closure of Gamma_D.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from vemkit.contact.boundary import ContactBoundary, _gap_values, edge_ends
from vemkit.exceptions import SceneError
from vemkit.mesh.mesh import Mesh
from vemkit.vem.assembly_k2 import edge_indices
from vemkit.vem.constraints_k2 import DofMapK2

SIMPSON_END, SIMPSON_MID = 1.0 / 6.0, 4.0 / 6.0


def _contact_edges(mesh: Mesh, parts) -> np.ndarray:
    edges = [np.asarray(mesh.boundary[name], dtype=np.int64).reshape(-1, 2) for name in parts]
    return np.concatenate(edges) if edges else np.zeros((0, 2), np.int64)


def check_quadrature(quadrature: str) -> None:
    """SceneError unless ``quadrature`` is nodal (Simpson's rule, the only one for k = 2)."""
    if quadrature != "nodal":
        raise SceneError(f"discretization.contact_quadrature = {quadrature!r} is not available with "
                         "discretization.order = 2 (Simpson's rule at the Gamma_C vertices and edge "
                         "midpoints is used); set contact_quadrature: nodal", key="discretization.contact_quadrature")


def contact_boundary_k2(mesh: Mesh, parts, dofs: DofMapK2, gap, quadrature: str = "nodal") -> ContactBoundary:
    """The Simpson contact points of the named boundary ``parts`` (module docstring).

    ``dofs`` must already carry the midpoint change of variables (``midpoint_change``): the
    contact dofs of an edge midpoint are the unknowns of its edge node. gap(x, y) -> array or a
    FoundationLine."""
    check_quadrature(quadrature)
    edges = _contact_edges(mesh, parts)
    nv = mesh.n_vertices
    length, weighted_normal, weight, nsum = edge_ends(mesh, edges, SIMPSON_END)
    unconstrained = dofs.unconstrained_nodes()
    verts = np.unique(edges)
    verts = verts[unconstrained[verts]]
    vertex_normal = nsum[verts] / np.linalg.norm(nsum[verts], axis=1, keepdims=True)
    mids = midpoint_edges(mesh, parts, dofs)
    edge_node = nv + edge_indices(mesh, edges)
    on_edge = {int(node): k for k, node in enumerate(edge_node)}
    k_mid = np.array([on_edge[int(nv + e)] for e in mids], dtype=np.int64)
    mid_normal = weighted_normal[k_mid] / length[k_mid, None]
    mid_coords = 0.5 * (mesh.vertices[edges[k_mid, 0]] + mesh.vertices[edges[k_mid, 1]])
    node = np.concatenate([verts, nv + mids])
    normal = np.concatenate([vertex_normal, mid_normal]).reshape(-1, 2)
    coords = np.concatenate([mesh.vertices[verts], mid_coords]).reshape(-1, 2)
    w = np.concatenate([weight[verts], SIMPSON_MID * length[k_mid]])
    free = dofs.nodes.free_index[node]
    g = _gap_values(gap, coords, normal)
    tangent = np.stack([-normal[:, 1], normal[:, 0]], axis=1)
    return ContactBoundary(node, np.stack([2 * free, 2 * free + 1], axis=1).reshape(-1, 2), w, normal, tangent, g,
                           coords, "nodal")


def midpoint_edges(mesh: Mesh, parts, dofs: DofMapK2) -> np.ndarray:
    """Indices (in ``mesh.edges``) of the Gamma_C edges whose edge node is a contact point: both
    components unknown (no Dirichlet data on the edge), sorted."""
    edges = _contact_edges(mesh, parts)
    if edges.size == 0:
        return np.zeros(0, np.int64)
    index = np.unique(edge_indices(mesh, edges))
    return index[dofs.unconstrained_nodes()[mesh.n_vertices + index]]


def midpoint_change(mesh: Mesh, dofs: DofMapK2, edges: np.ndarray) -> sp.csr_matrix:
    """E of the module docstring for the given edges (indices in ``mesh.edges``): the edge mean is
    m = w + E w with w the midpoint value, m = (4 w + u_a + u_b) / 6 (clamped ends are zero)."""
    n = dofs.n_free
    free_index = dofs.nodes.free_index
    rows, cols, vals = [], [], []
    m = free_index[mesh.n_vertices + edges]
    ends = free_index[mesh.edges[edges]]  # (k, 2), -1 at clamped ends
    for c in (0, 1):
        rows.append(2 * m + c)
        cols.append(2 * m + c)
        vals.append(np.full(m.size, SIMPSON_MID - 1.0))
        for end in (0, 1):
            keep = ends[:, end] >= 0
            rows.append(2 * m[keep] + c)
            cols.append(2 * ends[keep, end] + c)
            vals.append(np.full(int(keep.sum()), SIMPSON_END))
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))


def change_variables(stiffness: sp.csr_matrix, load: np.ndarray, change: sp.csr_matrix):
    """(T^T K T, T^T f) with T = I + E, E nonzero only in a few rows (the Gamma_C edge nodes).

    With M the rows of E: T^T K T = K + E_M^T K_M + (E_M^T K_M)^T + E_M^T (K_M E), each term
    touching only the rows and columns of M and of the ends of its edges: O(|Gamma_C|) work besides
    one sum with K."""
    rows = np.unique(change.nonzero()[0])
    if rows.size == 0:
        return stiffness, load
    E_M = change[rows]  # (|M|, n)
    K_M = stiffness[rows]  # (|M|, n)
    left = (E_M.T @ K_M).tocsr()  # E^T K
    update = left + left.T + E_M.T @ (K_M @ change)
    K = (stiffness + update).tocsr()
    K.sort_indices()
    return K, load + change.T @ load
