"""A solved problem, 2D or 3D, as a self-describing netCDF file or xarray Dataset, written safely and
read back (docs/reference/files.md).

:func:`solution_description` spells out the file once (a
:class:`~vemkit.mesh.file_description.FileDescription`): the mesh's UGRID topology (``mesh2d`` or
``mesh3d``, :mod:`vemkit.mesh.ugrid`), the nodal displacement, the per-cell strain, stress and a
cell scalar, the contact boundary quantities (``contact_node``; :mod:`vemkit.io.solution_fields`),
the solver history (``iteration``), and global attributes: the scene as YAML, solver, iterations,
wall time, version. :func:`solution_dataset` is its xarray Dataset (the Python API, the studies)
and :func:`write_file` writes either, :func:`write_solution_vtu` its VTU twin for ParaView (the command line writes the description directly: no
xarray, no pandas at its start-up). ``write_netcdf`` refuses NaN and writes through a temporary
file renamed over the target on success, so a failed or interrupted run leaves the target as it
was. :func:`read_solution` reads either dimension back, as its topology variable says.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

import vemkit
from vemkit.exceptions import ResultError
from vemkit.io.output_files import atomic_outputs
from vemkit.io.solution_fields import FIELD_NAMES, add_cell_fields, add_contact, add_displacement, add_node_fields
from vemkit.mesh.file_description import FileDescription
from vemkit.mesh.files import read_ugrid
from vemkit.mesh.ugrid import mesh_topology, topology_dimension, topology_file
from vemkit.solvers.solution import globalization

if TYPE_CHECKING:
    import xarray as xr


def solution_dataset(problem, solution, *, scene_yaml: str = "", extra_attrs=None) -> xr.Dataset:
    """Everything a user needs from one solve as an xarray Dataset (:func:`solution_description`)."""
    return solution_description(problem, solution, scene_yaml=scene_yaml, extra_attrs=extra_attrs).to_dataset()


def solution_description(problem, solution, *, scene_yaml: str = "", extra_attrs=None) -> FileDescription:
    """Everything a user needs from one solve, 2D or 3D, described by its own attributes: the mesh's
    file (:func:`vemkit.mesh.ugrid.topology_file`) with the fields of :mod:`vemkit.io.solution_fields`."""
    topology = mesh_topology(problem.mesh)
    ds = topology_file(topology)
    add_displacement(ds, topology, problem, solution)
    add_cell_fields(ds, topology, problem, solution)
    if problem.contact.size:
        add_contact(ds, topology, problem, solution)
    if len(problem.space.element.layout) > 1:
        add_node_fields(ds, topology, problem, solution)
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
            "solver_globalization": globalization(solution),
            "wall_time": float(solution.wall_time),
            "n_dofs": int(problem.n_dofs),
            "stabilization": problem.stabilization,
            "volumetric_strain": problem.volumetric_strain,
            "order": int(problem.space.order),
            "model": str(problem.model),
            "vemkit_version": vemkit.__version__,
        }
    )
    ds.attrs.update(extra_attrs or {})
    return ds


def write_solution_vtu(problem, solution, ds: xr.Dataset | FileDescription, path) -> None:
    """The displacement at the vertices and the cell stresses and cell scalar of the solution file
    ``ds`` as VTU (3D: VTK polyhedra, type 42)."""
    from vemkit.mesh.vtu import write_vtu

    names = FIELD_NAMES[problem.mesh.dimension]
    cells = {k: ds[k].values for k in [f"stress_{ij}" for ij in names.components] + [names.cell_scalar[0]]}
    write_vtu(problem.mesh, path, point_data={"displacement": problem.dofs.expand(solution.u)}, cell_data=cells)


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
    if topology_dimension(ds) == 3:
        from vemkit.mesh.files3d import read_ugrid3d  # lazily: a 2D command never loads the 3D readers

        return read_ugrid3d(path), ds
    return read_ugrid(path), ds
