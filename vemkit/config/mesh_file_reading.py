"""The means the mesh file readers share (:mod:`vemkit.config.mesh_file_header`,
:mod:`vemkit.config.gmsh_header`, :mod:`vemkit.config.ugrid_header`): the record of what a file
declares, the one-line refusal naming the file, and opening only a regular file."""

from __future__ import annotations

import os
import stat
from pathlib import Path
from typing import NamedTuple

from vemkit.config.safe_yaml import file_kind
from vemkit.exceptions import MeshError

__all__ = ["MeshFileHeader", "file_problem", "open_regular_file", "read_at"]


class MeshFileHeader(NamedTuple):
    """Counts and sides a mesh file declares; ``sides_complete``: every side name is listed
    (UGRID) or only the physical names (gmsh: numbers and ``untagged`` may come on top)."""

    vertices: int
    cells: int
    sides: tuple
    sides_complete: bool
    size: int
    other_sides: tuple = ()  # gmsh: physical names of the other dimension's sides (3D in 2D, 2D in 3D)


def file_problem(path: Path, problem: str) -> MeshError:
    """The refusal of the mesh file ``path``: ``<name>: <problem>``."""
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


def read_at(fd: int, offset: int, count: int) -> bytes:
    """Up to ``count`` bytes of the file ``fd`` from ``offset``."""
    return os.pread(fd, count, offset)
