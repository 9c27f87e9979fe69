"""Dirichlet conditions (2.4) and SPEC §7 for k = 2: which node components are prescribed, and the dof map.

The k = 2 degrees of freedom of a Dirichlet side are its vertex values and its edge means
(``vemkit.vem.assembly_k2``). A prescribed component gives

- at the side's vertices: the value there (exactly as for k = 1, ``vemkit.vem.constraints``:
  the side listed first wins at a shared vertex);
- at the side's edges: the edge MEAN of the prescribed value (5-point Gauss-Legendre), the
  degree of freedom itself, so a prescribed quadratic displacement is reproduced exactly.

A node with both components prescribed to exactly zero is *clamped* and eliminated while
assembling (``NodeMapK2.from_clamped_nodes``); every other prescribed component is a fixed dof held
by the symmetric elimination of ``vemkit.vem.constraints.apply_fixed_dofs`` (reused as it is).

``DofMapK2`` is the map between the unknown vector of a k = 2 problem and the degrees of freedom of
Section 3.1. It allows a change of variables ``change`` (a sparse E): the Section 3.1 degrees of
freedom on the free nodes are ``u + E u``. The contact problem uses it to carry the midpoint value
of each Gamma_C edge instead of its edge mean (``vemkit.contact.boundary_k2``); E = None is the
identity.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from vemkit.mesh.mesh import Mesh
from vemkit.vem.assembly_k2 import NodeMapK2, edge_indices
from vemkit.vem.constraints import _values, dirichlet_components

__all__ = ["DofMapK2", "constrained_nodes_k2", "dirichlet_components_k2"]


def _edge_means(mesh: Mesh, edges: np.ndarray, component, points: int = 5) -> np.ndarray:
    """(k,) the mean over every edge (a, b) of a number or a function of (x, y)."""
    from vemkit.vem.load import edge_quadrature

    if not callable(component):
        return np.full(edges.shape[0], float(component))
    t, w = edge_quadrature(points)
    pa, pb = mesh.vertices[edges[:, 0]], mesh.vertices[edges[:, 1]]
    x = pa[:, None, :] * (1 - t)[None, :, None] + pb[:, None, :] * t[None, :, None]
    return _values(component, x[..., 0], x[..., 1]) @ w


def dirichlet_components_k2(mesh: Mesh, dirichlet) -> tuple[np.ndarray, np.ndarray]:
    """(prescribed (n_nodes, 2) bool, values (n_nodes, 2)) of ``dirichlet`` (side names, u = 0, or
    a mapping side -> (u1, u2), each None, a number or a function of (x, y)) on the k = 2 nodes."""
    nv, ne = mesh.n_vertices, mesh.edges.shape[0]
    n_nodes = nv + ne + mesh.n_cells
    prescribed = np.zeros((n_nodes, 2), dtype=bool)
    values = np.zeros((n_nodes, 2))
    prescribed[:nv], values[:nv] = dirichlet_components(mesh, dirichlet)
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


@dataclass(frozen=True)
class DofMapK2:
    """The unknowns of a k = 2 problem: free nodes (``nodes``), fixed dofs held at their values, and
    an optional change of variables E (module docstring). Dof 2 * nodes.free_index[node] + component."""

    mesh: Mesh
    nodes: NodeMapK2
    fixed_dofs: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    fixed_values: np.ndarray = field(default_factory=lambda: np.zeros(0))
    change: sp.csr_matrix | None = None

    @property
    def n_free(self) -> int:
        return self.nodes.n_free

    def with_change(self, change: sp.csr_matrix | None) -> "DofMapK2":
        return DofMapK2(self.mesh, self.nodes, self.fixed_dofs, self.fixed_values, change)

    def dof_values(self, u: np.ndarray) -> np.ndarray:
        """The Section 3.1 degrees of freedom (vertex values, edge and cell means) on the free dofs."""
        u = np.asarray(u, dtype=float)
        return u if self.change is None else u + self.change @ u

    def node_values(self, u: np.ndarray) -> np.ndarray:
        """(n_nodes, 2) degrees of freedom of every node, clamped nodes zero (and the cell means zero when
        they are condensed: ``vemkit.vem.condensation_k2.recover_cell_means`` computes them)."""
        return self.nodes.expand(self.dof_values(u))

    def expand(self, u: np.ndarray) -> np.ndarray:
        """(n_vertices, 2) the displacement at the mesh vertices (as ``DofMap.expand`` for k = 1)."""
        out = np.zeros((self.nodes.n_vertices, 2))
        vertices = self.nodes.free_nodes < self.nodes.n_vertices
        out[self.nodes.free_nodes[vertices]] = np.asarray(u, dtype=float).reshape(-1, 2)[vertices]
        return out

    def unconstrained_nodes(self) -> np.ndarray:
        """(n_nodes,) bool: both components of the node are unknowns (no Dirichlet data)."""
        free = self.nodes.free_index >= 0
        free[self.nodes.free_nodes[np.unique(self.fixed_dofs // 2)]] = False
        return free

    def prescribed_displacement(self) -> np.ndarray:
        """(n_nodes, 2) the Dirichlet data: the fixed values, zero elsewhere."""
        u = np.zeros((self.nodes.n_nodes, 2))
        u.reshape(-1)[2 * self.nodes.free_nodes[self.fixed_dofs // 2] + self.fixed_dofs % 2] = self.fixed_values
        return u


def constrained_nodes_k2(mesh: Mesh, prescribed: np.ndarray, values: np.ndarray, condensed: bool = False) -> DofMapK2:
    """The dof map: clamped nodes (both components prescribed zero) eliminated, the other prescribed
    components fixed dofs of kept nodes (as ``vemkit.vem.constraints.constrained_dofs`` for k = 1);
    ``condensed``: the cell means are eliminated too (``vemkit.vem.condensation_k2``)."""
    clamped = np.all(prescribed, axis=1) & np.all(values == 0.0, axis=1)
    nodes = NodeMapK2.from_clamped_nodes(mesh, clamped, condensed)
    kept = prescribed[nodes.free_nodes]  # (n_free_nodes, 2), in the dof order
    fixed = np.flatnonzero(kept.ravel())
    return DofMapK2(mesh, nodes, fixed, values[nodes.free_nodes].ravel()[fixed].copy())
