"""The contact points of Gamma_C: the trace nodes of the space on its edges, with the element's nodal rule.

Quadrature (``Element.contact_rule``): the contact terms of (3.16) are integrated by a rule whose
points are the nodes of the trace on each Gamma_C edge e = (a, b):

- k = 1, the trapezoid (docs/reference/mathematics.md): |e|/2 at each end (a Gamma_C vertex gets half of each adjacent edge);
- k = 2, Simpson's rule (three-point Gauss-Lobatto): |e|/6 at each end, 4|e|/6 at the midpoint x_m.

Both are the rule whose points are the nodes of the trace, so the terms stay a sum of independent
point contributions (a diagonal "lumped" contact operator, one 2 x 2 block per point); their
weights are positive, so the discrete normal-compliance operator stays monotone and the friction
functional sum_c w_c k_tau |v_tau(x_c)| convex (higher Newton-Cotes rules have negative weights and
lose both); Simpson is exact for cubics, one degree more than the quadratic traces of k = 2 need
for the linear terms. The friction multiplier lives at the same points, with |lambda_c| <= 1 and
lambda_c u_tau(x_c) = |u_tau(x_c)| point by point, exactly as at the k = 1 vertices.

Change of variables. The k = 2 edge degree of freedom is the edge MEAN m_e, so the midpoint value is
a combination of three dofs; since Simpson's rule is exact for the quadratic trace,

    m_e = w_end u_a + w_mid w_e + w_end u_b      (w_end = 1/6, w_mid = 4/6, the rule's weights),

and the problem carries, on every Gamma_C edge with a contact midpoint, the midpoint value w_e as
its unknown instead of m_e: the Section 3.1 dofs are T u = u + E u, E = 0 except E[m, m] = w_mid - 1,
E[m, a] = E[m, b] = w_end (per component). The stiffness matrix and the load become T^T K T and
T^T f (the same sparsity: a, b and m belong to the one cell of the boundary edge), and every
contact point reads its (u1, u2) from two unknowns of its own, so one contact boundary and every
solver serve both elements.

Dropped points: a vertex or an edge with a Dirichlet component (clamped, or a prescribed
component) is not a contact point: it belongs to the closure of Gamma_D.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from vemkit.mesh.mesh import edge_indices


def contact_edges(mesh, parts) -> np.ndarray:
    """(E, 2) the boundary edges of the named parts, as stored."""
    edges = [np.asarray(mesh.boundary[name], dtype=np.int64).reshape(-1, 2) for name in parts]
    return np.concatenate(edges) if edges else np.zeros((0, 2), np.int64)


def rule_weights(element) -> tuple[float, float | None]:
    """(end weight, midpoint weight or None) of the element's nodal rule on Gamma_C."""
    rule = element.contact_rule
    return rule[0][1], (rule[2][1] if len(rule) > 2 else None)


def midpoint_edges(space, parts, dofs) -> np.ndarray:
    """Indices (in ``mesh.edges``) of the Gamma_C edges whose edge node is a contact point: both
    components unknown (no Dirichlet data on the edge), sorted; none for an element without edge nodes
    (k = 1, the 3D element): the element's layout says whether its facets carry nodes."""
    if not space.element.layout.get("edge", 0):
        return np.zeros(0, np.int64)
    edges = contact_edges(space.mesh, parts)
    if edges.size == 0:
        return np.zeros(0, np.int64)
    index = np.unique(edge_indices(space.mesh, edges))
    return index[dofs.unconstrained_nodes()[space.node_range("edge").start + index]]


def midpoint_change(space, dofs, edges: np.ndarray) -> sp.csr_matrix | None:
    """E of the module docstring for the given edges (indices in ``mesh.edges``): the edge mean is
    m = w + E w with w the midpoint value (clamped ends are zero); None when there are no such edges."""
    if edges.size == 0:
        return None
    w_end, w_mid = rule_weights(space.element)
    n = dofs.n_free
    free_index = dofs.free_index
    rows, cols, vals = [], [], []
    m = free_index[space.node_range("edge").start + edges]
    ends = free_index[space.mesh.edges[edges]]  # (k, 2), -1 at clamped ends
    d = dofs.dimension  # every node carries d components: dof = d node + c
    for c in range(d):
        rows.append(d * m + c)
        cols.append(d * m + c)
        vals.append(np.full(m.size, w_mid - 1.0))
        for end in (0, 1):
            keep = ends[:, end] >= 0
            rows.append(d * m[keep] + c)
            cols.append(d * ends[keep, end] + c)
            vals.append(np.full(int(keep.sum()), w_end))
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))


def change_variables(stiffness: sp.csr_matrix, load: np.ndarray, change: sp.csr_matrix | None):
    """(T^T K T, T^T f) with T = I + E, E nonzero only in a few rows (the Gamma_C edge nodes).

    With M the rows of E: T^T K T = K + E_M^T K_M + (E_M^T K_M)^T + E_M^T (K_M E), each term
    touching only the rows and columns of M and of the ends of its edges: O(|Gamma_C|) work besides
    one sum with K."""
    if change is None:
        return stiffness, load
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
