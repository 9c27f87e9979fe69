"""Whether a mesh size suits the body (docs/reference/files.md, issue 9): checked before any mesh is built.

The mesh families work in double precision with tolerances relative to the cell size h (points
closer than 1e-9 h are one vertex); a size far from the body's own scales breaks them, with an
internal error, a hang or a mesh that silently lost a hole. Refused with one line naming
``discretization.mesh`` and the fix (measured on rectangles, circles and notches, every family):

- **cells much larger than the body**: h > ``MAX_CELL_OVER_BODY`` x the body's larger side (h = 1e12
  on a 2 x 1 plate, n = 4 on a body of 1e-12: all points merge into one);
- **coordinates far larger than the cells**: max |x|, |y| of the body above ``MAX_COORDINATE_OVER_CELL``
  x the smallest cell (h / 2^levels for ``hanging``): double precision keeps too few digits of
  each cell (Voronoi fails from 1.6e5, the others from about 1e7; a body at 1e11 with cells of 0.25);
- **features below the resolution of double precision**: a hole, a gap, an edge shorter than
  ``MIN_FEATURE`` x the body's size (a hole of radius 1e-12 ends the assembly; Voronoi drops a
  hole of 1e-7);
- **voronoi with holes smaller than its cells**: a hole of radius below ``VORONOI_MIN_HOLE`` x h
  (1 in 8 seeds fail at 0.25 h; none at 0.3 h);
- **hanging towards a side the body does not have** (``contact_side`` defaults to ``bottom``).

A 3D body (a box, an extruded domain: :func:`check_mesh_resolution3d`) has the same size rules, its
extent along z included (3D Voronoi fails from 4e5 cells from the origin, like the 2D one), the
octree's finest cells h / 2 and its refined side, the base's own rules at the same h (prisms over
its 2D mesh, or tet), and one more: its smallest side at least ``MIN_FEATURE`` x its largest (a box
of 1 x 1 x 1e-7, a square extruded to 1e12: the rigid motions and the faces' planes of such a body
are rounding noise).

:func:`thin_part_triangles` predicts the triangles Triangle's quality mesh adds in parts of the body
thinner than h (a strip of width w and length L needs about 2 L / w of them whatever h is): the
resource estimate of :mod:`vemkit.config.limits` adds them, so a 1 x 1e-9 strip is refused with its
cost instead of filling the memory.
"""

from __future__ import annotations

import math

import numpy as np
import shapely

from vemkit.config.domain import CircleHole, Domain, cells_per_length, domain_from_spec
from vemkit.config.domain3d import Box, Extruded, cells_per_length3d
from vemkit.exceptions import SceneError

__all__ = [
    "MAX_CELL_OVER_BODY",
    "MAX_COORDINATE_OVER_CELL",
    "MIN_FEATURE",
    "VORONOI_MIN_HOLE",
    "check_cells",
    "check_mesh_resolution",
    "check_mesh_resolution3d",
    "check_refined_side",
    "scene_cells_per_length",
    "thin_part_triangles",
]

MAX_CELL_OVER_BODY = 10.0
MAX_COORDINATE_OVER_CELL = {"voronoi": 5e4, "other": 1e6}
MIN_FEATURE = 1e-6
VORONOI_MIN_HOLE = 0.3
_FIX = "fix the scene or --set discretization.mesh.h=..."


def cell_size(mesh: dict, domain: Domain) -> float:
    """The cell size h of ``discretization.mesh`` (1/n, h, or from cells) on ``domain``."""
    sizes = {key: mesh[key] for key in ("n", "h", "cells") if key in mesh}
    return 1.0 / float(
        cells_per_length(domain, **sizes, cells_per_square=2.0 if mesh.get("family") == "triangle" else 1.0)
    )


def scene_cells_per_length(scene) -> float:
    """n = 1/h of a scene with a mesh family (docs/reference/files.md)."""
    return 1.0 / cell_size(scene.mesh_options, domain_from_spec(scene.domain))


