"""The domain side of the clipped Voronoi family (``voronoi.py``): which cells the boundary may
cross, which side every other cell lies on, and the centroids of clipped cells.

``DomainIndex`` is built once per mesh: the boundary segments (oriented with the domain on their
left) binned on a g x g grid, and for every grid bin that no segment's bounding box touches, the
side of the boundary it lies on (a bin the boundary misses is wholly inside or wholly outside).

``clipped_centroids`` gives the centroid of K = cell ∩ domain for convex counter-clockwise cells
by Green's theorem over the directed pieces (x_i, y_i) -> (x_j, y_j) of K's boundary, with
c = x_i y_j − x_j y_i: |K| = ½ Σ c, ∫_K x = ⅙ Σ (x_i + x_j) c, ∫_K y = ⅙ Σ (y_i + y_j) c. The
pieces: the domain's boundary segments cut to the cell (by its half-planes), and the cell's edges
cut to the domain (at the boundary segments crossing them, from the side of the edge's first end).
Where the crossings along an edge do not lead to the side of its other end (the boundary through a
vertex, round-off) the cell is marked and the caller clips it with shapely; the tests pin the
centroids against shapely's.
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np
import shapely

from vemkit.mesh.families.voronoi_kernels import grid_index, segment_bins
from vemkit.mesh.geometry import bin_boxes


class DomainIndex(NamedTuple):
    """Boundary segments ``ends`` (x0, y0, x1, y1: domain on the left), their bounding boxes,
    the grid (origin, inv = bins per unit length, g) with the segments binned in CSR (ptr, items),
    ``bin_side`` (g² int8: 1 inside, 0 outside, -1 a segment's box touches the bin), ``convex``,
    a shapely STRtree of the segments and the number of coordinates of the shape's rings."""

    shape: object
    ends: np.ndarray
    seg_lo: np.ndarray
    seg_hi: np.ndarray
    origin: np.ndarray
    inv: float
    g: int
    ptr: np.ndarray
    items: np.ndarray
    bin_side: np.ndarray
    convex: bool
    segments: object
    n_coordinates: int


def domain_index(shape, count: int) -> DomainIndex:
    """The index of the (prepared) shapely Polygon ``shape`` for meshes of about ``count`` cells."""
    rings = [shape.exterior, *shape.interiors]
    ends = []
    for ring, outer in zip(rings, [True] + [False] * len(shape.interiors)):
        xy = np.asarray(ring.coords)
        if ring.is_ccw != outer:  # the exterior counter-clockwise, the holes clockwise
            xy = xy[::-1]
        ends.append(np.concatenate([xy[:-1], xy[1:]], axis=1))
    ends = np.ascontiguousarray(np.concatenate(ends))
    seg_lo = np.minimum(ends[:, :2], ends[:, 2:])
    seg_hi = np.maximum(ends[:, :2], ends[:, 2:])
    x0, y0, x1, y1 = shape.bounds
    g = int(min(2048, max(1, np.sqrt(count))))
    origin, inv = np.array([x0, y0]), g / max(x1 - x0, y1 - y0)
    ptr, items = bin_boxes(segment_bins(seg_lo, seg_hi, origin, inv, g), g)
    centre = (np.stack(np.meshgrid(np.arange(g), np.arange(g)), axis=-1).reshape(-1, 2) + 0.5) / inv + origin
    bin_side = shapely.contains_xy(shape, centre[:, 0], centre[:, 1]).astype(np.int8)
    bin_side[np.diff(ptr) > 0] = -1
    convex = not shape.convex_hull.area > shape.area * (1 + 1e-12)
    segments = shapely.STRtree(shapely.linestrings(ends.reshape(-1, 2, 2)))
    return DomainIndex(
        shape,
        ends,
        seg_lo,
        seg_hi,
        origin,
        inv,
        g,
        ptr,
        items,
        bin_side,
        convex,
        segments,
        len(shapely.get_coordinates(shape)),
    )


def side_of_boxes(index: DomainIndex, lo: np.ndarray, near: np.ndarray) -> np.ndarray:
    """For every box (low corners ``lo``) that no boundary segment's box meets (``near`` False),
    wholly on one side of the boundary: True inside the domain (False for the near ones)."""
    side = _box_sides(lo, near, index.bin_side, index.origin, index.inv, index.g, np.asarray(index.shape.bounds))
    ask = np.flatnonzero(side < 0)
    side[ask] = shapely.contains_xy(index.shape, lo[ask, 0], lo[ask, 1])
    return side == 1


@numba.njit(cache=True)
def _box_sides(lo, near, bin_side, origin, inv, g, bounds):
    """Per box: 2 if ``near``, else the side of its low corner: outside the domain's bounds 0,
    else the side of the corner's grid bin (1 inside, 0 outside, -1 the boundary passes the bin)."""
    side = np.empty(lo.shape[0], np.int8)
    for c in range(lo.shape[0]):
        if near[c]:
            side[c] = 2
        elif lo[c, 0] < bounds[0] or lo[c, 1] < bounds[1] or lo[c, 0] > bounds[2] or lo[c, 1] > bounds[3]:
            side[c] = 0
        else:
            side[c] = bin_side[grid_index(lo[c, 1], origin[1], inv, g) * g + grid_index(lo[c, 0], origin[0], inv, g)]
    return side


@numba.njit(cache=True)
def clipped_centroids(vertices, offsets, refs, cells, sites, vertex_in, ends, ptr, items, origin, inv, g, cell_area):
    """Centroids ``(len(cells), 2)`` of cell ∩ domain for the given convex counter-clockwise cells
    (Green's theorem, see the module; the terms relative to the cells' ``sites``, points inside
    them near the domain: a cell on the hull reaches far out) and ``ok``: False where the cell must
    be clipped otherwise (inconsistent crossings, an empty or impossible area)."""
    seen, ts = np.full(ends.shape[0], -1, np.int64), np.empty(ends.shape[0])
    local = np.empty((ends.shape[0], 4))  # the near segments' ends relative to the cell's origin
    out, ok = np.full((cells.shape[0], 2), np.nan), np.zeros(cells.shape[0], np.bool_)
    sums = np.empty(3)  # 2|K|, 6 ∫x, 6 ∫y (relative to the cell's origin)
    for c in range(cells.shape[0]):
        s, m = offsets[cells[c]], offsets[cells[c] + 1] - offsets[cells[c]]
        ox, oy = sites[c, 0], sites[c, 1]
        lx = hx = vertices[refs[s], 0]
        ly = hy = vertices[refs[s], 1]
        for i in range(s, s + m):
            lx, ly = min(lx, vertices[refs[i], 0]), min(ly, vertices[refs[i], 1])
            hx, hy = max(hx, vertices[refs[i], 0]), max(hy, vertices[refs[i], 1])
        n_near = 0
        for j in range(grid_index(ly, origin[1], inv, g), grid_index(hy, origin[1], inv, g) + 1):
            for i in range(grid_index(lx, origin[0], inv, g), grid_index(hx, origin[0], inv, g) + 1):
                for t in range(ptr[j * g + i], ptr[j * g + i + 1]):
                    e = items[t]
                    if (
                        seen[e] != c
                        and min(ends[e, 0], ends[e, 2]) <= hx
                        and lx <= max(ends[e, 0], ends[e, 2])
                        and min(ends[e, 1], ends[e, 3]) <= hy
                        and ly <= max(ends[e, 1], ends[e, 3])
                    ):
                        seen[e] = c
                        local[n_near, 0], local[n_near, 1] = ends[e, 0] - ox, ends[e, 1] - oy
                        local[n_near, 2], local[n_near, 3] = ends[e, 2] - ox, ends[e, 3] - oy
                        n_near += 1
        sums[:] = 0.0
        consistent = True
        for i in range(m):
            a, b = refs[s + i], refs[s + (i + 1) % m]
            consistent &= _edge_inside(
                vertices[a, 0] - ox,
                vertices[a, 1] - oy,
                vertices[b, 0] - ox,
                vertices[b, 1] - oy,
                vertex_in[a],
                vertex_in[b],
                local[:n_near],
                ts,
                sums,
            )
        for q in range(n_near):
            _segment_in_cell(vertices, refs, s, m, local[q], ox, oy, sums)
        area = 0.5 * sums[0]
        if consistent and 0.0 < area <= cell_area[c] * (1.0 + 1e-9):
            out[c, 0], out[c, 1] = ox + sums[1] / (3.0 * sums[0]), oy + sums[2] / (3.0 * sums[0])
            ok[c] = True
    return out, ok


@numba.njit(cache=True)
def _add_piece(x0, y0, x1, y1, sums):
    """Add the Green terms of the directed segment (x0, y0) -> (x1, y1) to sums."""
    cross = x0 * y1 - x1 * y0
    sums[0] += cross
    sums[1] += (x0 + x1) * cross
    sums[2] += (y0 + y1) * cross


@numba.njit(cache=True)
def _edge_inside(ax, ay, bx, by, a_in, b_in, segments, ts, sums):
    """Add the pieces of the cell edge a -> b inside the domain; False if the crossings found do
    not lead from a's side to b's. A segment p q crosses a b when p, q lie on either side of the
    line a b (on it counts as right) and a, b on either side of p q (on it counts as outside)."""
    ex, ey = bx - ax, by - ay
    n = 0
    for e in range(segments.shape[0]):
        px, py, qx, qy = segments[e, 0], segments[e, 1], segments[e, 2], segments[e, 3]
        if (ex * (py - ay) - ey * (px - ax) > 0) == (ex * (qy - ay) - ey * (qx - ax) > 0):
            continue
        fa = (qx - px) * (ay - py) - (qy - py) * (ax - px)
        fb = (qx - px) * (by - py) - (qy - py) * (bx - px)
        if (fa > 0) == (fb > 0):
            continue
        t = fa / (fa - fb)
        k = n  # insertion into the sorted crossings
        while k > 0 and ts[k - 1] > t:
            ts[k] = ts[k - 1]
            k -= 1
        ts[k] = t
        n += 1
    inside, t0 = a_in, 0.0
    for k in range(n + 1):
        t1 = ts[k] if k < n else 1.0
        if inside:
            _add_piece(ax + t0 * ex, ay + t0 * ey, ax + t1 * ex, ay + t1 * ey, sums)
        inside, t0 = inside != (k < n), t1
    return inside == b_in


@numba.njit(cache=True)
def _segment_in_cell(vertices, refs, s, m, segment, ox, oy, sums):
    """Add the piece of the boundary segment (relative to the origin) inside the convex cell
    (Cyrus-Beck: cut by the half-plane left of every edge)."""
    px, py, dx, dy = segment[0], segment[1], segment[2] - segment[0], segment[3] - segment[1]
    t0, t1 = 0.0, 1.0
    for i in range(m):
        ax, ay = vertices[refs[s + i], 0] - ox, vertices[refs[s + i], 1] - oy
        j = s + (i + 1) % m
        bx, by = vertices[refs[j], 0] - ox, vertices[refs[j], 1] - oy
        fp = (bx - ax) * (py - ay) - (by - ay) * (px - ax)
        fq = (bx - ax) * (segment[3] - ay) - (by - ay) * (segment[2] - ax)
        if fp < 0 and fq < 0:
            return
        if fp < 0:
            t0 = max(t0, fp / (fp - fq))
        elif fq < 0:
            t1 = min(t1, fp / (fp - fq))
    if t0 < t1:
        _add_piece(px + t0 * dx, py + t0 * dy, px + t1 * dx, py + t1 * dy, sums)
