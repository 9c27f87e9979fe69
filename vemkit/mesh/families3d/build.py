"""Meshing a 3D body (docs/reference/files.md) by family name and size: ``build_mesh3d("voronoi", {"box": ...}, n=8)``.

The body is parsed by :func:`vemkit.config.domain3d.domain3d_from_spec` (module doc there); on a box
the 3D families, on an extruded domain the prisms over the 2D family's mesh of the base, or (family
``tet``, which is no 2D family) gmsh's Delaunay tetrahedra of the extruded body itself.

``tet`` takes ``kind``: ``delaunay`` (the default: gmsh's quality Delaunay tetrahedra, about
6 n³ per unit volume, ``families3d.gmsh_tet``; on boxes and extruded domains; option ``optimize``,
default true: gmsh's quality optimization, false: its Delaunay mesh as it is) or ``structured``
(the Kuhn tetrahedra of the n-grid, 6 per cube, ``families3d.grid.tet``; boxes only).
"""

from __future__ import annotations

import inspect

import numpy as np

from vemkit.config.domain3d import BOX_FAMILIES as BOX_FAMILY_NAMES
from vemkit.config.domain3d import (
    EXTRUDE_FAMILIES_3D,
    FAMILIES_2D,
    TET_KINDS,
    Box,
    cells_per_length3d,
    domain3d_from_spec,
)
from vemkit.exceptions import SceneError
from vemkit.mesh.families.by_name import build_mesh
from vemkit.mesh.families3d.extrude import extrude
from vemkit.mesh.families3d.gmsh_tet import delaunay_tet, delaunay_tet_extruded, n_for_cells, surface_area
from vemkit.mesh.families3d.grid import hex, tet
from vemkit.mesh.families3d.octree import octree
from vemkit.mesh.families3d.voronoi3d import voronoi

#: family -> (builder, cells per n³ unit volume, for the size by ``cells``)
BOX_FAMILIES = {"hex": (hex, 1.0), "tet": (tet, 6.0), "octree": (octree, 1.0), "voronoi": (voronoi, 1.0)}


def build_mesh3d(family: str, domain, n=None, h=None, cells=None, layers=None, **options):
    """The PolyhedralMesh of ``family`` on a 3D ``domain`` (a spec mapping, Box or Extruded; module doc)."""
    body = domain3d_from_spec(domain)
    if family == "tet":
        return _tet(body, n, h, cells, layers, options)
    if isinstance(body, Box):
        if family not in BOX_FAMILY_NAMES:
            raise SceneError(
                f"mesh family {family!r} does not mesh a box; valid families: {', '.join(BOX_FAMILY_NAMES)}",
                key="discretization.mesh.family",
            )
        if layers is not None:
            raise SceneError(
                "discretization.mesh.layers applies to an extrude domain only; remove it",
                key="discretization.mesh.layers",
            )
        builder = BOX_FAMILIES[family][0]
        _check_options(family, builder, options)
        box = (body.lower, body.upper)
        if family == "voronoi" and cells is not None:
            return builder(box=box, sides=body.sides, cells=cells, **options)
        return builder(box_cells_per_length(family, body, n, h, cells, options), box=box, sides=body.sides, **options)
    if family not in FAMILIES_2D:
        raise SceneError(
            f"mesh family {family!r} does not mesh an extrude domain; valid families: "
            f"{', '.join(FAMILIES_2D)} (prisms over the 2D mesh of the base), "
            f"{', '.join(EXTRUDE_FAMILIES_3D)} (tetrahedra of the body)",
            key="discretization.mesh.family",
        )
    size = cells_per_length3d(body, n, h, cells, 2.0 if family == "triangle" else 1.0)
    _check_options(family, None, {k: v for k, v in options.items()})
    base = build_mesh(family, **({"h": h} if h is not None else {"n": size}), domain=body.base, **options)
    if layers is None:
        layers = max(1, int(round(body.depth * size)))
    elif isinstance(layers, bool) or not float(layers).is_integer() or int(layers) < 1:
        raise SceneError(
            f"discretization.mesh.layers = {layers!r}: give a whole number >= 1", key="discretization.mesh.layers"
        )
    return extrude(base, int(layers), body.depth, ends=body.ends)


