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

``anisotropy = a`` builds the Voronoi diagram of the points with x stretched by ``a`` and maps
it back: the cells are about ``a`` times taller than wide (a < 1: wider than tall).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import shapely
import triangle as shewchuk
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from vemkit.mesh.mesh import Mesh, tag_box_boundary

UNIT_SQUARE = shapely.box(0.0, 0.0, 1.0, 1.0)


def voronoi(n: int, seed: int = 0, lloyd_iterations: int = 30, domain=None, anisotropy: float = 1.0,
            merge_tol: float = 1e-9) -> Mesh:
    """About ``n²`` centroidal Voronoi cells of ``domain`` (a shapely Polygon; default unit square)."""
    n = int(n)
    if n < 1:
        raise ValueError(f"mesh n = {n}: the number of cells per side must be >= 1")
    if lloyd_iterations < 0:
        raise ValueError(f"lloyd_iterations = {lloyd_iterations}: give a number >= 0")
    if not anisotropy > 0:
        raise ValueError(f"anisotropy = {anisotropy}: give a positive stretch factor")
    domain = UNIT_SQUARE if domain is None else shapely.normalize(domain)
    if domain.geom_type != "Polygon" or not domain.is_valid or domain.interiors or domain.area <= 0:
        raise ValueError("domain: give a valid shapely Polygon without holes")
    shapely.prepare(domain)
    count = max(1, int(round(n * n * domain.area)))
    h = float(np.sqrt(domain.area / count))
    points = _random_points(domain, count, np.random.default_rng(seed))
    for _ in range(lloyd_iterations):
        points = _clipped_cells(points, domain, anisotropy, centroids_only=True).centroids
    cells = _clipped_cells(points, domain, anisotropy)
    mesh = _merged_mesh(cells, merge_tol * h)
    meta = {"family": "voronoi", "n": n, "seed": int(seed), "lloyd_iterations": int(lloyd_iterations),
            "anisotropy": float(anisotropy), "merge_tol": float(merge_tol)}
    if domain.equals(UNIT_SQUARE):
        mesh = tag_box_boundary(mesh)
    else:
        meta["domain"] = domain.wkt
        mesh = mesh.with_boundary(boundary=mesh.boundary_edges)
    return Mesh(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, mesh.boundary, meta)


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
    _, centroid = _shoelace(vertices[refs], offsets)

    vertex_in = shapely.contains_xy(domain, vertices[:, 0], vertices[:, 1])
    inside = np.logical_and.reduceat(vertex_in[refs], offsets[:-1])
    if domain.convex_hull.area > domain.area * (1 + 1e-12):  # non-convex: vertices inside is not enough
        candidates = np.flatnonzero(inside)
        inside[candidates] = shapely.contains(domain, _polygons(vertices, offsets, refs, candidates))
    cut = np.flatnonzero(~inside)
    if cut.size == 0:
        return _Cells(vertices, offsets, refs, centroid)

    clipped = shapely.intersection(_polygons(vertices, offsets, refs, cut), domain)
    centroid[cut] = shapely.get_coordinates(shapely.centroid(clipped))
    if centroids_only:
        return _Cells(None, None, None, centroid)
    pieces = shapely.get_parts(clipped)  # several per cell where the domain cuts a cell apart
    pieces = pieces[shapely.get_type_id(pieces) == shapely.GeometryType.POLYGON]
    coords, ring_of = shapely.get_coordinates(shapely.get_exterior_ring(pieces), return_index=True)
    ring_sizes = np.bincount(ring_of, minlength=pieces.size)
    keep = np.ones(coords.shape[0], dtype=bool)
    keep[np.cumsum(ring_sizes) - 1] = False  # the closing repeat of the first coordinate
    coords, piece_sizes = coords[keep], ring_sizes - 1

    kept = np.flatnonzero(inside)
    kept_sizes = sizes[kept]
    kept_refs = refs[np.repeat(offsets[kept], kept_sizes) + _ranges(kept_sizes)]
    pool = np.vstack([vertices, coords])
    clip_refs = vertices.shape[0] + np.arange(coords.shape[0], dtype=np.int64)
    all_sizes = np.concatenate([kept_sizes, piece_sizes])
    all_offsets = np.concatenate([[0], np.cumsum(all_sizes)])
    all_refs = _counter_clockwise(pool, all_offsets, np.concatenate([kept_refs, clip_refs]))
    return _Cells(pool, all_offsets, all_refs, centroid)


