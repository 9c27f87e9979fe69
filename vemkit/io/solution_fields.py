"""The fields of one solve in its solution file, 2D or 3D (docs/reference/files.md), added to the mesh's file.

One code path writes both dimensions; what differs between them is spelled out once, as a
:class:`FieldNames` per dimension (:data:`FIELD_NAMES`): the displacement's names, the cell
tensor's components, the cell scalar (2D: the shear energy density of Fig. 6; 3D: von Mises), the
contact node variables in file order and the contact frame (3D: the outward normal and the
per-vertex tangent basis t1 = e x nu / |e x nu|, e the axis least aligned with nu, t2 = nu x t1).

- nodes (``<mesh>_nNodes``): ``u1``, ``u2`` (, ``u3``);
- cells (``mesh2d_nFaces`` / ``mesh3d_nVolumes``): ``strain_IJ``, ``stress_IJ`` (cell means of
  eps(Pi u_h), constant per cell for k = 1, and sigma = C eps; with the nodal volumetric strain
  2 mu eps + lambda theta_K I, ``DiscreteProblem.cell_strain_stress``), then the cell scalar;
- contact (``contact_node``, sorted by x, then y (, then z)): the coordinates ``contact_x`` ...,
  ``contact_vertex``, ``contact_weight``, the pressures, bounds and displacements of
  :func:`vemkit.solvers.solution.contact_state`, ``contact_state`` (0 separated, 1 stick, 2 slip);
  a 3D tangential quantity has the dimensions (``contact_node``, ``contact_tangent``): its
  components along t1 and t2 (the global attribute ``contact_tangent_basis`` says so); a 2D one,
  (n_c, 1) in memory (``vemkit.contact.ball``), is the 1-D variable along tau (``as_written``);
- k = 2 (2D): the edge and cell means ``u1_edge_mean`` ... (``ENTITY_VARIABLES``) and the contact
  points that are edge midpoints (``contact_edge``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from vemkit.mesh.file_description import FileDescription
from vemkit.mesh.ugrid import MeshTopology
from vemkit.solvers.solution import contact_state
from vemkit.vem.projection import COMPONENTS_3D, shear_energy_density, von_mises

STATE_MEANINGS = "separated stick slip"
TANGENT_BASIS = (
    "tangential quantities (dimension contact_tangent) are the components along the per-vertex "
    "orthonormal basis (contact_tangent1, contact_tangent2): t1 = e x nu / |e x nu| with e the "
    "coordinate axis least aligned with the outward normal nu (first on ties), t2 = nu x t1"
)

#: the solution file's name of the degrees of freedom on each kind of mesh entity beyond the vertices
ENTITY_VARIABLES = {"edge": ("mesh2d_nEdges", "edge_mean", "edge"), "cell": ("mesh2d_nFaces", "face_mean", "face")}


class FieldNames(NamedTuple):
    """What the file calls the fields of a body of one dimension, and in which order it holds them."""

    axes: tuple[str, ...]
    displacement_long_names: tuple[str, ...]
    components: tuple[str, ...]  # the tensor components IJ of strain_IJ and stress_IJ
    stress_long_names: tuple[str, ...]
    cell_comment: str  # {k}: the order
    cell_scalar: tuple[str, str]  # name, long name (daN/mm2)
    cell_scalar_of: Callable  # (sigma, problem) -> the cell scalar
    contact_weight: tuple[str, str]  # long name, units
    contact_variables: tuple[tuple[str, str, str], ...]  # name, long name, units (file order)
    contact_frame: tuple[tuple[str, str], ...]  # file name, ContactBoundary attribute
    contact_attrs: dict


_PRESSURE = ("normal_pressure", "p_nu(u_nu - g_a) (2.6)", "daN/mm2")
_BOUND = ("friction_bound", "p_tau(u_nu - g_a)", "daN/mm2")
_PENETRATION = ("penetration", "u_nu - g_a (> 0: penetration)", "mm")

FIELD_NAMES = {
    2: FieldNames(
        axes=("x", "y"),
        displacement_long_names=("horizontal displacement", "vertical displacement"),
        components=("11", "22", "12"),
        stress_long_names=("stress sigma11 = C eps(Pi u)", "stress sigma22", "stress sigma12"),
        cell_comment="cell mean of the strain of the projection Pi_{k} (3.8) (constant per cell for k = 1)",
        cell_scalar=("shear_energy_density", "|dev sigma|^2/(4 mu) (Fig. 6)"),
        cell_scalar_of=lambda sigma, problem: shear_energy_density(sigma, problem.lam, problem.mu, problem.model),
        contact_weight=("nodal quadrature weight on Gamma_C", "mm"),
        contact_variables=(
            _PRESSURE,
            ("tangential_stress", "sigma_tau = -p_tau lambda (2.7)-(2.8)", "daN/mm2"),
            _BOUND,
            ("friction_multiplier", "lambda in [-1, 1] (5.3)", "1"),
            ("slip", "tangential displacement u_tau", "mm"),
            _PENETRATION,
        ),
        contact_frame=(),
        contact_attrs={},
    ),
    3: FieldNames(
        axes=("x", "y", "z"),
        displacement_long_names=tuple(f"displacement along {axis}" for axis in "xyz"),
        components=COMPONENTS_3D,
        stress_long_names=tuple(f"stress sigma{ij} = C eps(Pi u)" for ij in COMPONENTS_3D),
        cell_comment="of the projection Pi_{k} (3.8): constant per cell (k = 1)",
        cell_scalar=("von_mises", "von Mises stress sqrt(3/2 |dev sigma|^2)"),
        cell_scalar_of=lambda sigma, problem: von_mises(sigma),
        contact_weight=("nodal weight on Gamma_C: sum over its faces of int_F Pi^F phi_i ds", "mm2"),
        contact_variables=(
            _PRESSURE,
            _BOUND,
            _PENETRATION,
            ("tangential_stress", "sigma_tau = -p_tau lambda (2.7)-(2.8), in (t1, t2)", "daN/mm2"),
            ("friction_multiplier", "lambda in the unit disk (5.3), in (t1, t2)", "1"),
            ("slip", "tangential displacement u_tau, in (t1, t2)", "mm"),
        ),
        contact_frame=(("normal", "normal"), ("tangent1", "tangent"), ("tangent2", "tangent2")),
        contact_attrs={"contact_tangent_basis": TANGENT_BASIS},
    ),
}


def add_displacement(ds: FileDescription, topology: MeshTopology, problem, solution) -> None:
    """``u1``, ``u2`` (, ``u3``) at the mesh's vertices."""
    u = problem.vertex_displacement(solution.u)
    for c, long_name in enumerate(FIELD_NAMES[topology.dimension].displacement_long_names):
        attrs = {"long_name": long_name, "units": "mm", "mesh": topology.name, "location": "node"}
        ds.add(f"u{c + 1}", topology.node_dimension, u[:, c], attrs)