def _extent(domain: Domain) -> tuple:
    x0, y0, x1, y1 = domain.bounds
    return max(x1 - x0, y1 - y0), max(abs(x0), abs(x1), abs(y0), abs(y1)), (x1 - x0, y1 - y0)


def _given(mesh: dict) -> str:
    return ", ".join(f"{k} = {mesh[k]:g}" for k in ("n", "h", "cells") if k in mesh)


def check_cells(mesh: dict, h: float, finest: float, lower, upper, shift: str, structured: bool = False) -> None:
    """The size rules of 2D and 3D bodies alike (module doc): cells much larger than the body (the box
    ``lower``, ``upper`` around it, 2 or 3 coordinates), far too many across it, or too fine for double
    precision at the body's distance from the origin (``finest``: the smallest cell; ``shift``: how
    to move the body)."""
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    extents = upper - lower
    size, reach = float(extents.max()), float(np.abs([lower, upper]).max())
    body, given = " x ".join(f"{e:.3g}" for e in extents), _given(mesh)
    if h > MAX_CELL_OVER_BODY * size:
        raise SceneError(
            f"discretization.mesh ({given}): cells of size {h:.3g} on a body of {body}; "
            f"give h <= {size:.3g} (the body's larger side) or a larger n; {_FIX}",
            key="discretization.mesh",
        )
    ratio = MAX_COORDINATE_OVER_CELL.get(mesh["family"], MAX_COORDINATE_OVER_CELL["other"])
    if size > ratio * h:
        raise SceneError(
            f"discretization.mesh ({given}): about {size / h:.2g} cells of size {h:.3g} across a body of "
            f"{body}, far beyond any memory; give a larger h or a smaller n (at most "
            f"{ratio:.0e} cells across); {_FIX}",
            key="discretization.mesh",
        )
    if reach > ratio * finest and not structured:
        axes = ", ".join(f"|{axis}|" for axis in "xyz"[: extents.size])
        raise SceneError(
            f"discretization.mesh ({given}): cells of size {finest:.3g} at {axes} up to {reach:.3g}, more "
            f"than {ratio:.0e} cells from the origin: too fine for double precision there; move the body "
            f"near the origin ({shift}), or use coarser cells (fewer levels)",
            key="discretization.mesh",
        )


def check_refined_side(mesh: dict, sides) -> None:
    """A family that refines towards ``contact_side`` (hanging, octree) needs a side the body has."""
    side = mesh.get("contact_side", "bottom")
    if mesh.get("rule", "contact") == "contact" and side not in sides:
        raise SceneError(
            f"discretization.mesh.contact_side = {side!r}: the {mesh['family']} family refines towards a side "
            f"of the body; give one of {', '.join(dict.fromkeys(sides))} (or rule: random)",
            key="discretization.mesh.contact_side",
        )


def check_mesh_resolution(mesh: dict, domain: Domain, h: float | None = None) -> None:
    """SceneError if the mesh size of ``discretization.mesh`` cannot mesh ``domain`` (module doc);
    ``h``: the cell size when another rule than the 2D one gives it (the base of a 3D body)."""
    if "file" in mesh:
        return
    family = mesh["family"]
    h = cell_size(mesh, domain) if h is None else h
    x0, y0, x1, y1 = domain.bounds
    structured = domain.is_unit_square and family in ("square", "hanging") and float(1.0 / h).is_integer()
    finest = h / 2 ** int(mesh.get("levels", 1)) if family == "hanging" else h
    check_cells(mesh, h, finest, (x0, y0), (x1, y1), "shift domain.polygon and the holes", structured)
    size = _extent(domain)[0]
    _check_features(domain, max(h, size / 4096), size)
    if family == "voronoi":
        _check_voronoi_holes(domain, h)
    if family == "hanging":
        check_refined_side(mesh, domain.side_names)


