"""Parsing a mesh file, 2D or 3D, within a memory budget: the one path both readers take.

A mesh file is user input: a few kilobytes can declare a node number of 10^9 (meshio then
allocates a lookup table of that size) or a netCDF table of 10^8 rows whose chunks were never
written (netCDF reads it as gigabytes of fill values). So, before any parser runs,
:func:`parse_within_budget`

1. reads what the file declares (``vemkit.config.mesh_file_header``: a regular file; counts that
   fit its size, a mesh of that dimension and, for netCDF, table shapes proportional to the node
   count) and refuses a file that cannot be a mesh, in one line naming it;
2. predicts the solve from the declared counts (``vemkit.config.limits``) and refuses a mesh
   beyond this machine;
3. runs the parser within ``READ_BASE_BYTES + READ_BYTES_PER_FILE_BYTE`` x the file's size of
   address space (``vemkit.config.limits.memory_budget``): an allocation beyond is a MemoryError
   at once, reported as a MeshError naming the file, never gigabytes of swap.

Any other exception of the parser becomes a one-line MeshError naming the file and the reason.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

from vemkit.config.limits import check_resources, estimate_resources, estimate_resources3d, memory_budget
from vemkit.config.mesh_file_header import MESH_SUFFIXES, MeshFileHeader, mesh_file_header
from vemkit.exceptions import MeshError

__all__ = ["READ_BASE_BYTES", "READ_BYTES_PER_FILE_BYTE", "parse_within_budget"]

READ_BASE_BYTES = 512 << 20  # what meshio / netCDF may map beyond the file's own size ...
READ_BYTES_PER_FILE_BYTE = 16  # ... and per byte of the file (measured: gmsh text, 5 x its size)

T = TypeVar("T")


def parse_within_budget(path, dimension: int, parse: Callable[[Path], T]) -> tuple[T, MeshFileHeader]:
    """``(parse(path), header)``: the file's header checked (``dimension`` 2 or 3), the parser run
    within the memory budget of the module doc; MeshError (ResourceLimitError) naming the file
    otherwise."""
    path = Path(path)
    header = mesh_file_header(path, dimension)
    if dimension == 3:  # tetrahedra: about 2 faces per cell
        estimate = estimate_resources3d(header.cells, header.vertices, 2 * header.cells + header.vertices)
    else:
        estimate = estimate_resources(header.cells, header.vertices)
    check_resources(estimate, None, what=f"the mesh file {path.name}", fix="a coarser mesh")
    kind = MESH_SUFFIXES[path.suffix] if dimension == 2 or path.suffix == ".msh" else "a mesh3d netCDF file"
    try:
        with memory_budget(READ_BASE_BYTES + READ_BYTES_PER_FILE_BYTE * header.size):
            return parse(path), header
    except MeshError:
        raise
    except MemoryError:
        found = _largest_node_tag(path)
        if found is not None and found[1] > 2 * header.vertices:
            line, tag = found
            raise MeshError(
                f"{path.name}, line {line}: node number {tag:,} in a file of {header.vertices:,} nodes: reading "
                f"it needs a table of {tag:,} entries, far more memory than the mesh; number the nodes from 1 "
                "(gmsh: Mesh.Renumber, or export the mesh again)",
                key=str(path),
            ) from None
        raise MeshError(
            f"{path.name}: cannot be read as {kind}: reading it needs far more memory than a mesh of "
            f"{header.vertices:,} nodes (a node number or count beyond what the file holds); fix the "
            "file or export the mesh again",
            key=str(path),
        ) from None
    except Exception as error:  # a file the reader cannot parse: say which and why, in one line
        reason = " ".join(str(error).split())
        raise MeshError(
            f"{path.name}: cannot be read as {kind}: {reason[:200] or type(error).__name__}", key=str(path)
        ) from None


def _largest_node_tag(path: Path):
    """(line, number) of a gmsh file's largest node number (``vemkit.mesh.gmsh_errors``), or None."""
    if path.suffix != ".msh":
        return None
    from vemkit.mesh.gmsh_errors import largest_node_tag  # meshio: lazily, as the readers

    return largest_node_tag(path)
