"""The assembled discrete problem (3.16): stiffness, load and contact boundary on the free dofs.

``discrete_problem`` takes plain ingredients (a mesh, Lamé parameters, boundary parts and
callables for the data), so it knows nothing of scene files; ``scene_problem`` builds it from a scene.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import time

import numpy as np
import scipy.sparse as sp

from vemkit.config.boundary_conditions import check_expressions_on_mesh, rigid_motion_error
from vemkit.config.expressions import vector_field
from vemkit.exceptions import SceneError
from vemkit.vem.assembly import DofMap, stiffness_matrix
from vemkit.vem.constraints import apply_fixed_dofs, constrained_dofs, dirichlet_components, free_rigid_motion
from vemkit.contact.boundary import ContactBoundary, FoundationLine, contact_boundary
from vemkit.contact.laws import ContactLaw
from vemkit.vem.load import body_force_load, cell_averages, pressure_load, traction_load
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
    pressure=None,
    contact=(),
    gap=lambda x, y: np.zeros_like(x),
    law: ContactLaw | None = None,
    body_force=None,
    stabilization: str = "dofi-2mu",
    contact_quadrature: str = "nodal",
    contact_gauss_points: int = 3,
) -> DiscreteProblem:
    """Assemble (3.16) without the contact terms plus the contact boundary data.

    dirichlet: side names (u = 0) or {part: (u1, u2)}, each None (free), a number or a function
    of (x, y) (see vemkit.vem.constraints); a rigid motion left free is a SceneError.
    neumann: {part: traction(x, y) -> (f2_1, f2_2)}; pressure: {part: p(x, y)} (traction -p nu);
    body_force(x, y) -> (f1_1, f1_2).
    contact_quadrature: nodal or gauss (with contact_gauss_points per edge), see vemkit.contact.boundary.
    """
    for name in list(dirichlet) + list(neumann or {}) + list(pressure or {}) + list(contact):
        if name not in mesh.boundary:
            raise SceneError(f"boundary part {name!r} is not in the mesh; parts: {', '.join(sorted(mesh.boundary))}",
                             key="boundary")
    lam, mu = lame_parameters(E, nu)
    prescribed, values = dirichlet_components(mesh, dirichlet)
    motion = free_rigid_motion(mesh.vertices[np.any(prescribed, axis=1)], prescribed[np.any(prescribed, axis=1)])
    if motion is not None:
        raise rigid_motion_error(motion)
    dofs = constrained_dofs(prescribed, values)
    K = stiffness_matrix(mesh, lam, mu, stabilization, dofs)
    f = _load(mesh, neumann, pressure, body_force)
    K, load = apply_fixed_dofs(K, dofs.restrict(f), dofs)
    cb = contact_boundary(mesh, contact, dofs, gap, contact_quadrature, contact_gauss_points)
    return DiscreteProblem(
        mesh, dofs, K, load, cb, law or ContactLaw(0.0, 1.0, 0.0, 0.0), lam, mu, stabilization
    )


def _load(mesh: Mesh, neumann, pressure, body_force) -> np.ndarray:
    """(n_vertices, 2) load vector: tractions, normal pressures and the body force (3.16)."""
    f = np.zeros((mesh.n_vertices, 2))
    for name, traction in (neumann or {}).items():
        f += traction_load(mesh, mesh.boundary[name], traction)
    for name, p in (pressure or {}).items():
        f += pressure_load(mesh, mesh.boundary[name], p)
    if body_force is not None:
        from vemkit.mesh.triangulate import triangulate_cells

        triangles, parent = triangulate_cells(mesh)
        f += body_force_load(mesh, cell_averages(mesh, body_force, triangles, parent))
    return f


def _scene_gap(scene):
    """The gap of the scene: its foundation line (SPEC §7) or its gap expression (zero if none)."""
    if scene.foundation is not None:
        return FoundationLine(*scene.foundation)
    gap = scene.gap_expression
    return gap if gap is not None else (lambda x, y: np.zeros_like(x))


def scene_problem_data(scene) -> dict:
    """The keyword arguments of ``discrete_problem`` (and its k = 2 twin) that a scene gives:
    boundary conditions as callables, the gap or foundation, the contact law, the body force."""
    body = None
    if any(not (e.is_constant and float(e(0.0, 0.0)) == 0.0) for e in scene.body_force):
        body = vector_field(scene.body_force)
    normal, friction = scene.normal_compliance, scene.friction_bound
    law = ContactLaw(normal.k, normal.m, friction.k, friction.m) if normal is not None else None
    pressures = {side: scene.pressure(side) for side in scene.neumann_sides if scene.pressure(side) is not None}
    return dict(dirichlet=scene.dirichlet, pressure=pressures, contact=scene.contact_sides, gap=_scene_gap(scene),
                neumann={side: vector_field(scene.traction(side)) for side in scene.neumann_sides
                         if side not in pressures},
                law=law, body_force=body, stabilization=scene.stabilization,
                contact_quadrature=scene.contact_quadrature)


def scene_problem(scene, mesh: Mesh | None = None) -> DiscreteProblem:
    """Assemble the discrete problem (3.16) of a scene, on its own mesh unless one is given."""
    if scene.order == 2:  # k = 2 (vemkit.contact.problem_k2)
        from vemkit.contact.problem_k2 import scene_problem_k2
        return scene_problem_k2(scene, mesh)
    mesh = scene_mesh(scene) if mesh is None else mesh
    check_expressions_on_mesh(scene, mesh)  # a pole at a vertex: refused, not integrated around
    t0 = time.perf_counter()
    problem = discrete_problem(mesh, scene.E, scene.nu, contact_gauss_points=scene.contact_gauss_points,
                               **scene_problem_data(scene))
    problem.info["assembly_time"] = time.perf_counter() - t0
    return problem
