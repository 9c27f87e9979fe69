"""Centroidal Voronoi meshes, clipped to a polygonal domain (unit square by default).

``voronoi(n, seed)`` starts from ``round(n² · area)`` uniformly random points in the domain
(``numpy.random.default_rng(seed)``), runs ``lloyd_iterations`` Lloyd steps (every point moves to
the centroid of its clipped cell) and returns the clipped cells of the final points.
``lloyd_iterations=0`` gives the raw random Voronoi mesh: cells of very different sizes and
short edges, for stress tests.

Clipping is exact for any simple polygon (shapely), so on a non-convex domain (an L-shape) the
cells at the re-entrant corner come out non-convex; a cell cut into several pieces by the domain
gives one mesh cell per piece. The Voronoi diagram itself comes from Shewchuk's Delaunay
triangulation (package ``triangle``; far faster than Qhull here): cells that lie inside the domain
keep its circumcentres as vertices; clipped cells get their new vertices from shapely. All cell vertices are then
merged by distance (``merge_tol · h``, h the mean cell size), which makes the mesh conforming
and removes edges shorter than that tolerance (they collapse to a point).

Holes (a :class:`~vemkit.config.domain.Domain`; circles as polygons with edges of about 1/n):
a cell is inside when its vertices are and the domain's boundary does not pass through it; a
clipped piece that would enclose a whole hole is cut in two through the hole. Every boundary edge
takes the name of the side it lies on.

``anisotropy = a`` builds the Voronoi diagram of the points with x stretched by ``a`` and maps
it back: the cells are about ``a`` times taller than wide (a < 1: wider than tall).
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np
import shapely
import triangle as shewchuk

from vemkit.mesh.geometry import areas_centroids, bin_boxes, counter_clockwise, ranges
from vemkit.config.domain import Domain
from vemkit.mesh.families.polygons import merged_mesh, tag_sides, without_holes
from vemkit.mesh.mesh import Mesh, tag_box_boundary

UNIT_SQUARE = shapely.box(0.0, 0.0, 1.0, 1.0)


def voronoi(n: float, seed: int = 0, lloyd_iterations: int = 30, domain=None, anisotropy: float = 1.0,
            merge_tol: float = 1e-9) -> Mesh:
    """About ``n²`` centroidal Voronoi cells per unit area of ``domain``.

    ``domain``: a :class:`~vemkit.config.domain.Domain` (holes allowed; boundary parts named by its
    sides), a shapely Polygon without holes (one boundary part ``boundary``) or None (unit square).
    """
    n = int(n) if float(n).is_integer() else float(n)
    if not n > 0:
        raise ValueError(f"mesh n = {n}: the number of cells per unit length must be > 0")
    if lloyd_iterations < 0:
        raise ValueError(f"lloyd_iterations = {lloyd_iterations}: give a number >= 0")
    if not anisotropy > 0:
        raise ValueError(f"anisotropy = {anisotropy}: give a positive stretch factor")
    shape, sides = _domain_shape(domain, n)
    shapely.prepare(shape)
    count = max(1, int(round(n * n * shape.area)))
    h = float(np.sqrt(shape.area / count))
    points = _random_points(shape, count, np.random.default_rng(seed))
    for _ in range(lloyd_iterations):
        points = _clipped_cells(points, shape, anisotropy, centroids_only=True).centroids
    cells = _clipped_cells(points, shape, anisotropy)
    mesh = merged_mesh(cells, merge_tol * h)
    meta = {"family": "voronoi", "n": n, "seed": int(seed), "lloyd_iterations": int(lloyd_iterations),
            "anisotropy": float(anisotropy), "merge_tol": float(merge_tol)}
    if sides is not None:
        meta["domain"] = domain.to_spec()
        mesh = tag_sides(mesh, sides)
    elif shape.equals(UNIT_SQUARE):
        mesh = tag_box_boundary(mesh)
    else:
        meta["domain"] = shape.wkt
        mesh = mesh.with_boundary(boundary=mesh.boundary_edges)
    return Mesh(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, mesh.boundary, meta)


def _domain_shape(domain, n: float):
    """(shapely Polygon, PolygonalDomain or None): the region to mesh and where its sides are.

    A circle becomes a polygon with edges of about h = 1 / n."""
    if isinstance(domain, Domain):
        if domain.is_unit_square:
            return UNIT_SQUARE, None
        polygonal = domain.discretize(1.0 / n)
        return polygonal.shape, polygonal
    shape = UNIT_SQUARE if domain is None else shapely.normalize(domain)
    if shape.geom_type != "Polygon" or not shape.is_valid or shape.interiors or shape.area <= 0:
        raise ValueError("domain: give a vemkit Domain or a valid shapely Polygon without holes")
    return shape, None


def _random_points(domain, count: int, rng) -> np.ndarray:
    x0, y0, x1, y1 = domain.bounds
    found = np.zeros((0, 2))
    while found.shape[0] < count:
        trial = rng.random((2 * count, 2)) * [x1 - x0, y1 - y0] + [x0, y0]
        found = np.vstack([found, trial[shapely.contains_xy(domain, trial[:, 0], trial[:, 1])]])
    return found[:count]


class _Cells(NamedTuple):
    """Clipped cells in CSR (offsets, refs) over a point pool (Voronoi vertices, then clip vertices)."""

    pool: np.ndarray | None
    offsets: np.ndarray | None
    refs: np.ndarray | None
    centroids: np.ndarray


def _clipped_cells(points: np.ndarray, domain, anisotropy: float, centroids_only: bool = False) -> _Cells:
    x0, y0, x1, y1 = domain.bounds
    span = max(x1 - x0, y1 - y0) * max(anisotropy, 1.0 / anisotropy)
    cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    far = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=float) * 10.0 * span + [cx * anisotropy, cy]
    vertices, offsets, refs = _voronoi_cells(np.vstack([points * [anisotropy, 1.0], far]), points.shape[0])
    vertices = vertices / [anisotropy, 1.0]
    sizes = np.diff(offsets)
    _, centroid = areas_centroids(vertices[refs], offsets)

    vertex_in = shapely.contains_xy(domain, vertices[:, 0], vertices[:, 1])
    inside = np.logical_and.reduceat(vertex_in[refs], offsets[:-1])
    if domain.convex_hull.area > domain.area * (1 + 1e-12):  # non-convex: vertices inside is not enough
        inside[_crossed_by_boundary(domain, vertices, offsets, refs, np.flatnonzero(inside))] = False
    cut = np.flatnonzero(~inside)
    if cut.size == 0:
        return _Cells(vertices, offsets, refs, centroid)

    clipped = _clip(_polygons(vertices, offsets, refs, cut), domain)
    centroid[cut] = shapely.get_coordinates(shapely.centroid(clipped))
    if centroids_only:
        return _Cells(None, None, None, centroid)
    pieces = shapely.get_parts(clipped)  # several per cell where the domain cuts a cell apart
    pieces = without_holes(pieces[shapely.get_type_id(pieces) == shapely.GeometryType.POLYGON])
    coords, ring_of = shapely.get_coordinates(shapely.get_exterior_ring(pieces), return_index=True)
    ring_sizes = np.bincount(ring_of, minlength=pieces.size)
    keep = np.ones(coords.shape[0], dtype=bool)
    keep[np.cumsum(ring_sizes) - 1] = False  # the closing repeat of the first coordinate
    coords, piece_sizes = coords[keep], ring_sizes - 1

    kept = np.flatnonzero(inside)
    kept_sizes = sizes[kept]
    kept_refs = refs[np.repeat(offsets[kept], kept_sizes) + ranges(kept_sizes)]
    pool = np.vstack([vertices, coords])
    clip_refs = vertices.shape[0] + np.arange(coords.shape[0], dtype=np.int64)
    all_sizes = np.concatenate([kept_sizes, piece_sizes])
    all_offsets = np.concatenate([[0], np.cumsum(all_sizes)])
    all_refs = counter_clockwise(pool, all_offsets, np.concatenate([kept_refs, clip_refs]))
    return _Cells(pool, all_offsets, all_refs, centroid)


def _clip(cells: np.ndarray, domain) -> np.ndarray:
    """``shapely.intersection(cells, domain)``, faster on a domain with many vertices (holes):
    a cell inside one square tile (16 median cell widths wide) is cut with the domain's part in
    that tile only, the others with the whole domain."""
    if len(shapely.get_coordinates(domain)) < 64 or cells.size < 64:
        return shapely.intersection(cells, domain)
    bounds = shapely.bounds(cells)
    x0, y0 = domain.bounds[:2]
    tile = 16.0 * np.sqrt(np.median((bounds[:, 2] - bounds[:, 0]) * (bounds[:, 3] - bounds[:, 1])))
    lo = np.floor((bounds[:, :2] - [x0, y0]) / tile).astype(np.int64)
    hi = np.floor((bounds[:, 2:] - [x0, y0]) / tile).astype(np.int64)
    alone = (lo == hi).all(axis=1)
    out = np.empty(cells.size, dtype=object)
    out[~alone] = shapely.intersection(cells[~alone], domain)
    tiles, which = np.unique(lo[alone], axis=0, return_inverse=True)
    which = which.ravel()
    corner = tiles * tile + [x0, y0]
    pieces = shapely.intersection(domain, shapely.box(corner[:, 0], corner[:, 1], corner[:, 0] + tile, corner[:, 1] + tile))
    out[alone] = shapely.intersection(cells[alone], pieces[which])
    return out


def _crossed_by_boundary(domain, vertices, offsets, refs, cells) -> np.ndarray:
    """The cells (of those given) that the domain's boundary passes through: cells whose bounding
    box meets a boundary segment's (binned on a grid) are tested exactly with shapely."""
    if cells.size == 0:
        return cells
    rings = [np.asarray(r.coords) for r in (domain.exterior, *domain.interiors)]
    ends = np.concatenate([np.stack([c[:-1], c[1:]], axis=1) for c in rings])
    sizes = np.diff(offsets)[cells]
    xy = vertices[refs[np.repeat(offsets[cells], sizes) + ranges(sizes)]]
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    lo, hi = np.minimum.reduceat(xy, starts), np.maximum.reduceat(xy, starts)
    x0, y0, x1, y1 = domain.bounds
    g = int(min(2048, max(1, np.sqrt(cells.size))))
    inv = g / max(x1 - x0, y1 - y0)
    near = np.flatnonzero(_boxes_meet_segments(lo, hi, ends.min(axis=1), ends.max(axis=1), np.array([x0, y0]), inv, g))
    segments = shapely.STRtree(shapely.linestrings(ends))
    hit = segments.query(_polygons(vertices, offsets, refs, cells[near]), predicate="intersects")[0]
    return cells[near[np.unique(hit)]]


