"""Mesh families by name: ``build_mesh("voronoi", 32, seed=1)``, on any domain (docs/reference/files.md):
``build_mesh("square", h=2.0, domain={"polygon": ..., "sides": ..., "holes": ...})``.
On the unit square (the default):

- ``square``: n x n squares (no options);
- ``triangle``: ``kind="delaunay"`` (default; options ``seed``, ``min_angle``) about 2 n² quality
  Delaunay triangles, or ``kind="structured"`` the n x n grid cut along diagonals;
- ``voronoi``: about n² centroidal Voronoi cells (``seed``, ``lloyd_iterations``, ``anisotropy``,
  ``merge_tol``);
- ``hanging``: n x n squares quadrisected ``levels`` times (``levels``, ``rule``, ``seed``,
  ``fraction``, ``contact_side``).

On any other domain: ``triangle`` (delaunay) respects every side and hole, ``voronoi`` is clipped
to it (holes included), ``square`` and ``hanging`` are cut cells (``cut.py``); every boundary edge
is named after the side it lies on.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from typing import Any

from vemkit.config.domain import cells_per_length, domain_from_spec
from vemkit.exceptions import MeshError
from vemkit.mesh.families.hanging import hanging
from vemkit.mesh.families.square import square, structured_triangle
from vemkit.mesh.families.triangle import delaunay_triangle
from vemkit.mesh.families.voronoi import voronoi
from vemkit.mesh.mesh import Mesh

FAMILIES = ("square", "triangle", "voronoi", "hanging")
TRIANGLE_KINDS = ("delaunay", "structured")

_BUILDERS: dict[str | tuple[str, str], Callable[..., Mesh]] = {
    "square": square,
    ("triangle", "delaunay"): delaunay_triangle,
    ("triangle", "structured"): structured_triangle,
    "voronoi": voronoi,
    "hanging": hanging,
}


def family_builder(family: str, options: dict):
    """The builder of ``family`` for ``options`` (``kind`` removed from them); MeshError (an
    InputError) naming the family or the option that does not apply to it."""
    if family not in FAMILIES:
        raise MeshError(f"mesh family {family!r} is unknown; valid families: {', '.join(FAMILIES)}", key="family")
    key: str | tuple[str, str] = family
    if family == "triangle":
        kind = options.pop("kind", "delaunay")
        if kind not in TRIANGLE_KINDS:
            raise MeshError(
                f"triangle mesh kind {kind!r} is unknown; valid kinds: {', '.join(TRIANGLE_KINDS)}", key="kind"
            )
        key = (family, kind)
    builder = _BUILDERS[key]
    valid = [p for p in inspect.signature(builder).parameters if p not in ("n", "domain")]
    unknown = sorted(set(options) - set(valid))
    if unknown:
        name = family if family != "triangle" else f"triangle (kind={key[1]})"
        listing = ", ".join(valid + (["kind"] if family == "triangle" else [])) or "none"
        raise MeshError(
            f"mesh option {unknown[0]!r} is not valid for family {name}; valid options: {listing}", key=unknown[0]
        )
    return builder


def build_mesh(
    family: str, n: float | None = None, *, domain=None, h: float | None = None, cells: float | None = None, **options
) -> Mesh:
    """The mesh of ``family`` on ``domain``, made with ``options``.

    ``domain``: a :class:`~vemkit.config.domain.Domain`, its docs/reference/files.md mapping or None (the unit
    square). Size: exactly one of ``n`` (cells per unit length, n = 1/h: about n² cells per unit
    area), ``h`` or ``cells`` (about that many cells). On the unit square with a whole n every
    family makes exactly the mesh it always made.
    """
    builder = family_builder(family, options)
    region = domain_from_spec(domain)
    n = cells_per_length(region, n, h, cells, 2.0 if family == "triangle" else 1.0)
    if region.is_unit_square:
        return builder(n, **options)
    if builder is structured_triangle:
        raise MeshError(
            "triangle kind structured is a unit-square family; use kind delaunay on this domain", key="kind"
        )
    return builder(n, domain=region, **options)


__all__ = [
    "FAMILIES",
    "TRIANGLE_KINDS",
    "build_mesh",
    "checked_mesh",
    "scene_mesh",
    "family_builder",
    "square",
    "structured_triangle",
    "delaunay_triangle",
    "voronoi",
    "hanging",
]


def checked_mesh(mesh: Mesh, what: str, fix: str) -> Mesh:
    """``mesh``, validated (``vemkit.mesh.checks.validate_mesh``; a polyhedral mesh by
    ``vemkit.mesh.checks3d.validate_mesh3d``); a MeshError naming ``what`` was built and ``fix``
    otherwise. Every mesh a command solves or writes passes here or through
    ``vemkit.mesh.files.read_mesh``: ``vemkit solve``, ``adapt`` and ``mesh`` refuse the same meshes."""
    validate_mesh: Callable[..., None]  # the 2D or the 3D check
    if getattr(mesh, "dimension", 2) == 3:
        from vemkit.mesh.checks3d import validate_mesh3d as validate_mesh
    else:
        from vemkit.mesh.checks import validate_mesh

    try:
        validate_mesh(mesh)
    except MeshError as error:
        raise MeshError(f"{what} is broken: {error}; {fix}", key="discretization.mesh") from None
    return mesh


def scene_mesh(scene) -> Mesh:
    """The validated mesh a scene (``vemkit.config.Scene``) asks for: its family on its domain with
    one of n / h / cells (:func:`checked_mesh`), or its mesh file (docs/reference/files.md, read and validated)."""
    three_d = scene.dimension == 3
    if scene.mesh_file is not None:
        read_mesh: Callable[..., Any]  # the 2D or the 3D reader
        if three_d:
            from vemkit.mesh.files3d import read_mesh3d as read_mesh
        else:
            from vemkit.mesh.files import read_mesh

        return read_mesh(scene.mesh_file)
    opts = scene.mesh_options
    family = opts.pop("family")
    sizes = {key: opts.pop(key) for key in ("n", "h", "cells") if key in opts}
    # options were checked by the scene schema and build_mesh; the domain by the scene (docs/reference/files.md)
    size = ", ".join(f"{key} = {value:g}" for key, value in sizes.items())
    build: Callable[..., Any]  # build_mesh or build_mesh3d
    if three_d:  # the 3D families build on the 2D ones (prisms): imported here, not at the top
        from vemkit.mesh.families3d import build_mesh3d as build
    else:
        build = build_mesh
    return checked_mesh(
        build(family, domain=scene.domain, **sizes, **opts),
        f"the {family} mesh ({size})",
        "try another discretization.mesh size or family",
    )
