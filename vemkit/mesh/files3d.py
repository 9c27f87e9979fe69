"""3D mesh files (docs/reference/files.md): the ``mesh3d`` UGRID-style netCDF topology (round trip), VTU with VTK
polyhedron cells (type 42, for ParaView) and gmsh ``.msh`` 3D meshes (read, through meshio).

netCDF layout (``mesh3d_description`` / ``read_ugrid3d``):

- ``mesh3d``: the topology variable, ``cf_role = "mesh_topology"``, ``topology_dimension = 3``,
  ``node_coordinates``, ``face_node_connectivity``, ``volume_face_connectivity``; ``vemkit_meta``
  (JSON of ``meta``) and ``vemkit_boundary_parts`` (JSON list of the part names);
- ``mesh3d_node_x``, ``_y``, ``_z`` (``mesh3d_nNodes``), float64;
- ``mesh3d_face_nodes`` (``mesh3d_nFaces``, ``mesh3d_nMax_face_nodes``): every face once, its
  vertices in order (right-hand rule gives its normal), ``_FillValue = -1``, ``start_index = 0``;
- ``mesh3d_volume_faces`` (``mesh3d_nVolumes``, ``mesh3d_nMax_volume_faces``): the faces of every
  cell, outward taken with their signs: f as stored, ``-(f + 1)`` reversed; ``_FillValue`` =
  ``VOLUME_FILL`` (the most negative int64, since -1 is a face);
- ``mesh3d_boundary_<name>`` (``mesh3d_boundary_<name>_nFaces``): the faces of each boundary part.

VTU: one ``UnstructuredGrid`` piece, cells in mesh order, all of type 42 (VTK_POLYHEDRON) with
``connectivity`` (the cell's distinct vertices), ``faces`` (per cell: number of faces, then per
face its vertex count and vertices, outward) and ``faceoffsets`` (end of each cell's stream),
binary (base64, UInt64 headers).

gmsh: linear ``tetra``, ``hexahedron``, ``wedge`` and ``pyramid`` elements are the cells (an
element given with mirrored node order is turned outward); physical SURFACE groups (triangles,
quadrilaterals) name the sides, by physical name or else number; boundary faces in no group form
the part ``untagged``. ``read_mesh3d`` parses within the 2D reader's memory budget
(``vemkit.mesh.file_budget``) and validates (``validate_mesh3d``): a broken file is one line naming it.
"""

from __future__ import annotations

import base64
import json
from pathlib import Path

import numpy as np

from vemkit.config.domain import SIDE_NAME
from vemkit.config.mesh_file_header import OTHER_DIMENSION
from vemkit.exceptions import MeshError
from vemkit.mesh.checks3d import validate_mesh3d
from vemkit.mesh.file_description import FileDescription
from vemkit.mesh.files import check_coordinate_precision, json_scalar
from vemkit.mesh.polyhedral import PolyhedralMesh
from vemkit.mesh.polyhedral_build import csr_rows, from_face_soup

TOPOLOGY = "mesh3d"
FACE_FILL = -1
VOLUME_FILL = np.iinfo(np.int64).min
VTK_POLYHEDRON = 42


def mesh3d_description(mesh: PolyhedralMesh) -> FileDescription:
    """The ``mesh3d`` topology of the module doc, ready to take node or volume data."""
    t = TOPOLOGY
    faces = csr_rows(mesh.face_offsets, mesh.face_vertices, FACE_FILL)
    volumes = csr_rows(mesh.cell_offsets, mesh.cell_faces, VOLUME_FILL)
    out = FileDescription()
    for k, a in enumerate("xyz"):
        out.add(f"{t}_node_{a}", f"{t}_nNodes", mesh.vertices[:, k])
    out.add(
        f"{t}_face_nodes",
        (f"{t}_nFaces", f"{t}_nMax_face_nodes"),
        faces,
        {"cf_role": "face_node_connectivity", "start_index": 0},
        encoding={"_FillValue": FACE_FILL},
    )
    out.add(
        f"{t}_volume_faces",
        (f"{t}_nVolumes", f"{t}_nMax_volume_faces"),
        volumes,
        {"cf_role": "volume_face_connectivity", "start_index": 0, "orientation": "outward; -(f+1) is face f reversed"},
        encoding={"_FillValue": VOLUME_FILL},
    )
    for name, part in mesh.boundary.items():
        out.add(f"{t}_boundary_{name}", f"{t}_boundary_{name}_nFaces", np.asarray(part, np.int64))
    topology = {
        "cf_role": "mesh_topology",
        "topology_dimension": 3,
        "node_coordinates": f"{t}_node_x {t}_node_y {t}_node_z",
        "face_node_connectivity": f"{t}_face_nodes",
        "volume_face_connectivity": f"{t}_volume_faces",
        "vemkit_meta": json.dumps(mesh.meta, default=json_scalar),
        "vemkit_boundary_parts": json.dumps(list(mesh.boundary)),
    }
    out.add(t, (), np.int32(0), topology)
    return out