def _voronoi_cells(points: np.ndarray, count: int):
    """Voronoi cells of the first ``count`` points (interior to the hull of all points).

    From Shewchuk's Delaunay triangulation: the Voronoi vertices are the triangles' circumcentres
    and cell i lists the circumcentres of the triangles around point i, counter-clockwise (sorted
    by the angle of the triangles' centroids seen from point i, which orders a fan robustly).
    """
    tris = shewchuk.delaunay(points).astype(np.int64)
    a, b, c = points[tris[:, 0]], points[tris[:, 1]], points[tris[:, 2]]
    ab, ac = b - a, c - a
    d = 2.0 * (ab[:, 0] * ac[:, 1] - ab[:, 1] * ac[:, 0])
    nb, nc = (ab**2).sum(axis=1), (ac**2).sum(axis=1)
    centres = a + np.stack([ac[:, 1] * nb - ab[:, 1] * nc, ab[:, 0] * nc - ac[:, 0] * nb], axis=1) / d[:, None]
    corner_point = tris.ravel()
    corner_tri = np.repeat(np.arange(tris.shape[0]), 3)
    real = corner_point < count
    corner_point, corner_tri = corner_point[real], corner_tri[real]
    towards = (a + b + c)[corner_tri] / 3.0 - points[corner_point]
    angle = np.arctan2(towards[:, 1], towards[:, 0]) + np.pi  # in [0, 2π] < 8
    order = np.argsort(corner_point * 8.0 + angle)
    sizes = np.bincount(corner_point, minlength=count)
    return centres, np.concatenate([[0], np.cumsum(sizes)]), corner_tri[order]


def _polygons(vertices, offsets, refs, cells):
    """shapely Polygons of the given cells."""
    sizes = np.diff(offsets)[cells]
    coords = vertices[refs[np.repeat(offsets[cells], sizes) + _ranges(sizes)]]
    ring_offsets = np.concatenate([[0], np.cumsum(sizes)])
    return shapely.from_ragged_array(shapely.GeometryType.POLYGON, coords, (ring_offsets, np.arange(cells.size + 1)))


def _ranges(sizes: np.ndarray) -> np.ndarray:
    """0..s-1 for every s in sizes, concatenated."""
    starts = np.repeat(np.cumsum(sizes) - sizes, sizes)
    return np.arange(int(sizes.sum()), dtype=np.int64) - starts


def _shoelace(coords: np.ndarray, offsets: np.ndarray):
    nxt = np.arange(1, coords.shape[0] + 1)
    nxt[offsets[1:] - 1] = offsets[:-1]
    x, y = coords[:, 0], coords[:, 1]
    cross = x * y[nxt] - x[nxt] * y
    area = 0.5 * np.add.reduceat(cross, offsets[:-1])
    cx = np.add.reduceat((x + x[nxt]) * cross, offsets[:-1]) / (6 * area)
    cy = np.add.reduceat((y + y[nxt]) * cross, offsets[:-1]) / (6 * area)
    return area, np.stack([cx, cy], axis=1)


def _counter_clockwise(pool: np.ndarray, offsets: np.ndarray, refs: np.ndarray) -> np.ndarray:
    """Reverse the vertex order of every clockwise cell."""
    area, _ = _shoelace(pool[refs], offsets)
    sizes = np.diff(offsets)
    local = _ranges(sizes)
    flip = np.repeat(area < 0, sizes)
    source = np.where(flip, np.repeat(offsets[1:], sizes) - 1 - local, np.repeat(offsets[:-1], sizes) + local)
    return refs[source]


def _merged_mesh(cells: _Cells, tol: float) -> Mesh:
    """Merge pool points closer than tol, drop repeats and unused points: a conforming mesh."""
    used = np.unique(cells.refs)
    pairs = cKDTree(cells.pool[used]).query_pairs(tol, output_type="ndarray")
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(used.size, used.size))
    _, component = connected_components(graph, directed=False)
    # every component is represented by its first (lowest) member: scipy's vertices come first
    first = np.full(component.max() + 1, used.size)
    np.minimum.at(first, component, np.arange(used.size))
    vertices = cells.pool[used[first]]
    refs = component[np.searchsorted(used, cells.refs)]

    sizes = np.diff(cells.offsets)
    cell_of = np.repeat(np.arange(sizes.size), sizes)
    nxt = np.arange(1, refs.size + 1)
    nxt[cells.offsets[1:] - 1] = cells.offsets[:-1]
    keep = refs != refs[nxt]
    refs, cell_of = refs[keep], cell_of[keep]
    sizes = np.bincount(cell_of, minlength=sizes.size)
    good = sizes >= 3
    refs = refs[good[cell_of]]
    sizes = sizes[good]
    offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    key = np.sort(np.repeat(np.arange(sizes.size), sizes) * np.int64(vertices.shape[0]) + refs)
    if (key[1:] == key[:-1]).any():
        k = int(key[np.flatnonzero(key[1:] == key[:-1])[0]] // vertices.shape[0])
        raise RuntimeError(f"voronoi: cell {k} pinches to a point after merging close vertices; try another seed")
    present = np.zeros(vertices.shape[0], dtype=bool)
    present[refs] = True
    renumber = np.cumsum(present) - 1
    return Mesh(vertices[present], offsets, renumber[refs], {}, {})
