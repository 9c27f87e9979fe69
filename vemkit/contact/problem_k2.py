"""The k = 2 discrete contact problem (3.16): stiffness, load and Simpson contact boundary.

``DiscreteProblemK2`` has the interface of ``vemkit.contact.problem.DiscreteProblem`` that the
solvers, the independent check and the solution file use (``stiffness``, ``load``, ``n_dofs``,
``near_nullspace``, ``contact``, ``law``, ``lam``, ``mu``, ``stabilization``, ``dofs.expand``),
so ``ssn``, ``uzawa``, ``vemkit.solvers.dispatch.solve`` and ``verify_solution`` run on it unchanged.

Ingredients (Section 3 with k = 2):
- stiffness: the k = 2 element (3.9) of ``vemkit.vem.element_k2``, clamped nodes eliminated
  (``vemkit.vem.assembly_k2``), other Dirichlet components held by symmetric elimination
  (``vemkit.vem.constraints_k2``);
- load: tractions and pressures integrated exactly on the quadratic traces, the body force through
  P_0 f1 (Section 3.3, k - 2 = 0: it acts on the cell means);
- contact: Simpson's rule at the Gamma_C vertices and edge midpoints, the friction multiplier at
  the same points, the Gamma_C edge unknowns changed from edge means to midpoint values
  (``vemkit.contact.boundary_k2``, which explains the choice);
- the cell means are condensed out cell by cell (``vemkit.vem.condensation_k2``): the unknowns
  (``n_dofs``) are the vertex and edge dofs; ``node_values(u)`` gives back every Section 3.1 degree
  of freedom (edge means, recovered cell means), ``n_space_dofs`` counts them.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
import scipy.sparse as sp

from vemkit.config.boundary_conditions import check_expressions_on_mesh
from vemkit.contact.boundary import ContactBoundary
from vemkit.contact.boundary_k2 import change_variables, check_quadrature, contact_boundary_k2, midpoint_change, midpoint_edges
from vemkit.contact.laws import ContactLaw
from vemkit.contact.problem import scene_problem_data
from vemkit.exceptions import SceneError
from vemkit.mesh.families import scene_mesh
from vemkit.mesh.mesh import Mesh
from vemkit.vem.assembly_k2 import stiffness_matrix_k2
from vemkit.vem.constraints import apply_fixed_dofs, free_rigid_motion
from vemkit.vem.condensation_k2 import cell_load, condense_load, recover_cell_means
from vemkit.vem.constraints_k2 import DofMapK2, constrained_nodes_k2, dirichlet_components_k2
from vemkit.vem.elasticity import lame_parameters, rigid_body_modes
from vemkit.vem.load_k2 import body_force_k2, body_force_p1_k2, cell_frames, pressure_load_k2, traction_load_k2
from vemkit.vem.norms_k2 import ProjectedSolutionK2, projected_solution_k2


@dataclass
class DiscreteProblemK2:
    mesh: Mesh
    dofs: DofMapK2
    stiffness: sp.csr_matrix
    load: np.ndarray
    contact: ContactBoundary
    law: ContactLaw
    lam: float
    mu: float
    stabilization: str
    cell_load: np.ndarray  # (M, 2) the load on the condensed cell nodes, |K| P_0 f1 (for their recovery)
    info: dict = field(default_factory=dict)
    order: ClassVar[int] = 2

    @property
    def n_dofs(self) -> int:
        return self.dofs.n_free

    @property
    def near_nullspace(self) -> np.ndarray:
        """The rigid motions on the unknowns: a rigid motion is linear, so its vertex values, edge
        means, edge midpoint values and cell means are its values at the vertices, the edge
        midpoints and the centroids."""
        return rigid_body_modes(node_coordinates(self.mesh)[self.dofs.nodes.free_nodes])

    @property
    def n_space_dofs(self) -> int:
        """Degrees of freedom of the discrete space on the free nodes, the condensed cell means included."""
        return self.n_dofs + 2 * self.mesh.n_cells

    def node_values(self, u) -> np.ndarray:
        """(n_nodes, 2) the Section 3.1 degrees of freedom of every node (clamped nodes zero), the
        condensed cell means recovered."""
        return recover_cell_means(self.mesh, self.lam, self.mu, self.stabilization, self.dofs.node_values(u),
                                  self.cell_load)

    def projected(self, u) -> ProjectedSolutionK2:
        """Pi_2 u_h (3.8) on every cell."""
        return projected_solution_k2(self.mesh, self.node_values(u), self.lam, self.mu)

    def cell_mean_strain(self, u) -> np.ndarray:
        """(M, 3) eps11, eps22, eps12: the cell mean of eps(Pi_2 u_h) (linear: its value at the centroid)."""
        proj = self.projected(u)
        g = proj.gradient(np.arange(self.mesh.n_cells), proj.frame[:, :2])
        return np.stack([g[:, 0, 0], g[:, 1, 1], 0.5 * (g[:, 0, 1] + g[:, 1, 0])], axis=1)


def node_coordinates(mesh: Mesh) -> np.ndarray:
    """(n_nodes, 2): vertices, edge midpoints and cell centroids (the k = 2 node order)."""
    mid = 0.5 * (mesh.vertices[mesh.edges[:, 0]] + mesh.vertices[mesh.edges[:, 1]])
    return np.concatenate([mesh.vertices, mid, cell_frames(mesh)[:, :2]])


def _check_parts(mesh: Mesh, names) -> None:
    for name in names:
        if name not in mesh.boundary:
            raise SceneError(f"boundary part {name!r} is not in the mesh; parts: {', '.join(sorted(mesh.boundary))}",
                             key="boundary")


def _constrained(mesh: Mesh, dirichlet) -> DofMapK2:
    """The k = 2 dof map of the Dirichlet data; a rigid motion left free is a SceneError."""
    prescribed, values = dirichlet_components_k2(mesh, dirichlet)
    held = np.any(prescribed[: mesh.n_vertices], axis=1)
    motion = free_rigid_motion(mesh.vertices[held], prescribed[: mesh.n_vertices][held])
    if motion is not None:
        raise SceneError(f"boundary.dirichlet leaves {motion} of the body free (the stiffness is singular); "
                         "prescribe a component that stops it, e.g. clamp a side", key="boundary.dirichlet")
    return constrained_nodes_k2(mesh, prescribed, values, condensed=True)


def _load_k2(mesh: Mesh, neumann, pressure, body_force, projection: str, lam: float, mu: float) -> np.ndarray:
    """(n_nodes, 2) load vector: tractions, normal pressures and the body force (Section 3.3), whose
    projection is the paper's P_0 f1 (``projection`` "p0") or P_1 f1 against Pi_2 v ("p1")."""
    f = np.zeros((mesh.n_vertices + mesh.edges.shape[0] + mesh.n_cells, 2))
    for name, traction in (neumann or {}).items():
        f += traction_load_k2(mesh, mesh.boundary[name], traction)
    for name, p in (pressure or {}).items():
        f += pressure_load_k2(mesh, mesh.boundary[name], p)
    if body_force is not None:
        f += body_force_k2(mesh, body_force) if projection == "p0" else body_force_p1_k2(mesh, body_force, lam, mu)
    return f


