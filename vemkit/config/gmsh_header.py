"""What a gmsh ``.msh`` file (versions 2 and 4, text or binary) declares before it is parsed
(:mod:`vemkit.config.mesh_file_header`): the ``$Nodes`` and ``$Elements`` counts, the physical
names of the sides, and the dimension of the body the file holds.

The dimension a file shows (:func:`gmsh_dimension`, one reader for the scene's body and for the
header's check): 3 with a physical volume named (no mesh is of a higher dimension); else the highest
dimension of its entities (format 4: volumes 3, surfaces but no volume 2); else, in a text gmsh 2
file, 3 when an element is of a 3D type and 2 when none is; None when the file does not say.
"""

from __future__ import annotations

import re
import struct
from pathlib import Path

from vemkit.config.body_forms import FORMS
from vemkit.config.mesh_file_reading import MeshFileHeader, file_problem, read_at

__all__ = ["MAX_BYTES_PER_ITEM", "MIN_NODE_BYTES", "gmsh_dimension", "gmsh_header"]

MIN_NODE_BYTES = 7  # the shortest gmsh node: "1 0 0 0\n" (text) or a tag and three doubles (binary)
MAX_BYTES_PER_ITEM = 16 << 10  # a node or element line is < 200 bytes; $NodeData and $Entities add some
_SCAN_CHUNK = 4 << 20
_MAX_BEFORE_NODES = 64 << 20  # $MeshFormat, $PhysicalNames, $Entities come before $Nodes
_HIGHEST = max(FORMS)  # the highest dimension of a mesh: a physical group of it says the body's
#: gmsh element types of dimension 3 (tetrahedra, hexahedra, prisms, pyramids of every order)
_GMSH_3D_TYPES = (4, 5, 6, 7, 11, 12, 13, 14, 17, 18, 19, 29, 30, 31, 92, 93)
_GMSH_3D_ELEMENT = re.compile(rb"(?m)^[ \t]*\d+[ \t]+(?:" + b"|".join(b"%d" % t for t in _GMSH_3D_TYPES) + rb")[ \t]")


def _find_section(fd: int, name: str, start: int, stop: int) -> int | None:
    """The offset just past the first line ``$name`` between ``start`` and ``stop``, or None."""
    pattern = re.compile(rb"(?m)^\$" + name.encode() + rb"\r?$")
    offset, tail = start, b""
    while offset < stop:
        chunk = tail + read_at(fd, offset, min(_SCAN_CHUNK, stop - offset))
        base = offset - len(tail)
        match = next((m for m in pattern.finditer(chunk) if m.end() < len(chunk)), None)
        if match is not None:
            return base + match.end() + 1
        offset += _SCAN_CHUNK
        tail = chunk[-64:]
    return None


def _gmsh_format(fd: int, path: Path) -> tuple:
    """(version, binary, word size) of the ``$MeshFormat`` line; MeshError when it is not gmsh 2 or 4."""
    start = read_at(fd, 0, 4096).lstrip()
    while start.startswith(b"$Comments"):  # gmsh allows comment blocks before $MeshFormat
        end = start.find(b"$EndComments")
        start = start[end + len(b"$EndComments") :].lstrip() if end >= 0 else b""
    lines = start.split(b"\n", 2)
    if len(lines) < 2 or lines[0].strip() != b"$MeshFormat":
        raise file_problem(
            path, "cannot be read as gmsh: the file does not start with $MeshFormat; give a gmsh .msh file"
        )
    fields = lines[1].split()
    if (
        len(fields) != 3
        or fields[0][:2] not in (b"2.", b"4.")
        or fields[1] not in (b"0", b"1")
        or fields[2] not in (b"4", b"8")
    ):
        raise file_problem(path, f"cannot be read as gmsh: format line {_show(lines[1])}; vemkit reads gmsh 2 and 4")
    return int(fields[0][:1]), fields[1] == b"1", int(fields[2])


def _nodes_section(fd: int, path: Path, size: int) -> int:
    at_nodes = _find_section(fd, "Nodes", 0, min(size, _MAX_BEFORE_NODES))
    if at_nodes is None:
        raise file_problem(path, "cannot be read as gmsh: no $Nodes section")
    return at_nodes


def gmsh_dimension(fd: int, path: Path, size: int) -> int | None:
    """The dimension of the body in the gmsh file ``fd`` (module docstring), its elements scanned
    if need be; MeshError when the file is not gmsh."""
    version, binary, word = _gmsh_format(fd, path)
    at_nodes = _nodes_section(fd, path, size)
    named = _physical_names(fd, _find_section(fd, "PhysicalNames", 0, at_nodes), path)
    return _shown_dimension(fd, (version, binary, word), at_nodes, named, size)


def _shown_dimension(fd, form, at_nodes, named, elements_until: int | None) -> int | None:
    """The dimension the file shows (module docstring); ``elements_until``: the file's size, to scan a
    text gmsh 2 file's elements, or None not to."""
    version, binary, word = form
    if max((group for group, _ in named), default=0) == _HIGHEST:
        return _HIGHEST
    if version == 4:
        return _entities_dimension(fd, at_nodes, binary, word)
    if binary or elements_until is None:
        return None
    return _elements_dimension(fd, at_nodes, elements_until)


