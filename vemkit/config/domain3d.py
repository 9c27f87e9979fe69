"""3D bodies (docs/reference/files.md): a box, or a 2D domain extruded along z; parsed, validated and meshed.

```yaml
domain: {box: [[0, 0, 0], [1, 1, 0.5]], sides: [left, right, front, back, bottom, top]}
domain:
  extrude: {depth: 0.25, ends: [front, back]}
  polygon: [[0, 0], [1, 0], [1, 1], [0, 1]]
  sides: [bottom, right, top, left]
  holes: [{circle: [0.5, 0.5, 0.2], side: bore}]
```
``domain3d_from_spec`` returns a :class:`Box` or an :class:`Extruded` (whose base is a 2D
:class:`~vemkit.config.domain.Domain`, parsed by ``domain_from_spec``) and refuses a broken entry
with a one-line ``SceneError`` whose ``key`` names it. ``vemkit.mesh.families3d.build_mesh3d(family,
domain, n=/h=/cells=)`` meshes it: on a box the 3D families ``hex``, ``tet``, ``octree``, ``voronoi``;
on an extruded domain the prisms over the 2D family's mesh of the base (exactly ``build_mesh(family, ...)`` of the same
keys) in ``layers`` layers (default ``max(1, round(depth n))``, about depth / h), or ``tet``: a 3D
family, not a 2D one, so on an extruded domain it means gmsh's Delaunay tetrahedra of the extruded
body (lateral faces named by the 2D sides, end faces by ``ends``), not prisms.
``tet`` has ``kind: delaunay`` (the default, gmsh; boxes and extruded domains) or ``kind: structured``
(the Kuhn tetrahedra of the hex grid, boxes only).
Sizes: ``n`` cells per unit length (about n³ cells per unit volume; tet: about 6 n³), ``h = 1 / n`` or ``cells``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vemkit.config.domain import SIDE_NAME, Domain, domain_from_spec, mesh_density
from vemkit.exceptions import InputError, SceneError

BOX_SIDES = ("left", "right", "front", "back", "bottom", "top")
DEFAULT_ENDS = ("front", "back")
FAMILIES_2D = ("square", "triangle", "voronoi", "hanging")
BOX_FAMILIES = ("hex", "tet", "octree", "voronoi")
#: 3D families that mesh an extruded body itself (not prisms over a 2D mesh)
EXTRUDE_FAMILIES_3D = ("tet",)
#: how the tet family makes its tetrahedra: gmsh's Delaunay mesher, or the Kuhn cut of the hex grid
TET_KINDS = ("delaunay", "structured")
PLANE = 2  # the dimension of a domain that is not a solid
#: the dimension of the body a key of a ``domain`` mapping makes (any other key: a plane domain)
DOMAIN_KEY_DIMENSION = {"box": 3, "extrude": 3}


@dataclass(frozen=True)
class Box:
    """An axis-aligned box [lower, upper] with its six sides named (xmin, xmax, ymin, ymax, zmin, zmax)."""

    lower: tuple
    upper: tuple
    sides: tuple = BOX_SIDES
    volume = property(lambda self: float(np.prod(np.subtract(self.upper, self.lower))), doc="its volume")
    base = None  # no plane section with curves: its faces are planes (``plane_section``)

    @property
    def side_names(self) -> tuple:
        return tuple(dict.fromkeys(self.sides))


@dataclass(frozen=True)
class Extruded:
    """A docs/reference/files.md domain extruded along z to ``depth``, its end faces named ``ends`` (z = 0, z = depth)."""

    base: Domain
    depth: float
    ends: tuple = DEFAULT_ENDS
    volume = property(lambda self: self.depth * self.base.exact_area, doc="its volume")

    @property
    def side_names(self) -> tuple:
        return tuple(dict.fromkeys(self.base.side_names + self.ends))


def is_3d_domain(spec) -> bool:
    """Whether a scene's ``domain`` entry is a 3D body (a mapping with ``box`` or ``extrude``)."""
    return isinstance(spec, (Box, Extruded)) or (isinstance(spec, dict) and ("box" in spec or "extrude" in spec))


def domain_dimension(spec) -> int:
    """The dimension of the body a scene's ``domain`` entry describes: 3 for a solid (a mapping with
    ``box`` or ``extrude``, a :class:`Box`, an :class:`Extruded`), 2 for a plane body (``unit_square``,
    a polygon, a :class:`~vemkit.config.domain.Domain`)."""
    if isinstance(spec, dict):
        return max((DOMAIN_KEY_DIMENSION.get(key, PLANE) for key in spec), default=PLANE)
    return SOLID_DIMENSION.get(type(spec), PLANE)


