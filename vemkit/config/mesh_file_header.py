"""What a mesh file (docs/reference/files.md) declares, read before the file is parsed: the input checks of issue 9.

A scene's ``discretization.mesh.file`` is user input like the scene itself, so it is looked at
before any mesh is built: :func:`mesh_file_header` opens only a regular file (a FIFO, a device or a
directory is refused, never read), reads the counts the file declares (vertices, cells) and its
side names, and refuses with one line a file whose declared counts could not fit in its size or
in a plane mesh: more than ``MAX_BYTES_PER_ITEM`` bytes per declared node or element (a garbage
file behind a valid header), fewer than ``MIN_NODE_BYTES`` bytes per declared node (a header that
declares 10^8 nodes in a few bytes), more cells than ``2 V + 2`` (Euler: a plane mesh of V
vertices has fewer faces). The prediction of :mod:`vemkit.config.limits` then uses the counts.

- gmsh ``.msh`` (versions 2 and 4, text or binary): the ``$Nodes`` and ``$Elements`` headers and
  the physical names of dimension 1 from ``$PhysicalNames``. Unnamed physical groups become sides
  named by their numbers and edges in no group ``untagged`` when the file is read, so the sides
  of a gmsh file are ``complete`` only as far as names go.
- UGRID ``.nc``: the dimensions of the node coordinates, the face table and the boundary parts
  (netCDF declares them truthfully: a compressed file cannot hide a larger array), the JSON list
  ``vemkit_boundary_parts``.

:func:`mesh_file_dimension` tells a scene whether its mesh file is a plane or a 3D body (the
scene's dimension comes from its body, docs/reference/files.md): a UGRID file's
``topology_dimension``, a gmsh 4 file's ``$Entities`` (volumes or none), a gmsh 2 file's physical
volumes or, in text, its elements; None when the file does not say (it is then checked as the
scene's model says, as before).

Only this module's cheap imports (netCDF4 for ``.nc``) are needed: a refusal takes well under a second.
"""

from __future__ import annotations

import json
import os
import re
import stat
import struct
from pathlib import Path
from typing import NamedTuple

from vemkit.config.safe_yaml import file_kind
from vemkit.exceptions import MeshError

__all__ = [
    "MESH_SUFFIXES",
    "OTHER_DIMENSION",
    "MeshFileHeader",
    "mesh_file_dimension",
    "mesh_file_header",
    "open_regular_file",
]

MESH_SUFFIXES = {".msh": "gmsh", ".nc": "UGRID netCDF"}
MIN_NODE_BYTES = 7  # the shortest gmsh node: "1 0 0 0\n" (text) or a tag and three doubles (binary)
MAX_BYTES_PER_ITEM = 16 << 10  # a node or element line is < 200 bytes; $NodeData and $Entities add some
_SCAN_CHUNK = 4 << 20
_MAX_BEFORE_NODES = 64 << 20  # $MeshFormat, $PhysicalNames, $Entities come before $Nodes


class MeshFileHeader(NamedTuple):
    """Counts and sides a mesh file declares; ``sides_complete``: every side name is listed
    (UGRID) or only the physical names (gmsh: numbers and ``untagged`` may come on top)."""

    vertices: int
    cells: int
    sides: tuple
    sides_complete: bool
    size: int
    other_sides: tuple = ()  # gmsh: physical names of the other dimension's sides (3D in 2D, 2D in 3D)


def _fail(path: Path, problem: str) -> MeshError:
    return MeshError(f"{path.name}: {problem}", key=str(path))


