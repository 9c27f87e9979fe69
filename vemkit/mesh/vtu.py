"""A mesh and its data as one VTU file for ParaView, 2D or 3D, written by one writer (docs/reference/files.md).

One ``UnstructuredGrid`` piece, binary (base64, UInt64 headers, zlib-compressed in one block per
array: ``vtkZLibDataCompressor``), points with three coordinates (z = 0 in 2D). Its cells, by the dimension the mesh says it has:

- 2D: VTK polygons (type 7), grouped by their number of vertices (the mesh's order within a
  group), so the cell data array ``cell_index`` gives every written cell's index in the mesh;
- 3D: VTK polyhedra (type 42), in mesh order, with ``connectivity`` (the cell's distinct
  vertices), ``faces`` (per cell: number of faces, then per face its vertex count and vertices,
  outward) and ``faceoffsets`` (end of each cell's stream); ``cell_index`` numbers them 0, 1, ...

Point and cell data are arrays with one row per vertex or cell (float64); two-component vectors (a
2D displacement) get a zero third component.
"""

from __future__ import annotations

import base64
import zlib
from pathlib import Path

import numpy as np

VTK_POLYGON = 7
VTK_POLYHEDRON = 42
_VTK_TYPES = {np.dtype(np.float64): "Float64", np.dtype(np.int64): "Int64", np.dtype(np.uint8): "UInt8"}


def write_vtu(mesh, path, point_data: dict | None = None, cell_data: dict | None = None) -> None:
    """Write ``mesh`` (2D or 3D) and its data as VTU (module docstring)."""
    order, cells = VTK_CELLS[mesh.dimension](mesh)
    point_arrays = _data_rows(point_data, mesh.n_vertices, "points")
    cell_arrays = {name: values[order] for name, values in _data_rows(cell_data, mesh.n_cells, "cells").items()}
    cell_arrays["cell_index"] = order
    points = np.zeros((mesh.n_vertices, 3))
    points[:, : mesh.vertices.shape[1]] = mesh.vertices
    parts = [
        '<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
        'header_type="UInt64" compressor="vtkZLibDataCompressor">\n<UnstructuredGrid>\n',
        f'<Piece NumberOfPoints="{mesh.n_vertices}" NumberOfCells="{mesh.n_cells}">\n',
        "<Points>\n",
        _data_array("Points", points.astype("<f8"), 3),
        "</Points>\n<Cells>\n",
        *(_data_array(name, values) for name, values in cells.items()),
        "</Cells>\n",
    ]
    for tag, arrays in (("PointData", point_arrays), ("CellData", cell_arrays)):
        parts.append(f"<{tag}>\n")
        for name, values in arrays.items():
            parts.append(_data_array(name, values, 1 if values.ndim == 1 else values.shape[1]))
        parts.append(f"</{tag}>\n")
    parts.append("</Piece>\n</UnstructuredGrid>\n</VTKFile>\n")
    Path(path).write_text("".join(parts), encoding="ascii")


def polygon_cells(mesh) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """(written cell order, the ``<Cells>`` arrays) of a polygonal mesh: polygons grouped by size."""
    sizes = mesh.cell_sizes
    order = np.argsort(sizes, kind="stable").astype(np.int64)
    starts = mesh.cell_offsets[order]
    within = np.arange(int(sizes.sum()), dtype=np.int64) - np.repeat(
        np.cumsum(sizes[order]) - sizes[order], sizes[order]
    )
    connectivity = mesh.cell_vertices[np.repeat(starts, sizes[order]) + within]
    cells = {
        "connectivity": connectivity,
        "offsets": np.cumsum(sizes[order]).astype(np.int64),
        "types": np.full(mesh.n_cells, VTK_POLYGON, dtype=np.uint8),
    }
    return order, cells


def polyhedron_cells(mesh) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """(written cell order, the ``<Cells>`` arrays) of a polyhedral mesh: VTK polyhedra, faces outward."""
    connectivity, offsets, faces, faceoffsets = polyhedron_streams(mesh)
    cells = {
        "connectivity": connectivity,
        "offsets": offsets,
        "types": np.full(mesh.n_cells, VTK_POLYHEDRON, dtype=np.uint8),
        "faces": faces,
        "faceoffsets": faceoffsets,
    }
    return np.arange(mesh.n_cells, dtype=np.int64), cells


def polyhedron_streams(mesh):
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


#: the written cells of a mesh of each dimension: (their order, the ``<Cells>`` arrays)
VTK_CELLS = {2: polygon_cells, 3: polyhedron_cells}


def _data_rows(data: dict | None, count: int, where: str) -> dict[str, np.ndarray]:
    """The arrays of ``data`` as float64, one row per point or cell, two-component rows given a zero third."""
    out = {}
    for name, values in (data or {}).items():
        values = np.asarray(values, dtype=np.float64)
        if values.shape[0] != count:
            raise ValueError(f"{where} data {name!r} has {values.shape[0]} rows; the mesh has {count} {where}")
        if values.ndim == 2 and values.shape[1] == 2:
            values = np.column_stack([values, np.zeros(count)])
        out[name] = values
    return out


def _data_array(name: str, values: np.ndarray, components: int = 1) -> str:
    values = np.ascontiguousarray(values)
    raw = values.tobytes()
    packed = zlib.compress(raw, 6)
    # the compressed header: number of blocks, block size, last block's size, each block's packed size
    header = np.array([1, len(raw), len(raw), len(packed)] if raw else [0, 0, 0], dtype="<u8")
    text = base64.b64encode(header.tobytes()).decode("ascii") + base64.b64encode(packed if raw else b"").decode("ascii")
    shape = f' NumberOfComponents="{components}"' if components > 1 else ""
    return f'<DataArray type="{_VTK_TYPES[values.dtype]}" Name="{name}"{shape} format="binary">{text}</DataArray>\n'
