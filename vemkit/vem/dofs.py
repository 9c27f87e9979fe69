"""One numbering for every element: which nodes carry unknowns, and how Dirichlet data holds the rest.

A :class:`DofMap` maps the unknown vector of a problem to the nodes of a space (vertices, edges,
cells; ``vemkit.vem.elements.base``): dof = d * free_index[node] + component, d the ``dimension``
(2, or 3 for the 3D element).

- A node with all its components prescribed to exactly zero is *clamped*: eliminated while assembling,
  as the paper's u = 0 on Gamma_D (2.4).
- With ``condensed`` the interior nodes (the k = 2 cell means) carry no unknowns either: they are
  eliminated cell by cell (``vemkit.vem.condensation``).
- Every other prescribed component is a *fixed dof* of a kept node (a roller's component, a non-zero
  prescribed displacement): after assembly its column times the value moves to the right-hand side,
  its row and column are zeroed and the diagonal entry K_ii kept, with f_i = K_ii g_i
  (:func:`apply_fixed_dofs`, symmetric elimination: the system stays symmetric positive definite
  and u_i = g_i exactly in its solution).
- An optional change of variables ``change`` (a sparse E): the degrees of freedom of Section 3.1 on
  the free nodes are ``u + E u``. The k = 2 contact boundary uses it to carry the midpoint value of
  each Gamma_C edge instead of its edge mean (``vemkit.contact.boundary``); None is the identity.

The order of the free nodes is the element's ``numbering`` (``numbered``): the mesh's own order
(k = 1), or the order of first appearance in the cells taken along a Morton curve (locality for the
parallel row-chunk scatter and the caches). Vectors always go through ``restrict`` and ``expand``.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numba
import numpy as np
import scipy.sparse as sp

from vemkit.mesh.mesh import Mesh

__all__ = ["DofMap", "apply_fixed_dofs", "morton_order"]


@dataclass(frozen=True)
class DofMap:
    """The unknowns of a problem on ``n_nodes`` nodes, the first ``n_vertices`` of them the vertices."""

    n_vertices: int
    free_nodes: np.ndarray
    free_index: np.ndarray  # (n_nodes,), -1 where the node carries no unknown
    fixed_dofs: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    fixed_values: np.ndarray = field(default_factory=lambda: np.zeros(0))
    condensed: bool = False
    change: sp.csr_matrix | None = None
    dimension: int = 2  # d: the components of every node

    @property
    def n_nodes(self) -> int:
        return self.free_index.size

    @property
    def n_free(self) -> int:
        return self.dimension * self.free_nodes.size

    @property
    def clamped_nodes(self) -> np.ndarray:
        return np.flatnonzero(self.free_index < 0)

    def with_change(self, change: sp.csr_matrix | None) -> "DofMap":
        return replace(self, change=change)

    def with_fixed(self, prescribed: np.ndarray, values: np.ndarray) -> "DofMap":
        """The fixed dofs: the prescribed (n_nodes, d) components of the kept nodes, held at ``values``."""
        fixed = np.flatnonzero(prescribed[self.free_nodes].ravel())
        return replace(self, fixed_dofs=fixed, fixed_values=values[self.free_nodes].ravel()[fixed].copy())

    def unconstrained_nodes(self) -> np.ndarray:
        """(n_nodes,) bool: all components of the node are unknowns (no Dirichlet data)."""
        free = self.free_index >= 0
        free[self.free_nodes[np.unique(self.fixed_dofs // self.dimension)]] = False
        return free

    def prescribed_displacement(self) -> np.ndarray:
        """(n_nodes, d) the Dirichlet data: the fixed values, zero elsewhere."""
        d = self.dimension
        u = np.zeros((self.n_nodes, d))
        u.reshape(-1)[d * self.free_nodes[self.fixed_dofs // d] + self.fixed_dofs % d] = self.fixed_values
        return u

    def dof_values(self, u: np.ndarray) -> np.ndarray:
        """The Section 3.1 degrees of freedom on the free dofs (the change of variables undone)."""
        u = np.asarray(u, dtype=float)
        return u if self.change is None else u + self.change @ u

    def unknowns(self, node_values: np.ndarray) -> np.ndarray:
        """The unknown vector of given degrees of freedom (n_nodes, d): ``restrict`` with the change of
        variables inverted (its rows hold the changed dof on the diagonal and unchanged dofs besides)."""
        d = self.restrict(node_values).astype(float)
        if self.change is None:
            return d
        diagonal = self.change.diagonal()
        rows = np.flatnonzero(diagonal)
        off = self.change - sp.diags(diagonal)
        d[rows] = (d[rows] - (off @ d)[rows]) / (1.0 + diagonal[rows])
        return d

    def node_values(self, u: np.ndarray, clamped_values: np.ndarray | None = None) -> np.ndarray:
        """(n_nodes, d) degrees of freedom of every node; clamped nodes zero or ``clamped_values``,
        condensed interior nodes zero (``vemkit.vem.condensation.recover_interior`` computes them)."""
        d = self.dimension
        out = np.zeros((self.n_nodes, d)) if clamped_values is None else np.array(clamped_values, float)
        out[self.free_nodes] = self.dof_values(u).reshape(-1, d)
        return out

    def expand(self, u: np.ndarray) -> np.ndarray:
        """(n_vertices, d) the displacement at the mesh vertices, zero at clamped vertices."""
        out = np.zeros((self.n_vertices, self.dimension))
        vertices = self.free_nodes < self.n_vertices
        out[self.free_nodes[vertices]] = np.asarray(u, dtype=float).reshape(-1, self.dimension)[vertices]
        return out

    def restrict(self, node_values: np.ndarray) -> np.ndarray:
        """(n_nodes, d) -> free-dof vector."""
        return np.ascontiguousarray(np.asarray(node_values)[self.free_nodes]).ravel()

    @classmethod
    def numbered(
        cls, n_vertices: int, order: np.ndarray, free: np.ndarray, condensed: bool = False, dimension: int = 2
    ) -> "DofMap":
        """The free nodes (mask ``free``, (n_nodes,)) numbered in ``order`` (every node, the numbering)."""
        free_nodes = order[free[order]]
        free_index = np.full(free.size, -1, dtype=np.int64)
        free_index[free_nodes] = np.arange(free_nodes.size)
        return cls(int(n_vertices), free_nodes, free_index, condensed=condensed, dimension=int(dimension))


def morton_order(mesh: Mesh) -> np.ndarray:
    """The cells sorted along a Z-order (Morton) curve of their vertex means: neighbours stay near."""
    count = np.maximum(mesh.cell_sizes, 1)
    centre = np.stack(
        [
            np.bincount(mesh.half_edge_cells, mesh.vertices[mesh.cell_vertices, k], mesh.n_cells) / count
            for k in range(2)
        ],
        axis=1,
    )
    lo, hi = centre.min(axis=0), centre.max(axis=0)
    q = ((centre - lo) / np.maximum(hi - lo, 1e-300) * 65535).astype(np.uint64)
    code = np.zeros(mesh.n_cells, dtype=np.uint64)
    for bit in range(16):
        for k in range(2):
            code |= ((q[:, k] >> np.uint64(bit)) & np.uint64(1)) << np.uint64(2 * bit + k)
    return np.argsort(code, kind="stable")


@numba.njit(cache=True)
def first_appearance(nodes, n_nodes):
    """The nodes in the order of their first appearance in a list of cell nodes: the dof numbering.

    Rows of one cell then lie close together, so the row chunks of the parallel assembly share few
    cells (vertices, edges and cells numbered apart would make every cell straddle three chunks),
    and with the cells in Morton order the rows a cell writes stay in cache."""
    seen = np.zeros(n_nodes, dtype=np.bool_)
    order = np.empty(n_nodes, dtype=np.int64)
    k = 0
    for p in range(nodes.shape[0]):
        if not seen[nodes[p]]:
            seen[nodes[p]] = True
            order[k] = nodes[p]
            k += 1
    return order[:k]


def cell_order_numbering(mesh: Mesh, offsets: np.ndarray, nodes: np.ndarray, n_nodes: int) -> np.ndarray:
    """Every node that belongs to a cell, in the order of its first appearance along the Morton curve."""
    cells = morton_order(mesh)
    sizes = offsets[cells + 1] - offsets[cells]
    idx = np.repeat(offsets[cells] - np.cumsum(sizes) + sizes, sizes) + np.arange(int(sizes.sum()))
    return first_appearance(nodes[idx], n_nodes)


@numba.njit(cache=True)
def _kept(i, j, value, held):
    """Whether entry (i, j) stays: a held row keeps its diagonal only, a free row its entries off the
    held columns that are not stored zeros."""
    return (j == i) if held[i] else (not held[j] and value != 0.0)


@numba.njit(cache=True, parallel=True)
def _held_out(indptr, indices, data, held):
    """The CSR arrays of A without the rows and columns of the held dofs, a held row keeping only its
    diagonal entry, and without A's stored zeros (as zeroing, eliminate_zeros and adding the diagonal
    back would give), its rows counted and then copied on the threads."""
    n = indptr.shape[0] - 1
    out_indptr = np.zeros(n + 1, dtype=np.int64)
    for i in numba.prange(n):
        count = 0
        for p in range(indptr[i], indptr[i + 1]):
            count += _kept(i, indices[p], data[p], held)
        out_indptr[i + 1] = count
    out_indptr = np.cumsum(out_indptr)
    out_indices = np.empty(out_indptr[n], dtype=indices.dtype)
    out_data = np.empty(out_indptr[n], dtype=data.dtype)
    for i in numba.prange(n):
        q = out_indptr[i]
        for p in range(indptr[i], indptr[i + 1]):
            if _kept(i, indices[p], data[p], held):
                out_indices[q] = indices[p]
                out_data[q] = data[p]
                q += 1
    return out_data, out_indices, out_indptr


def apply_fixed_dofs(stiffness: sp.csr_matrix, load: np.ndarray, dofs: DofMap):
    """(K, f) with the fixed dofs held at their values by symmetric elimination (module doc)."""
    if dofs.fixed_dofs.size == 0:
        return stiffness, load
    fixed, g = dofs.fixed_dofs, dofs.fixed_values
    load = load - stiffness[:, fixed] @ g
    K = stiffness.tocsr()
    K.sum_duplicates()  # canonical: sorted, one entry per position (a no-op for the assembled matrix)
    held = np.zeros(K.shape[0], dtype=np.bool_)
    held[fixed] = True
    K = sp.csr_matrix(_held_out(K.indptr, K.indices, K.data, held), shape=K.shape)
    K.has_canonical_format = True
    # a held row keeps its diagonal entry only (none where K stores none): K's diagonal there
    stored = K.indptr[fixed + 1] > K.indptr[fixed]
    diagonal = np.zeros(fixed.size, dtype=K.dtype)
    diagonal[stored] = K.data[K.indptr[fixed[stored]]]
    load[fixed] = diagonal * g
    return K, load
