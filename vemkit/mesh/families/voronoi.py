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

Speed (about 100 000 cells in under 3 s, most of it in Triangle): the fans, cells, areas and
bounding boxes come from Numba kernels (``voronoi_kernels``) with the bits of the numpy code they
replaced; only cells whose bounding box meets a boundary segment's are tested exactly, the others
take the side of their grid bin (``voronoi_clip.DomainIndex``); in the Lloyd steps on a domain
with 64 boundary points or more (holes, circles) the centroids of the clipped cells come from
Green's theorem (``voronoi_clip.clipped_centroids``, equal to shapely's up to round-off), on
smaller domains (the unit square) from shapely as before. The unit-square meshes are unchanged
bit for bit.
"""

from __future__ import annotations

from dataclasses import replace
from typing import NamedTuple

import numpy as np
import shapely
import triangle as shewchuk

from vemkit.config.domain import Domain
from vemkit.mesh.families.polygons import merged_mesh, tag_sides, without_holes
from vemkit.mesh.families.voronoi_clip import DomainIndex, clipped_centroids, domain_index, side_of_boxes
from vemkit.mesh.families.voronoi_kernels import all_vertices_in, argsort_fans, boxes_meet_segments, fan_cells, fans
from vemkit.mesh.geometry import areas_centroids, counter_clockwise, ranges
from vemkit.mesh.mesh import Mesh, tag_box_boundary

UNIT_SQUARE = shapely.box(0.0, 0.0, 1.0, 1.0)


def voronoi(
    n: float, seed: int = 0, lloyd_iterations: int = 30, domain=None, anisotropy: float = 1.0, merge_tol: float = 1e-9
) -> Mesh:
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
    index = domain_index(shape, count)
    points = _lloyd(points, index, anisotropy, lloyd_iterations, h)
    cells = _clipped_cells(points, index, anisotropy)
    mesh = merged_mesh(cells, merge_tol * h)
    meta = {
        "family": "voronoi",
        "n": n,
        "seed": int(seed),
        "lloyd_iterations": int(lloyd_iterations),
        "anisotropy": float(anisotropy),
        "merge_tol": float(merge_tol),
    }
    if sides is not None:
        meta["domain"] = domain.to_spec()
        mesh = tag_sides(mesh, sides)
    elif shape.equals(UNIT_SQUARE):
        mesh = tag_box_boundary(mesh)
    else:
        meta["domain"] = shape.wkt
        mesh = mesh.with_boundary(boundary=mesh.boundary_edges)
    return replace(mesh, meta=meta)


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


def _lloyd(points: np.ndarray, index: DomainIndex, anisotropy: float, iterations: int, h: float) -> np.ndarray:
    """``iterations`` Lloyd steps: every point moves to the centroid of its clipped cell.

    The steps visit the points in a spatial order (strips 8 h high, by x within a strip), for local
    memory access only: Triangle's output does not depend on the order of its input points (a test
    pins this) and every cell is computed on its own, so the points come out bit for bit the same."""
    if iterations == 0:
        return points
    x0, y0, x1, y1 = index.shape.bounds
    strip = np.floor((points[:, 1] - y0) / (8.0 * h))
    order = np.argsort(strip * 2.0 * (x1 - x0) + (points[:, 0] - x0))
    moved = points[order]
    for _ in range(iterations):
        moved = _clipped_cells(moved, index, anisotropy, centroids_only=True).centroids
    points = np.empty_like(points)
    points[order] = moved
    return points


class _Cells(NamedTuple):
    """Clipped cells in CSR (offsets, refs) over a point pool (Voronoi vertices, then clip vertices)."""

    pool: np.ndarray | None
    offsets: np.ndarray | None
    refs: np.ndarray | None
    centroids: np.ndarray


def _clipped_cells(points: np.ndarray, index: DomainIndex, anisotropy: float, centroids_only: bool = False) -> _Cells:
    domain = index.shape
    x0, y0, x1, y1 = domain.bounds
    span = max(x1 - x0, y1 - y0) * max(anisotropy, 1.0 / anisotropy)
    cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    far = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=float) * 10.0 * span + [cx * anisotropy, cy]
    vertices, offsets, refs, area, centroid, lo, hi = _voronoi_cells(
        np.vstack([points * [anisotropy, 1.0], far]), points.shape[0], anisotropy
    )
    sizes = np.diff(offsets)
    inside, vertex_in = _inside(index, vertices, offsets, refs, lo, hi)
    cut = np.flatnonzero(~inside)
    if cut.size == 0:
        return _Cells(vertices, offsets, refs, centroid)
    if centroids_only:
        centroid[cut] = _clipped_centroids(index, vertices, offsets, refs, cut, points[cut], vertex_in, area[cut])
        return _Cells(None, None, None, centroid)

    clipped = _clip(_polygons(vertices, offsets, refs, cut), domain)
    centroid[cut] = shapely.get_coordinates(shapely.centroid(clipped))
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


def _inside(index: DomainIndex, vertices, offsets, refs, lo, hi):
    """(inside, vertex_in): the cells (bounding boxes lo, hi) inside the domain, and whether each
    vertex of a cell near the boundary is (contains_xy; False for the other vertices).

    A cell whose bounding box meets no boundary segment's lies wholly on one side (read from the
    domain's grid); a cell near the boundary is inside when its vertices are and, on a non-convex
    domain, no boundary segment passes through it (shapely)."""
    near = boxes_meet_segments(lo, hi, index.seg_lo, index.seg_hi, index.origin, index.inv, index.g)
    inside = side_of_boxes(index, lo, near)
    near = np.flatnonzero(near)
    sizes = np.diff(offsets)[near]
    vertex_in = np.zeros(vertices.shape[0], dtype=bool)
    vertex_in[refs[np.repeat(offsets[near], sizes) + ranges(sizes)]] = True
    ask = np.flatnonzero(vertex_in)
    vertex_in[ask] = shapely.contains_xy(index.shape, vertices[ask, 0], vertices[ask, 1])
    inside[near] = all_vertices_in(offsets, refs, near, vertex_in)
    candidates = near[inside[near]]
    if not index.convex and candidates.size:  # vertices inside is not enough
        hit = index.segments.query(_polygons(vertices, offsets, refs, candidates), predicate="intersects")[0]
        inside[candidates[np.unique(hit)]] = False
    return inside, vertex_in


def _clipped_centroids(index: DomainIndex, vertices, offsets, refs, cut, sites, vertex_in, area) -> np.ndarray:
    """Centroids of the cut cells (generated by ``sites``) clipped to the domain: by shapely on a
    domain with fewer than 64 boundary points (the unit square, whose meshes are pinned bit for
    bit), else by Green's theorem (``clipped_centroids``; the cells it cannot settle by shapely)."""
    if index.n_coordinates < 64:
        return shapely.get_coordinates(shapely.centroid(_clip(_polygons(vertices, offsets, refs, cut), index.shape)))
    centroid, ok = clipped_centroids(
        vertices,
        offsets,
        refs,
        cut,
        sites,
        vertex_in,
        index.ends,
        index.ptr,
        index.items,
        index.origin,
        index.inv,
        index.g,
        area,
    )
    if not ok.all():
        clipped = _clip(_polygons(vertices, offsets, refs, cut[~ok]), index.shape)
        centroid[~ok] = shapely.get_coordinates(shapely.centroid(clipped))
    return centroid


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
    pieces = shapely.intersection(
        domain, shapely.box(corner[:, 0], corner[:, 1], corner[:, 0] + tile, corner[:, 1] + tile)
    )
    out[alone] = shapely.intersection(cells[alone], pieces[which])
    return out


