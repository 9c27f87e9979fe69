"""The assembled discrete problem (3.16): stiffness, load and contact boundary on the free dofs.

``discrete_problem`` takes plain ingredients (a mesh, Lamé parameters, boundary parts and
callables for the data), so it knows nothing of scene files; ``scene_problem`` builds it from a scene.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import time

import numpy as np
import scipy.sparse as sp

from vemkit.exceptions import SceneError
from vemkit.vem.assembly import DofMap, stiffness_matrix
from vemkit.contact.boundary import ContactBoundary, contact_boundary
from vemkit.contact.laws import ContactLaw
from vemkit.vem.load import body_force_load, cell_averages, traction_load
from vemkit.mesh.families import scene_mesh
from vemkit.mesh.mesh import Mesh
from vemkit.vem.elasticity import lame_parameters, rigid_body_modes


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
    contact_quadrature: str = "nodal",
    contact_gauss_points: int = 3,
) -> DiscreteProblem:
    """Assemble (3.16) without the contact terms plus the contact boundary data.

    neumann: {part: traction(x, y) -> (f2_1, f2_2)}; body_force(x, y) -> (f1_1, f1_2).
    contact_quadrature: nodal or gauss (with contact_gauss_points per edge), see vemkit.contact.boundary.
    """
    for name in list(dirichlet) + list(neumann or {}) + list(contact):
        if name not in mesh.boundary:
            raise SceneError(f"boundary part {name!r} is not in the mesh; parts: {', '.join(sorted(mesh.boundary))}",
                             key="boundary")
    lam, mu = lame_parameters(E, nu)
    clamped = np.unique(np.concatenate([mesh.boundary[n].ravel() for n in dirichlet])) if dirichlet else []
    dofs = DofMap.from_clamped(mesh.n_vertices, clamped)
    K = stiffness_matrix(mesh, lam, mu, stabilization, dofs)
    f = np.zeros((mesh.n_vertices, 2))
    for name, traction in (neumann or {}).items():
        f += traction_load(mesh, mesh.boundary[name], traction)
    if body_force is not None:
        from vemkit.mesh.triangulate import triangulate_cells

        triangles, parent = triangulate_cells(mesh)
        f += body_force_load(mesh, cell_averages(mesh, body_force, triangles, parent))
    cb = contact_boundary(mesh, contact, dofs, gap, contact_quadrature, contact_gauss_points)
    return DiscreteProblem(
        mesh, dofs, K, dofs.restrict(f), cb, law or ContactLaw(0.0, 1.0, 0.0, 0.0), lam, mu, stabilization
    )


def _pair(expressions):
    fx, fy = expressions

    def field(x, y):
        return np.broadcast_to(fx(x, y), np.shape(x)), np.broadcast_to(fy(x, y), np.shape(x))

    return field


def scene_problem(scene, mesh: Mesh | None = None) -> DiscreteProblem:
    """Assemble the discrete problem (3.16) of a scene, on its own mesh unless one is given."""
    mesh = scene_mesh(scene) if mesh is None else mesh
    body = None
    if any(not (e.is_constant and float(e(0.0, 0.0)) == 0.0) for e in scene.body_force):
        body = _pair(scene.body_force)
    normal, friction = scene.normal_compliance, scene.friction_bound
    law = ContactLaw(normal.k, normal.m, friction.k, friction.m) if normal is not None else None
    gap = scene.gap_expression
    t0 = time.perf_counter()
    problem = discrete_problem(
        mesh,
        scene.E,
        scene.nu,
        dirichlet=scene.dirichlet_sides,
        neumann={side: _pair(scene.traction(side)) for side in scene.neumann_sides},
        contact=scene.contact_sides,
        gap=(lambda x, y: np.broadcast_to(gap(x, y), np.shape(x))) if gap is not None else (lambda x, y: np.zeros_like(x)),
        law=law,
        body_force=body,
        stabilization=scene.stabilization,
        contact_quadrature=scene.contact_quadrature,
        contact_gauss_points=scene.contact_gauss_points,
    )
    problem.info["assembly_time"] = time.perf_counter() - t0
    return problem
