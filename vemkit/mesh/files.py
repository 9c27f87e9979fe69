"""Reading 2D mesh files: UGRID-1.0 netCDF and gmsh ``.msh`` (the writers: ``vemkit.mesh.ugrid``, ``vemkit.mesh.vtu``).

``read_mesh(path)`` reads ``.nc`` (UGRID) or ``.msh`` (gmsh, versions 2 and 4 through meshio) and
validates the mesh like a family's: a broken mesh is refused with a one-line ``MeshError`` naming
the file and the cell or vertex (docs/reference/files.md). Before parsing, the file must be a regular file whose
declared counts fit its size, a plane mesh and the machine (``vemkit.config.mesh_file_header``);
the parser runs within a memory budget (``vemkit.mesh.file_budget``, shared with the 3D reader).

gmsh: the 2D elements (linear triangles and quadrilaterals, mixed freely) are the cells, turned
counter-clockwise if needed; nodes used by no cell (geometry points) are dropped; z must be 0.
Line elements carry the sides: each physical line group becomes the boundary part named by its
physical name, or by its number when it has none. Boundary edges in no group form the part
``untagged``; a tagged line that is not a boundary edge is refused.

UGRID layout (what ``vemkit.mesh.ugrid.write_ugrid`` writes, as xugrid would, and ``read_ugrid`` reads):

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

import numpy as np

from vemkit.config.domain import SIDE_NAME
from vemkit.config.mesh_file_header import OTHER_DIMENSION
from vemkit.exceptions import MeshError
from vemkit.mesh.check_kernels import worst_coordinate_over_edge
from vemkit.mesh.checks import validate_mesh
from vemkit.mesh.file_budget import parse_within_budget
from vemkit.mesh.geometry import counter_clockwise
from vemkit.mesh.mesh import Mesh
from vemkit.mesh.ugrid import FACE_FILL

FILL_VALUE = FACE_FILL


def read_ugrid(path) -> Mesh:
    """Read a mesh written by ``write_ugrid`` (or any UGRID-1.0 file with one 2D topology).

    Only the variables of the mesh are read (node coordinates, face table, boundary parts), never
    the rest of the file (a solution file's fields)."""
    import netCDF4  # not xarray: 0.3-0.6 s of a command's start-up

    with netCDF4.Dataset(Path(path)) as nc:
        nc.set_auto_maskandscale(False)  # the stored values, as xarray's mask_and_scale=False
        topologies = [v for v in nc.variables if _attrs(nc[v]).get("cf_role") == "mesh_topology"]
        if len(topologies) != 1:
            raise ValueError(f"{path}: expected one UGRID mesh topology variable, found {topologies or 'none'}")
        topo = _attrs(nc[topologies[0]])
        x_name, y_name = topo["node_coordinates"].split()
        faces = nc[topo["face_node_connectivity"]]
        fill = _attrs(faces).get("_FillValue", FILL_VALUE)
        start = int(_attrs(faces).get("start_index", 0))
        table = np.asarray(faces[...], dtype=np.int64)
        vertices = np.stack([nc[x_name][...], nc[y_name][...]], axis=1).astype(np.float64)
        names = json.loads(topo.get("vemkit_boundary_parts", "[]"))
        boundary = {name: np.asarray(nc[f"boundary_{name}"][...], dtype=np.int64) for name in names}
        try:
            meta = json.loads(topo.get("vemkit_meta", "{}"))
        except ValueError:
            meta = None
    if not isinstance(meta, dict):
        raise MeshError(
            f"{Path(path).name}: the attribute vemkit_meta must be a JSON mapping (text); fix or remove it",
            key=str(path),
        )
    valid = table != fill
    sizes = valid.sum(axis=1)
    offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    cell_vertices = table[valid] - start
    return Mesh(vertices, offsets, cell_vertices, boundary, meta)


def _attrs(variable) -> dict:
    """A netCDF4 variable's attributes by name."""
    return {key: variable.getncattr(key) for key in variable.ncattrs()}


# -- any mesh file ------------------------------------------------------------------------------
_GMSH_CELLS = ("triangle", "quad")
MAX_FILE_COORDINATE_OVER_EDGE = 1e7  # a unit square at 1e9 has a shoelace area of rounding noise


def read_mesh(path) -> Mesh:
    """The validated mesh in ``path`` (``.msh``: gmsh 2 or 4; ``.nc``: UGRID); MeshError otherwise.

    Before the file is parsed: it must be a regular file whose declared counts fit its size, a plane
    mesh and this machine; the parser then runs within a memory budget (a node tag of 10^10 in a
    small file would otherwise make meshio allocate gigabytes): ``vemkit.mesh.file_budget``, the
    path the 3D reader takes too."""
    path = Path(path)
    mesh, _ = parse_within_budget(path, 2, read_gmsh if path.suffix == ".msh" else read_ugrid)
    _check_precision(mesh, path)
    try:
        validate_mesh(mesh)
    except MeshError as error:
        raise MeshError(f"{path.name}: {error}", key=str(path)) from None
    return mesh


def _check_precision(mesh: Mesh, path: Path) -> None:
    """An edge far shorter than its distance from the origin loses its cells' shape in double precision
    (a unit square at x = 1e9: its shoelace area is rounding noise): refused naming the file when the
    ratio passes ``MAX_FILE_COORDINATE_OVER_EDGE`` (a plate at 1e6 still solves to 15 digits)."""
    if mesh.cell_vertices.size and mesh.cell_sizes.min() >= 3:  # else validate_mesh names the cell
        check_coordinate_precision(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, path)


def check_coordinate_precision(vertices: np.ndarray, offsets: np.ndarray, polygons: np.ndarray, path: Path) -> None:
    """The check of :func:`_check_precision` on the edges of ``polygons`` (CSR: a 2D mesh's cells, a
    3D mesh's faces: a cube at x = 1e9 has faces whose planes are rounding noise); broken arrays
    pass, the validation names them."""
    v, n = vertices, polygons.size
    if v.size == 0 or n == 0 or not np.isfinite(v).all() or polygons.min() < 0 or polygons.max() >= v.shape[0]:
        return
    if offsets[0] != 0 or offsets[-1] != n or (np.diff(offsets) < 0).any():
        return
    worst, ratio, length, reach = worst_coordinate_over_edge(v, offsets, polygons)
    if ratio > MAX_FILE_COORDINATE_OVER_EDGE:
        cell = int(np.searchsorted(offsets, worst, side="right")) - 1
        a, b = polygons[worst], polygons[worst + 1 if worst + 1 < offsets[cell + 1] else offsets[cell]]
        axes = ", ".join(f"|{axis}|" for axis in "xyz"[: v.shape[1]])
        raise MeshError(
            f"{path.name}: edge ({a}, {b}) is {length:.3g} long at {axes} = {reach:.3g}, more "
            f"than {MAX_FILE_COORDINATE_OVER_EDGE:.0e} times shorter than its distance from the origin: too "
            "small for double precision there; shift the mesh near the origin",
            key=str(path),
        )


def read_gmsh(path) -> Mesh:
    """The mesh of a gmsh file (not validated; see ``read_mesh``), sides from physical line groups."""
    path = Path(path)
    from vemkit.mesh.gmsh_errors import read_gmsh_data  # meshio: lazily, not in the core's import

    data = read_gmsh_data(path)
    if any(block.dim == 3 for block in data.cells):
        raise MeshError(f"{path.name}: {OTHER_DIMENSION[3]}", key=str(path))
    if data.points.shape[1] == 3 and np.abs(data.points[:, 2]).max(initial=0.0) > 0.0:
        v = int(np.flatnonzero(data.points[:, 2] != 0)[0])
        raise MeshError(
            f"{path.name}: node {v} (counting from 0) has z = {data.points[v, 2]:g}; give a plane mesh (z = 0)",
            key=str(path),
        )
    polygons, lines, line_tags = [], [], []
    physical = data.cell_data.get("gmsh:physical", [None] * len(data.cells))
    for block, tags in zip(data.cells, physical):
        if block.dim == 2:
            if block.type not in _GMSH_CELLS:
                raise MeshError(
                    f"{path.name}: element type {block.type!r} is not supported; give linear triangles or "
                    "quadrilaterals",
                    key=str(path),
                )
            polygons.append(np.asarray(block.data, dtype=np.int64))
        elif block.type == "line":
            lines.append(np.asarray(block.data, dtype=np.int64))
            line_tags.append(np.zeros(len(block.data), np.int64) if tags is None else np.asarray(tags, np.int64))
        elif block.dim != 0:
            raise MeshError(
                f"{path.name}: element type {block.type!r} ({block.dim}D) is not supported; give a plane "
                "mesh of linear triangles and quadrilaterals with linear lines",
                key=str(path),
            )
    if not polygons:
        raise MeshError(f"{path.name}: no triangles or quadrilaterals in the file", key=str(path))
    sizes = np.concatenate([np.full(len(p), p.shape[1]) for p in polygons])
    refs = np.concatenate([p.ravel() for p in polygons])
    used = np.zeros(data.points.shape[0], dtype=bool)
    used[refs] = True
    renumber = np.cumsum(used) - 1
    vertices = np.asarray(data.points[used, :2], dtype=np.float64)
    offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    mesh = Mesh(
        vertices,
        offsets,
        counter_clockwise(vertices, offsets, renumber[refs]),
        {},
        {"file": path.name, "format": "gmsh"},
    )
    names = {int(tag): name for name, (tag, dim) in data.field_data.items() if int(dim) == 1}
    if lines:
        lines = np.concatenate(lines)
        if not used[lines].all():
            raise MeshError(
                f"{path.name}: a line element uses node {int(lines[~used[lines]][0])} (counting from 0), "
                "which no cell uses; tag boundary lines of the mesh only",
                key=str(path),
            )
        return mesh.with_boundary(**_gmsh_sides(mesh, renumber[lines], np.concatenate(line_tags), names, path))
    return mesh.with_boundary(untagged=mesh.boundary_edges)


def _gmsh_sides(mesh: Mesh, lines: np.ndarray, tags: np.ndarray, names: dict, path: Path) -> dict:
    """Boundary parts from line elements: (a, b) oriented as the boundary edge runs in its cell."""
    n = np.int64(mesh.n_vertices)
    be = mesh.boundary_edges
    forward = dict(zip((be[:, 0] * n + be[:, 1]).tolist(), range(be.shape[0])))
    backward = dict(zip((be[:, 1] * n + be[:, 0]).tolist(), range(be.shape[0])))
    edge = np.array([forward.get(int(a) * n + int(b), backward.get(int(a) * n + int(b), -1)) for a, b in lines])
    if (edge < 0).any():
        a, b = lines[edge < 0][0]
        raise MeshError(
            f"{path.name}: line element ({a}, {b}) of physical group {tags[edge < 0][0]} is not a boundary "
            "edge of the mesh; tag boundary lines only",
            key=str(path),
        )
    parts = {}
    for tag in dict.fromkeys(tags.tolist()):
        name = names.get(tag, str(tag)) if tag else "untagged"
        if not SIDE_NAME.fullmatch(name):
            raise MeshError(
                f"{path.name}: physical name {name!r} is not an identifier; use letters, digits, _ and -", key=str(path)
            )
        parts[name] = be[np.unique(edge[tags == tag])]
    rest = np.setdiff1d(np.arange(be.shape[0]), edge)
    if rest.size:
        parts["untagged"] = np.concatenate([parts.get("untagged", np.zeros((0, 2), np.int64)), be[rest]])
    return parts