def discrete_problem_k2(mesh: Mesh, E: float, nu: float, *, dirichlet=("right",), neumann=None, pressure=None,
                        contact=(), gap=lambda x, y: np.zeros_like(x), law: ContactLaw | None = None,
                        body_force=None, stabilization: str = "dofi-2mu",
                        contact_quadrature: str = "nodal", body_force_projection: str = "p0") -> DiscreteProblemK2:
    """Assemble (3.16) with k = 2 (arguments as ``vemkit.contact.problem.discrete_problem``;
    ``body_force_projection``: "p0", the paper's P_0 f1, or "p1", P_1 f1 against Pi_2 v)."""
    _check_parts(mesh, list(dirichlet) + list(neumann or {}) + list(pressure or {}) + list(contact))
    check_quadrature(contact_quadrature)
    lam, mu = lame_parameters(E, nu)
    dofs = _constrained(mesh, dirichlet)
    K = stiffness_matrix_k2(mesh, lam, mu, stabilization, dofs.nodes)
    full_load = _load_k2(mesh, neumann, pressure, body_force, body_force_projection, lam, mu)
    f = condense_load(mesh, lam, mu, stabilization, dofs.nodes, full_load)
    dofs = dofs.with_change(midpoint_change(mesh, dofs, midpoint_edges(mesh, contact, dofs)))
    K, f = change_variables(K, f, dofs.change)
    K, f = apply_fixed_dofs(K, f, dofs)
    cb = contact_boundary_k2(mesh, contact, dofs, gap, contact_quadrature)
    return DiscreteProblemK2(mesh, dofs, K, f, cb, law or ContactLaw(0.0, 1.0, 0.0, 0.0), lam, mu, stabilization,
                             cell_load(mesh, full_load))


def scene_problem_k2(scene, mesh: Mesh | None = None) -> DiscreteProblemK2:
    """Assemble the k = 2 discrete problem of a scene (``discretization.order: 2``)."""
    mesh = scene_mesh(scene) if mesh is None else mesh
    check_expressions_on_mesh(scene, mesh)  # a pole at a vertex: refused, not integrated around
    t0 = time.perf_counter()
    problem = discrete_problem_k2(mesh, scene.E, scene.nu, body_force_projection=scene.body_force_projection,
                                  **scene_problem_data(scene))
    problem.info["assembly_time"] = time.perf_counter() - t0
    problem.info["order"] = 2
    return problem
