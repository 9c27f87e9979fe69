"""What a mesh file (docs/reference/files.md) declares, read before the file is parsed: the input checks of issue 9.

A scene's ``discretization.mesh.file`` is user input like the scene itself, so it is looked at
before any mesh is built: :func:`mesh_file_header` opens only a regular file (a FIFO, a device or a
directory is refused, never read), reads the counts the file declares (vertices, cells) and its
side names, and refuses with one line a file whose declared counts could not fit in its size or
in a mesh of the scene's dimension: more than ``MAX_BYTES_PER_ITEM`` bytes per declared node or
element (a garbage file behind a valid header), fewer than ``MIN_NODE_BYTES`` bytes per declared
node (a header that declares 10^8 nodes in a few bytes), more cells than a mesh of V vertices has
(``cells_per_vertex`` of :mod:`vemkit.config.body_forms`; a plane mesh: Euler, ``2 V + 2``). The
prediction of :mod:`vemkit.config.limits` then uses the counts.

- gmsh ``.msh`` (versions 2 and 4, text or binary; :mod:`vemkit.config.gmsh_header`): the ``$Nodes``
  and ``$Elements`` headers and the physical names of the sides from ``$PhysicalNames``. Unnamed
  physical groups become sides named by their numbers and edges in no group ``untagged`` when the
  file is read, so the sides of a gmsh file are ``complete`` only as far as names go.
- UGRID ``.nc`` (:mod:`vemkit.config.ugrid_header`): the dimensions of the node coordinates, the
  face table and the boundary parts, the JSON list ``vemkit_boundary_parts``.

:func:`mesh_file_dimension` tells a scene whether its mesh file is a plane or a 3D body (the
scene's dimension comes from its body, docs/reference/files.md): a UGRID file's
``topology_dimension``, a gmsh 4 file's ``$Entities`` (volumes or none), a gmsh 2 file's physical
volumes or, in text, its elements; None when the file does not say (it is then checked as the
scene's model says, as before).

Only this module's cheap imports (netCDF4 for ``.nc``) are needed: a refusal takes well under a second.
"""

from __future__ import annotations

import os
import struct
from pathlib import Path

from vemkit.config.body_forms import FORMS
from vemkit.config.gmsh_header import MAX_BYTES_PER_ITEM, MIN_NODE_BYTES, gmsh_dimension, gmsh_header
from vemkit.config.mesh_file_reading import MeshFileHeader, file_problem, open_regular_file
from vemkit.config.ugrid_header import ugrid_dimension, ugrid_header
from vemkit.exceptions import MeshError

__all__ = [
    "MAX_BYTES_PER_ITEM",
    "MESH_SUFFIXES",
    "MIN_NODE_BYTES",
    "OTHER_DIMENSION",
    "MeshFileHeader",
    "mesh_file_dimension",
    "mesh_file_header",
    "open_regular_file",
]

MESH_SUFFIXES = {".msh": "gmsh", ".nc": "UGRID netCDF"}
#: the refusal of a mesh file of the other dimension, by the dimension the file shows (the header's
#: and the mesh readers' words, after "<file>: ")
OTHER_DIMENSION = {dimension: form.file_in_other_scene for dimension, form in FORMS.items()}


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
            gmsh_header(fd, path, size, dimension) if path.suffix == ".msh" else ugrid_header(path, size, dimension)
        )
    finally:
        os.close(fd)
    form = FORMS[dimension]
    if header.cells > form.cells_per_vertex * header.vertices + 2:
        raise file_problem(
            path,
            f"declares {header.cells:,} cells on {header.vertices:,} vertices, more than {form.mesh_words} "
            f"can have ({form.cells_per_vertex} per vertex); the file is broken",
        )
    return header


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
        return gmsh_dimension(fd, path, size) if path.suffix == ".msh" else ugrid_dimension(path)
    except (MeshError, OSError, ValueError, IndexError, struct.error, UnicodeError):
        return None
    finally:
        os.close(fd)
