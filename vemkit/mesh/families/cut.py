"""Cut cells: the Cartesian grid of squares clipped to a domain (``square`` and ``hanging`` on any
domain, docs/reference/files.md).

The grid starts at the lower-left corner of the domain's bounding box, with squares of side
h = 1/n. A square inside the domain stays a square; a square the boundary passes through is
replaced by its intersection with the domain: one polygon per connected piece (a piece that
would enclose a whole hole is cut in two through the hole). Pieces become a conforming mesh
(``polygons.conforming_mesh``: shared points merged, hanging nodes listed by both cells).

Small pieces. The rule: a cell whose area is below ``MERGE_RATIO`` = 1/2 of the area of its own
grid square is merged into the neighbour it shares the longest boundary with (smallest first,
repeated while the merged cell is still below its threshold). So every cell has at least half of
its square's area, and a cell receiving slivers grows to at most about 1.5-2 squares: the ratio of
a cell's area to its largest neighbour's stays above about 1/4 (the benchmark and the tests
measure it).

``hanging``: before cutting, the squares are refined ``levels`` times by quadrisection, either
those touching the side ``contact_side`` or a random ``fraction`` of them (as on the unit square,
``hanging.py``); the pieces of the refined squares are the refined cut cells.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import shapely

from vemkit.config.domain import Domain, PolygonalDomain
from vemkit.mesh.families.polygons import Pieces, conforming_mesh, merge_small_cells, tag_sides, without_holes
from vemkit.mesh.mesh import Mesh

MERGE_RATIO = 0.5
_MERGE_TOL = 1e-9  # points closer than this times the finest square side are one vertex


def cut_squares(domain: Domain, n: float) -> Mesh:
    """The grid of squares of side 1/n clipped to ``domain``, small pieces merged."""
    polygonal = domain.discretize(1.0 / n)
    squares = _grid_squares(polygonal.shape, 1.0 / n, 1)
    mesh = cut_mesh(polygonal, squares, 1.0 / n)
    meta = {"family": "square", "n": n, "merge_ratio": MERGE_RATIO, "domain": domain.to_spec()}
    return replace(mesh, meta=meta)


def cut_hanging(
    domain: Domain, n: float, levels: int, rule: str, seed: int, fraction: float, contact_side: str
) -> Mesh:
    """Squares of side 1/n refined ``levels`` times by ``rule``, clipped to ``domain``."""
    h = 1.0 / n
    unit = 1 << levels
    fine = h / unit
    polygonal = domain.discretize(fine)  # curved sides follow the refinement: chords of the finest squares
    squares = _grid_squares(polygonal.shape, h, unit)
    on_side = polygonal.segments[polygonal.segment_sides == contact_side]
    side = shapely.multilinestrings(polygonal.points[on_side]) if rule == "contact" else None
    rng = np.random.default_rng(seed)
    origin = np.asarray(polygonal.shape.bounds[:2])
    for _ in range(levels):
        if rule == "contact":
            chosen = shapely.intersects(_boxes(squares, origin, fine), side)
        else:
            chosen = np.zeros(squares.shape[0], dtype=bool)
            chosen[rng.choice(squares.shape[0], int(round(fraction * squares.shape[0])), replace=False)] = True
        squares = quadrisect(squares, chosen)
    mesh = cut_mesh(polygonal, squares, fine)
    meta = {"family": "hanging", "n": n, "levels": levels, "rule": rule, "seed": int(seed)}
    meta.update({"fraction": float(fraction)} if rule == "random" else {"contact_side": contact_side})
    meta.update({"merge_ratio": MERGE_RATIO, "domain": domain.to_spec()})
    return replace(mesh, meta=meta)


def quadrisect(squares: np.ndarray, chosen: np.ndarray) -> np.ndarray:
    """Replace every chosen square, in place, by its four children (lower-left, lower-right, upper-right, upper-left)."""
    copies = np.where(chosen, 4, 1)
    out = np.repeat(squares, copies, axis=0)
    child = np.arange(out.shape[0]) - np.repeat(np.cumsum(copies) - copies, copies)
    split = np.repeat(chosen, copies)
    half = out[:, 2] // 2
    dx = np.array([0, 1, 1, 0])[child % 4]
    dy = np.array([0, 0, 1, 1])[child % 4]
    out[split, 0] += (dx * half)[split]
    out[split, 1] += (dy * half)[split]
    out[split, 2] = half[split]
    return out


def _grid_squares(shape, h: float, unit: int) -> np.ndarray:
    """(x0, y0, size) on the fine integer grid (unit fine steps per square) of the squares of side h
    covering the bounding box of ``shape`` that meet ``shape``."""
    x0, y0, x1, y1 = shape.bounds
    nx = max(1, int(np.ceil((x1 - x0) / h - 1e-9)))
    ny = max(1, int(np.ceil((y1 - y0) / h - 1e-9)))
    j, i = np.divmod(np.arange(nx * ny, dtype=np.int64), nx)
    squares = np.stack([i * unit, j * unit, np.full(nx * ny, unit)], axis=1)
    meets = shapely.intersects(shape, _boxes(squares, np.array([x0, y0]), h / unit))
    return squares[meets]


def _boxes(squares: np.ndarray, origin: np.ndarray, fine: float) -> np.ndarray:
    lo = origin + squares[:, :2] * fine
    hi = origin + (squares[:, :2] + squares[:, 2:3]) * fine
    return shapely.box(lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1])


def cut_mesh(polygonal: PolygonalDomain, squares: np.ndarray, fine: float) -> Mesh:
    """The squares (x0, y0, size on the fine grid of step ``fine``) clipped to the domain, as a
    conforming mesh with small cells merged (``MERGE_RATIO``) and every boundary edge named."""
    shape = polygonal.shape
    origin = np.asarray(shape.bounds[:2])
    lo = origin + squares[:, :2] * fine
    hi = origin + (squares[:, :2] + squares[:, 2:3]) * fine
    boxes = shapely.box(lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1])
    boundary = shapely.STRtree(shapely.linestrings(polygonal.points[polygonal.segments]))
    crossed = np.zeros(squares.shape[0], dtype=bool)
    crossed[boundary.query(boxes, predicate="intersects")[0]] = True
    inside = ~crossed & shapely.contains_xy(shape, lo[:, 0], lo[:, 1])
    full = np.flatnonzero(inside)
    cut = np.flatnonzero(crossed)
    parts, parent = shapely.get_parts(shapely.intersection(boxes[cut], shape), return_index=True)
    polygon = shapely.get_type_id(parts) == shapely.GeometryType.POLYGON
    parts, parent = without_holes(parts[polygon], cut[parent[polygon]])
    parts = shapely.normalize(parts)  # a fixed ring start and orientation: reproducible meshes
    coords, ring = shapely.get_coordinates(shapely.get_exterior_ring(parts), return_index=True)
    ring_sizes = np.bincount(ring, minlength=parts.size)
    keep = np.ones(coords.shape[0], dtype=bool)
    keep[np.cumsum(ring_sizes) - 1] = False  # the closing repeat of the first point
    corners = np.stack(
        [lo[full], np.stack([hi[full, 0], lo[full, 1]], 1), hi[full], np.stack([lo[full, 0], hi[full, 1]], 1)], axis=1
    ).reshape(-1, 2)
    pool = np.vstack([corners, coords[keep]])
    sizes = np.concatenate([np.full(full.size, 4), ring_sizes - 1])
    owner = np.concatenate([full, parent])
    kept = []
    mesh = conforming_mesh(
        Pieces(pool, np.concatenate([[0], np.cumsum(sizes)]), np.arange(pool.shape[0])), _MERGE_TOL * fine, kept
    )
    square_area = (squares[owner[kept[0]], 2] * fine) ** 2
    mesh = merge_small_cells(mesh, MERGE_RATIO * square_area)
    return tag_sides(mesh, polygonal)
