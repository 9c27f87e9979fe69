"""The element interface: what one virtual element tells the space, the assembly and the solvers.

An element is a plug-in (scikit-fem's design): it declares its degrees of freedom per mesh entity
and its local kernels, while one numbering (``vemkit.vem.dofs``), one space
(``vemkit.vem.space.VirtualElementSpace``) and one assembly (``vemkit.vem.assembly``) serve every
element. A *node* is a place that carries one displacement vector (``dimension`` scalars): a
vertex value, an edge mean, a cell mean. Global node numbers run over the entities in the order
vertices, edges, cells (``layout``). Each element module provides:

``order``, ``dimension``, ``layout``
    k of Section 3, d, and the nodes per entity: {"vertex": 1} for k = 1; {"vertex": 1, "edge": 1,
    "cell": 1} for k = 2 (the moments of Section 3.1 scaled as means).
``condensed_nodes``
    how many of a cell's local nodes (its last ones) are interior: they couple only within the cell
    and are eliminated cell by cell (static condensation).
``numbering``
    "mesh": free nodes numbered in the mesh's order; "cells": in the order of their first appearance
    along a Morton curve of the cells (locality when a cell has edge and cell nodes).
``cell_nodes(mesh)``
    CSR (offsets, nodes) of every cell's nodes in the kernel's local order.
``workspace(max_nodes)``, ``cell_matrix(c, geometry, offsets, nodes, lam, mu, stab, work)``
    Numba functions: work arrays, and the local stiffness (3.9) of cell c (consistency plus the
    stabilization S_K scaled by ``stab``) in the leading block of the matrix returned.
``geometry(mesh)``
    what ``cell_matrix`` reads besides the cell's nodes: the vertex coordinates (the default, every
    2D element), or a tuple of arrays (the 3D element: coordinates and the cells' faces).
``traction_load(mesh, edges, traction)``, ``body_force_load(mesh, field, lam, mu, projection)``
    the load vector of Section 3.3, (n_nodes, d) (3D: boundary faces instead of edges).
``project(mesh, node_values, lam, mu)``
    Pi u_h (3.8) on every cell: an object with ``evaluate(cells, points)``,
    ``gradient_at(cells, points)`` and ``cell_mean_strain()``; ``projection_uses_material``: whether
    Pi depends on the Lame parameters (the energy projection of k >= 2 does; k = 1's is geometric).
``interpolate(mesh, field)``, ``dirichlet_components(mesh, dirichlet)``, ``node_coordinates(mesh)``
    the degrees of freedom of a field, of Dirichlet data, and where the nodes are.
``edge_trace(s)``
    (P, k + 1) the weights of the trace on an edge at parameters s in [0, 1] on the edge's nodes
    (its two vertices, then its edge nodes).
``divergence_table(mesh)``
    k = 1 only: (weights, measures), the divergence of Pi v on every cell as a linear form of its
    vertex values and the cells' measures (``k1_divergence``): what the nodal averaging of the
    volumetric strain reads (``vemkit.vem.volumetric``). Other elements refuse it.
``contact_rule``
    the nodal quadrature on Gamma_C: (parameter, weight) per trace node of an edge -- the
    trapezoid for k = 1, Simpson's rule for k = 2 (``vemkit.contact.boundary``).
"""

from __future__ import annotations

from collections.abc import Callable
from importlib import import_module
from typing import Any

import numpy as np

STABILIZATIONS = ("dofi", "dofi-2mu", "trace")


def stabilization_code(name: str) -> int:
    """The kernels' code of a stabilization scaling alpha_K (docs/reference/mathematics.md): 0 dofi, 1 dofi-2mu, 2 trace."""
    try:
        return STABILIZATIONS.index(name)
    except ValueError:
        raise ValueError(f"stabilization {name!r} is unknown; use one of {', '.join(STABILIZATIONS)}") from None


ENTITIES = ("vertex", "edge", "cell")  # the order of global node numbers