@numba.njit(cache=True)
def _boxes_meet_segments(lo, hi, seg_lo, seg_hi, origin, inv, g):
    """Which boxes [lo, hi] overlap the bounding box of some segment (grid bins of 1/inv)."""
    boxes = np.empty((seg_lo.shape[0], 4), dtype=np.int64)
    for s in range(seg_lo.shape[0]):
        boxes[s, 0] = min(max(int((seg_lo[s, 0] - origin[0]) * inv), 0), g - 1)
        boxes[s, 1] = min(max(int((seg_hi[s, 0] - origin[0]) * inv), 0), g - 1)
        boxes[s, 2] = min(max(int((seg_lo[s, 1] - origin[1]) * inv), 0), g - 1)
        boxes[s, 3] = min(max(int((seg_hi[s, 1] - origin[1]) * inv), 0), g - 1)
    ptr, items = bin_boxes(boxes, g)
    out = np.zeros(lo.shape[0], dtype=np.bool_)
    for c in range(lo.shape[0]):
        i0 = min(max(int((lo[c, 0] - origin[0]) * inv), 0), g - 1)
        i1 = min(max(int((hi[c, 0] - origin[0]) * inv), 0), g - 1)
        j0 = min(max(int((lo[c, 1] - origin[1]) * inv), 0), g - 1)
        j1 = min(max(int((hi[c, 1] - origin[1]) * inv), 0), g - 1)
        for j in range(j0, j1 + 1):
            for i in range(i0, i1 + 1):
                for t in range(ptr[j * g + i], ptr[j * g + i + 1]):
                    s = items[t]
                    if seg_lo[s, 0] <= hi[c, 0] and lo[c, 0] <= seg_hi[s, 0] and \
                            seg_lo[s, 1] <= hi[c, 1] and lo[c, 1] <= seg_hi[s, 1]:
                        out[c] = True
    return out