def mesh3d_to_dataset(mesh: PolyhedralMesh):
    """The ``mesh3d`` topology as an xarray Dataset (:func:`mesh3d_description`)."""
    return mesh3d_description(mesh).to_dataset()


def write_ugrid3d(mesh: PolyhedralMesh, path) -> None:
    mesh3d_description(mesh).write_netcdf4(path)


def read_ugrid3d(path) -> PolyhedralMesh:
    """The validated mesh of a ``mesh3d`` netCDF file; MeshError naming the file otherwise."""
    return _validated(parse_ugrid3d(Path(path)), Path(path))


def parse_ugrid3d(path: Path) -> PolyhedralMesh:
    """The mesh of a ``mesh3d`` netCDF file, not validated; MeshError naming the file (a MemoryError
    passes: see ``read_mesh3d``). Read through netCDF4 (the stored values, as xarray's
    ``mask_and_scale=False``), not xarray: its import is 0.7 s of a 3D command."""
    path = Path(path)
    t = TOPOLOGY
    import netCDF4

    try:
        with netCDF4.Dataset(path) as nc:
            nc.set_auto_maskandscale(False)
            if t not in nc.variables:
                raise MeshError(
                    f"{path.name}: no variable {t!r}; give a file written by vemkit (a mesh3d topology)", key=str(path)
                )
            return _mesh_from_dataset(_StoredVariables(nc), path)
    except (MeshError, MemoryError):
        raise
    except Exception as error:
        reason = " ".join(str(error).split())[:200] or type(error).__name__
        raise MeshError(f"{path.name}: cannot be read as a mesh3d netCDF file: {reason}", key=str(path)) from None


class _StoredVariable:
    """One netCDF4 variable as ``_mesh_from_dataset`` reads an xarray one: ``values``, ``attrs``."""

    def __init__(self, variable):
        self._variable = variable
        self.attrs = {key: variable.getncattr(key) for key in variable.ncattrs()}

    @property
    def values(self) -> np.ndarray:
        return np.asarray(self._variable[...])


class _StoredVariables:
    """An open netCDF4 file as ``_mesh_from_dataset`` reads an xarray Dataset: ``variables``, ``ds[name]``."""

    def __init__(self, nc):
        self._nc = nc
        self.variables = nc.variables

    def __getitem__(self, name: str) -> _StoredVariable:
        return _StoredVariable(self._nc[name])


def _mesh_from_dataset(ds, path: Path) -> PolyhedralMesh:
    """The mesh of an xarray Dataset or of ``_StoredVariables`` (the same names, values and attributes)."""
    t = TOPOLOGY
    for name in (f"{t}_node_x", f"{t}_node_y", f"{t}_node_z", f"{t}_face_nodes", f"{t}_volume_faces"):
        if name not in ds.variables:
            raise MeshError(f"{path.name}: variable {name} is missing; give a complete mesh3d topology", key=str(path))
    vertices = np.stack([ds[f"{t}_node_{a}"].values.astype(float) for a in "xyz"], axis=1)
    faces = ds[f"{t}_face_nodes"]
    stored = faces.values
    table = stored.astype(np.int64) - int(faces.attrs.get("start_index", 0))
    fill = int(faces.attrs.get("_FillValue", FACE_FILL))
    valid = stored != fill
    volumes = ds[f"{t}_volume_faces"]
    vfill = int(volumes.attrs.get("_FillValue", VOLUME_FILL))
    vtable = volumes.values.astype(np.int64)
    vvalid = vtable != vfill
    parts = json.loads(str(ds[t].attrs.get("vemkit_boundary_parts", "[]")))
    boundary = {}
    for name in parts:
        key = f"{t}_boundary_{name}"
        if key not in ds.variables:
            raise MeshError(
                f"{path.name}: boundary part {name!r} is listed but variable {key} is missing", key=str(path)
            )
        boundary[name] = ds[key].values.astype(np.int64)
    meta = json.loads(str(ds[t].attrs.get("vemkit_meta", "{}")))
    return PolyhedralMesh(
        vertices,
        np.concatenate([[0], np.cumsum(valid.sum(axis=1))]),
        table[valid],
        np.concatenate([[0], np.cumsum(vvalid.sum(axis=1))]),
        vtable[vvalid],
        boundary,
        meta if isinstance(meta, dict) else {},
    )