class Element:
    """The interface (module docstring); the elements are the subclasses in ``k1`` and ``k2``."""

    name: str
    order: int
    dimension: int = 2
    layout: dict
    condensed_nodes: int = 0
    numbering: str = "mesh"
    projection_uses_material: bool = True
    default_body_force_projection: str = "p0"  # the body-force load's projection of f1 (Section 3.3)
    stress_degree: int = 1  # degree of sigma(Pi u_h) on a cell: k - 1
    polynomial_on_triangles: bool = False  # V_h^K = [P_k]^2 on triangles: Pi = I, the stabilization vanishes
    contact_rule: tuple  # ((s, weight), ...) per trace node of an edge, in ``edge_trace`` order

    kernel_module: str  # the module of the element's Numba hooks ``workspace`` and ``cell_matrix``
    fields_module: str  # the module of its loads, projected fields and interpolation

    # the hooks every element class defines (module docstring), declared for the type checker
    cell_nodes: Callable[..., tuple]
    node_coordinates: Callable[..., Any]
    dirichlet_components: Callable[..., tuple]
    interpolate: Callable[..., Any]
    project: Callable[..., Any]
    edge_trace: Callable[..., Any]
    traction_load: Callable[..., Any]
    body_force_load: Callable[..., Any]

    # the kernels and fields are imported on first use: the element's facts (layout, ...) cost no Numba import
    @property
    def workspace(self):
        return import_module(self.kernel_module).workspace

    @property
    def cell_matrix(self):
        return import_module(self.kernel_module).cell_matrix

    @property
    def fields(self):
        return import_module(self.fields_module)

    def divergence_table(self, mesh):
        """(weights, measures) of ``k1_divergence``; only elements with a constant strain per cell have it."""
        raise ValueError(f"the {self.name} element has no constant divergence per cell: no nodal averaging")

    def body_force_averages(self, mesh, field) -> np.ndarray:
        """(M, d) P_0 f on every cell of a field f(x, y) -> (f1, f2): the averages the k = 1 load and
        the estimator's volume residual read (a triangulation of each polygon)."""
        from vemkit.vem.quadrature import body_force_averages

        return body_force_averages(mesh, field)

    def geometry(self, mesh):
        """The first argument of ``cell_matrix`` (module docstring): the vertex coordinates."""
        return mesh.vertices

    def pressure_load(self, mesh, edges, pressure):
        """(n_nodes, d) the load of a normal pressure p on boundary ``edges`` (traction -p nu, docs/reference/files.md):
        the traction load of -p nu (``vemkit.vem.quadrature.pressure_traction``)."""
        from vemkit.vem.quadrature import pressure_traction

        edges, traction = pressure_traction(mesh, edges, pressure)
        return self.traction_load(mesh, edges, traction)

    def edge_nodes(self, mesh, edges) -> np.ndarray:
        """(E, k + 1) the trace nodes of every edge (a, b): its two vertices, then its edge nodes."""
        from vemkit.mesh.mesh import edge_indices

        edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
        if "edge" not in self.layout:
            return edges
        return np.concatenate([edges, self.first_node(mesh, "edge") + edge_indices(mesh, edges)[:, None]], axis=1)

    def boundary_nodes(self, mesh, sides) -> np.ndarray:
        """The nodes on boundary ``sides`` (edges (k, 2) of a side; 3D elements: face numbers): what
        ``dirichlet: [side]`` clamps. On edges, their trace nodes (``edge_nodes``)."""
        edges = np.asarray(sides, dtype=np.int64).reshape(-1, 2)
        return self.edge_nodes(mesh, edges).ravel() if edges.size else np.zeros(0, dtype=np.int64)

    def __repr__(self) -> str:
        return f"<{self.name} virtual element (k = {self.order}, d = {self.dimension})>"

    def entity_counts(self, mesh) -> dict:
        """{entity: how many the mesh has}, in node order (edges counted only where the element has
        nodes on them: a mesh's edge table is built on demand)."""
        return {
            "vertex": mesh.n_vertices,
            "edge": mesh.edges.shape[0] if "edge" in self.layout else 0,
            "cell": mesh.n_cells,
        }

    def node_ranges(self, counts: dict) -> dict:
        """{entity: slice of the global node numbers on it} for entity ``counts`` (vertices, edges, cells)."""
        ranges, first = {}, 0
        for entity in ENTITIES:
            stop = first + self.layout.get(entity, 0) * int(counts[entity])
            ranges[entity], first = slice(first, stop), stop
        return ranges

    def n_nodes(self, mesh) -> int:
        return self.node_ranges(self.entity_counts(mesh))["cell"].stop

    def first_node(self, mesh, entity: str) -> int:
        """The global number of the first node on ``entity`` (nodes run vertices, edges, cells)."""
        return self.node_ranges(self.entity_counts(mesh))[entity].start

    def count_dofs(self, vertices: int, edges: int, cells: int) -> int:
        """Scalar degrees of freedom of the space on a mesh with these entity counts (resource checks)."""
        return self.dimension * self.node_ranges({"vertex": vertices, "edge": edges, "cell": cells})["cell"].stop