def add_cell_fields(ds: FileDescription, topology: MeshTopology, problem, solution) -> None:
    """``strain_IJ``, ``stress_IJ`` and the cell scalar, one value per cell."""
    names = FIELD_NAMES[topology.dimension]
    strain, sigma = problem.cell_strain_stress(solution.u)
    cell = {
        "mesh": topology.name,
        "location": topology.cell_location,
        "comment": names.cell_comment.format(k=problem.space.order),
    }
    where = topology.cell_dimension
    for k, ij in enumerate(names.components):
        ds.add(f"strain_{ij}", where, strain[:, k], dict(cell, long_name=f"strain eps{ij} of Pi u", units="1"))
    for k, (ij, long_name) in enumerate(zip(names.components, names.stress_long_names, strict=True)):
        ds.add(f"stress_{ij}", where, sigma[:, k], dict(cell, long_name=long_name, units="daN/mm2"))
    name, long_name = names.cell_scalar
    ds.add(name, where, names.cell_scalar_of(sigma, problem), dict(cell, long_name=long_name, units="daN/mm2"))


#: a contact node's tangential quantity as the file holds it, per dimension: 2D's one component
#: ((n_c, 1) in memory, ``vemkit.contact.ball``) is the 1-D variable along tau; 3D's two components
#: are the dimension ``contact_tangent``
TANGENTIAL_FILE_SHAPE = {2: (), 3: (2,)}


def as_written(values, dimension: int) -> np.ndarray:
    """Contact-node values as the files of a body of ``dimension`` hold them: a tangential quantity
    ((n_c, d - 1)) in :data:`TANGENTIAL_FILE_SHAPE`, a scalar ((n_c,)) as it is."""
    data = np.asarray(values, dtype=float)
    tangential = data.ndim == 2
    return data.reshape(data.shape[0], *TANGENTIAL_FILE_SHAPE[dimension]) if tangential else data