def tet_kind(options: dict) -> str:
    """The ``kind`` of a tet request (removed from ``options``); SceneError for an unknown one."""
    kind = options.pop("kind", "delaunay")
    if kind not in TET_KINDS:
        raise SceneError(
            f"tet mesh kind {kind!r} is unknown; valid kinds: {', '.join(TET_KINDS)}", key="discretization.mesh.kind"
        )
    return kind


def tet_cells_per_length(body, n=None, h=None, cells=None, kind: str = "delaunay") -> float:
    """n of the tet family: from n or h = 1/n; from ``cells`` by the Kuhn count (6 n³ V, structured) or
    by the fitted Delaunay count 6 n³ V + c n² A (``gmsh_tet.tet_counts``)."""
    if cells is None or kind == "structured":
        return cells_per_length3d(body, n, h, cells, 6.0)
    cells_per_length3d(body, n, h, cells, 6.0)  # checks that cells alone is given, and positive
    return n_for_cells(float(cells), body.volume, surface_area(body))


def _tet(body, n, h, cells, layers, options: dict):
    options = dict(options)
    kind = tet_kind(options)
    if layers is not None:
        raise SceneError(
            "discretization.mesh.layers applies to the prism families on an extrude domain; remove it for family tet",
            key="discretization.mesh.layers",
        )
    if kind == "structured" and not isinstance(body, Box):
        raise SceneError(
            "tet kind structured (Kuhn tetrahedra of a grid) meshes a box only; use kind delaunay on an extrude domain",
            key="discretization.mesh.kind",
        )
    builder = tet if kind == "structured" else delaunay_tet if isinstance(body, Box) else delaunay_tet_extruded
    _check_options(f"tet (kind={kind})", builder, options, extra=["kind"])
    size = tet_cells_per_length(body, n, h, cells, kind)
    if isinstance(body, Box):
        return builder(size, box=(body.lower, body.upper), sides=body.sides, **options)
    return builder(size, body, **options)


def _check_options(family: str, builder, options: dict, extra=()) -> None:
    """SceneError naming an option the box family does not take (2D families: ``build_mesh`` checks)."""
    if builder is None:
        return
    valid = [
        p for p in inspect.signature(builder).parameters if p not in ("n", "box", "sides", "cells", "shape", "body")
    ] + list(extra)
    unknown = sorted(set(options) - set(valid))
    if unknown:
        raise SceneError(
            f"mesh option {unknown[0]!r} is not valid for family {family}; valid options: {', '.join(valid) or 'none'}",
            key=f"discretization.mesh.{unknown[0]}",
        )


def box_cells_per_length(family: str, body: Box, n=None, h=None, cells=None, options=None) -> float:
    """n of a box family from n, h or cells. For ``octree`` ``cells`` counts the cells after the
    refinement: (1 + 7 fraction) per grid cell (random), or n³ V + 7 n² A with A the area of the
    contact side (contact), solved for n."""
    options = options or {}
    if family == "tet":
        return tet_cells_per_length(body, n, h, cells, options.get("kind", "delaunay"))
    if family != "octree" or cells is None:
        return cells_per_length3d(body, n, h, cells, BOX_FAMILIES[family][1])
    if options.get("rule", "contact") == "random":
        return cells_per_length3d(body, cells=cells, cells_per_cube=1.0 + 7.0 * float(options.get("fraction", 0.3)))
    side = options.get("contact_side", "bottom")
    target = float(cells_per_length3d(body, cells=cells)) ** 3 * body.volume  # checks cells
    if side not in body.sides:
        return cells_per_length3d(body, cells=cells)  # octree names the side
    size = np.subtract(body.upper, body.lower)
    area = float(np.prod(np.delete(size, list(body.sides).index(side) // 2)))
    lo, hi = 0.0, (target / body.volume) ** (1.0 / 3.0)
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if mid**3 * body.volume + 7.0 * mid**2 * area < target else (lo, mid)
    return hi