def _validated(mesh: PolyhedralMesh, path: Path) -> PolyhedralMesh:
    check_coordinate_precision(mesh.vertices, mesh.face_offsets, mesh.face_vertices, path)  # as in 2D
    try:
        validate_mesh3d(mesh)
    except MeshError as error:
        raise MeshError(f"{path.name}: {error}", key=str(path)) from None
    return mesh


# -- VTU ------------------------------------------------------------------------------------------
def polyhedron_streams(mesh: PolyhedralMesh):
    """(connectivity, offsets, faces, faceoffsets) of the VTK polyhedron cells, faces outward."""
    conn_offsets, conn = mesh.cell_vertex_lists
    cf = mesh.cell_faces
    faces = np.where(cf >= 0, cf, -cf - 1)
    sizes = np.diff(mesh.face_offsets)[faces]
    start = mesh.face_offsets[faces]
    entry = np.repeat(np.arange(faces.size), sizes)
    local = np.arange(entry.size) - np.repeat(np.cumsum(sizes) - sizes, sizes)
    local = np.where(cf[entry] >= 0, local, sizes[entry] - 1 - local)
    ids = mesh.face_vertices[start[entry] + local]
    # stream: per cell [nF, (n, ids...) per face]; place the headers and the ids in one array
    per_cell = np.diff(mesh.cell_offsets)
    cells = np.repeat(np.arange(mesh.n_cells), per_cell)
    length = 1 + np.bincount(cells, weights=sizes + 1, minlength=mesh.n_cells).astype(np.int64)
    ends = np.cumsum(length)
    stream = np.empty(int(ends[-1]), dtype=np.int64)
    cell_start = ends - length
    stream[cell_start] = per_cell
    face_pos = (
        cell_start[cells]
        + 1
        + (np.cumsum(sizes + 1) - (sizes + 1))
        - np.repeat((np.cumsum(sizes + 1) - (sizes + 1))[mesh.cell_offsets[:-1]], per_cell)
    )
    stream[face_pos] = sizes
    stream[np.repeat(face_pos + 1, sizes) + (np.arange(entry.size) - np.repeat(np.cumsum(sizes) - sizes, sizes))] = ids
    return conn, conn_offsets[1:], stream, ends


def _data_array(name: str, values: np.ndarray, components: int = 1) -> str:
    values = np.ascontiguousarray(values)
    kind = {np.dtype(np.float64): "Float64", np.dtype(np.int64): "Int64", np.dtype(np.uint8): "UInt8"}[values.dtype]
    raw = values.tobytes()
    text = base64.b64encode(np.uint64(len(raw)).tobytes() + raw).decode("ascii")
    shape = f' NumberOfComponents="{components}"' if components > 1 else ""
    return f'<DataArray type="{kind}" Name="{name}"{shape} format="binary">{text}</DataArray>\n'


