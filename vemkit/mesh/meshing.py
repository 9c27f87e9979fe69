"""A mesh of any dimension from a scene, and the check every mesh a command solves passes.

The one place that knows both the 2D families (``vemkit.mesh.families``) and the 3D ones
(``vemkit.mesh.families3d``, which builds prisms over the 2D families through
``vemkit.mesh.families.by_name``): each dimension's builder, reader and check is looked up by
``scene.dimension`` or ``mesh.dimension`` (:class:`~vemkit.mesh.interface.MeshInterface`), so no
caller asks which mesh class it has. The functions are named per dimension (:data:`BY_DIMENSION`)
and imported on first use, so that a 2D command never loads the 3D modules; the import graph of
``vemkit.mesh`` has no cycle (tests/mesh/test_mesh_imports.py walks it).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any

from vemkit.exceptions import MeshError

#: role -> dimension -> (module, function): the mesh check, the mesh-file reader (it validates what it
#: reads), the family builder (family name, domain, size, options) and the resource prediction of each
#: dimension. Named, not imported: a 2D command never loads the 3D modules (their imports cost a fixed time per process,
#: tests/cli/test_cli_imports.py); none of them imports this module, so there is no cycle either.
BY_DIMENSION: dict[str, dict[int, tuple[str, str]]] = {
    "validate": {2: ("vemkit.mesh.checks", "validate_mesh"), 3: ("vemkit.mesh.checks3d", "validate_mesh3d")},
    "read": {2: ("vemkit.mesh.files", "read_mesh"), 3: ("vemkit.mesh.files3d", "read_mesh3d")},
    "build": {2: ("vemkit.mesh.families.by_name", "build_mesh"), 3: ("vemkit.mesh.families3d.build", "build_mesh3d")},
    # the prediction of a scene's cells, DOFs and memory before its mesh is built (scene, max_dofs, layout,
    # ranks=(on this machine, in all) of an MPI job)
    "check_resources": {
        2: ("vemkit.config.limits", "check_scene_resources"),
        3: ("vemkit.mesh.families3d.resources", "check_scene_resources3d"),
    },
    # the refinement of marked cells with hanging vertices: plane meshes; polyhedral meshes of boxes
    "refine": {2: ("vemkit.mesh.refine", "refine_cells"), 3: ("vemkit.mesh.refine_polyhedra", "refine_cells")},
    # (mesh, curves) -> None or a MeshError naming a cell the refinement cannot split (before any solve)
    "check_refinable": {
        2: ("vemkit.mesh.refine", "check_refinable"),
        3: ("vemkit.mesh.families3d.resources", "check_refinable3d"),
    },
}

#: the dimensions whose refinement (``BY_DIMENSION["refine"]``) can keep at most k hanging vertices per
#: edge of a cell (``max_hanging``; polyhedra: not yet)
HANGING_LIMIT_DIMENSIONS = (2,)


def of_dimension(role: str, dimension: int) -> Callable[..., Any]:
    """The function of ``role`` (a key of :data:`BY_DIMENSION`) for meshes of ``dimension``."""
    module, name = BY_DIMENSION[role][dimension]
    return getattr(importlib.import_module(module), name)


__all__ = ["HANGING_LIMIT_DIMENSIONS", "BY_DIMENSION", "checked_mesh", "of_dimension", "scene_mesh"]


def checked_mesh(mesh, what: str, fix: str):
    """``mesh``, validated (``vemkit.mesh.checks.validate_mesh``; a polyhedral mesh by
    ``vemkit.mesh.checks3d.validate_mesh3d``); a MeshError naming ``what`` was built and ``fix``
    otherwise. Every mesh a command solves or writes passes here or through
    ``vemkit.mesh.files.read_mesh``: ``vemkit solve``, ``adapt`` and ``mesh`` refuse the same meshes."""
    try:
        of_dimension("validate", mesh.dimension)(mesh)
    except MeshError as error:
        raise MeshError(f"{what} is broken: {error}; {fix}", key="discretization.mesh") from None
    return mesh


def scene_mesh(scene):
    """The validated mesh a scene (``vemkit.config.Scene``) asks for: its family on its domain with
    one of n / h / cells (:func:`checked_mesh`), or its mesh file (docs/reference/files.md, read and validated)."""
    if scene.mesh_file is not None:
        return of_dimension("read", scene.dimension)(scene.mesh_file)
    opts = scene.mesh_options
    family = opts.pop("family")
    sizes = {key: opts.pop(key) for key in ("n", "h", "cells") if key in opts}
    # options were checked by the scene schema and build_mesh; the domain by the scene (docs/reference/files.md)
    size = ", ".join(f"{key} = {value:g}" for key, value in sizes.items())
    return checked_mesh(
        of_dimension("build", scene.dimension)(family, domain=scene.domain, **sizes, **opts),
        f"the {family} mesh ({size})",
        "try another discretization.mesh size or family",
    )
