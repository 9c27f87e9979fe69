"""A mesh's UGRID topology described once, 2D or 3D, and the one writer of it (docs/reference/files.md).

:func:`mesh_topology` describes any mesh (a polygonal :class:`~vemkit.mesh.mesh.Mesh` or a
:class:`~vemkit.mesh.polyhedral.PolyhedralMesh`, told apart by their own ``dimension``) as a
:class:`MeshTopology`: the topology variable's name (``mesh2d``, ``mesh3d``) and attributes, the
node coordinates per axis, the connectivity tables, the boundary parts, and the order in which the
file holds them. :func:`topology_file` is the one writer: it serializes any description as a
:class:`~vemkit.mesh.file_description.FileDescription`, which the mesh file (:func:`write_ugrid`)
and the solution file (``vemkit.io.solution_file``) then fill.

2D, ``mesh2d`` (what ``xugrid.Ugrid2d(...).to_dataset()`` gives; a test compares them): the
topology variable first (``vemkit_boundary_parts``, ``vemkit_meta``: JSON text), then
``mesh2d_face_nodes`` (the cells' vertices counter-clockwise, padded with ``_FillValue = -1``),
``mesh2d_edge_nodes`` (``Mesh.edges``), the coordinates ``mesh2d_node_x``, ``mesh2d_node_y`` and
one ``boundary_<name>`` (edges as vertex pairs) per boundary part.

3D, ``mesh3d``: ``mesh3d_node_x``, ``_y``, ``_z``; ``mesh3d_face_nodes`` (every face once, right-hand
rule gives its normal, ``_FillValue = -1``); ``mesh3d_volume_faces`` (the faces of every cell,
outward with their signs: f as stored, ``-(f + 1)`` reversed; ``_FillValue`` = ``VOLUME_FILL``,
since -1 is a face); one ``mesh3d_boundary_<name>`` (face indices) per part; the topology variable
last (``topology_dimension = 3``, ``volume_face_connectivity``, ``vemkit_meta``,
``vemkit_boundary_parts``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from vemkit.config.domain import SIDE_NAME
from vemkit.mesh.file_description import FileDescription
from vemkit.mesh.polyhedral_build import csr_rows

#: the topology variable of a mesh of each dimension
TOPOLOGY_NAMES = {2: "mesh2d", 3: "mesh3d"}
FACE_FILL = -1
VOLUME_FILL = np.iinfo(np.int64).min  # -1 is face 0 reversed in a volume's signed face list


class TopologyVariable(NamedTuple):
    """One variable of a topology: its name, dimensions, values and attributes as the file holds them."""

    name: str
    dims: tuple[str, ...]
    values: np.ndarray
    attrs: dict[str, Any]
    encoding: dict[str, Any] = {}
    coordinate: bool = False


@dataclass(frozen=True)
class MeshTopology:
    """A mesh as its UGRID file describes it (module docstring), for one writer to serialize."""

    name: str
    dimension: int
    attrs: dict[str, Any]
    node_coordinates: tuple[TopologyVariable, ...]
    connectivity: tuple[TopologyVariable, ...]
    boundary_parts: tuple[TopologyVariable, ...]
    #: the file order of the sections: "topology" (the topology variable) and the tuples above
    layout: tuple[str, ...]
    cell_location: str  # "face" (2D) or "volume" (3D): where cell values live
    topology_dtype: type = np.int64
    file_attrs: dict[str, Any] = field(default_factory=dict)

    @property
    def node_dimension(self) -> str:
        return f"{self.name}_nNodes"

    @property
    def cell_dimension(self) -> str:
        """``mesh2d_nFaces`` or ``mesh3d_nVolumes``: the file dimension of cell values."""
        return f"{self.name}_n{self.cell_location.capitalize()}s"


def mesh_topology(mesh) -> MeshTopology:
    """The UGRID description of ``mesh``, by the dimension the mesh says it has (``TOPOLOGY_OF``)."""
    return TOPOLOGY_OF[mesh.dimension](mesh)


def topology_file(topology: MeshTopology) -> FileDescription:
    """The one writer: the file of ``topology``, its sections in ``topology.layout``, ready to take data."""
    out = FileDescription(topology.file_attrs)
    for section in topology.layout:
        if section == "topology":
            out.add(topology.name, (), topology.topology_dtype(0), topology.attrs)
            continue
        for v in getattr(topology, section):
            out.add(v.name, v.dims, v.values, v.attrs, coordinate=v.coordinate, encoding=v.encoding)
    return out


def topology_dimension(ds) -> int:
    """2 or 3: the dimension of the mesh of a file or Dataset (its variables), as its topology variable names it."""
    return 3 if TOPOLOGY_NAMES[3] in ds.variables else 2


def mesh_file(mesh) -> FileDescription:
    """The mesh file of ``mesh`` (2D or 3D): :func:`topology_file` of :func:`mesh_topology`."""
    return topology_file(mesh_topology(mesh))


def mesh_to_ugrid_dataset(mesh):
    """The mesh file as an ``xarray.Dataset``."""
    return mesh_file(mesh).to_dataset()


def write_ugrid(mesh, path) -> None:
    """Write the mesh (2D or 3D) as its UGRID netCDF4 file."""
    mesh_file(mesh).write_netcdf4(path)


def json_scalar(value):
    """A numpy value of a mesh's meta as plain JSON (for json.dumps(default=...))."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"mesh meta value {value!r} cannot be stored as JSON")


