"""The assembled discrete problem (3.16): stiffness, load and contact boundary on the free dofs.

``discrete_problem`` takes plain ingredients (a mesh, Lamé parameters, boundary parts and
callables for the data), so it knows nothing of scene files; ``vemkit.run`` builds it from a scene.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from vemkit.assembly import DofMap, stiffness_matrix
from vemkit.contact.boundary import ContactBoundary, contact_boundary
from vemkit.contact.laws import ContactLaw
from vemkit.linear_solvers import rigid_body_modes
from vemkit.load import body_force_load, cell_averages, traction_load
from vemkit.mesh import Mesh


def lame_parameters(E: float, nu: float):
    """(lambda*, mu) of the paper's (plane stress) C: lambda* = E nu / (1 - nu^2), mu = E / (2 (1 + nu))."""
    return E * nu / (1.0 - nu * nu), E / (2.0 * (1.0 + nu))


@dataclass
class DiscreteProblem:
    mesh: Mesh
    dofs: DofMap
    stiffness: sp.csr_matrix
    load: np.ndarray
    contact: ContactBoundary
    law: ContactLaw
    lam: float
    mu: float
    stabilization: str
    info: dict = field(default_factory=dict)

    @property
    def n_dofs(self) -> int:
        return self.dofs.n_free

    @property
    def near_nullspace(self) -> np.ndarray:
        return rigid_body_modes(self.mesh.vertices[self.dofs.free_vertices])


def _no_force(x, y):
    return np.zeros_like(x), np.zeros_like(x)


def discrete_problem(
    mesh: Mesh,
    E: float,
    nu: float,
    *,
    dirichlet=("right",),
    neumann=None,
    contact=(),
    gap=lambda x, y: np.zeros_like(x),
    law: ContactLaw | None = None,
    body_force=None,
    stabilization: str = "dofi-2mu",
) -> DiscreteProblem:
    """Assemble (3.16) without the contact terms plus the contact boundary data.

    neumann: {part: traction(x, y) -> (f2_1, f2_2)}; body_force(x, y) -> (f1_1, f1_2).
    """
    for name in list(dirichlet) + list(neumann or {}) + list(contact):
        if name not in mesh.boundary:
            raise ValueError(f"boundary part {name!r} is not in the mesh; parts: {', '.join(sorted(mesh.boundary))}")
    lam, mu = lame_parameters(E, nu)
    clamped = np.unique(np.concatenate([mesh.boundary[n].ravel() for n in dirichlet])) if dirichlet else []
    dofs = DofMap.from_clamped(mesh.n_vertices, clamped)
    K = stiffness_matrix(mesh, lam, mu, stabilization, dofs)
    f = np.zeros((mesh.n_vertices, 2))
    for name, traction in (neumann or {}).items():
        f += traction_load(mesh, mesh.boundary[name], traction)
    if body_force is not None:
        from vemkit.triangulate import triangulate_cells

        triangles, parent = triangulate_cells(mesh)
        f += body_force_load(mesh, cell_averages(mesh, body_force, triangles, parent))
    cb = contact_boundary(mesh, contact, dofs, gap)
    return DiscreteProblem(
        mesh, dofs, K, dofs.restrict(f), cb, law or ContactLaw(0.0, 1.0, 0.0, 0.0), lam, mu, stabilization
    )
