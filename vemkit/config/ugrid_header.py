"""What a netCDF mesh file declares before it is read (:mod:`vemkit.config.mesh_file_header`): a
UGRID ``mesh2d`` file (a plane mesh) or a ``mesh3d`` file. netCDF declares its dimensions truthfully
(a compressed file cannot hide a larger array), so the counts come from the dimensions of the node
coordinates, the face (volume) tables and the boundary parts, the side names from the JSON list
``vemkit_boundary_parts``, the body's dimension from the topology's ``topology_dimension``."""

from __future__ import annotations

import json
from pathlib import Path

from vemkit.config.body_forms import FORMS
from vemkit.config.mesh_file_reading import MeshFileHeader, file_problem

__all__ = ["TABLE_ENTRIES_PER_VERTEX", "ugrid_dimension", "ugrid_header"]

#: most entries of a mesh3d face or volume table per vertex (8 bytes each): a tetrahedral mesh has
#: about 13 faces of 3 vertices and 6 cells of 4 faces per vertex; padding to the largest face or
#: cell leaves a margin of 5 or more
TABLE_ENTRIES_PER_VERTEX = 256
_EDGE_VERTICES = 2  # a boundary part's table: one row of vertex indices per edge


def _topologies(nc) -> list:
    return [v for v in nc.variables.values() if getattr(v, "cf_role", None) == "mesh_topology"]


def ugrid_dimension(path: Path) -> int | None:
    """2 or 3: the ``topology_dimension`` of the one mesh topology of the netCDF file ``path``;
    None when it has not exactly one or says another dimension."""
    import netCDF4

    with netCDF4.Dataset(path, "r") as nc:
        topologies = _topologies(nc)
        if len(topologies) != 1:
            return None
        value = str(getattr(topologies[0], "topology_dimension", "2")).strip()
        return int(value) if value in ("2", "3") else None


def ugrid_header(path: Path, size: int, dimension: int = 2) -> MeshFileHeader:
    """The counts and sides the netCDF file ``path`` declares for a scene of ``dimension``."""
    import netCDF4

    try:
        nc = netCDF4.Dataset(path, "r")
    except OSError as error:
        raise file_problem(
            path, f"cannot be read as {FORMS[dimension].netcdf_words}: not a netCDF file ({error.strerror or error})"
        ) from None
    try:
        nc.set_auto_mask(False)
        return _COUNTS[dimension](nc, path, size)
    finally:
        nc.close()


def _ugrid_variable(nc, name, path, role: str, rank: int):
    if not isinstance(name, str) or name not in nc.variables:
        raise file_problem(path, f"cannot be read as UGRID netCDF: the {role} variable {str(name)[:60]!r} is missing")
    variable = nc.variables[name]
    if variable.ndim != rank or getattr(variable.dtype, "kind", "O") not in "iuf":
        raise file_problem(
            path,
            f"cannot be read as UGRID netCDF: {name[:60]} ({role}) must be a numeric "
            f"{'vector' if rank == 1 else 'table'}",
        )
    return variable


def _mesh2d_counts(nc, path: Path, size: int) -> MeshFileHeader:
    topologies = _topologies(nc)
    if len(topologies) != 1:
        raise file_problem(
            path, f"cannot be read as UGRID netCDF: expected one mesh topology variable, found {len(topologies)}"
        )
    topology = topologies[0]
    coordinates = str(getattr(topology, "node_coordinates", "")).split()
    if str(getattr(topology, "topology_dimension", "2")) == "3":
        raise file_problem(
            path, "is a 3D mesh (mesh3d) but the scene is 2D; give a 2D mesh file, or write the scene for a 3D body"
        )
    if len(coordinates) != 2:
        raise file_problem(path, "cannot be read as UGRID netCDF: node_coordinates must name two variables (x y)")
    x, y = (_ugrid_variable(nc, name, path, "node coordinate", 1) for name in coordinates)
    faces = _ugrid_variable(nc, getattr(topology, "face_node_connectivity", None), path, "face_node_connectivity", 2)
    if getattr(faces.dtype, "kind", "O") not in "iu":
        raise file_problem(path, "cannot be read as UGRID netCDF: face_node_connectivity must hold integers")
    vertices, (cells, corners) = x.shape[0], faces.shape
    if y.shape[0] != vertices:
        raise file_problem(path, f"cannot be read as UGRID netCDF: {x.shape[0]} x but {y.shape[0]} y node coordinates")
    if cells * corners > 64 * vertices + (1 << 20):
        raise file_problem(
            path,
            f"declares a face table of {cells:,} x {corners:,} entries for {vertices:,} vertices; the file is broken",
        )
    sides = _mesh2d_sides(nc, topology, vertices, path)
    return MeshFileHeader(vertices, cells, sides, True, size)