def write_vtu3d(mesh: PolyhedralMesh, path, point_data: dict | None = None, cell_data: dict | None = None) -> None:
    """Write the mesh (and data: arrays of n_vertices / n_cells rows) as VTU polyhedra (module doc);
    the cell data array ``cell_index`` numbers the cells as in the mesh."""
    conn, offsets, faces, faceoffsets = polyhedron_streams(mesh)
    arrays = {"points": {}, "cells": {}}
    for where, data, count in (("points", point_data, mesh.n_vertices), ("cells", cell_data, mesh.n_cells)):
        for name, values in (data or {}).items():
            values = np.asarray(values, dtype=np.float64)
            if values.shape[0] != count:
                raise ValueError(f"{where} data {name!r} has {values.shape[0]} rows; the mesh has {count} {where}")
            arrays[where][name] = values
    arrays["cells"]["cell_index"] = np.arange(mesh.n_cells, dtype=np.int64)
    parts = [
        '<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
        'header_type="UInt64">\n<UnstructuredGrid>\n',
        f'<Piece NumberOfPoints="{mesh.n_vertices}" NumberOfCells="{mesh.n_cells}">\n',
        "<Points>\n",
        _data_array("Points", mesh.vertices.astype("<f8"), 3),
        "</Points>\n<Cells>\n",
        _data_array("connectivity", conn),
        _data_array("offsets", offsets),
        _data_array("types", np.full(mesh.n_cells, VTK_POLYHEDRON, dtype=np.uint8)),
        _data_array("faces", faces),
        _data_array("faceoffsets", faceoffsets),
        "</Cells>\n",
    ]
    for tag, where in (("PointData", "points"), ("CellData", "cells")):
        parts.append(f"<{tag}>\n")
        for name, values in arrays[where].items():
            parts.append(_data_array(name, values, 1 if values.ndim == 1 else values.shape[1]))
        parts.append(f"</{tag}>\n")
    parts.append("</Piece>\n</UnstructuredGrid>\n</VTKFile>\n")
    Path(path).write_text("".join(parts), encoding="ascii")


# -- gmsh -----------------------------------------------------------------------------------------
#: outward faces of the linear gmsh (= VTK) elements in their standard node order, and the three
#: edges from node 0 whose determinant is positive for that order
GMSH_CELLS = {
    "tetra": ([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]], (1, 2, 3)),
    "hexahedron": ([[0, 4, 7, 3], [1, 2, 6, 5], [0, 1, 5, 4], [3, 7, 6, 2], [0, 3, 2, 1], [4, 5, 6, 7]], (1, 3, 4)),
    "wedge": ([[0, 2, 1], [3, 4, 5], [0, 1, 4, 3], [1, 2, 5, 4], [2, 0, 3, 5]], (1, 2, 3)),
    "pyramid": ([[0, 3, 2, 1], [0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]], (1, 3, 4)),
}
GMSH_SURFACES = ("triangle", "quad")


def _element_soup(points: np.ndarray, kind: str, nodes: np.ndarray):
    """(face rows padded to 4, faces per element) of one block of elements, turned outward."""
    table, (i, j, k) = GMSH_CELLS[kind]
    p = points[nodes]
    det = np.einsum("ij,ij->i", p[:, i] - p[:, 0], np.cross(p[:, j] - p[:, 0], p[:, k] - p[:, 0]))
    rows = np.full((nodes.shape[0], len(table), 4), -1, dtype=np.int64)
    for f, face in enumerate(table):
        ids = nodes[:, face]
        ids[det < 0] = ids[det < 0][:, ::-1]
        rows[:, f, : len(face)] = ids
    return rows.reshape(-1, 4), np.full(nodes.shape[0], len(table))


def read_gmsh3d(path) -> PolyhedralMesh:
    """The validated mesh of a 3D gmsh file (module doc); MeshError naming the file otherwise."""
    from vemkit.mesh.gmsh_errors import read_gmsh_data  # meshio: lazily, not in the core's import

    return _validated(gmsh3d_mesh(read_gmsh_data(path), Path(path)), Path(path))