def _voronoi_cells(points: np.ndarray, count: int):
    """Voronoi cells of the first ``count`` points (interior to the hull of all points).

    From Shewchuk's Delaunay triangulation: the Voronoi vertices are the triangles' circumcentres
    and cell i lists the circumcentres of the triangles around point i, counter-clockwise (sorted
    by the angle of the triangles' centroids seen from point i, which orders a fan robustly).
    """
    tris = shewchuk.delaunay(points).astype(np.int64)
    centres, corner_point, corner_tri, towards = _fans(points, tris, count)
    angle = np.arctan2(towards[:, 1], towards[:, 0]) + np.pi  # in [0, 2π] < 8
    order = np.argsort(corner_point * 8.0 + angle)
    sizes = np.bincount(corner_point, minlength=count)
    return centres, np.concatenate([[0], np.cumsum(sizes)]), corner_tri[order]


@numba.njit(cache=True)
def _fans(points, tris, count):
    """Circumcentres of the triangles and, for every corner at one of the first ``count`` points
    (in triangle order), its point, its triangle and the vector from the point to the triangle's
    centroid. ``fans_reference`` is the same in numpy (bit for bit: the tests compare them)."""
    n_real = 0
    for t in range(tris.shape[0]):
        for k in range(3):
            n_real += tris[t, k] < count
    centres = np.empty((tris.shape[0], 2))
    corner_point = np.empty(n_real, np.int64)
    corner_tri = np.empty(n_real, np.int64)
    towards = np.empty((n_real, 2))
    r = 0
    for t in range(tris.shape[0]):
        ax, ay = points[tris[t, 0], 0], points[tris[t, 0], 1]
        bx, by = points[tris[t, 1], 0], points[tris[t, 1], 1]
        cx, cy = points[tris[t, 2], 0], points[tris[t, 2], 1]
        abx, aby, acx, acy = bx - ax, by - ay, cx - ax, cy - ay
        d = 2.0 * (abx * acy - aby * acx)
        nb = abx * abx + aby * aby
        nc = acx * acx + acy * acy
        centres[t, 0] = ax + (acy * nb - aby * nc) / d
        centres[t, 1] = ay + (abx * nc - acx * nb) / d
        gx, gy = (ax + bx + cx) / 3.0, (ay + by + cy) / 3.0
        for k in range(3):
            p = tris[t, k]
            if p < count:
                corner_point[r], corner_tri[r] = p, t
                towards[r, 0], towards[r, 1] = gx - points[p, 0], gy - points[p, 1]
                r += 1
    return centres, corner_point, corner_tri, towards


