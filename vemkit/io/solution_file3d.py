"""The solution file of a 3D body (docs/reference/files.md): the ``mesh3d`` topology and the fields of one solve.

On top of :func:`vemkit.mesh.files3d.mesh3d_description` (nodes, polygonal faces, the signed faces
of each volume, the named boundary parts): node variables ``u1``, ``u2``, ``u3``
(``mesh3d_nNodes``); volume variables ``strain_IJ`` and ``stress_IJ`` for IJ = 11, 22, 33, 12, 13,
23 (tensor components of eps(Pi u_h), constant per cell for k = 1, and sigma = C eps) and
``von_mises`` (``mesh3d_nVolumes``); the solver history and the global attributes of a 2D file
(:func:`vemkit.io.solution_file.with_solver_record`).

With contact (dimension ``contact_node``, sorted by x, y, z), the 2D contact node variables:
coordinates ``contact_x``, ``contact_y``, ``contact_z``, ``contact_vertex`` (mesh3d node index),
``contact_weight`` (the nodal weight int Pi^F phi_i over the Gamma_C faces), ``normal_pressure``,
``penetration``, ``friction_bound``, ``contact_state``, the outward normal ``contact_normal_x..z``
and the per-vertex tangent basis ``contact_tangent1_x..z``, ``contact_tangent2_x..z``
(``vemkit.contact.boundary3d``: t1 = e x nu / |e x nu|, e the axis least aligned with nu,
t2 = nu x t1). The tangential quantities ``tangential_stress``, ``friction_multiplier`` and
``slip`` have the dimensions (``contact_node``, ``contact_tangent``), ``contact_tangent`` of size 2:
their components along t1 and t2 (the global attribute ``contact_tangent_basis`` says so).
"""

from __future__ import annotations

import numpy as np

from vemkit.mesh.file_description import FileDescription
from vemkit.mesh.files3d import TOPOLOGY, mesh3d_description
from vemkit.vem.projection import COMPONENTS_3D, stress, von_mises

AXES = ("x", "y", "z")


def solution_description3d(problem, solution, *, scene_yaml: str = "", extra_attrs=None) -> FileDescription:
    """The ``mesh3d`` file of a solved 3D problem (module docstring)."""
    from vemkit.io.solution_file import with_solver_record

    u = problem.vertex_displacement(solution.u)
    strain = problem.projected(solution.u).cell_mean_strain()  # (M, 6), COMPONENTS_3D
    sigma = stress(strain, problem.lam, problem.mu)
    ds = mesh3d_description(problem.mesh)
    node, volume = f"{TOPOLOGY}_nNodes", f"{TOPOLOGY}_nVolumes"
    for c, axis in enumerate(AXES):
        ds.add(
            f"u{c + 1}",
            node,
            u[:, c],
            {"long_name": f"displacement along {axis}", "units": "mm", "mesh": TOPOLOGY, "location": "node"},
        )
    cell = {
        "mesh": TOPOLOGY,
        "location": "volume",
        "comment": "of the projection Pi_1 (3.8): constant per cell (k = 1)",
    }
    for k, ij in enumerate(COMPONENTS_3D):
        ds.add(f"strain_{ij}", volume, strain[:, k], dict(cell, long_name=f"strain eps{ij} of Pi u", units="1"))
    for k, ij in enumerate(COMPONENTS_3D):
        ds.add(
            f"stress_{ij}",
            volume,
            sigma[:, k],
            dict(cell, long_name=f"stress sigma{ij} = C eps(Pi u)", units="daN/mm2"),
        )
    ds.add(
        "von_mises",
        volume,
        von_mises(sigma),
        dict(cell, long_name="von Mises stress sqrt(3/2 |dev sigma|^2)", units="daN/mm2"),
    )
    if problem.contact.size:
        _add_contact(ds, problem, solution)
    return with_solver_record(ds, problem, solution, scene_yaml, extra_attrs)


TANGENT_BASIS = (
    "tangential quantities (dimension contact_tangent) are the components along the per-vertex "
    "orthonormal basis (contact_tangent1, contact_tangent2): t1 = e x nu / |e x nu| with e the "
    "coordinate axis least aligned with the outward normal nu (first on ties), t2 = nu x t1"
)


def _add_contact(ds: FileDescription, problem, solution) -> None:
    """The contact node variables of the module docstring."""
    from vemkit.io.solution_file import STATE_MEANINGS
    from vemkit.solvers.solution import contact_state

    cb = problem.contact
    st = contact_state(problem, solution.u, solution.multiplier)
    order = np.lexsort((cb.coords[:, 2], cb.coords[:, 1], cb.coords[:, 0]))
    c, t = "contact_node", "contact_tangent"
    for k, a in enumerate(AXES):
        ds.add(
            f"contact_{a}",
            c,
            cb.coords[order, k],
            {"long_name": f"{a} of contact vertex", "units": "mm"},
            coordinate=True,
        )
    ds.add("contact_vertex", c, cb.vertices[order], {"long_name": "mesh3d node index of the contact vertex"})
    ds.add(
        "contact_weight",
        c,
        cb.weight[order],
        {"long_name": "nodal weight on Gamma_C: sum over its faces of int_F Pi^F phi_i ds", "units": "mm2"},
    )
    for name, values, long_name, units in (
        ("normal_pressure", st.normal_pressure, "p_nu(u_nu - g_a) (2.6)", "daN/mm2"),
        ("friction_bound", st.friction_bound, "p_tau(u_nu - g_a)", "daN/mm2"),
        ("penetration", st.penetration, "u_nu - g_a (> 0: penetration)", "mm"),
    ):
        ds.add(name, c, np.asarray(values, dtype=float)[order], {"long_name": long_name, "units": units})
    for name, values, long_name, units in (
        ("tangential_stress", st.tangential_stress, "sigma_tau = -p_tau lambda (2.7)-(2.8), in (t1, t2)", "daN/mm2"),
        ("friction_multiplier", solution.multiplier, "lambda in the unit disk (5.3), in (t1, t2)", "1"),
        ("slip", st.slip, "tangential displacement u_tau, in (t1, t2)", "mm"),
    ):
        ds.add(name, (c, t), np.asarray(values, dtype=float)[order], {"long_name": long_name, "units": units})
    for name, vectors in (("normal", cb.normal), ("tangent1", cb.tangent), ("tangent2", cb.tangent2)):
        for k, a in enumerate(AXES):
            ds.add(
                f"contact_{name}_{a}",
                c,
                vectors[order, k],
                {"long_name": f"{a} component of the unit {'outward normal nu' if name == 'normal' else name}"},
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
    ds.attrs["contact_tangent_basis"] = TANGENT_BASIS
