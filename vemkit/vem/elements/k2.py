"""The second-order element (k = 2, Section 3, Fig. 1 right): vertex values, edge means, cell means.

Its kernels are ``k2_kernel`` (the projection Pi_2 (3.8)) and ``k2_stiffness`` (the stiffness (3.9)
in low-rank form), its nodes, loads and projected fields ``k2_fields``, its numpy twin
``k2_reference``. The cell mean couples only within its cell: it is condensed out.
"""

from __future__ import annotations

import numpy as np

from vemkit.config.loads import DEFAULT_BODY_FORCE_PROJECTION_K2
from vemkit.vem.elements.base import Element


class SecondOrder(Element):
    name = "k2"
    order = 2
    layout = {"vertex": 1, "edge": 1, "cell": 1}
    condensed_nodes = 1
    numbering = "cells"
    # P_1 f1 against Pi_2 v: L2 order 3 (the paper's P_0 f1 caps it at 2; README "Order 2"); the scene's default
    default_body_force_projection = DEFAULT_BODY_FORCE_PROJECTION_K2
    # Simpson's rule at the trace nodes: |e|/6 at each vertex, 4|e|/6 at the midpoint (vemkit.contact.boundary)
    contact_rule = ((0.0, 1.0 / 6.0), (1.0, 1.0 / 6.0), (0.5, 4.0 / 6.0))

    kernel_module = "vemkit.vem.elements.k2_stiffness"
    fields_module = "vemkit.vem.elements.k2_fields"

    def cell_nodes(self, mesh):
        return self.fields.cell_nodes(mesh)

    def node_coordinates(self, mesh) -> np.ndarray:
        return self.fields.node_coordinates(mesh)

    def traction_load(self, mesh, edges, traction) -> np.ndarray:
        return self.fields.traction_load_k2(mesh, edges, traction)

    def body_force_load(self, mesh, field, lam, mu, projection="p0") -> np.ndarray:
        """P_0 f1 on the cell means (the paper's P_{k-2} f1) or P_1 f1 against Pi_2 v ("p1")."""
        if projection == "p0":
            return self.fields.body_force_k2(mesh, field)
        return self.fields.body_force_p1_k2(mesh, field, lam, mu)

    def project(self, mesh, node_values, lam, mu):
        return self.fields.projected_solution_k2(mesh, node_values, lam, mu)

    def interpolate(self, mesh, field) -> np.ndarray:
        return self.fields.interpolate_k2(mesh, field)

    def dirichlet_components(self, mesh, dirichlet):
        return self.fields.dirichlet_components(mesh, dirichlet)

    def edge_trace(self, s) -> np.ndarray:
        return self.fields.trace_weights(np.asarray(s, dtype=float))


ELEMENT = SecondOrder()