def _bounds3d(body) -> tuple:
    """(lower, upper) corners of a 3D body's bounding box."""
    if isinstance(body, Box):
        return np.asarray(body.lower, dtype=float), np.asarray(body.upper, dtype=float)
    x0, y0, x1, y1 = body.base.bounds
    return np.array([x0, y0, 0.0]), np.array([x1, y1, body.depth])


def _check_aspect(body, lower, upper) -> None:
    """A body whose smallest side is below ``MIN_FEATURE`` x its largest: no mesh resolves it in double
    precision (its rigid motions, its faces' planes are rounding noise)."""
    extents = upper - lower
    if extents.min() >= MIN_FEATURE * extents.max():
        return
    shape = " x ".join(f"{e:.3g}" for e in extents)
    most = f"{1 / MIN_FEATURE:.0e}"
    if isinstance(body, Box):
        key, where = "domain.box", f"domain.box: a box of {shape}"
        fix = f"give sides within a factor {most} of each other"
    else:
        key, where = "domain.extrude.depth", f"domain.extrude.depth = {body.depth:g}: a body of {shape}"
        fix = f"give a depth within a factor {most} of the base's size {float(extents[:2].max()):.3g}"
    raise SceneError(
        f"{where} is {extents.max() / extents.min():.1e} times longer than thick, beyond what a mesh "
        f"resolves in double precision (at most {most}); {fix}",
        key=key,
    )


def check_mesh_resolution3d(mesh: dict, body) -> None:
    """The rules of :func:`check_mesh_resolution` for a 3D body (a Box or an Extruded): its aspect, the
    cell size against the body (the octree's halves the finest cells), the octree's refined side and
    level; on an extruded body the base's own rules at the same h (prisms over its 2D mesh, or tet)."""
    if "file" in mesh:
        return
    family = mesh["family"]
    lower, upper = _bounds3d(body)
    _check_aspect(body, lower, upper)
    per_cube = 6.0 if family == "tet" else 2.0 if family == "triangle" else 1.0
    sizes = {key: mesh[key] for key in ("n", "h", "cells") if key in mesh}
    h = 1.0 / float(cells_per_length3d(body, **sizes, cells_per_cube=per_cube))
    shift = "shift domain.box" if isinstance(body, Box) else "shift domain.polygon and the holes"
    check_cells(mesh, h, h / 2 if family == "octree" else h, lower, upper, shift)
    if family == "octree":
        check_refined_side(mesh, body.sides)
        if int(mesh.get("levels", 1)) != 1:
            raise SceneError(
                f"discretization.mesh.levels = {mesh['levels']}: the octree family refines one level; "
                "set discretization.mesh.levels=1 (or drop it)",
                key="discretization.mesh.levels",
            )
    if isinstance(body, Extruded) and family != "tet":
        check_mesh_resolution(mesh, body.base, h)
    elif isinstance(body, Extruded):
        size = _extent(body.base)[0]
        _check_features(body.base, max(h, size / 4096), size)


def _circle_gaps(domain: Domain):
    """(gap, x, y): the narrowest gap between a circular hole and the boundary or another hole, on
    the circles themselves (their polygons may miss it), and a point of it."""
    outer = shapely.LinearRing(domain.outer_ring(None)[0])
    others = [shapely.Polygon(h.polygon) for h in domain.holes if not isinstance(h, CircleHole)]
    circles = [h for h in domain.holes if isinstance(h, CircleHole)]
    best = (math.inf, 0.0, 0.0)
    for i, c in enumerate(circles):
        centre = shapely.Point(c.cx, c.cy)
        gaps = [outer.distance(centre) - c.r] + [p.distance(centre) - c.r for p in others]
        gaps += [math.hypot(c.cx - d.cx, c.cy - d.cy) - c.r - d.r for d in circles[i + 1 :]]
        best = min(best, (min(gaps), c.cx, c.cy))
    return best


