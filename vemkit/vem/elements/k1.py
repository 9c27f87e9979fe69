"""The lowest-order element (k = 1, Section 3): the displacement at the vertices.

Its kernel is ``k1_kernel`` (the projection (3.8) from boundary values and the stiffness (3.9)), its
loads and projected fields ``k1_fields``, its numpy twin ``k1_reference``.
"""

from __future__ import annotations

import numpy as np

from vemkit.vem.elements.base import Element


class FirstOrder(Element):
    name = "k1"
    order = 1
    layout = {"vertex": 1}
    condensed_nodes = 0
    numbering = "mesh"
    stress_degree = 0  # Pi_1 u is linear: a constant strain and stress per cell
    # docs/reference/mathematics.md: on triangles V_h is P1, the stiffness that of P1 finite elements
    polynomial_on_triangles = True
    projection_uses_material = False  # Pi_1: the strain is the cell average of eps(v), from boundary values
    # the trapezoid: half of each adjacent edge per vertex (docs/reference/mathematics.md)
    contact_rule = ((0.0, 0.5), (1.0, 0.5))

    kernel_module = "vemkit.vem.elements.k1_kernel"
    fields_module = "vemkit.vem.elements.k1_fields"

    def cell_nodes(self, mesh):
        return mesh.cell_offsets, mesh.cell_vertices

    def node_coordinates(self, mesh) -> np.ndarray:
        return self.fields.node_coordinates(mesh)

    def traction_load(self, mesh, edges, traction) -> np.ndarray:
        return self.fields.traction_load(mesh, edges, traction)

    def body_force_load(self, mesh, field, lam, mu, projection="p0") -> np.ndarray:
        """int_K P_0 f1 . Pi v_h dx (Section 3.3); the k = 1 load has no other projection."""
        from vemkit.vem.quadrature import body_force_averages

        return self.fields.body_force_load(mesh, body_force_averages(mesh, field))

    def project(self, mesh, node_values, lam=None, mu=None):
        return self.fields.projected_solution(mesh, node_values)

    def divergence_table(self, mesh):
        from vemkit.vem.elements.k1_divergence import divergence_2d

        return divergence_2d(mesh)

    def interpolate(self, mesh, field) -> np.ndarray:
        f1, f2 = field(mesh.vertices[:, 0], mesh.vertices[:, 1])
        return np.stack(np.broadcast_arrays(f1, f2), axis=1).astype(float)

    def dirichlet_components(self, mesh, dirichlet):
        return self.fields.dirichlet_components(mesh, dirichlet)

    def edge_trace(self, s) -> np.ndarray:
        s = np.asarray(s, dtype=float)
        return np.stack([1.0 - s, s], axis=1)


ELEMENT = FirstOrder()
