"""The assembled discrete problem (3.16) of any element: stiffness, load and contact boundary on the free dofs.

``discrete_problem`` takes plain ingredients (a mesh, the order k, Lamé parameters, boundary parts
and callables for the data), so it knows nothing of scene files; ``scene_problem`` builds it from a
scene. The ingredients come from the space (``vemkit.vem.space.VirtualElementSpace``):

- stiffness: the element (3.9), its volumetric part per cell or averaged at the nodes
  (``volumetric_strain``, ``vemkit.vem.volumetric``), clamped nodes eliminated, interior nodes (the k = 2 cell means)
  condensed out cell by cell, other Dirichlet components held by symmetric elimination;
- load: tractions and pressures integrated exactly on the traces, the body force through the
  element's projection of the data (Section 3.3);
- contact: the element's nodal rule at the trace nodes of Gamma_C (trapezoid or Simpson), the
  Gamma_C edge unknowns of k = 2 changed from edge means to midpoint values
  (``vemkit.contact.trace_nodes``), or Gauss points on Gamma_C edges (k = 1).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from vemkit.config.boundary_conditions import check_expressions_on_mesh, free_rigid_motion, rigid_motion_error
from vemkit.config.expressions import vector_field
from vemkit.config.volumetric import resolved_volumetric_strain
from vemkit.contact.boundary import ContactBoundary, FoundationLine, check_quadrature, contact_boundary
from vemkit.contact.laws import ContactLaw, FoundationLaw, contact_law
from vemkit.contact.trace_nodes import change_variables, midpoint_change, midpoint_edges
from vemkit.exceptions import SceneError
from vemkit.mesh.components import mesh_pieces
from vemkit.mesh.mesh import Mesh
from vemkit.mesh.meshing import scene_mesh
from vemkit.vem.condensation import condense_load, interior_load, recover_interior
from vemkit.vem.distributed_assembly import distributed_stiffness, splits
from vemkit.vem.dofs import DofMap, apply_fixed_dofs
from vemkit.vem.elasticity import lame_parameters, rigid_body_modes
from vemkit.vem.space import VirtualElementSpace
from vemkit.vem.volumetric import cell_stress, stiffness_matrix


@dataclass
class DiscreteProblem:
    space: VirtualElementSpace
    dofs: DofMap
    stiffness: sp.csr_matrix  # or a DistributedStiffness across MPI ranks (vemkit.vem.distributed_matrix)
    load: np.ndarray
    contact: ContactBoundary
    law: FoundationLaw
    lam: float
    mu: float
    stabilization: str
    interior_load: np.ndarray | None = None  # (M, 2) the load on condensed interior nodes (their recovery)
    info: dict = field(default_factory=dict)
    model: str = "plane_stress"  # the material law (vemkit.config.material)
    volumetric_strain: str = "cell"  # the treatment of the lambda part (vemkit.vem.volumetric)

    @property
    def mesh(self) -> Mesh:
        return self.space.mesh

    @property
    def order(self) -> int:
        return self.space.order

    @property
    def n_dofs(self) -> int:
        """The unknowns (after elimination and condensation)."""
        return self.dofs.n_free

    @property
    def n_space_dofs(self) -> int:
        """Degrees of freedom of the space on the free nodes, condensed interior nodes included."""
        condensed = self.space.node_range("cell") if self.dofs.condensed else slice(0, 0)
        return self.n_dofs + 2 * (condensed.stop - condensed.start)

    @property
    def near_nullspace(self) -> np.ndarray:
        """The rigid motions on the unknowns (their values at the free nodes' places)."""
        return rigid_body_modes(self.space.node_coordinates[self.dofs.free_nodes])

    def vertex_displacement(self, u) -> np.ndarray:
        """(n_vertices, 2) the displacement at the mesh vertices."""
        return self.dofs.expand(u)

    def node_values(self, u) -> np.ndarray:
        """(n_nodes, 2) the Section 3.1 degrees of freedom of every node (clamped nodes zero), the
        condensed interior nodes recovered."""
        values = self.dofs.node_values(u)
        if self.interior_load is None:
            return values
        return recover_interior(self.space, self.lam, self.mu, self.stabilization, values, self.interior_load)

    def projected(self, u):
        """Pi u_h (3.8) on every cell."""
        return self.space.project(self.node_values(u), self.lam, self.mu)

    def cell_strain_stress(self, u) -> tuple[np.ndarray, np.ndarray]:
        """(strain, stress) per cell: the cell mean of eps(Pi u_h) and the formulation's stress
        (C eps; with ``nodal_average`` 2 mu eps + lambda theta_K I, ``vemkit.vem.volumetric``)."""
        values = self.node_values(u)
        strain = self.space.project(values, self.lam, self.mu).cell_mean_strain()
        return strain, cell_stress(self.space, values, strain, self.lam, self.mu, self.volumetric_strain)


def check_parts(mesh: Mesh, names) -> None:
    for name in names:
        if name not in mesh.boundary:
            raise SceneError(
                f"boundary part {name!r} is not in the mesh; parts: {', '.join(sorted(mesh.boundary))}", key="boundary"
            )


def _piece_words(mesh, pieces, piece: int) -> str:
    """The piece in words, "the piece of 3 cells (cells 6, 7, 8) around (5.5, 0.5)": its size, its
    first cells, a point in it (``MeshPieces.point_in``)."""
    cells = pieces.cells(piece)
    centre = ", ".join(f"{c:.6g}" for c in pieces.point_in(mesh, piece))
    listed = ", ".join(map(str, cells[:3])) + (f" and {cells.shape[0] - 3} more" if cells.shape[0] > 3 else "")
    plural = "s" if cells.shape[0] > 1 else ""
    return f"the piece of {cells.shape[0]} cell{plural} (cell{plural} {listed}) around ({centre})"


def check_pieces_held(mesh, prescribed: np.ndarray) -> None:
    """Every piece of the mesh (:func:`vemkit.mesh.components.mesh_pieces`) held by its own Dirichlet
    components (``prescribed`` (N, d): u_i prescribed at vertex k), else a SceneError naming the motion
    and, for a mesh in several pieces, the piece (its cells, a point of it) and the fix.

    Contact sides do not count, for one piece as for many: the normal compliance and friction forces
    act only where a point penetrates, and the solvers factorize or precondition the stiffness matrix
    on its own (Uzawa's steps solve with it alone), so it must be regular before any contact term.
    A piece held by nothing makes it singular; the solvers would then fail with a misleading message."""
    pieces = mesh_pieces(mesh)
    for piece in range(pieces.count):
        on = pieces.vertex_piece == piece if pieces.count > 1 else np.ones(mesh.n_vertices, dtype=bool)
        held = on & np.any(prescribed, axis=1)
        motion = free_rigid_motion(mesh.vertices[held], prescribed[held])
        if motion is None:
            continue
        if pieces.count == 1:
            raise rigid_motion_error(motion)
        where = _piece_words(mesh, pieces, piece)
        what = (
            f"no side of boundary.dirichlet holds {where}: it floats"
            if not held.any()
            else f"boundary.dirichlet leaves {motion} of {where} free"
        )
        raise SceneError(
            f"the mesh is in {pieces.count} separate pieces and {what} (the stiffness is singular); "
            "prescribe a side on that piece in boundary.dirichlet, or remove the piece from the mesh "
            "(discretization.mesh)",
            key="boundary.dirichlet",
        )


def constrained(space: VirtualElementSpace, dirichlet) -> DofMap:
    """The dof map of the Dirichlet data; a rigid motion of the body or of any of its pieces left free
    is a SceneError (:func:`check_pieces_held`)."""
    prescribed, values = space.dirichlet_components(dirichlet)
    check_pieces_held(space.mesh, prescribed[: space.mesh.n_vertices])
    return space.constrain(prescribed, values)


def problem_load(
    space: VirtualElementSpace, neumann, pressure, body_force, projection: str, lam: float, mu: float
) -> np.ndarray:
    """(n_nodes, d) load vector: tractions, normal pressures and the body force (3.16)."""
    f = np.zeros((space.n_nodes, space.element.dimension))
    for name, traction in (neumann or {}).items():
        f += space.traction_load(space.mesh.boundary[name], traction)
    for name, p in (pressure or {}).items():
        f += space.pressure_load(space.mesh.boundary[name], p)
    if body_force is not None:
        f += space.body_force_load(body_force, lam, mu, projection)
    return f


def discrete_problem(
    mesh: Mesh,
    E: float,
    nu: float,
    *,
    order: int = 1,
    dirichlet=("right",),
    neumann=None,
    pressure=None,
    contact=(),
    gap=lambda x, *_: np.zeros_like(x),
    law: FoundationLaw | None = None,
    body_force=None,
    stabilization: str = "dofi-2mu",
    contact_quadrature: str = "nodal",
    contact_gauss_points: int = 3,
    body_force_projection: str | None = None,
    model: str = "plane_stress",
    volumetric_strain: str = "auto",
    comm=None,
) -> DiscreteProblem:
    """Assemble (3.16) without the contact terms plus the contact boundary data, with the element of
    order ``order``.

    dirichlet: side names (u = 0) or {part: (u1, u2)}, each None (free), a number or a function
    of (x, y); a rigid motion left free is a SceneError.
    neumann: {part: traction(x, y) -> (f2_1, f2_2)}; pressure: {part: p(x, y)} (traction -p nu);
    body_force(x, y) -> (f1_1, f1_2), projected as ``body_force_projection`` (k = 2: "p1", the default,
    or "p0", the paper's P_0 f1; None: the element's default). contact_quadrature: nodal or gauss
    (with contact_gauss_points per edge).
    model: plane_stress (the paper's C) or plane_strain (``vemkit.config.material``).
    volumetric_strain: cell (the paper's), nodal_average (k = 1, ``vemkit.vem.volumetric``) or auto
    (the scene key's default: nodal_average for k = 1, plane strain or 3D, nu > 0.45; ``vemkit.config.volumetric``).
    comm: an MPI communicator (``vemkit.vem.parallel.solve_communicator``): the stiffness is split
    across its ranks, each assembling its own cells, as PETSc's matrix (``vemkit.vem.distributed_assembly``);
    on one rank only where the split covers the formulation (else the scipy matrix, as without comm).
    """
    check_parts(mesh, list(dirichlet) + list(neumann or {}) + list(pressure or {}) + list(contact))
    space = VirtualElementSpace(mesh, order)
    check_quadrature(space, contact_quadrature)
    lam, mu = lame_parameters(E, nu, model)
    volumetric_strain = resolved_volumetric_strain(volumetric_strain, space.order, model, nu)
    dofs = constrained(space, dirichlet)
    # the Gamma_C edge nodes (k = 2 midpoints) as unknowns; none for an element without edge nodes
    change = midpoint_change(space, dofs, midpoint_edges(space, contact, dofs))
    comm = comm if comm is not None and splits(comm, volumetric_strain, change) else None
    K = stiffness_matrix(space, lam, mu, stabilization, dofs, volumetric_strain) if comm is None else None
    projection = body_force_projection or space.element.default_body_force_projection
    full_load = problem_load(space, neumann, pressure, body_force, projection, lam, mu)
    if dofs.condensed:
        f = condense_load(space, lam, mu, stabilization, dofs, full_load)
        interior = interior_load(space, full_load)
    else:
        f, interior = dofs.restrict(full_load), None
    dofs = dofs.with_change(change)
    if comm is None:
        K, f = change_variables(K, f, dofs.change)
        K, f = apply_fixed_dofs(K, f, dofs)
    else:
        K, f = distributed_stiffness(space, lam, mu, stabilization, dofs, f, comm, volumetric_strain)
    cb = contact_boundary(space, contact, dofs, gap, contact_quadrature, contact_gauss_points)
    law = law or ContactLaw(0.0, 1.0, 0.0, 0.0)
    return DiscreteProblem(
        space, dofs, K, f, cb, law, lam, mu, stabilization, interior, model=model, volumetric_strain=volumetric_strain
    )


def scene_gap(scene):
    """The gap of the scene: its foundation line or plane (docs/reference/files.md) or its gap expression of the
    coordinates (zero if none), as ``ContactBoundary.with_gap`` takes it."""
    if scene.foundation is not None:
        return FoundationLine(*scene.foundation)
    gap = scene.gap_expression
    return gap if gap is not None else (lambda x, *_: np.zeros_like(x))


def scene_problem_data(scene) -> dict:
    """The keyword arguments of ``discrete_problem`` that a scene gives: the order, boundary
    conditions as callables, the gap or foundation, the contact law, the body force and its projection."""
    body = None
    if any(not (e.is_constant and float(e(0.0, 0.0)) == 0.0) for e in scene.body_force):
        body = vector_field(scene.body_force)
    normal, friction = scene.normal_compliance, scene.friction_bound
    law = contact_law(normal, friction) if normal is not None else None
    pressures = {side: scene.pressure(side) for side in scene.neumann_sides if scene.pressure(side) is not None}
    return dict(
        order=scene.order,
        dirichlet=scene.dirichlet,
        pressure=pressures,
        contact=scene.contact_sides,
        gap=scene_gap(scene),
        law=law,
        body_force=body,
        stabilization=scene.stabilization,
        neumann={side: vector_field(scene.traction(side)) for side in scene.neumann_sides if side not in pressures},
        contact_quadrature=scene.contact_quadrature,
        contact_gauss_points=scene.contact_gauss_points,
        body_force_projection=scene.body_force_projection,
        model=scene.model,
        volumetric_strain=scene.volumetric_strain,
    )


def scene_problem(scene, mesh: Mesh | None = None, comm=None) -> DiscreteProblem:
    """Assemble the discrete problem (3.16) of a scene, on its own mesh unless one is given (``comm``:
    split across MPI ranks, :func:`discrete_problem`)."""
    mesh = scene_mesh(scene) if mesh is None else mesh
    check_expressions_on_mesh(scene, mesh)  # a pole at a vertex: refused, not integrated around
    t0 = time.perf_counter()
    problem = discrete_problem(mesh, scene.E, scene.nu, **scene_problem_data(scene), comm=comm)
    problem.info["assembly_time"] = time.perf_counter() - t0
    problem.info["order"] = scene.order
    problem.info["scene"] = scene  # the solution Dataset records it as the file of vemkit solve does
    return problem