def open_regular_file(path, what: str = "mesh file") -> int:
    """A read-only descriptor of the regular file ``path`` (never blocks on a FIFO); MeshError
    naming the path otherwise."""
    path = Path(path)
    if "\0" in str(path):
        raise MeshError(f"{str(path)[:80]!r}: a {what} name cannot contain a NUL character", key="file")
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise MeshError(f"{path}: no such {what}", key=str(path)) from None
    except OSError as error:
        raise MeshError(f"{path}: cannot open the {what} ({error.strerror or error})", key=str(path)) from None
    mode = os.fstat(fd).st_mode
    if not stat.S_ISREG(mode):
        os.close(fd)
        raise MeshError(f"{path}: the {what} is {file_kind(mode)}, not a regular file", key=str(path))
    return fd


#: most cells per vertex a mesh can have: a plane mesh (Euler: 2 V + 2 faces), a 3D mesh (tetrahedra:
#: about 6.5 per vertex in quality meshes, 6 in the Kuhn cubes; 10 leaves a margin)
CELLS_PER_VERTEX = {2: 2, 3: 10}


def mesh_file_header(path, dimension: int = 2) -> MeshFileHeader:
    """The counts and sides the mesh file ``path`` declares (see the module doc); MeshError if
    the file cannot be a mesh vemkit reads. ``dimension`` 3: a 3D mesh (docs/reference/files.md; gmsh physical
    surfaces as sides, a ``mesh3d`` netCDF file)."""
    path = Path(path)
    if path.suffix not in MESH_SUFFIXES:
        raise MeshError(
            f"{path}: unknown mesh file type {path.suffix!r}; give a gmsh .msh or a UGRID .nc file", key=str(path)
        )
    fd = open_regular_file(path)
    try:
        size = os.fstat(fd).st_size
        header = (
            _gmsh_header(fd, path, size, dimension) if path.suffix == ".msh" else _ugrid_header(path, size, dimension)
        )
    finally:
        os.close(fd)
    most = CELLS_PER_VERTEX[dimension]
    if header.cells > most * header.vertices + 2:
        kind = "a plane mesh" if dimension == 2 else "a 3D mesh"
        raise _fail(
            path,
            f"declares {header.cells:,} cells on {header.vertices:,} vertices, more than {kind} "
            f"can have ({most} per vertex); the file is broken",
        )
    return header


# -- gmsh ---------------------------------------------------------------------------------------
#: gmsh element types of dimension 3 (tetrahedra, hexahedra, prisms, pyramids of every order)
_GMSH_3D_TYPES = (4, 5, 6, 7, 11, 12, 13, 14, 17, 18, 19, 29, 30, 31, 92, 93)
_GMSH_3D_ELEMENT = re.compile(rb"(?m)^[ \t]*\d+[ \t]+(?:" + b"|".join(b"%d" % t for t in _GMSH_3D_TYPES) + rb")[ \t]")


def mesh_file_dimension(path) -> int | None:
    """2 or 3: the dimension of the body in the mesh file ``path`` (module docstring), read from its
    header; None when the file cannot be opened or does not say. Never raises: the file's problems
    are reported by :func:`mesh_file_header` when the scene is solved."""
    path = Path(path)
    if path.suffix not in MESH_SUFFIXES:
        return None
    try:
        fd = open_regular_file(path)
    except MeshError:
        return None
    try:
        size = os.fstat(fd).st_size
        return _gmsh_file_dimension(fd, size) if path.suffix == ".msh" else _ugrid_dimension(path)
    except (MeshError, OSError, ValueError, IndexError, struct.error, UnicodeError):
        return None
    finally:
        os.close(fd)


def _ugrid_dimension(path: Path) -> int | None:
    import netCDF4

    with netCDF4.Dataset(path, "r") as nc:
        topologies = [v for v in nc.variables.values() if getattr(v, "cf_role", None) == "mesh_topology"]
        if len(topologies) != 1:
            return None
        value = str(getattr(topologies[0], "topology_dimension", "2")).strip()
        return int(value) if value in ("2", "3") else None