def _check_features(domain: Domain, h: float, size: float) -> None:
    """The smallest distance across the body (a hole, a gap, an edge) is at least MIN_FEATURE x size."""
    if domain.is_unit_square:
        return
    shape = domain.discretize(h).shape
    clearance = shapely.minimum_clearance(shape)
    x, y = shapely.get_coordinates(shapely.minimum_clearance_line(shape))[0] if clearance < math.inf else (0, 0)
    clearance, x, y = min((clearance, x, y), _circle_gaps(domain))
    if clearance < MIN_FEATURE * size:
        raise SceneError(
            f"domain: the body has a feature of {clearance:.3g} near ({x:.6g}, {y:.6g}) (a hole, a gap or "
            f"an edge), {clearance / size:.1e} of its size {size:.3g}: below what a mesh resolves in double "
            "precision; remove it or merge the corners",
            key="domain",
        )


def _check_voronoi_holes(domain: Domain, h: float) -> None:
    for i, hole in enumerate(domain.holes):
        if isinstance(hole, CircleHole):
            radius = hole.r
        else:  # half the narrower side of the hole's smallest enclosing rectangle
            box = shapely.oriented_envelope(shapely.Polygon(hole.polygon))
            corners = shapely.get_coordinates(box)
            radius = 0.5 * min(np.hypot(*(corners[1] - corners[0])), np.hypot(*(corners[2] - corners[1])))
        if radius < VORONOI_MIN_HOLE * h:
            raise SceneError(
                f"domain.holes[{i}] (about {2 * radius:.3g} across) is too small for voronoi cells of size "
                f"{h:.3g}: give h <= {radius / VORONOI_MIN_HOLE:.3g} or the triangle family; {_FIX}",
                key="discretization.mesh",
            )


def _sharp_corners(shape) -> tuple:
    """(points, angles) of the corners where the body's angle is below 90 degrees."""
    points, angles = [], []
    for index, ring in enumerate((shape.exterior, *shape.interiors)):
        p = np.asarray(ring.coords)[:-1]
        if ring.is_ccw != (index == 0):  # walk with the body on the left
            p = p[::-1]
        a, b = np.roll(p, 1, axis=0) - p, np.roll(p, -1, axis=0) - p
        cross = b[:, 0] * a[:, 1] - b[:, 1] * a[:, 0]  # > 0: a convex corner of the body
        angle = np.arctan2(np.abs(cross), (a * b).sum(axis=1))
        keep = (cross > 0) & (angle < 0.5 * math.pi)
        points.append(p[keep])
        angles.append(angle[keep])
    return np.concatenate(points), np.concatenate(angles)


def thin_part_triangles(domain: Domain, h: float) -> int:
    """About how many triangles a quality mesh of size h puts in the parts of ``domain`` thinner
    than h: the area narrower than 2 r (what an opening of radius r removes, corners sharper than a
    right angle left out: Triangle does not refine into them) at r = h/2, h/4, ..., each band
    filled with triangles of its width. An upper bound within a factor 3 on strips and fins."""
    size = _extent(domain)[0]
    if domain.is_unit_square or not h > 0:
        return 0
    shape = domain.discretize(max(h, size / 64)).shape
    if shapely.minimum_clearance(shape) >= 0.5 * h:
        return 0
    points, angles = _sharp_corners(shape)
    bands, r = [], 0.5 * h
    while r > MIN_FEATURE * size * 0.25:
        thin = shape.difference(shape.buffer(-r).buffer(r))
        if points.size:  # the tips of sharp corners, narrower than 2 r within r / sin(angle / 2)
            thin = thin.difference(
                shapely.union_all(shapely.buffer(shapely.points(points), 1.01 * r / np.sin(0.5 * angles)))
            )
        bands.append((r, thin.area))
        if thin.area <= 1e-12 * shape.area:
            break
        r *= 0.5
    bands.append((0.5 * r, 0.0))
    extra = sum(2.0 * (a0 - a1) / (2.0 * r1) ** 2 for (_, a0), (r1, a1) in zip(bands, bands[1:]))
    return int(min(extra, 1e16))
