"""The virtual element space V_h (3.1) of one element on one mesh: layout, numbering, constraints,
interpolation, traces, loads and the projection of discrete fields.

``VirtualElementSpace(mesh, order)`` (or an :class:`~vemkit.vem.elements.Element`) is the one object
the rest of vemkit asks: how many degrees of freedom there are and where (``n_nodes``,
``node_coordinates``, ``cell_nodes``), how the unknowns are numbered and constrained
(``numbering``, ``constrain``: a :class:`~vemkit.vem.dofs.DofMap`), what a field's degrees of
freedom are (``interpolate``), the trace of a discrete field on the boundary sides
(``boundary_trace``, the trace nodes of an edge and their weights: what the loads and the contact
boundary need), the load vector (``traction_load``, ``pressure_load``, ``body_force_load``), the
stiffness matrix (``stiffness_matrix``) and Pi of a discrete field (``project``).
"""

from __future__ import annotations

from functools import cached_property

import numpy as np

from vemkit.mesh.mesh import Mesh
from vemkit.vem.dofs import DofMap, cell_order_numbering
from vemkit.vem.elements import Element, element_for


class VirtualElementSpace:
    """V_h of ``element`` (or of the element of order ``element``, an int, in the mesh's dimension:
    a :class:`~vemkit.mesh.polyhedral.PolyhedralMesh` is 3D) on ``mesh``. Every node carries d =
    ``element.dimension`` components."""

    def __init__(self, mesh: Mesh, element: Element | int = 1):
        self.mesh = mesh
        if isinstance(element, (int, np.integer)):
            element = element_for(element, mesh.dimension)
        self.element = element

    def __repr__(self) -> str:
        return f"VirtualElementSpace({self.element.name}, {self.mesh.n_cells} cells, {self.n_dofs} dofs)"

    @property
    def order(self) -> int:
        return self.element.order

    @cached_property
    def _node_ranges(self) -> dict:
        return self.element.node_ranges(self.element.entity_counts(self.mesh))

    @property
    def n_nodes(self) -> int:
        return self._node_ranges["cell"].stop

    @property
    def n_dofs(self) -> int:
        """Scalar degrees of freedom of the space (no constraint applied)."""
        return self.element.dimension * self.n_nodes

    @cached_property
    def cell_nodes(self) -> tuple[np.ndarray, np.ndarray]:
        """CSR (offsets, nodes) of every cell's nodes in the element's local order."""
        return self.element.cell_nodes(self.mesh)

    @cached_property
    def node_coordinates(self) -> np.ndarray:
        """(n_nodes, d): where the nodes are (vertices, edge midpoints, cell centroids)."""
        return self.element.node_coordinates(self.mesh)

    def node_range(self, entity: str) -> slice:
        """The global node numbers on one kind of entity ("vertex", "edge", "cell")."""
        return self._node_ranges[entity]

    # -- numbering and constraints ---------------------------------------------------------
    @cached_property
    def _numbering_order(self) -> np.ndarray:
        if self.element.numbering == "cells":
            offsets, nodes = self.cell_nodes
            return cell_order_numbering(self.mesh, offsets, nodes, self.n_nodes)
        return np.arange(self.n_nodes, dtype=np.int64)

    def numbering(self, clamped: np.ndarray | None = None, condensed: bool = False, natural: bool = False) -> DofMap:
        """The unknowns: every node but the ``clamped`` ones (mask (n_nodes,)) and, with ``condensed``,
        the interior nodes, in the element's numbering (``natural``: in node order, dof = d node + c)."""
        free = np.ones(self.n_nodes, dtype=bool) if clamped is None else ~np.asarray(clamped, dtype=bool)
        if condensed and self.element.condensed_nodes:
            free[self.node_range("cell")] = False
        order = np.arange(self.n_nodes, dtype=np.int64) if natural else self._numbering_order
        return DofMap.numbered(
            self.mesh.n_vertices,
            order,
            free,
            condensed=bool(condensed and self.element.condensed_nodes),
            dimension=self.element.dimension,
        )

    def clamped_on(self, edges) -> np.ndarray:
        """(n_nodes,) mask of the trace nodes of the given boundary edges (vertex pairs (k, 2)): what
        ``dirichlet: [side]`` clamps. In 3D ``edges`` are boundary faces (face numbers): their vertices."""
        mask = np.zeros(self.n_nodes, dtype=bool)
        mask[self.element.boundary_nodes(self.mesh, edges)] = True
        return mask

    def dirichlet_components(self, dirichlet) -> tuple[np.ndarray, np.ndarray]:
        """(prescribed (n_nodes, d) bool, values (n_nodes, d)) of ``dirichlet``: side names (u = 0) or
        a mapping side -> (u1, u2) (3D: (u1, u2, u3)), each None (free), a number or a function of
        (x, y) (3D: (x, y, z))."""
        return self.element.dirichlet_components(self.mesh, dirichlet)

    def constrain(self, prescribed: np.ndarray, values: np.ndarray, condensed: bool | None = None) -> DofMap:
        """The dof map of Dirichlet data: clamped nodes (all components prescribed zero) eliminated,
        the other prescribed components fixed dofs of kept nodes; interior nodes condensed (default:
        whenever the element has them)."""
        condensed = bool(self.element.condensed_nodes) if condensed is None else condensed
        clamped = np.all(prescribed, axis=1) & np.all(values == 0.0, axis=1)
        return self.numbering(clamped, condensed).with_fixed(prescribed, values)

    # -- fields ----------------------------------------------------------------------------
    def interpolate(self, field) -> np.ndarray:
        """(n_nodes, d) the degrees of freedom of a field(x, y) -> (f1, f2) (3D: field(x, y, z) -> (f1, f2, f3))."""
        return self.element.interpolate(self.mesh, field)

    def project(self, node_values: np.ndarray, lam: float, mu: float):
        """Pi u_h (3.8) of the degrees of freedom ``node_values`` (n_nodes, d) on every cell."""
        return self.element.project(self.mesh, node_values, lam, mu)

    def edge_nodes(self, edges: np.ndarray) -> np.ndarray:
        """(E, k + 1) the trace nodes of every edge (a, b): its two vertices, then its edge nodes."""
        return self.element.edge_nodes(self.mesh, edges)

    def boundary_trace(self, edges: np.ndarray, node_values: np.ndarray, s: np.ndarray) -> np.ndarray:
        """(E, 2) the trace of a discrete field (n_nodes, 2) at parameter s[e] in [0, 1] of every edge (a, b)."""
        weights = self.element.edge_trace(np.asarray(s, dtype=float))  # (E, k + 1)
        values = np.asarray(node_values, dtype=float).reshape(-1, 2)[self.edge_nodes(edges)]  # (E, k + 1, 2)
        trace = weights[:, 0:1] * values[:, 0]
        for k in range(1, weights.shape[1]):  # node by node, in the trace's order
            trace = trace + weights[:, k : k + 1] * values[:, k]
        return trace

    # -- loads and the stiffness matrix -----------------------------------------------------
    def traction_load(self, edges: np.ndarray, traction) -> np.ndarray:
        """(n_nodes, 2) int_e f2 . phi ds over boundary ``edges`` (k, 2); traction(x, y) -> (f1, f2)."""
        return self.element.traction_load(self.mesh, edges, traction)

    def pressure_load(self, edges: np.ndarray, pressure) -> np.ndarray:
        """(n_nodes, d) the load of a normal pressure p (traction -p nu, docs/reference/files.md) on boundary edges
        (3D: faces)."""
        return self.element.pressure_load(self.mesh, edges, pressure)

    def body_force_load(self, field, lam: float, mu: float, projection: str = "p0") -> np.ndarray:
        """(n_nodes, 2) the body-force load of Section 3.3 (``projection``: the data's projection)."""
        return self.element.body_force_load(self.mesh, field, lam, mu, projection)

    def body_force_averages(self, field) -> np.ndarray:
        """(M, d) the cell averages P_0 f of a body force field(x, y[, z]) (Section 3.3)."""
        return self.element.body_force_averages(self.mesh, field)

    def stiffness_matrix(self, lam: float, mu: float, stabilization: str, dofs: DofMap | None = None):
        """The global stiffness matrix (3.9) on the free dofs of ``dofs`` (``vemkit.vem.assembly``)."""
        from vemkit.vem.assembly import stiffness_matrix

        return stiffness_matrix(self, lam, mu, stabilization, dofs)