def _gmsh_file_dimension(fd: int, size: int) -> int | None:
    """The body's dimension by the file's format line, entities, physical names or (text gmsh 2) element types."""
    start = _read_at(fd, 0, 4096)
    match = re.search(rb"(?m)^\$MeshFormat\r?\n([^\n]*)\n", start)
    if match is None:
        return None
    fields = match.group(1).split()
    version, binary, word = int(fields[0][:1]), fields[1] == b"1", int(fields[2])
    at_nodes = _find_section(fd, "Nodes", 0, min(size, _MAX_BEFORE_NODES))
    if at_nodes is None:
        return None
    at_entities = _find_section(fd, "Entities", 0, at_nodes) if version == 4 else None
    if at_entities is not None:  # numPoints numCurves numSurfaces numVolumes
        head = _read_at(fd, at_entities, 256)
        counts = struct.unpack(f"<4{'Q' if word == 8 else 'I'}", head[: 4 * word]) if binary else head.split()[:4]
        return 3 if int(counts[3]) > 0 else 2
    at_names = _find_section(fd, "PhysicalNames", 0, at_nodes)
    if at_names is not None:
        lines = _read_at(fd, at_names, 1 << 20).split(b"\n")
        if any(line.split()[:1] == [b"3"] for line in lines[1 : 1 + int(lines[0])]):
            return 3  # a physical volume
    if version != 2 or binary:
        return None
    at_elements = _find_section(fd, "Elements", at_nodes, size)
    if at_elements is None:
        return None
    offset, tail = at_elements, b""
    while offset < size:  # the element lines "tag type ..." of a text gmsh 2 file: one of a 3D type?
        chunk = tail + _read_at(fd, offset, min(_SCAN_CHUNK, size - offset))
        end = chunk.find(b"$EndElements")
        if _GMSH_3D_ELEMENT.search(chunk if end < 0 else chunk[:end]):
            return 3
        if end >= 0:
            return 2
        offset += _SCAN_CHUNK
        tail = chunk[chunk.rfind(b"\n") + 1 :] if b"\n" in chunk else b""
    return None


def _read_at(fd: int, offset: int, count: int) -> bytes:
    return os.pread(fd, count, offset)


def _find_section(fd: int, name: str, start: int, stop: int) -> int | None:
    """The offset just past the first line ``$name`` between ``start`` and ``stop``, or None."""
    pattern = re.compile(rb"(?m)^\$" + name.encode() + rb"\r?$")
    offset, tail = start, b""
    while offset < stop:
        chunk = tail + _read_at(fd, offset, min(_SCAN_CHUNK, stop - offset))
        base = offset - len(tail)
        match = next((m for m in pattern.finditer(chunk) if m.end() < len(chunk)), None)
        if match is not None:
            return base + match.end() + 1
        offset += _SCAN_CHUNK
        tail = chunk[-64:]
    return None


