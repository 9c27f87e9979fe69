"""Reading 3D mesh files (docs/reference/files.md): the ``mesh3d`` UGRID-style netCDF topology and gmsh
``.msh`` 3D meshes (through meshio). The writers: ``vemkit.mesh.ugrid`` (netCDF) and ``vemkit.mesh.vtu``.

netCDF layout (``vemkit.mesh.ugrid.write_ugrid`` / ``read_ugrid3d``):

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

gmsh: linear ``tetra``, ``hexahedron``, ``wedge`` and ``pyramid`` elements are the cells (an
element given with mirrored node order is turned outward); physical SURFACE groups (triangles,
quadrilaterals) name the sides, by physical name or else number; boundary faces in no group form
the part ``untagged``. ``read_mesh3d`` parses within the 2D reader's memory budget
(``vemkit.mesh.file_budget``) and validates (``validate_mesh3d``): a broken file is one line naming it.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from vemkit.config.domain import SIDE_NAME
from vemkit.config.mesh_file_header import OTHER_DIMENSION
from vemkit.exceptions import MeshError
from vemkit.mesh.checks3d import validate_mesh3d
from vemkit.mesh.files import check_coordinate_precision
from vemkit.mesh.polyhedral import PolyhedralMesh
from vemkit.mesh.polyhedral_build import csr_rows, from_face_soup
from vemkit.mesh.ugrid import FACE_FILL, TOPOLOGY_NAMES, VOLUME_FILL

TOPOLOGY = TOPOLOGY_NAMES[3]


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
