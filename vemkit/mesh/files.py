"""Mesh files: UGRID-1.0 netCDF (round trip) and VTU (for ParaView).

UGRID layout (what ``mesh_to_ugrid_dataset`` builds with xugrid, and ``read_ugrid`` reads):

- topology variable ``mesh2d`` (cf_role mesh_topology); its attribute ``vemkit_meta`` holds the
  mesh's ``meta`` as JSON text, ``vemkit_boundary_parts`` the boundary part names (JSON list);
- ``mesh2d_node_x``, ``mesh2d_node_y`` (dimension ``mesh2d_nNodes``), float64;
- ``mesh2d_face_nodes`` (``mesh2d_nFaces``, ``mesh2d_nMax_face_nodes``): the polygons' vertices,
  counter-clockwise, padded with ``_FillValue = -1``, ``start_index = 0``;
- ``mesh2d_edge_nodes`` (``mesh2d_nEdges``, ``two``): the mesh's edges (``Mesh.edges``);
- one variable ``boundary_<name>`` (``boundary_<name>_nEdges``, ``two``) per boundary part.

Everything vemkit needs sits on variables (not global attributes), so a result file built on this
dataset can set its own global attributes freely and still be read back by ``read_ugrid``.
"""

from __future__ import annotations

import json
from pathlib import Path

import meshio
import numpy as np
import xarray as xr
import xugrid

from vemkit.mesh.mesh import Mesh

TOPOLOGY = "mesh2d"
FILL_VALUE = -1


def padded_face_nodes(mesh: Mesh, fill_value: int = FILL_VALUE) -> np.ndarray:
    """``(M, max cell size)`` vertex indices of every cell, padded with ``fill_value`` (vectorised)."""
    sizes = mesh.cell_sizes
    out = np.full((mesh.n_cells, int(sizes.max()) if mesh.n_cells else 0), fill_value, dtype=np.int64)
    rows = np.repeat(np.arange(mesh.n_cells, dtype=np.int64), sizes)
    cols = np.arange(mesh.cell_vertices.size, dtype=np.int64) - np.repeat(mesh.cell_offsets[:-1], sizes)
    out[rows, cols] = mesh.cell_vertices
    return out


def mesh_to_ugrid_dataset(mesh: Mesh) -> xr.Dataset:
    """The mesh as a UGRID-1.0 ``xarray.Dataset`` (see the module docstring), ready to take node or face data."""
    grid = xugrid.Ugrid2d(
        mesh.vertices[:, 0], mesh.vertices[:, 1], FILL_VALUE, padded_face_nodes(mesh),
        name=TOPOLOGY, edge_node_connectivity=mesh.edges,
    )
    ds = grid.to_dataset()
    names = list(mesh.boundary)
    for name in names:
        if not name.isidentifier():
            raise ValueError(f"boundary part name {name!r}: use letters, digits and underscores only")
        ds[f"boundary_{name}"] = xr.DataArray(
            mesh.boundary[name], dims=(f"boundary_{name}_nEdges", "two"),
            attrs={"long_name": f"boundary part {name}: edges as vertex pairs, counter-clockwise",
                   "start_index": 0, "mesh": TOPOLOGY},
        )
    ds[TOPOLOGY].attrs["vemkit_boundary_parts"] = json.dumps(names)
    ds[TOPOLOGY].attrs["vemkit_meta"] = json.dumps(mesh.meta, default=_json_scalar)
    return ds


def write_ugrid(mesh: Mesh, path) -> None:
    """Write the mesh as a UGRID-1.0 netCDF4 file."""
    mesh_to_ugrid_dataset(mesh).to_netcdf(Path(path), format="NETCDF4")


def read_ugrid(path) -> Mesh:
    """Read a mesh written by ``write_ugrid`` (or any UGRID-1.0 file with one 2D topology)."""
    with xr.open_dataset(Path(path), mask_and_scale=False) as ds:
        ds = ds.load()
    topologies = [v for v in ds.variables if ds[v].attrs.get("cf_role") == "mesh_topology"]
    if len(topologies) != 1:
        raise ValueError(f"{path}: expected one UGRID mesh topology variable, found {topologies or 'none'}")
    topo = ds[topologies[0]].attrs
    x_name, y_name = topo["node_coordinates"].split()
    faces = ds[topo["face_node_connectivity"]]
    fill = faces.attrs.get("_FillValue", FILL_VALUE)
    start = int(faces.attrs.get("start_index", 0))
    table = np.asarray(faces.values, dtype=np.int64)
    valid = table != fill
    sizes = valid.sum(axis=1)
    offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    cell_vertices = table[valid] - start
    vertices = np.stack([ds[x_name].values, ds[y_name].values], axis=1).astype(np.float64)
    names = json.loads(topo.get("vemkit_boundary_parts", "[]"))
    boundary = {name: np.asarray(ds[f"boundary_{name}"].values, dtype=np.int64) for name in names}
    meta = json.loads(topo.get("vemkit_meta", "{}"))
    return Mesh(vertices, offsets, cell_vertices, boundary, meta)


def write_vtu(mesh: Mesh, path, point_data: dict | None = None, cell_data: dict | None = None) -> None:
    """Write the mesh (and data) as VTU: VTK_POLYGON blocks grouped by vertex count.

    Cells are written grouped by their number of vertices, so the file's cell order differs from
    the mesh's; the cell data array ``cell_index`` gives every written cell's index in the mesh.
    Two-component vectors (displacements) are padded with a zero third component for ParaView.
    """
    sizes = mesh.cell_sizes
    groups = [np.flatnonzero(sizes == s) for s in np.unique(sizes)]
    blocks = [
        ("polygon", mesh.cell_vertices[mesh.cell_offsets[cells][:, None] + np.arange(sizes[cells[0]])])
        for cells in groups
    ]
    cells_out = {"cell_index": [cells.astype(np.int64) for cells in groups]}
    for name, values in (cell_data or {}).items():
        values = _three_components(np.asarray(values), mesh.n_cells, f"cell_data {name!r}")
        cells_out[name] = [values[cells] for cells in groups]
    points_out = {
        name: _three_components(np.asarray(values), mesh.n_vertices, f"point_data {name!r}")
        for name, values in (point_data or {}).items()
    }
    points = np.column_stack([mesh.vertices, np.zeros(mesh.n_vertices)])
    meshio.Mesh(points, blocks, point_data=points_out, cell_data=cells_out).write(Path(path), file_format="vtu")


def _three_components(values: np.ndarray, count: int, what: str) -> np.ndarray:
    if values.shape[0] != count:
        raise ValueError(f"{what} has {values.shape[0]} entries; the mesh has {count}")
    if values.ndim == 2 and values.shape[1] == 2:
        values = np.column_stack([values, np.zeros(count, dtype=values.dtype)])
    return values


def _json_scalar(value):
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"mesh meta value {value!r} cannot be stored as JSON")