def fans_reference(points, tris, count):
    """The numpy twin of ``_fans``."""
    a, b, c = points[tris[:, 0]], points[tris[:, 1]], points[tris[:, 2]]
    ab, ac = b - a, c - a
    d = 2.0 * (ab[:, 0] * ac[:, 1] - ab[:, 1] * ac[:, 0])
    nb, nc = (ab**2).sum(axis=1), (ac**2).sum(axis=1)
    centres = a + np.stack([ac[:, 1] * nb - ab[:, 1] * nc, ab[:, 0] * nc - ac[:, 0] * nb], axis=1) / d[:, None]
    corner_point = tris.ravel()
    corner_tri = np.repeat(np.arange(tris.shape[0]), 3)
    real = corner_point < count
    corner_point, corner_tri = corner_point[real], corner_tri[real]
    return centres, corner_point, corner_tri, (a + b + c)[corner_tri] / 3.0 - points[corner_point]


def _polygons(vertices, offsets, refs, cells):
    """shapely Polygons of the given cells."""
    sizes = np.diff(offsets)[cells]
    coords = vertices[refs[np.repeat(offsets[cells], sizes) + ranges(sizes)]]
    ring_offsets = np.concatenate([[0], np.cumsum(sizes)])
    return shapely.from_ragged_array(shapely.GeometryType.POLYGON, coords, (ring_offsets, np.arange(cells.size + 1)))