def _gmsh_header(fd: int, path: Path, size: int, dimension: int = 2) -> MeshFileHeader:
    start = _read_at(fd, 0, 4096).lstrip()
    while start.startswith(b"$Comments"):  # gmsh allows comment blocks before $MeshFormat
        end = start.find(b"$EndComments")
        start = start[end + len(b"$EndComments") :].lstrip() if end >= 0 else b""
    lines = start.split(b"\n", 2)
    if len(lines) < 2 or lines[0].strip() != b"$MeshFormat":
        raise _fail(path, "cannot be read as gmsh: the file does not start with $MeshFormat; give a gmsh .msh file")
    fields = lines[1].split()
    if (
        len(fields) != 3
        or fields[0][:2] not in (b"2.", b"4.")
        or fields[1] not in (b"0", b"1")
        or fields[2] not in (b"4", b"8")
    ):
        raise _fail(path, f"cannot be read as gmsh: format line {_show(lines[1])}; vemkit reads gmsh 2 and 4")
    version, binary, word = int(fields[0][:1]), fields[1] == b"1", int(fields[2])
    at_nodes = _find_section(fd, "Nodes", 0, min(size, _MAX_BEFORE_NODES))
    if at_nodes is None:
        raise _fail(path, "cannot be read as gmsh: no $Nodes section")
    nodes = _gmsh_count(fd, at_nodes, version, binary, word, path, "$Nodes")
    if nodes * MIN_NODE_BYTES > size:
        raise _fail(path, f"declares {nodes:,} nodes but has only {size:,} bytes; the file is broken")
    per_node = 7 if dimension == 2 else 17  # elements: 2D < 2 V cells + 3 V lines + V points; 3D < 10 V + 6 V faces
    if size > MAX_BYTES_PER_ITEM * (per_node * nodes + 16) + (1 << 20):
        raise _fail(path, f"is {size:,} bytes long for {nodes:,} nodes; the file is broken or not a mesh")
    at_elements = _find_section(fd, "Elements", at_nodes, size)
    if at_elements is None:
        raise _fail(path, "cannot be read as gmsh: no $Elements section")
    elements = _gmsh_count(fd, at_elements, version, binary, word, path, "$Elements")
    if elements > (per_node - 1) * nodes + 16:
        raise _fail(
            path,
            f"declares {elements:,} elements on {nodes:,} nodes, more than a "
            f"{'plane' if dimension == 2 else '3D'} mesh has; the file is broken",
        )
    named = _physical_names(fd, _find_section(fd, "PhysicalNames", 0, at_nodes), path)
    shown = _gmsh_dimension(fd, named, version, binary, word, at_nodes)
    if shown is not None and shown != dimension:
        raise _fail(path, OTHER_DIMENSION[shown])
    names = tuple(name for dim, name in named if dim == dimension - 1)
    others = tuple(name for dim, name in named if dim == (2 if dimension == 2 else 1))
    return MeshFileHeader(nodes, min(elements, CELLS_PER_VERTEX[dimension] * nodes + 2), names, False, size, others)


#: the refusal of a mesh file of the other dimension, by the dimension the file shows (the header's
#: and the gmsh readers' words, after "<file>: ")
OTHER_DIMENSION = {
    3: "is a 3D mesh (it has volumes) but the scene is 2D; give a 2D mesh file, or write the scene for a 3D body",
    2: "is a 2D mesh (it has surfaces but no volumes) but the scene is 3D; give a 3D mesh file, or drop model: 3d",
}


def _gmsh_dimension(fd, named, version, binary, word, at_nodes) -> int | None:
    """The dimension a gmsh file shows before its elements are read, or None: 3 with a physical
    volume named, or volume entities (format 4); 2 with surface but no volume entities (format 4)."""
    if any(dim == 3 for dim, _ in named):
        return 3
    if version != 4:
        return None
    at = _find_section(fd, "Entities", 0, at_nodes)
    if at is None:
        return None
    head = _read_at(fd, at, 256)
    try:
        if binary:
            counts = struct.unpack(f"<4{'Q' if word == 8 else 'I'}", head[: 4 * word])
        else:
            counts = tuple(int(v) for v in head.split(b"\n", 1)[0].split()[:4])
    except (ValueError, struct.error):
        return None
    if len(counts) != 4:
        return None
    return 3 if counts[3] > 0 else 2 if counts[2] > 0 else None


def _gmsh_count(fd, offset, version, binary, word, path, section) -> int:
    """The number of nodes (elements) in the header line of a $Nodes ($Elements) section."""
    head = _read_at(fd, offset, 256)
    try:
        if version == 4 and binary:
            count = struct.unpack(f"<{'Q' if word == 8 else 'I'}", head[word : 2 * word])[0]
        else:
            values = head.split(b"\n", 1)[0].split()
            count = int(values[1 if version == 4 else 0])
    except (IndexError, ValueError, struct.error):
        raise _fail(path, f"cannot be read as gmsh: the {section} header is broken") from None
    if not 0 <= count < 2**62:
        raise _fail(path, f"cannot be read as gmsh: the {section} header declares {count} items")
    return count