def _mesh3d_counts(nc, path: Path, size: int) -> MeshFileHeader:
    """The counts and sides of a ``mesh3d`` file from its dimensions and attributes; its
    tables' declared shapes must be proportional to its nodes (netCDF reads unwritten chunks as fill
    values: a 40 kB file can declare gigabytes)."""
    topologies = _topologies(nc)
    if len(topologies) == 1 and str(getattr(topologies[0], "topology_dimension", "2")) == "2":
        raise file_problem(
            path, "is a 2D mesh (UGRID mesh2d) but the scene is 3D; give a 3D mesh file, or drop model: 3d"
        )
    if len(topologies) != 1 or str(getattr(topologies[0], "topology_dimension", "")) != "3":
        raise file_problem(
            path,
            "cannot be read as a mesh3d netCDF file: expected one 3D mesh topology variable (topology_dimension = 3)",
        )
    topology = topologies[0]
    volumes = _ugrid_variable(
        nc, getattr(topology, "volume_face_connectivity", None), path, "volume_face_connectivity", 2
    )
    faces = _ugrid_variable(nc, getattr(topology, "face_node_connectivity", None), path, "face_node_connectivity", 2)
    coordinates = str(getattr(topology, "node_coordinates", "")).split()
    if len(coordinates) != 3:
        raise file_problem(
            path, "cannot be read as a mesh3d netCDF file: node_coordinates must name three variables (x y z)"
        )
    x, y, z = (_ugrid_variable(nc, name, path, "node coordinate", 1) for name in coordinates)
    vertices = x.shape[0]
    if y.shape[0] != vertices or z.shape[0] != vertices:
        raise file_problem(
            path,
            f"{vertices:,} x but {y.shape[0]:,} y and {z.shape[0]:,} z node coordinates; the file is broken: "
            "write it again (vemkit mesh --scene)",
        )
    most = TABLE_ENTRIES_PER_VERTEX * vertices + (1 << 20)
    for table, what in ((faces, "face"), (volumes, "volume")):
        if table.shape[0] * table.shape[1] > most:
            raise file_problem(
                path,
                f"declares a {what} table of {table.shape[0]:,} x {table.shape[1]:,} entries for {vertices:,} "
                "vertices; the file is broken: write it again (vemkit mesh --scene)",
            )
    names = _side_names(topology, path, "a mesh3d netCDF file")
    for name in names:
        key = f"mesh3d_boundary_{name}"
        if key in nc.variables and (nc.variables[key].ndim != 1 or nc.variables[key].shape[0] > faces.shape[0]):
            raise file_problem(
                path,
                f"{key[:80]} declares {nc.variables[key].size:,} faces but the mesh has {faces.shape[0]:,}; "
                "the file is broken: write it again (vemkit mesh --scene)",
            )
    return MeshFileHeader(vertices, volumes.shape[0], tuple(names), True, size)


def _side_names(topology, path: Path, kind: str) -> list:
    """The JSON list ``vemkit_boundary_parts`` of the topology; a one-line refusal otherwise."""
    text = getattr(topology, "vemkit_boundary_parts", "[]")
    try:
        names = json.loads(text) if isinstance(text, str) else None
    except ValueError:
        names = None
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        raise file_problem(
            path,
            f"cannot be read as {kind}: the attribute vemkit_boundary_parts must be a JSON list of side names",
        )
    return names


def _mesh2d_sides(nc, topology, vertices: int, path: Path) -> tuple:
    names = _side_names(topology, path, "UGRID netCDF")
    for name in names:
        part = _ugrid_variable(nc, f"boundary_{name}", path, f"boundary part {name[:40]!r}", 2)
        if (
            part.shape[1] != _EDGE_VERTICES
            or part.shape[0] > 3 * vertices + 3
            or getattr(part.dtype, "kind", "O") not in "iu"
        ):
            raise file_problem(
                path,
                f"cannot be read as UGRID netCDF: boundary_{name[:40]} must be an integer table of "
                "edges (vertex pairs)",
            )
    return tuple(names)


#: the counts of a netCDF mesh file by the dimension of the scene it is read for
_COUNTS = {2: _mesh2d_counts, 3: _mesh3d_counts}
