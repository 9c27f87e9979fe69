"""The body a mesh covers (docs/reference/files.md): an outer polygon and holes, every edge with a side name.

A :class:`Domain` is plain data: the outer polygon (counter-clockwise), one side name per outer
edge (edge i runs from corner i to corner i + 1), and holes, each a polygon with one side name per
edge or a circle ``(cx, cy, r)`` with one side name. An outer edge may be an arc (``arcs``, an
extension of docs/reference/files.md, :mod:`vemkit.config.domain_arcs`): ``arcs[i] = (cx, cy)``
makes edge i the shorter arc (less than a half circle) of the circle through its two corners centred at (cx, cy); ``None`` keeps it straight. The arc
bulges away from its centre: outwards when the centre lies on the body's side of the chord.
``domain_from_spec`` builds it from the scene
mapping of docs/reference/files.md (or ``"unit_square"``) and refuses a broken domain with a one-line
``InputError`` whose ``key`` names the entry (``domain.polygon``, ``domain.holes[1]`` ...).

Meshing needs polygons only: ``Domain.discretize(h)`` replaces every circle by the polygon whose
``m = max(8, ceil(2 π r / h))`` vertices lie on the circle (edges of length about h), and every arc
of angle θ by ``max(ceil(8 θ / 2π), ceil(r θ / h))`` chords with their ends on the arc, and returns a
:class:`PolygonalDomain`: the shapely polygon, the boundary segments with their side names, and a
point inside every hole (for Triangle).

The unit square's side names live here, and only here: ``UNIT_SQUARE_SIDE_LINES``.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import shapely

from vemkit.config.domain_arcs import (
    MIN_CIRCLE_VERTICES,
    arc_angles,
    arc_box,
    arc_points,
    arcs_from_spec,
    point_words,
)
from vemkit.exceptions import InputError

#: the sides of the unit square (docs/reference/files.md): name -> (axis, value) of the line x_axis = value it lies on
UNIT_SQUARE_SIDE_LINES = {"left": (0, 0.0), "right": (0, 1.0), "bottom": (1, 0.0), "top": (1, 1.0)}
UNIT_SQUARE_SIDES = tuple(UNIT_SQUARE_SIDE_LINES)
UNIT_SQUARE_CORNERS = ((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0))


def _edge_sides_on_lines(corners, lines) -> tuple:
    """The name of the line (axis, value) each edge corner i -> i+1 lies on."""
    k = len(corners)
    return tuple(
        next(name for name, (axis, value) in lines.items() if corners[i][axis] == value == corners[(i + 1) % k][axis])
        for i in range(k)
    )


UNIT_SQUARE_EDGE_SIDES = _edge_sides_on_lines(UNIT_SQUARE_CORNERS, UNIT_SQUARE_SIDE_LINES)  # bottom, right, top, left
SIDE_NAME = re.compile(r"[A-Za-z0-9_-]+")


@dataclass(frozen=True)
class PolygonHole:
    """A polygonal hole: corners counter-clockwise (normalized), one side name per edge."""

    polygon: tuple
    sides: tuple


@dataclass(frozen=True)
class CircleHole:
    """A circular hole of centre (cx, cy) and radius r; all its edges are the side ``side``."""

    cx: float
    cy: float
    r: float
    side: str

    def polygon(self, h: float) -> np.ndarray:
        """Vertices on the circle, counter-clockwise, edges of length about h (at least 8 of them)."""
        m = max(MIN_CIRCLE_VERTICES, math.ceil(2.0 * math.pi * self.r / h))
        t = 2.0 * np.pi * np.arange(m) / m
        return np.stack([self.cx + self.r * np.cos(t), self.cy + self.r * np.sin(t)], axis=1)


class PolygonalDomain(NamedTuple):
    """A domain with every circle replaced by a polygon: what the mesh families work on.

    ``points`` (P, 2); ``segments`` (S, 2) indices into points, oriented with the body on the left
    (outer boundary counter-clockwise, holes clockwise); ``segment_sides`` (S,) side names;
    ``hole_points`` (H, 2) one point inside every hole; ``shape`` the shapely Polygon.
    """

    points: np.ndarray
    segments: np.ndarray
    segment_sides: np.ndarray
    hole_points: np.ndarray
    shape: shapely.Polygon


@dataclass(frozen=True)
class Domain:
    polygon: tuple = UNIT_SQUARE_CORNERS
    sides: tuple = UNIT_SQUARE_EDGE_SIDES
    holes: tuple = ()
    arcs: tuple = ()  # empty (every outer edge straight) or one centre (cx, cy) or None per edge

    @property
    def side_names(self) -> tuple:
        """Every side name once, in order of appearance (outer edges, then holes)."""
        names = list(self.sides)
        for hole in self.holes:
            names += list(hole.sides) if isinstance(hole, PolygonHole) else [hole.side]
        return tuple(dict.fromkeys(names))

    @property
    def is_unit_square(self) -> bool:
        return self == UNIT_SQUARE

    @property
    def bounds(self) -> tuple:
        """(x0, y0, x1, y1) of the outer boundary, arcs included."""
        p = np.asarray(self.polygon)
        boxes = [(*p.min(axis=0).tolist(), *p.max(axis=0).tolist())]
        k = len(self.polygon)
        boxes += [arc_box(self.polygon[i], self.polygon[(i + 1) % k], c) for i, c in enumerate(self.arcs) if c]
        lo, hi = np.min([b[:2] for b in boxes], axis=0), np.max([b[2:] for b in boxes], axis=0)
        return (*lo.tolist(), *hi.tolist())

    def outer_ring(self, h: float | None) -> tuple:
        """(points (P, 2), side of each edge point i -> i+1): the outer boundary counter-clockwise,
        every arc replaced by chords of about h (``None``: half-degree steps, see ``vemkit.config.domain_arcs.arc_chords``)."""
        corners = np.asarray(self.polygon, dtype=float)
        if not self.arcs:
            return corners, list(self.sides)
        k = corners.shape[0]
        points, sides = [], []
        for i, centre in enumerate(self.arcs):
            inner = (
                np.zeros((0, 2))
                if centre is None
                else arc_points(self.polygon[i], self.polygon[(i + 1) % k], centre, h)
            )
            points += [corners[i : i + 1], inner]
            sides += [self.sides[i]] * (inner.shape[0] + 1)
        return np.concatenate(points), sides

    def discretize(self, h: float) -> PolygonalDomain:
        """The polygonal domain for cells of size h (circles and arcs become chords, see the module doc)."""
        rings = [self.outer_ring(h)]
        inside = []
        for hole in self.holes:
            if isinstance(hole, CircleHole):
                ring = hole.polygon(h)
                rings.append((ring[::-1], [hole.side] * ring.shape[0]))
                inside.append((hole.cx, hole.cy))
            else:
                ring = np.asarray(hole.polygon, dtype=float)
                # reversed (clockwise): edge j runs from corner k-1-j to corner k-2-j, side of edge k-2-j
                k = ring.shape[0]
                rings.append((ring[::-1], [hole.sides[(k - 2 - j) % k] for j in range(k)]))
                p = shapely.Polygon(ring).point_on_surface()
                inside.append((p.x, p.y))
        points = np.concatenate([r for r, _ in rings])
        start = np.cumsum([0] + [r.shape[0] for r, _ in rings])
        segments = np.concatenate(
            [np.stack([np.arange(a, b), np.r_[np.arange(a + 1, b), a]], axis=1) for a, b in zip(start[:-1], start[1:])]
        ).astype(np.int64)
        names = np.array(sum((s for _, s in rings), []), dtype=object)
        shape = shapely.Polygon(rings[0][0], [r for r, _ in rings[1:]])
        return PolygonalDomain(points, segments, names, np.array(inside, dtype=float).reshape(-1, 2), shape)

    def area(self, h: float) -> float:
        """Area of the polygonal domain for cells of size h."""
        return float(self.discretize(h).shape.area)

    @property
    def exact_area(self) -> float:
        """Area of the body with circles as circles and arcs as arcs: each arc adds (bulging out) or
        removes (bulging in) its circular segment r²/2 (θ - sin θ)."""
        area = shapely.Polygon(self.polygon).area
        k = len(self.polygon)
        for i, centre in enumerate(self.arcs):
            if centre is not None:
                a, b = self.polygon[i], self.polygon[(i + 1) % k]
                r, _, dt = arc_angles(a, b, centre)
                out = (b[0] - a[0]) * (centre[1] - a[1]) - (b[1] - a[1]) * (
                    centre[0] - a[0]
                ) > 0  # centre on the body's side
                area += (1.0 if out else -1.0) * 0.5 * r * r * (abs(dt) - math.sin(abs(dt)))
        for hole in self.holes:
            area -= math.pi * hole.r**2 if isinstance(hole, CircleHole) else shapely.Polygon(hole.polygon).area
        return float(area)

    def to_spec(self):
        """The docs/reference/files.md mapping of this domain (``"unit_square"`` for the default): JSON-ready."""
        if self.is_unit_square:
            return "unit_square"
        holes = [
            {"circle": [h.cx, h.cy, h.r], "side": h.side}
            if isinstance(h, CircleHole)
            else {"polygon": [list(p) for p in h.polygon], "sides": list(h.sides)}
            for h in self.holes
        ]
        spec = {"polygon": [list(p) for p in self.polygon], "sides": list(self.sides)}
        if self.arcs:
            spec["arcs"] = [None if c is None else list(c) for c in self.arcs]
        if holes:
            spec["holes"] = holes
        return spec


UNIT_SQUARE = Domain()


def cells_per_length(domain: Domain, n=None, h=None, cells=None, cells_per_square: float = 1.0):
    """The mesh density n (cells per unit length, docs/reference/files.md) from exactly one of n, h (n = 1/h) and
    cells (about that many cells; a family with ``cells_per_square`` cells per n x n square, such
    as triangles with 2, gets n = √(cells / (cells_per_square · area))). Whole numbers come back as int."""
    return mesh_density(n, h, cells, lambda count: math.sqrt(count / (cells_per_square * domain.exact_area)))


def mesh_density(n, h, cells, from_cells, error=InputError, where: str | None = None):
    """n from exactly one of n, h = 1/n and cells (``from_cells(cells) -> n``, the body's own rule);
    whole numbers come back as int. Errors name ``where`` (e.g. ``discretization.mesh``) or "mesh size"."""
    given = [(key, value) for key, value in (("n", n), ("h", h), ("cells", cells)) if value is not None]
    if len(given) != 1:
        named = ", ".join(f"{k} = {v}" for k, v in given) or "none"
        raise error(f"{where or 'mesh size'}: give exactly one of n, h and cells (given: {named})", key=where or "n")
    key, value = given[0]
    try:
        value = float(value)
    except (TypeError, ValueError):
        value = float("nan")
    if not (math.isfinite(value) and value > 0):
        name = f"{where}.{key}" if where else f"mesh size {key}"
        raise error(f"{name} = {given[0][1]!r}: give a positive number", key=f"{where}.{key}" if where else key)
    value = 1.0 / value if key == "h" else from_cells(value) if key == "cells" else value
    near = round(value)
    return int(near) if near >= 1 and abs(value - near) <= 1e-9 * value else value


def domain_from_spec(spec=None) -> Domain:
    """The Domain of a docs/reference/files.md ``domain:`` entry (``None`` or ``"unit_square"``: the unit square)."""
    if spec is None or isinstance(spec, Domain):
        return UNIT_SQUARE if spec is None else spec
    if isinstance(spec, str):
        if spec != "unit_square":
            raise InputError(
                f"domain = {spec!r}: the only named domain is unit_square; give a mapping {{polygon: ..., sides: ...}}",
                key="domain",
            )
        return UNIT_SQUARE
    if not isinstance(spec, dict):
        raise InputError("domain: give unit_square or a mapping {polygon: [[x, y], ...], sides: [...]}", key="domain")
    unknown = sorted(set(spec) - {"polygon", "sides", "holes", "arcs"})
    if unknown:
        raise InputError(
            f"domain.{unknown[0]}: unknown key; valid keys: polygon, sides, arcs, holes", key=f"domain.{unknown[0]}"
        )
    for required in ("polygon", "sides"):
        if required not in spec:
            raise InputError(
                f"domain.{required} is missing; give the outer polygon and one side name per edge",
                key=f"domain.{required}",
            )
    outer = _corners(spec["polygon"], "domain.polygon")
    sides = _side_list(spec["sides"], len(outer), "domain")
    ring = shapely.LinearRing(outer)
    _check_simple(ring, "domain.polygon", "the outer boundary")
    if not ring.is_ccw:
        raise InputError(
            "domain.polygon is clockwise; list its corners counter-clockwise (reverse the list, and its sides)",
            key="domain.polygon",
        )
    arcs = arcs_from_spec(spec.get("arcs"), outer)
    body = Domain(tuple(outer), tuple(sides), (), arcs)
    if arcs:
        curved = shapely.LinearRing(body.outer_ring(None)[0])
        _check_simple(
            curved,
            "domain.arcs",
            "the outer boundary with its arcs",
            "move an arc's centre farther from its edge (flatter arc) or to its other side",
        )
        if not curved.is_ccw:
            raise InputError(
                "domain.arcs: the outer boundary with its arcs is clockwise; move the arc centres "
                "to the other side of their edges",
                key="domain.arcs",
            )
    holes = spec.get("holes") or []
    if not isinstance(holes, list):
        raise InputError(
            "domain.holes: give a list of {circle: [cx, cy, r], side: NAME} or {polygon: [...], sides: [...]}",
            key="domain.holes",
        )
    parsed = tuple(_hole(entry, f"domain.holes[{i}]") for i, entry in enumerate(holes))
    _check_placement(shapely.Polygon(body.outer_ring(None)[0]), parsed)
    return Domain(tuple(outer), tuple(sides), parsed, arcs)


def _corners(value, key: str) -> list:
    try:
        points = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        points = None
    if points is None or points.ndim != 2 or points.shape[1] != 2 or points.shape[0] < 3:
        raise InputError(f"{key}: give a list of at least 3 corners [x, y]", key=key)
    if not np.isfinite(points).all():
        raise InputError(
            f"{key}: corner {int(np.flatnonzero(~np.isfinite(points).all(axis=1))[0])} is not a finite number pair",
            key=key,
        )
    k = points.shape[0]
    for i in range(k):
        a, b = points[i], points[(i + 1) % k]
        if np.array_equal(a, b):
            hint = " (do not repeat the first corner at the end)" if i == k - 1 else ""
            raise InputError(
                f"{key}: edge {i} from {point_words(a)} to {point_words(b)} has zero length; remove the repeated corner{hint}",
                key=key,
            )
    return [(float(x), float(y)) for x, y in points]


def _side_list(names, edges: int, key: str) -> list:
    if not isinstance(names, (list, tuple)) or len(names) != edges:
        count = len(names) if isinstance(names, (list, tuple)) else "no list of"
        raise InputError(
            f"{key}.sides has {count} names but the polygon has {edges} edges; give one name per edge i -> i+1",
            key=f"{key}.sides",
        )
    for name in names:
        _check_name(name, f"{key}.sides")
    return [str(n) for n in names]


def _check_name(name, key: str) -> None:
    if not isinstance(name, str) or not SIDE_NAME.fullmatch(name):
        raise InputError(f"{key}: side name {name!r} is not an identifier; use letters, digits, _ and - only", key=key)


def _check_simple(ring, key: str, what: str, fix: str = "list the corners in order along the boundary") -> None:
    if not ring.is_simple:
        reason = shapely.is_valid_reason(shapely.Polygon(ring))
        where = reason.split("[", 1)[1].rstrip("]") if "[" in reason else "somewhere"
        raise InputError(f"{key}: {what} crosses itself (near {where}); {fix}", key=key)


def _hole(entry, key: str):
    if not isinstance(entry, dict) or ("circle" in entry) == ("polygon" in entry):
        raise InputError(
            f"{key}: give either {{circle: [cx, cy, r], side: NAME}} or {{polygon: [[x, y], ...], sides: [...]}}",
            key=key,
        )
    if "circle" in entry:
        unknown = sorted(set(entry) - {"circle", "side"})
        if unknown:
            raise InputError(f"{key}.{unknown[0]}: unknown key; a circle hole has circle and side", key=key)
        try:
            cx, cy, r = (float(v) for v in entry["circle"])
        except (TypeError, ValueError):
            raise InputError(f"{key}.circle: give [cx, cy, r] (three numbers)", key=f"{key}.circle") from None
        if not all(map(math.isfinite, (cx, cy, r))) or r <= 0:
            raise InputError(f"{key}.circle: radius {r:g} must be a positive finite number", key=f"{key}.circle")
        if "side" not in entry:
            raise InputError(f"{key}.side is missing; name the side of the circle", key=f"{key}.side")
        _check_name(entry["side"], f"{key}.side")
        return CircleHole(cx, cy, r, entry["side"])
    unknown = sorted(set(entry) - {"polygon", "sides"})
    if unknown:
        raise InputError(f"{key}.{unknown[0]}: unknown key; a polygon hole has polygon and sides", key=key)
    corners = _corners(entry["polygon"], f"{key}.polygon")
    sides = _side_list(entry.get("sides"), len(corners), key)
    ring = shapely.LinearRing(corners)
    _check_simple(ring, f"{key}.polygon", "the hole's boundary")
    if not ring.is_ccw:  # either orientation is fine: store counter-clockwise
        k = len(corners)
        corners, sides = corners[::-1], [sides[(k - 2 - j) % k] for j in range(k)]
    return PolygonHole(tuple(corners), tuple(sides))


def _check_placement(outer: shapely.Polygon, holes: tuple) -> None:
    """Every hole strictly inside the body, clear of its boundary and of the other holes."""
    shapes = [
        (shapely.Point(h.cx, h.cy), h.r) if isinstance(h, CircleHole) else (shapely.Polygon(h.polygon), 0.0)
        for h in holes
    ]
    for i, (shape, r) in enumerate(shapes):
        key = f"domain.holes[{i}]"
        if outer.distance(shape) > r:
            raise InputError(f"{key} lies outside the body; move it inside domain.polygon", key=key)
        if not outer.contains_properly(shape) or outer.exterior.distance(shape) <= r:
            raise InputError(f"{key} overlaps the outer boundary; keep every hole strictly inside the body", key=key)
        for j in range(i):
            other, s = shapes[j]
            if shape.distance(other) <= r + s:
                raise InputError(f"{key} overlaps domain.holes[{j}]; holes must not touch", key=key)