def _polygon_topology(mesh) -> MeshTopology:
    """``mesh2d``: xugrid's variables, attributes and order, plus the boundary parts and the meta."""
    t = TOPOLOGY_NAMES[2]
    names = list(mesh.boundary)
    for name in names:
        if not SIDE_NAME.fullmatch(name):
            raise ValueError(f"boundary part name {name!r}: use letters, digits, _ and - only")
    connectivity = tuple(
        TopologyVariable(
            f"{t}_{kind}_nodes",
            dims,
            np.asarray(table, dtype=np.int64),
            {"cf_role": f"{kind}_node_connectivity", "start_index": 0, "_FillValue": FACE_FILL},
        )
        for kind, dims, table in (
            ("face", (f"{t}_nFaces", f"{t}_nMax_face_nodes"), csr_rows(mesh.cell_offsets, mesh.cell_vertices)),
            ("edge", (f"{t}_nEdges", "two"), mesh.edges),
        )
    )
    coordinates = tuple(
        TopologyVariable(
            f"{t}_node_{axis}",
            (f"{t}_nNodes",),
            mesh.vertices[:, k],
            {"standard_name": f"projection_{axis}_coordinate"},
            coordinate=True,
        )
        for k, axis in enumerate("xy")
    )
    parts = tuple(
        TopologyVariable(
            f"boundary_{name}",
            (f"boundary_{name}_nEdges", "two"),
            mesh.boundary[name],
            {
                "long_name": f"boundary part {name}: edges as vertex pairs, counter-clockwise",
                "start_index": 0,
                "mesh": t,
            },
        )
        for name in names
    )
    attrs = _xugrid_topology_attrs(t, names, mesh.meta)
    layout = ("topology", "connectivity", "node_coordinates", "boundary_parts")
    return MeshTopology(
        t, 2, attrs, coordinates, connectivity, parts, layout, "face", np.int64, {"Conventions": "CF-1.9 UGRID-1.0"}
    )


def _xugrid_topology_attrs(t: str, names: list[str], meta: dict) -> dict[str, Any]:
    """The attributes of xugrid's topology variable (UGRID-1.0 ``mesh_topology``), then the part names and meta."""
    return {
        "cf_role": "mesh_topology",
        "long_name": "Topology data of 2D mesh",
        "topology_dimension": 2,
        "node_dimension": f"{t}_nNodes",
        "edge_dimension": f"{t}_nEdges",
        "face_dimension": f"{t}_nFaces",
        "max_face_nodes_dimension": f"{t}_nMax_face_nodes",
        "edge_node_connectivity": f"{t}_edge_nodes",
        "face_node_connectivity": f"{t}_face_nodes",
        "node_coordinates": f"{t}_node_x {t}_node_y",
        "name": t,
        "vemkit_boundary_parts": json.dumps(names),
        "vemkit_meta": json.dumps(meta, default=json_scalar),
    }


def _polyhedron_topology(mesh) -> MeshTopology:
    """``mesh3d``: nodes, polygonal faces, the signed faces of each volume, the boundary parts."""
    t = TOPOLOGY_NAMES[3]
    coordinates = tuple(
        TopologyVariable(f"{t}_node_{axis}", (f"{t}_nNodes",), mesh.vertices[:, k], {}) for k, axis in enumerate("xyz")
    )
    faces = TopologyVariable(
        f"{t}_face_nodes",
        (f"{t}_nFaces", f"{t}_nMax_face_nodes"),
        csr_rows(mesh.face_offsets, mesh.face_vertices, FACE_FILL),
        {"cf_role": "face_node_connectivity", "start_index": 0},
        {"_FillValue": FACE_FILL},
    )
    volumes = TopologyVariable(
        f"{t}_volume_faces",
        (f"{t}_nVolumes", f"{t}_nMax_volume_faces"),
        csr_rows(mesh.cell_offsets, mesh.cell_faces, VOLUME_FILL),
        {"cf_role": "volume_face_connectivity", "start_index": 0, "orientation": "outward; -(f+1) is face f reversed"},
        {"_FillValue": VOLUME_FILL},
    )
    parts = tuple(
        TopologyVariable(f"{t}_boundary_{name}", (f"{t}_boundary_{name}_nFaces",), np.asarray(part, np.int64), {})
        for name, part in mesh.boundary.items()
    )
    attrs = {
        "cf_role": "mesh_topology",
        "topology_dimension": 3,
        "node_coordinates": f"{t}_node_x {t}_node_y {t}_node_z",
        "face_node_connectivity": f"{t}_face_nodes",
        "volume_face_connectivity": f"{t}_volume_faces",
        "vemkit_meta": json.dumps(mesh.meta, default=json_scalar),
        "vemkit_boundary_parts": json.dumps(list(mesh.boundary)),
    }
    layout = ("node_coordinates", "connectivity", "boundary_parts", "topology")
    return MeshTopology(t, 3, attrs, coordinates, (faces, volumes), parts, layout, "volume", np.int32)


#: the UGRID description of a mesh of each dimension
TOPOLOGY_OF = {2: _polygon_topology, 3: _polyhedron_topology}