def gmsh3d_mesh(data, path: Path) -> PolyhedralMesh:
    """The mesh (not validated) of what meshio read from the 3D gmsh file ``path``."""
    points = np.asarray(data.points, dtype=float)
    if points.shape[1] != 3:
        points = np.column_stack([points, np.zeros((points.shape[0], 3 - points.shape[1]))])
    physical = data.cell_data.get("gmsh:physical", [None] * len(data.cells))
    soups, counts, surfaces, tags = [], [], [], []
    for block, tag in zip(data.cells, physical):
        if block.type in GMSH_CELLS:
            rows, count = _element_soup(points, block.type, np.asarray(block.data, np.int64))
            soups.append(rows)
            counts.append(count)
        elif block.type in GMSH_SURFACES:
            surfaces += [np.sort(np.asarray(block.data, np.int64), axis=1)]
            tags.append(np.zeros(len(block.data), np.int64) if tag is None else np.asarray(tag, np.int64))
        elif block.dim == 3 or block.dim == 2:
            raise MeshError(
                f"{path.name}: element type {block.type!r} is not supported; give linear tetrahedra, "
                "hexahedra, prisms (wedge) or pyramids, with triangles or quadrilaterals as surfaces",
                key=str(path),
            )
    if not soups and surfaces:
        raise MeshError(f"{path.name}: {OTHER_DIMENSION[2]}", key=str(path))
    if not soups:
        raise MeshError(
            f"{path.name}: no tetrahedra, hexahedra, prisms or pyramids in the file; give a 3D mesh", key=str(path)
        )
    rows = np.concatenate(soups)
    used = np.unique(rows[rows >= 0])
    renumber = np.full(points.shape[0], -1, dtype=np.int64)
    renumber[used] = np.arange(used.size)
    valid = rows >= 0
    mesh = from_face_soup(
        points[used],
        np.concatenate(counts),
        valid.sum(axis=1),
        renumber[rows[valid]],
        None,
        (),
        {"file": path.name, "format": "gmsh"},
    )
    names = {int(tag): name for name, (tag, dim) in data.field_data.items() if int(dim) == 2}
    parts = _gmsh_sides3d(mesh, surfaces, tags, renumber, names, path)
    mesh = PolyhedralMesh(
        mesh.vertices, mesh.face_offsets, mesh.face_vertices, mesh.cell_offsets, mesh.cell_faces, parts, mesh.meta
    )
    return _validated(mesh, path)


def _face_keys(mesh: PolyhedralMesh, faces: np.ndarray) -> np.ndarray:
    """Sorted vertex rows (padded to 4 with -1 at the front) of faces with 3 or 4 vertices."""
    rows = csr_rows(mesh.face_offsets, mesh.face_vertices)[faces]
    rows = np.pad(rows, ((0, 0), (0, max(0, 4 - rows.shape[1]))), constant_values=-1)[:, :4]
    return np.sort(rows, axis=1)


def _gmsh_sides3d(mesh, surfaces, tags, renumber, names, path) -> dict:
    bf = mesh.boundary_faces
    if not surfaces:
        return {"untagged": bf}
    keys = _face_keys(mesh, bf)
    lookup = {tuple(k): f for k, f in zip(keys.tolist(), bf.tolist())}
    parts, seen = {}, np.zeros(mesh.n_faces, dtype=bool)
    for nodes, tag in zip(surfaces, tags):
        ids = np.sort(np.where(renumber[nodes] >= 0, renumber[nodes], -2), axis=1)
        ids = np.pad(ids, ((0, 0), (4 - ids.shape[1], 0)), constant_values=-1)
        faces = np.array([lookup.get(tuple(k), -1) for k in ids.tolist()], dtype=np.int64)
        if (faces < 0).any():
            bad = int(np.flatnonzero(faces < 0)[0])
            raise MeshError(
                f"{path.name}: surface element {nodes[bad].tolist()} (nodes counting from 0) of physical "
                f"group {tag[bad]} is not a boundary face of the mesh; tag boundary surfaces only",
                key=str(path),
            )
        for t in dict.fromkeys(tag.tolist()):
            name = names.get(t, str(t)) if t else "untagged"
            if not SIDE_NAME.fullmatch(name):
                raise MeshError(
                    f"{path.name}: physical name {name!r} is not an identifier; use letters, digits, _ and -",
                    key=str(path),
                )
            part = np.unique(faces[tag == t])
            parts[name] = np.union1d(parts.get(name, np.zeros(0, np.int64)), part)
            seen[part] = True
    rest = bf[~seen[bf]]
    if rest.size:
        parts["untagged"] = np.union1d(parts.get("untagged", np.zeros(0, np.int64)), rest)
    return parts


def read_mesh3d(path) -> PolyhedralMesh:
    """A validated 3D mesh file: ``.msh`` (gmsh 2 or 4) or ``.nc`` (mesh3d netCDF). Read as the 2D
    reader reads (``vemkit.mesh.file_budget``): the header checked first, the parser within a memory
    budget, then the mesh built and validated."""
    from vemkit.mesh.file_budget import parse_within_budget
    from vemkit.mesh.gmsh_errors import read_gmsh_data

    path = Path(path)
    if path.suffix == ".msh":
        data, _ = parse_within_budget(path, 3, read_gmsh_data)
        mesh = gmsh3d_mesh(data, path)
    else:
        mesh, _ = parse_within_budget(path, 3, parse_ugrid3d)
    return _validated(mesh, path)