def _entities_dimension(fd, at_nodes, binary, word) -> int | None:
    """The highest dimension of a gmsh 4 file's ``$Entities`` (points, curves, surfaces, volumes)
    when it is a body's, else None."""
    at = _find_section(fd, "Entities", 0, at_nodes)
    if at is None:
        return None
    head = read_at(fd, at, 256)
    try:
        if binary:
            counts = struct.unpack(f"<4{'Q' if word == 8 else 'I'}", head[: 4 * word])
        else:
            counts = tuple(int(v) for v in head.split(b"\n", 1)[0].split()[:4])
    except (ValueError, struct.error):
        return None
    if len(counts) != 4:
        return None
    highest = max((entity for entity, count in enumerate(counts) if count > 0), default=None)
    return highest if highest in FORMS else None


def _elements_dimension(fd, at_nodes, size) -> int | None:
    """A text gmsh 2 file: 3 when one of its element lines "tag type ..." is of a 3D type, 2 when
    none is, None without a complete ``$Elements`` section."""
    at_elements = _find_section(fd, "Elements", at_nodes, size)
    if at_elements is None:
        return None
    offset, tail = at_elements, b""
    while offset < size:
        chunk = tail + read_at(fd, offset, min(_SCAN_CHUNK, size - offset))
        end = chunk.find(b"$EndElements")
        if _GMSH_3D_ELEMENT.search(chunk if end < 0 else chunk[:end]):
            return 3
        if end >= 0:
            return 2
        offset += _SCAN_CHUNK
        tail = chunk[chunk.rfind(b"\n") + 1 :] if b"\n" in chunk else b""
    return None


def gmsh_header(fd: int, path: Path, size: int, dimension: int = 2) -> MeshFileHeader:
    """The counts and sides a gmsh file declares for a scene of ``dimension``
    (:func:`vemkit.config.mesh_file_header.mesh_file_header`)."""
    form = FORMS[dimension]
    version, binary, word = _gmsh_format(fd, path)
    at_nodes = _nodes_section(fd, path, size)
    nodes = _gmsh_count(fd, at_nodes, version, binary, word, path, "$Nodes")
    if nodes * MIN_NODE_BYTES > size:
        raise file_problem(path, f"declares {nodes:,} nodes but has only {size:,} bytes; the file is broken")
    per_node = form.gmsh_items_per_node
    if size > MAX_BYTES_PER_ITEM * (per_node * nodes + 16) + (1 << 20):
        raise file_problem(path, f"is {size:,} bytes long for {nodes:,} nodes; the file is broken or not a mesh")
    at_elements = _find_section(fd, "Elements", at_nodes, size)
    if at_elements is None:
        raise file_problem(path, "cannot be read as gmsh: no $Elements section")
    elements = _gmsh_count(fd, at_elements, version, binary, word, path, "$Elements")
    if elements > (per_node - 1) * nodes + 16:
        raise file_problem(
            path,
            f"declares {elements:,} elements on {nodes:,} nodes, more than {form.mesh_words} has; the file is broken",
        )
    named = _physical_names(fd, _find_section(fd, "PhysicalNames", 0, at_nodes), path)
    shown = _shown_dimension(fd, (version, binary, word), at_nodes, named, None)
    if shown is not None and shown != dimension:
        raise file_problem(path, FORMS[shown].file_in_other_scene)
    names = tuple(name for group, name in named if group == dimension - 1)  # a side: one dimension lower
    others = tuple(name for group, name in named if group == form.other_dimension - 1)
    return MeshFileHeader(nodes, min(elements, form.cells_per_vertex * nodes + 2), names, False, size, others)


def _gmsh_count(fd, offset, version, binary, word, path, section) -> int:
    """The number of nodes (elements) in the header line of a $Nodes ($Elements) section."""
    head = read_at(fd, offset, 256)
    try:
        if version == 4 and binary:
            count = struct.unpack(f"<{'Q' if word == 8 else 'I'}", head[word : 2 * word])[0]
        else:
            values = head.split(b"\n", 1)[0].split()
            count = int(values[1 if version == 4 else 0])
    except (IndexError, ValueError, struct.error):
        raise file_problem(path, f"cannot be read as gmsh: the {section} header is broken") from None
    if not 0 <= count < 2**62:
        raise file_problem(path, f"cannot be read as gmsh: the {section} header declares {count} items")
    return count


def _physical_names(fd, offset, path) -> tuple:
    """(dimension, name) of every named physical group (the sides: lines in 2D, surfaces in 3D)."""
    if offset is None:
        return ()
    text = read_at(fd, offset, 1 << 20).decode("utf-8", errors="replace").split("\n")
    try:
        count = int(text[0])
    except ValueError:
        raise file_problem(path, "cannot be read as gmsh: the $PhysicalNames header is broken") from None
    names = []
    for line in text[1 : 1 + count]:
        parts = line.split(None, 2)
        if len(parts) == 3 and parts[0] in ("0", "1", "2", "3"):
            names.append((int(parts[0]), parts[2].strip().strip('"')))
    return tuple(names)


def _show(data: bytes) -> str:
    text = data.decode("utf-8", errors="replace").strip()
    return repr(text if len(text) <= 40 else text[:37] + "...")