def add_contact(ds: FileDescription, topology: MeshTopology, problem, solution) -> None:
    """The contact node variables (module docstring), sorted by the contact points' coordinates."""
    names = FIELD_NAMES[topology.dimension]
    cb = problem.contact
    st = contact_state(problem, solution.u, solution.multiplier)
    order = np.lexsort(cb.coords.T[::-1])
    c = "contact_node"
    for k, axis in enumerate(names.axes):
        attrs = {"long_name": f"{axis} of contact vertex", "units": "mm"}
        ds.add(f"contact_{axis}", c, cb.coords[order, k], attrs, coordinate=True)
    ds.add("contact_vertex", c, cb.vertices[order], {"long_name": f"{topology.name} node index of the contact vertex"})
    long_name, units = names.contact_weight
    ds.add("contact_weight", c, cb.weight[order], {"long_name": long_name, "units": units})
    values = {
        "normal_pressure": st.normal_pressure,
        "tangential_stress": st.tangential_stress,
        "friction_bound": st.friction_bound,
        "friction_multiplier": solution.multiplier,
        "slip": st.slip,
        "penetration": st.penetration,
    }
    for name, long_name, units in names.contact_variables:
        data = as_written(values[name], topology.dimension)[order]
        dims = (c,) if data.ndim == 1 else (c, "contact_tangent")
        ds.add(name, dims, data, {"long_name": long_name, "units": units})
    for name, attribute in names.contact_frame:
        vectors = getattr(cb, attribute)
        what = "outward normal nu" if name == "normal" else name
        for k, axis in enumerate(names.axes):
            ds.add(
                f"contact_{name}_{axis}", c, vectors[order, k], {"long_name": f"{axis} component of the unit {what}"}
            )
    ds.add(
        "contact_state",
        c,
        np.asarray(st.state, dtype=np.int8)[order],
        {
            "long_name": "contact state (separated: u_nu <= g_a; stick: u_tau = 0; slip)",
            "flag_values": np.array([0, 1, 2], np.int8),
            "flag_meanings": STATE_MEANINGS,
        },
    )
    ds.attrs.update(names.contact_attrs)


def add_node_fields(ds: FileDescription, topology: MeshTopology, problem, solution) -> None:
    """The degrees of freedom on entities other than vertices (k = 2: the edge and cell means of
    Section 3.1) as edge and face variables; contact points are vertices or edge midpoints
    (``contact_vertex`` / ``contact_edge``, -1 where the other applies)."""
    space = problem.space
    values = problem.node_values(solution.u)
    ds.attrs["n_space_dofs"] = int(problem.n_space_dofs)  # n_dofs: the unknowns after condensation
    for entity in (e for e in space.element.layout if e != "vertex"):
        dimension, suffix, location = ENTITY_VARIABLES[entity]
        for c in (1, 2):
            ds.add(
                f"u{c}_{suffix}",
                dimension,
                values[space.node_range(entity), c - 1],
                {
                    "long_name": f"mean of u{c} over the {entity} (k = {space.order} degree of freedom)",
                    "units": "mm",
                    "mesh": topology.name,
                    "location": location,
                },
            )
    cb = problem.contact
    if cb.size and "edge" in space.element.layout:
        _add_midpoint_contact(ds, problem)


def _add_midpoint_contact(ds: FileDescription, problem) -> None:
    """k = 2: a contact point is a vertex (``contact_vertex``) or an edge midpoint (``contact_edge``)."""
    cb = problem.contact
    nv = problem.mesh.n_vertices
    node = cb.vertices[np.lexsort(cb.coords.T[::-1])]
    ds.add(
        "contact_vertex",
        "contact_node",
        np.where(node < nv, node, -1),
        {"long_name": "mesh2d node index of the contact vertex (-1: an edge midpoint)"},
    )
    ds.add(
        "contact_edge",
        "contact_node",
        np.where(node < nv, -1, node - nv),
        {"long_name": "mesh2d edge index of the contact edge midpoint (-1: a vertex)"},
    )
    ds["contact_weight"].attrs["long_name"] = (
        "Simpson quadrature weight on Gamma_C (|e|/6 at vertices, 4|e|/6 at midpoints)"
    )
