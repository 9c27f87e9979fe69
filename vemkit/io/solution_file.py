"""A solved problem as a self-describing netCDF file or xarray Dataset, written safely (docs/reference/files.md).

:func:`solution_description` spells out the file once (a
:class:`~vemkit.mesh.file_description.FileDescription`); :func:`solution_dataset` is its xarray
Dataset (the Python API, the studies) and :func:`write_file` writes either (the command line writes
the description directly: no xarray, no pandas at its start-up). The file carries the UGRID-1.0 mesh topology ``mesh2d``, the nodal displacement ``u1``,
``u2`` (``mesh2d_nNodes``), per-cell strain, stress and shear energy density
(``mesh2d_nFaces``), the contact boundary quantities (``contact_node``), the solver history
(``iteration``), and global attributes: the scene as YAML, solver, iterations, wall time, version.
``write_netcdf`` refuses NaN and writes through a temporary file renamed over the target on success,
so a failed or interrupted run leaves the target as it was.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

import vemkit
from vemkit.exceptions import ResultError
from vemkit.io.output_files import atomic_outputs
from vemkit.mesh.file_description import FileDescription
from vemkit.mesh.files import mesh_description, read_ugrid
from vemkit.vem.projection import shear_energy_density, stress

if TYPE_CHECKING:
    import xarray as xr

STATE_MEANINGS = "separated stick slip"


def solution_dataset(problem, solution, *, scene_yaml: str = "", extra_attrs=None) -> xr.Dataset:
    """Everything a user needs from one solve as an xarray Dataset (:func:`solution_description`)."""
    return solution_description(problem, solution, scene_yaml=scene_yaml, extra_attrs=extra_attrs).to_dataset()


def solution_description(problem, solution, *, scene_yaml: str = "", extra_attrs=None) -> FileDescription:
    """Everything a user needs from one solve, described by its own attributes (a 3D body: the
    ``mesh3d`` file of ``vemkit.io.solution_file3d``)."""
    from vemkit.solvers.solution import contact_state

    if problem.space.element.dimension == 3:
        from vemkit.io.solution_file3d import solution_description3d

        return solution_description3d(problem, solution, scene_yaml=scene_yaml, extra_attrs=extra_attrs)
    mesh = problem.mesh
    element_order = problem.space.order  # k of Section 3
    u = problem.vertex_displacement(solution.u)
    strain = problem.projected(solution.u).cell_mean_strain()
    sig = stress(strain, problem.lam, problem.mu)
    ds = mesh_description(mesh)
    node, face = "mesh2d_nNodes", "mesh2d_nFaces"
    for component, direction in ((1, "horizontal"), (2, "vertical")):
        attrs = {"long_name": f"{direction} displacement", "units": "mm", "mesh": "mesh2d", "location": "node"}
        ds.add(f"u{component}", node, u[:, component - 1], attrs)
    face_attrs = {
        "mesh": "mesh2d",
        "location": "face",
        "comment": f"cell mean of the strain of the projection Pi_{element_order} (3.8) (constant per cell for k = 1)",
    }
    for name, values, long_name, units in (
        ("strain_11", strain[:, 0], "strain eps11 of Pi u", "1"),
        ("strain_22", strain[:, 1], "strain eps22 of Pi u", "1"),
        ("strain_12", strain[:, 2], "strain eps12 of Pi u", "1"),
        ("stress_11", sig[:, 0], "stress sigma11 = C eps(Pi u)", "daN/mm2"),
        ("stress_22", sig[:, 1], "stress sigma22", "daN/mm2"),
        ("stress_12", sig[:, 2], "stress sigma12", "daN/mm2"),
        (
            "shear_energy_density",
            shear_energy_density(sig, problem.lam, problem.mu, problem.model),
            "|dev sigma|^2/(4 mu) (Fig. 6)",
            "daN/mm2",
        ),
    ):
        ds.add(name, face, values, dict(face_attrs, long_name=long_name, units=units))

    cb = problem.contact
    if cb.size:
        st = contact_state(problem, solution.u, solution.multiplier)
        order = np.lexsort((cb.coords[:, 1], cb.coords[:, 0]))
        c = "contact_node"
        for k, axis in enumerate("xy"):
            attrs = {"long_name": f"{axis} of contact vertex", "units": "mm"}
            ds.add(f"contact_{axis}", c, cb.coords[order, k], attrs, coordinate=True)
        ds.add("contact_vertex", c, cb.vertices[order], {"long_name": "mesh2d node index of the contact vertex"})
        ds.add(
            "contact_weight", c, cb.weight[order], {"long_name": "nodal quadrature weight on Gamma_C", "units": "mm"}
        )
        for name, values, long_name, units in (
            ("normal_pressure", st.normal_pressure, "p_nu(u_nu - g_a) (2.6)", "daN/mm2"),
            ("tangential_stress", st.tangential_stress, "sigma_tau = -p_tau lambda (2.7)-(2.8)", "daN/mm2"),
            ("friction_bound", st.friction_bound, "p_tau(u_nu - g_a)", "daN/mm2"),
            ("friction_multiplier", solution.multiplier, "lambda in [-1, 1] (5.3)", "1"),
            ("slip", st.slip, "tangential displacement u_tau", "mm"),
            ("penetration", st.penetration, "u_nu - g_a (> 0: penetration)", "mm"),
        ):
            ds.add(name, c, np.asarray(values, dtype=float)[order], {"long_name": long_name, "units": units})
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
    if len(problem.space.element.layout) > 1:
        _add_node_fields(ds, problem, solution)
    return with_solver_record(ds, problem, solution, scene_yaml, extra_attrs)


def with_solver_record(ds: FileDescription, problem, solution, scene_yaml: str, extra_attrs=None) -> FileDescription:
    """``ds`` with the solver history (``iteration``) and the global attributes of docs/reference/files.md (2D and 3D)."""
    for key, values in solution.history.items():
        ds.add(f"history_{key}", "iteration", np.asarray(values, dtype=float), {"long_name": f"solver history: {key}"})
    ds.attrs.update(
        {
            "Conventions": "CF-1.8 UGRID-1.0",
            "title": "vemkit solution",
            "scene": scene_yaml,
            "solver": solution.method,
            "iterations": int(solution.iterations),
            "linear_iterations": int(solution.linear_iterations),
            "wall_time": float(solution.wall_time),
            "n_dofs": int(problem.n_dofs),
            "stabilization": problem.stabilization,
            "order": int(problem.space.order),
            "model": str(problem.model),
            "vemkit_version": vemkit.__version__,
        }
    )
    ds.attrs.update(extra_attrs or {})
    return ds


#: the solution file's dimension and name of the degrees of freedom on each kind of mesh entity
ENTITY_VARIABLES = {"edge": ("mesh2d_nEdges", "edge_mean", "edge"), "cell": ("mesh2d_nFaces", "face_mean", "face")}


def _add_node_fields(ds: FileDescription, problem, solution) -> None:
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
                    "long_name": f"mean of u{c} over the {'cell' if entity == 'cell' else entity} "
                    f"(k = {space.order} degree of freedom)",
                    "units": "mm",
                    "mesh": "mesh2d",
                    "location": location,
                },
            )
    cb = problem.contact
    if cb.size and "edge" in space.element.layout:
        nv = problem.mesh.n_vertices
        node = cb.vertices[np.lexsort((cb.coords[:, 1], cb.coords[:, 0]))]
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


def check_finite(ds: xr.Dataset | FileDescription, what: str = "result") -> None:
    for name, var in ds.variables.items():
        values = np.asarray(var.values)
        if np.issubdtype(values.dtype, np.floating) and not np.all(np.isfinite(values)):
            raise ResultError(f"{what}: variable {name} holds NaN or inf; nothing was written")


def write_file(contents: xr.Dataset | FileDescription, path) -> None:
    """Write a description through netCDF4 (no xarray) or a Dataset through xarray: the same file
    for the same contents (:mod:`vemkit.mesh.file_description`)."""
    if isinstance(contents, FileDescription):
        contents.write_netcdf4(path)
    else:
        contents.to_netcdf(path, format="NETCDF4", engine="netcdf4")


def write_netcdf(ds: xr.Dataset | FileDescription, path) -> Path:
    """Write ``ds`` to ``path`` (netCDF4) atomically: all or nothing, never NaN.

    The file is written next to ``path`` and renamed over it only when complete
    (:func:`vemkit.io.output_files.atomic_outputs`); a failure or a signal leaves ``path`` as it was.
    """
    path = Path(path)
    check_finite(ds, str(path))
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_outputs(path) as (temporary,):
        write_file(ds, temporary)
    return path


def read_solution(path):
    """(Mesh, Dataset) of a solution file written by ``vemkit solve`` or the workflow: a
    :class:`~vemkit.mesh.mesh.Mesh` (``mesh2d``) or a :class:`~vemkit.mesh.polyhedral.PolyhedralMesh`
    (``mesh3d``, docs/reference/files.md)."""
    import xarray as xr

    with xr.open_dataset(path) as ds:
        ds = ds.load()
    if "mesh3d" in ds.variables:
        from vemkit.mesh.files3d import read_ugrid3d

        return read_ugrid3d(path), ds
    return read_ugrid(path), ds