def _physical_names(fd, offset, path) -> tuple:
    """(dimension, name) of every named physical group (the sides: lines in 2D, surfaces in 3D)."""
    if offset is None:
        return ()
    text = _read_at(fd, offset, 1 << 20).decode("utf-8", errors="replace").split("\n")
    try:
        count = int(text[0])
    except ValueError:
        raise _fail(path, "cannot be read as gmsh: the $PhysicalNames header is broken") from None
    names = []
    for line in text[1 : 1 + count]:
        parts = line.split(None, 2)
        if len(parts) == 3 and parts[0] in ("0", "1", "2", "3"):
            names.append((int(parts[0]), parts[2].strip().strip('"')))
    return tuple(names)


def _show(data: bytes) -> str:
    text = data.decode("utf-8", errors="replace").strip()
    return repr(text if len(text) <= 40 else text[:37] + "...")


# -- UGRID --------------------------------------------------------------------------------------
def _ugrid_header(path: Path, size: int, dimension: int = 2) -> MeshFileHeader:
    import netCDF4

    try:
        nc = netCDF4.Dataset(path, "r")
    except OSError as error:
        kind = "UGRID netCDF" if dimension == 2 else "a mesh3d netCDF file"
        raise _fail(path, f"cannot be read as {kind}: not a netCDF file ({error.strerror or error})") from None
    try:
        nc.set_auto_mask(False)
        return _ugrid_counts(nc, path, size) if dimension == 2 else _mesh3d_counts(nc, path, size)
    finally:
        nc.close()


def _ugrid_variable(nc, name, path, role: str, rank: int):
    if not isinstance(name, str) or name not in nc.variables:
        raise _fail(path, f"cannot be read as UGRID netCDF: the {role} variable {str(name)[:60]!r} is missing")
    variable = nc.variables[name]
    if variable.ndim != rank or getattr(variable.dtype, "kind", "O") not in "iuf":
        raise _fail(
            path,
            f"cannot be read as UGRID netCDF: {name[:60]} ({role}) must be a numeric "
            f"{'vector' if rank == 1 else 'table'}",
        )
    return variable


def _ugrid_counts(nc, path: Path, size: int) -> MeshFileHeader:
    topologies = [v for v in nc.variables.values() if getattr(v, "cf_role", None) == "mesh_topology"]
    if len(topologies) != 1:
        raise _fail(
            path, f"cannot be read as UGRID netCDF: expected one mesh topology variable, found {len(topologies)}"
        )
    topology = topologies[0]
    coordinates = str(getattr(topology, "node_coordinates", "")).split()
    if str(getattr(topology, "topology_dimension", "2")) == "3":
        raise _fail(
            path, "is a 3D mesh (mesh3d) but the scene is 2D; give a 2D mesh file, or write the scene for a 3D body"
        )
    if len(coordinates) != 2:
        raise _fail(path, "cannot be read as UGRID netCDF: node_coordinates must name two variables (x y)")
    x, y = (_ugrid_variable(nc, name, path, "node coordinate", 1) for name in coordinates)
    faces = _ugrid_variable(nc, getattr(topology, "face_node_connectivity", None), path, "face_node_connectivity", 2)
    if getattr(faces.dtype, "kind", "O") not in "iu":
        raise _fail(path, "cannot be read as UGRID netCDF: face_node_connectivity must hold integers")
    vertices, (cells, corners) = x.shape[0], faces.shape
    if y.shape[0] != vertices:
        raise _fail(path, f"cannot be read as UGRID netCDF: {x.shape[0]} x but {y.shape[0]} y node coordinates")
    if cells * corners > 64 * vertices + (1 << 20):
        raise _fail(
            path,
            f"declares a face table of {cells:,} x {corners:,} entries for {vertices:,} vertices; the file is broken",
        )
    sides = _ugrid_sides(nc, getattr(topology, "vemkit_boundary_parts", "[]"), vertices, path)
    return MeshFileHeader(vertices, cells, sides, True, size)


