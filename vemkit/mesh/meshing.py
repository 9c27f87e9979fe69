"""A mesh of any dimension from a scene, and the check every mesh a command solves passes.

The one place that knows both the 2D families (``vemkit.mesh.families``) and the 3D ones
(``vemkit.mesh.families3d``, which builds prisms over the 2D families through
``vemkit.mesh.families.by_name``): each dimension's builder, reader and check is looked up by
``scene.dimension`` or ``mesh.dimension`` (:class:`~vemkit.mesh.interface.MeshInterface`), so no
caller asks which mesh class it has. Imported at the top, never inside a function: the import
graph of ``vemkit.mesh`` has no cycle (tests/mesh/test_mesh_interface.py walks it).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from vemkit.exceptions import MeshError
from vemkit.mesh.checks import validate_mesh
from vemkit.mesh.checks3d import validate_mesh3d
from vemkit.mesh.families.by_name import build_mesh
from vemkit.mesh.families3d.build import build_mesh3d
from vemkit.mesh.files import read_mesh
from vemkit.mesh.files3d import read_mesh3d

#: dimension -> the mesh check of that dimension
VALIDATORS: dict[int, Callable[..., None]] = {2: validate_mesh, 3: validate_mesh3d}
#: dimension -> the mesh-file reader of that dimension (it validates what it reads)
READERS: dict[int, Callable[..., Any]] = {2: read_mesh, 3: read_mesh3d}
#: dimension -> the family builder of that dimension (family name, domain, size, options)
BUILDERS: dict[int, Callable[..., Any]] = {2: build_mesh, 3: build_mesh3d}

__all__ = ["BUILDERS", "READERS", "VALIDATORS", "checked_mesh", "scene_mesh"]


def checked_mesh(mesh, what: str, fix: str):
    """``mesh``, validated (``vemkit.mesh.checks.validate_mesh``; a polyhedral mesh by
    ``vemkit.mesh.checks3d.validate_mesh3d``); a MeshError naming ``what`` was built and ``fix``
    otherwise. Every mesh a command solves or writes passes here or through
    ``vemkit.mesh.files.read_mesh``: ``vemkit solve``, ``adapt`` and ``mesh`` refuse the same meshes."""
    try:
        VALIDATORS[mesh.dimension](mesh)
    except MeshError as error:
        raise MeshError(f"{what} is broken: {error}; {fix}", key="discretization.mesh") from None
    return mesh


def scene_mesh(scene):
    """The validated mesh a scene (``vemkit.config.Scene``) asks for: its family on its domain with
    one of n / h / cells (:func:`checked_mesh`), or its mesh file (docs/reference/files.md, read and validated)."""
    if scene.mesh_file is not None:
        return READERS[scene.dimension](scene.mesh_file)
    opts = scene.mesh_options
    family = opts.pop("family")
    sizes = {key: opts.pop(key) for key in ("n", "h", "cells") if key in opts}
    # options were checked by the scene schema and build_mesh; the domain by the scene (docs/reference/files.md)
    size = ", ".join(f"{key} = {value:g}" for key, value in sizes.items())
    return checked_mesh(
        BUILDERS[scene.dimension](family, domain=scene.domain, **sizes, **opts),
        f"the {family} mesh ({size})",
        "try another discretization.mesh size or family",
    )