def domain3d_from_spec(spec):
    """The Box or Extruded of a docs/reference/files.md ``domain:`` mapping; SceneError naming the key otherwise."""
    if isinstance(spec, (Box, Extruded)):
        return spec
    kinds = [key for key in _SOLIDS if key in spec] if isinstance(spec, dict) else []
    if not kinds:
        raise SceneError(
            "domain: give a 3D body {box: [[x0, y0, z0], [x1, y1, z1]]} or {extrude: {depth: ...}, "
            "polygon: ..., sides: ...}",
            key="domain",
        )
    if len(kinds) > 1:
        raise SceneError("domain: give either box or extrude, not both", key="domain")
    return _SOLIDS[kinds[0]](spec)


def plane_section(spec):
    """The plane Domain whose curves (arcs, circular holes) a body's boundary follows: a plane body's own
    domain, an extruded body's base (curves in the xy plane, the same at every z); None for a box."""
    solid = isinstance(spec, (Box, Extruded)) or (isinstance(spec, dict) and any(key in spec for key in _SOLIDS))
    return domain3d_from_spec(spec).base if solid else domain_from_spec(spec)


def _names(value, count: int, key: str, what: str) -> tuple:
    if not isinstance(value, (list, tuple)) or len(value) != count:
        given = len(value) if isinstance(value, (list, tuple)) else "no list of"
        raise SceneError(f"{key} has {given} names; give {count} ({what})", key=key)
    for name in value:
        if not isinstance(name, str) or not SIDE_NAME.fullmatch(name):
            raise SceneError(
                f"{key}: side name {name!r} is not an identifier; use letters, digits, _ and - only", key=key
            )
    return tuple(value)


def _box(spec: dict) -> Box:
    unknown = sorted(set(spec) - {"box", "sides"})
    if unknown:
        raise SceneError(
            f"domain.{unknown[0]}: unknown key; a box domain has box and sides", key=f"domain.{unknown[0]}"
        )
    try:
        corners = np.asarray(spec["box"], dtype=float)
    except (TypeError, ValueError):
        corners = None
    if corners is None or corners.shape != (2, 3) or not np.isfinite(corners).all():
        raise SceneError("domain.box: give two corners [[x0, y0, z0], [x1, y1, z1]] (finite numbers)", key="domain.box")
    thin = np.flatnonzero(corners[1] <= corners[0])
    if thin.size:
        axis = "xyz"[thin[0]]
        hi, lo = corners[1, thin[0]], corners[0, thin[0]]
        raise SceneError(
            f"domain.box: {axis}1 = {hi:g} is not above {axis}0 = {lo:g}; "
            "give the lower corner first and a positive size along x, y and z",
            key="domain.box",
        )
    sides = _names(
        spec.get("sides", list(BOX_SIDES)), 6, "domain.sides", "the faces xmin, xmax, ymin, ymax, zmin, zmax"
    )
    return Box(tuple(corners[0].tolist()), tuple(corners[1].tolist()), sides)


def _extruded(spec: dict) -> Extruded:
    ext = spec["extrude"]
    if not isinstance(ext, dict):
        raise SceneError("domain.extrude: give {depth: D, ends: [front, back]}", key="domain.extrude")
    unknown = sorted(set(ext) - {"depth", "ends"})
    if unknown:
        raise SceneError(
            f"domain.extrude.{unknown[0]}: unknown key; valid keys: depth, ends", key=f"domain.extrude.{unknown[0]}"
        )
    if "depth" not in ext:
        raise SceneError(
            "domain.extrude.depth is missing; give the extrusion depth along z", key="domain.extrude.depth"
        )
    try:
        depth = float(ext["depth"])
    except (TypeError, ValueError):
        depth = float("nan")
    if not (math.isfinite(depth) and depth > 0) or isinstance(ext["depth"], bool):
        raise SceneError(f"domain.extrude.depth = {ext['depth']!r}: give a positive number", key="domain.extrude.depth")
    ends = _names(ext.get("ends", list(DEFAULT_ENDS)), 2, "domain.extrude.ends", "the faces z = 0 and z = depth")
    base = {k: v for k, v in spec.items() if k != "extrude"}
    try:
        domain = domain_from_spec(base)
    except SceneError:
        raise
    except InputError as error:
        raise SceneError(str(error), key=error.key) from None
    return Extruded(domain, depth, ends)


#: the dimension of a parsed solid (any other body, a :class:`~vemkit.config.domain.Domain`: plane)
SOLID_DIMENSION = {Box: 3, Extruded: 3}
#: the parser of a solid ``domain`` mapping by its key
_SOLIDS = {"box": _box, "extrude": _extruded}


def cells_per_length3d(domain, n=None, h=None, cells=None, cells_per_cube: float = 1.0):
    """n (cells per unit length) from exactly one of n, h = 1/n and cells (about n³ x volume x
    ``cells_per_cube`` of them); whole numbers come back as int."""
    return mesh_density(
        n,
        h,
        cells,
        lambda count: (count / (cells_per_cube * domain.volume)) ** (1.0 / 3.0),
        SceneError,
        "discretization.mesh",
    )