#: most entries of a mesh3d face or volume table per vertex (8 bytes each): a tetrahedral mesh has
#: about 13 faces of 3 vertices and 6 cells of 4 faces per vertex; padding to the largest face or
#: cell leaves a margin of 5 or more
TABLE_ENTRIES_PER_VERTEX = 256


def _mesh3d_counts(nc, path: Path, size: int) -> MeshFileHeader:
    """The counts and sides of a ``mesh3d`` file from its dimensions and attributes; its
    tables' declared shapes must be proportional to its nodes (netCDF reads unwritten chunks as fill
    values: a 40 kB file can declare gigabytes)."""
    topologies = [v for v in nc.variables.values() if getattr(v, "cf_role", None) == "mesh_topology"]
    if len(topologies) == 1 and str(getattr(topologies[0], "topology_dimension", "2")) == "2":
        raise _fail(path, "is a 2D mesh (UGRID mesh2d) but the scene is 3D; give a 3D mesh file, or drop model: 3d")
    if len(topologies) != 1 or str(getattr(topologies[0], "topology_dimension", "")) != "3":
        raise _fail(
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
        raise _fail(path, "cannot be read as a mesh3d netCDF file: node_coordinates must name three variables (x y z)")
    x, y, z = (_ugrid_variable(nc, name, path, "node coordinate", 1) for name in coordinates)
    vertices = x.shape[0]
    if y.shape[0] != vertices or z.shape[0] != vertices:
        raise _fail(
            path,
            f"{vertices:,} x but {y.shape[0]:,} y and {z.shape[0]:,} z node coordinates; the file is broken: "
            "write it again (vemkit mesh --scene)",
        )
    most = TABLE_ENTRIES_PER_VERTEX * vertices + (1 << 20)
    for table, what in ((faces, "face"), (volumes, "volume")):
        if table.shape[0] * table.shape[1] > most:
            raise _fail(
                path,
                f"declares a {what} table of {table.shape[0]:,} x {table.shape[1]:,} entries for {vertices:,} "
                "vertices; the file is broken: write it again (vemkit mesh --scene)",
            )
    try:
        names = json.loads(getattr(topology, "vemkit_boundary_parts", "[]"))
    except ValueError:
        names = None
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        raise _fail(
            path,
            "cannot be read as a mesh3d netCDF file: the attribute vemkit_boundary_parts must be a "
            "JSON list of side names",
        )
    for name in names:
        key = f"mesh3d_boundary_{name}"
        if key in nc.variables and (nc.variables[key].ndim != 1 or nc.variables[key].shape[0] > faces.shape[0]):
            raise _fail(
                path,
                f"{key[:80]} declares {nc.variables[key].size:,} faces but the mesh has {faces.shape[0]:,}; "
                "the file is broken: write it again (vemkit mesh --scene)",
            )
    return MeshFileHeader(vertices, volumes.shape[0], tuple(names), True, size)


def _ugrid_sides(nc, text, vertices: int, path: Path) -> tuple:
    try:
        names = json.loads(text) if isinstance(text, str) else None
    except ValueError:
        names = None
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        raise _fail(
            path,
            "cannot be read as UGRID netCDF: the attribute vemkit_boundary_parts must be a JSON list of side names",
        )
    for name in names:
        part = _ugrid_variable(nc, f"boundary_{name}", path, f"boundary part {name[:40]!r}", 2)
        if part.shape[1] != 2 or part.shape[0] > 3 * vertices + 3 or getattr(part.dtype, "kind", "O") not in "iu":
            raise _fail(
                path,
                f"cannot be read as UGRID netCDF: boundary_{name[:40]} must be an integer table of "
                "edges (vertex pairs)",
            )
    return tuple(names)