def _voronoi_cells(points: np.ndarray, count: int, anisotropy: float):
    """Voronoi cells of the first ``count`` points (interior to the hull of all points), with x
    divided by ``anisotropy``: (vertices, offsets, refs, area, centroid, lo, hi) with the cells'
    signed areas, centroids and bounding boxes.

    From Shewchuk's Delaunay triangulation: the Voronoi vertices are the triangles' circumcentres
    and cell i lists the circumcentres of the triangles around point i, counter-clockwise (sorted
    by the angle of the triangles' centroids seen from point i, which orders a fan robustly).
    """
    tris = shewchuk.delaunay(points)
    centres, offsets, corner_tri, towards = fans(points, tris, count)
    angle = np.arctan2(towards[1], towards[0]) + np.pi  # in [0, 2π] < 8; numpy's bits
    vertices = centres / [anisotropy, 1.0]
    refs, tied, area, centroid, lo, hi = fan_cells(vertices, offsets, corner_tri, angle)
    if tied:  # two keys of a point are equal (never seen): the twin decides
        refs = argsort_fans(tris, count, angle)
        area, centroid = areas_centroids(vertices[refs], offsets)
        corners = vertices[refs]
        lo, hi = np.minimum.reduceat(corners, offsets[:-1]), np.maximum.reduceat(corners, offsets[:-1])
    return vertices, offsets, refs, area, centroid, lo, hi


def _polygons(vertices, offsets, refs, cells):
    """shapely Polygons of the given cells."""
    sizes = np.diff(offsets)[cells]
    coords = vertices[refs[np.repeat(offsets[cells], sizes) + ranges(sizes)]]
    ring_offsets = np.concatenate([[0], np.cumsum(sizes)])
    return shapely.from_ragged_array(shapely.GeometryType.POLYGON, coords, (ring_offsets, np.arange(cells.size + 1)))
