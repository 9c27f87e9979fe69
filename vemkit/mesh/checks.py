"""Validation of a polygonal mesh: every way a mesh can be broken, with a one-line message.

``validate_mesh(mesh)`` returns ``None`` for a valid mesh and raises ``MeshError`` naming the
offending cell, vertex or edge, and the fix, for the first problem found. The checks run in
order: arrays, cells (size, indices, repeats, orientation, area, self-intersection), vertices
(duplicates, unused), edges (shared by > 2 cells or traversed twice in the same direction), the
cover (T-junctions, angle sums, non-crossing boundary, winding number) and the named boundary
parts.

Why the cover checks are what they are. Once every edge is shared by at most two cells,
traversed once in each direction, the boundary edges always form closed loops (every vertex has
as many boundary edges leaving as arriving), and the sum of the cells' shoelace areas always
equals the shoelace area enclosed by the boundary edges (interior contributions cancel exactly):
neither can fail any more, and neither sees overlaps. What is checked instead: no vertex inside
another cell's edge (a non-conforming T-junction: hanging nodes must be vertices of both
polygons); the cell angles at every vertex add up to 2π (interior vertex) or to the boundary's
interior angle (boundary vertex with one boundary edge out); boundary edges meet only at shared
end points; and the winding number of the boundary just outside every boundary edge is 0. The
number of cells covering a point equals the boundary's winding number there, so the last two
make it 0 or 1 everywhere: the cells tile the enclosed region exactly once.
"""

from __future__ import annotations

import numba
import numpy as np

from vemkit.exceptions import MeshError
from vemkit.mesh.check_kernels import cell_perimeters, corner_angle_sums, edges_shared_properly, first_repeated_vertex
from vemkit.mesh.close_points import close_pairs, has_close_pair
from vemkit.mesh.geometry import bin_boxes, bounds, extents
from vemkit.mesh.mesh import Mesh


def validate_mesh(mesh: Mesh, tol: float = 1e-12) -> None:
    """Raise ``MeshError`` for the first defect found; ``tol`` is relative to the mesh extent."""
    _check_arrays(mesh)
    v = mesh.vertices
    extent = float(np.max(extents(v))) if v.shape[0] else 1.0
    length_tol = tol * max(extent, np.finfo(float).tiny)
    _check_cells(mesh)
    _check_vertices(mesh, length_tol)
    _check_edges(mesh)
    _check_cover(mesh, length_tol)
    _check_boundary_parts(mesh)


# -- arrays ---------------------------------------------------------------------------------
def _check_arrays(mesh: Mesh) -> None:
    v, off, cv = mesh.vertices, mesh.cell_offsets, mesh.cell_vertices
    if v.ndim != 2 or v.shape[1] != 2:
        raise MeshError(f"vertices have shape {v.shape}; give an (N, 2) array of x, y coordinates")
    bad = np.zeros(0, dtype=np.int64) if np.isfinite(v).all() else np.flatnonzero(~np.isfinite(v).all(axis=1))
    if bad.size:
        raise MeshError(f"vertex {bad[0]} has non-finite coordinates {tuple(v[bad[0]].tolist())}; fix its coordinates")
    if off.ndim != 1 or off.size < 1 or off[0] != 0:
        raise MeshError("cell_offsets must be a 1-D array starting at 0 (CSR offsets, one more than cells)")
    if cv.ndim != 1 or off[-1] != cv.size:
        raise MeshError(f"cell_offsets end at {off[-1]} but there are {cv.size} cell_vertices; make them agree")
    sizes = np.diff(off)
    if (sizes < 0).any():
        k = int(np.flatnonzero(sizes < 0)[0])
        raise MeshError(f"cell_offsets decrease at cell {k} ({off[k]} > {off[k + 1]}); offsets must not decrease")
    if mesh.n_cells == 0:
        raise MeshError("the mesh has no cells; give at least one polygon")
    small = np.flatnonzero(sizes < 3)
    if small.size:
        k = int(small[0])
        raise MeshError(f"cell {k} has {sizes[k]} vertices; a polygon needs at least 3")
    out = np.flatnonzero((cv < 0) | (cv >= v.shape[0]))
    if out.size:
        k = int(np.searchsorted(off, out[0], side="right") - 1)
        raise MeshError(
            f"cell {k} refers to vertex {cv[out[0]]} but vertex indices run from 0 to {v.shape[0] - 1}; "
            "fix its vertex list"
        )


# -- cells ----------------------------------------------------------------------------------
def _check_cells(mesh: Mesh) -> None:
    k, vtx = first_repeated_vertex(mesh.cell_offsets, mesh.cell_vertices)
    if k >= 0:
        raise MeshError(f"cell {k} lists vertex {vtx} more than once; list every vertex of a polygon once")
    k, i, j = _first_self_intersection(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices)
    if k >= 0:
        c = mesh.cell(k)
        m = c.size
        raise MeshError(
            f"cell {k} is self-intersecting: its edges ({c[i]}, {c[(i + 1) % m]}) and "
            f"({c[j]}, {c[(j + 1) % m]}) meet; order its vertices along its boundary"
        )
    perimeter = cell_perimeters(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices)
    area = mesh.cell_areas
    flat = np.abs(area) <= 1e-12 * perimeter**2
    if flat.any():
        k = int(np.flatnonzero(flat)[0])
        raise MeshError(f"cell {k} has zero area (its vertices are collinear); remove it or fix its vertices")
    cw = np.flatnonzero(area < 0)
    if cw.size:
        k = int(cw[0])
        raise MeshError(f"cell {k} is clockwise (signed area {area[k]:.3g}); list its vertices counter-clockwise")


@numba.njit(cache=True)
def _orient(ax, ay, bx, by, cx, cy):
    d = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    if d > 0.0:
        return 1
    if d < 0.0:
        return -1
    return 0


@numba.njit(cache=True)
def _on_segment(ax, ay, bx, by, cx, cy):
    """For c collinear with a-b: does c lie on the closed segment a-b?"""
    return min(ax, bx) <= cx <= max(ax, bx) and min(ay, by) <= cy <= max(ay, by)


@numba.njit(cache=True)
def _segments_meet(ax, ay, bx, by, cx, cy, dx, dy):
    """Do the closed segments a-b and c-d share a point?"""
    o1 = _orient(ax, ay, bx, by, cx, cy)
    o2 = _orient(ax, ay, bx, by, dx, dy)
    o3 = _orient(cx, cy, dx, dy, ax, ay)
    o4 = _orient(cx, cy, dx, dy, bx, by)
    if o1 * o2 < 0 and o3 * o4 < 0:
        return True
    if o1 == 0 and _on_segment(ax, ay, bx, by, cx, cy):
        return True
    if o2 == 0 and _on_segment(ax, ay, bx, by, dx, dy):
        return True
    if o3 == 0 and _on_segment(cx, cy, dx, dy, ax, ay):
        return True
    if o4 == 0 and _on_segment(cx, cy, dx, dy, bx, by):
        return True
    return False


@numba.njit(cache=True)
def _first_self_intersection(vertices, offsets, cell_vertices):
    """First cell in which two non-adjacent edges meet: (cell, i, j) edge starts, or (-1, -1, -1)."""
    for k in range(offsets.size - 1):
        s, m = offsets[k], offsets[k + 1] - offsets[k]
        if m <= 3:
            continue  # a triangle's edges are all adjacent
        for i in range(m):
            a, b = vertices[cell_vertices[s + i]], vertices[cell_vertices[s + (i + 1) % m]]
            for j in range(i + 2, m):
                if i == 0 and j == m - 1:
                    continue
                c, d = vertices[cell_vertices[s + j]], vertices[cell_vertices[s + (j + 1) % m]]
                if _segments_meet(a[0], a[1], b[0], b[1], c[0], c[1], d[0], d[1]):
                    return k, i, j
    return -1, -1, -1


# -- vertices -------------------------------------------------------------------------------
def _check_vertices(mesh: Mesh, length_tol: float) -> None:
    pairs = close_pairs(mesh.vertices, length_tol) if has_close_pair(mesh.vertices, length_tol) else np.zeros((0, 2))
    if pairs.size:
        a, b = sorted(int(x) for x in pairs[np.argmin(pairs.min(axis=1))])
        raise MeshError(
            f"vertices {a} and {b} have the same coordinates {tuple(mesh.vertices[a].tolist())}; merge them into one vertex"
        )
    used = np.bincount(mesh.cell_vertices, minlength=mesh.n_vertices)
    unused = np.flatnonzero(used == 0)
    if unused.size:
        raise MeshError(f"vertex {unused[0]} belongs to no cell; remove it (and renumber)")


# -- edges ----------------------------------------------------------------------------------
def _check_edges(mesh: Mesh) -> None:
    if not edges_shared_properly(mesh.half_edges, mesh.half_edge_edge, mesh.edge_first_half_edges):
        _name_edge_defect(mesh)


def _name_edge_defect(mesh: Mesh) -> None:
    """The edge checks in numpy (``edges_shared_properly`` is their screen): the first edge in more
    than two cells, or the smallest directed pair traversed twice the same way."""
    he, cells = mesh.half_edges, mesh.half_edge_cells
    counts = np.bincount(mesh.half_edge_edge)
    crowded = np.flatnonzero(counts > 2)
    if crowded.size:
        e = int(crowded[0])
        owners = np.unique(cells[mesh.half_edge_edge == e])
        a, b = mesh.edges[e]
        raise MeshError(
            f"edge ({a}, {b}) belongs to {counts[e]} cells {owners.tolist()}; an edge is shared by at most 2 cells"
        )
    # at most two half-edges per edge: its first (the smaller index) and its second, if any
    first = mesh.edge_first_half_edges
    second = np.ones(he.shape[0], dtype=bool)
    second[first] = False
    h1 = np.flatnonzero(second)
    h0 = first[mesh.half_edge_edge[h1]]
    same = np.flatnonzero(he[h0, 0] == he[h1, 0])
    if same.size:
        key = he[h0[same], 0] * np.int64(mesh.n_vertices) + he[h0[same], 1]
        h0, h1 = h0[same], h1[same]
        pick = int(np.argmin(key))  # the smallest directed (a, b) of all, as a sort by it names
        h0, h1 = h0[pick], h1[pick]
        a, b = he[h0]
        raise MeshError(
            f"edge ({a}, {b}) is traversed in the same direction by cells {cells[h0]} and {cells[h1]}; "
            "the cells overlap or one is listed clockwise"
        )


# -- cover ----------------------------------------------------------------------------------
def _check_cover(mesh: Mesh, length_tol: float) -> None:
    v = mesh.vertices
    edges = mesh.edges
    grid = _grid_for(v, edges.shape[0])
    vertex, e = _first_t_junction(v, edges, *grid, length_tol)
    if vertex >= 0:
        k = int(mesh.edge_cells[e, 0])
        raise MeshError(
            f"vertex {vertex} lies inside edge ({edges[e, 0]}, {edges[e, 1]}) of cell {k} without being a vertex "
            f"of it (non-conforming T-junction); insert vertex {vertex} into cell {k} (hanging node)"
        )
    be = mesh.boundary_edges
    _check_angle_sums(mesh, be, np.bincount(be[:, 0], minlength=mesh.n_vertices))
    grid = _grid_for(v, be.shape[0])
    bins, items = _bin_segments(v, be, *grid, length_tol)
    i, j = _first_boundary_crossing(v, be, bins, items, *grid)
    if i >= 0:
        raise MeshError(
            f"boundary edges ({be[i, 0]}, {be[i, 1]}) and ({be[j, 0]}, {be[j, 1]}) cross or overlap; "
            "cells overlap or leave a gap there"
        )
    i = _outside_winding_edge(v, be, length_tol)
    if i >= 0:
        raise MeshError(
            f"the region just outside boundary edge ({be[i, 0]}, {be[i, 1]}) is covered by cells; "
            "some cells lie on top of others"
        )


def _corner_angles(p, v, q):
    """Counter-clockwise angle at v from direction q - v to direction p - v, in [0, 2π)."""
    a, b = q - v, p - v
    ang = np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], (a * b).sum(axis=1))
    return np.where(ang < 0, ang + 2 * np.pi, ang)


def _check_angle_sums(mesh: Mesh, be: np.ndarray, out_deg: np.ndarray) -> None:
    v = mesh.vertices
    total = corner_angle_sums(v, mesh.cell_offsets, mesh.cell_vertices)
    expected = np.full(mesh.n_vertices, 2 * np.pi)
    simple = out_deg[be[:, 0]] == 1
    arrive_from = np.full(mesh.n_vertices, -1, dtype=np.int64)
    arrive_from[be[:, 1]] = be[:, 0]
    b = be[simple]
    expected[b[:, 0]] = _corner_angles(v[arrive_from[b[:, 0]]], v[b[:, 0]], v[b[:, 1]])
    checked = out_deg <= 1
    bad = np.flatnonzero(checked & (np.abs(total - expected) > 1e-8))
    if bad.size:
        x = int(bad[0])
        raise MeshError(
            f"the cells around vertex {x} cover an angle of {total[x]:.6g} rad instead of {expected[x]:.6g}; "
            "cells overlap or leave a gap at that vertex"
        )


def _grid_for(v: np.ndarray, n_segments: int):
    lo, hi = bounds(v)
    size = max(float(np.max(hi - lo)), np.finfo(float).tiny)
    g = int(min(4096, max(1, np.ceil(np.sqrt(n_segments)))))
    return lo, g / size, g


@numba.njit(cache=True)
def _bin_range(x, lo, inv_cell, g):
    i = int((x - lo) * inv_cell)
    return min(max(i, 0), g - 1)


@numba.njit(cache=True)
def _segment_bin_box(v, seg, s, lo, inv_cell, g, pad):
    a, b = v[seg[s, 0]], v[seg[s, 1]]
    i0 = _bin_range(min(a[0], b[0]) - pad, lo[0], inv_cell, g)
    i1 = _bin_range(max(a[0], b[0]) + pad, lo[0], inv_cell, g)
    j0 = _bin_range(min(a[1], b[1]) - pad, lo[1], inv_cell, g)
    j1 = _bin_range(max(a[1], b[1]) + pad, lo[1], inv_cell, g)
    return i0, i1, j0, j1


@numba.njit(cache=True)
def _bin_segments(v, seg, lo, inv_cell, g, pad):
    """CSR of the segments whose (padded) bounding box touches each of the g x g grid bins."""
    boxes = np.empty((seg.shape[0], 4), dtype=np.int64)
    for s in range(seg.shape[0]):
        boxes[s, 0], boxes[s, 1], boxes[s, 2], boxes[s, 3] = _segment_bin_box(v, seg, s, lo, inv_cell, g, pad)
    return bin_boxes(boxes, g)


@numba.njit(cache=True)
def _bin_points(v, lo, inv_cell, g):
    """CSR (ptr, points) of the points in each of the g x g grid bins (points in increasing order)."""
    where = np.empty(v.shape[0], dtype=np.int64)
    ptr = np.zeros(g * g + 1, dtype=np.int64)
    for x in range(v.shape[0]):
        where[x] = _bin_range(v[x, 1], lo[1], inv_cell, g) * g + _bin_range(v[x, 0], lo[0], inv_cell, g)
        ptr[where[x] + 1] += 1
    for b in range(g * g):
        ptr[b + 1] += ptr[b]
    points = np.empty(v.shape[0], dtype=np.int64)
    fill = ptr[:-1].copy()
    for x in range(v.shape[0]):
        points[fill[where[x]]] = x
        fill[where[x]] += 1
    return ptr, points


@numba.njit(cache=True)
def _first_t_junction(v, seg, lo, inv_cell, g, tol):
    """The smallest (vertex, segment) with the vertex within tol of the interior of a segment it is
    not an end of, among the pairs whose vertex lies in a bin of the segment's (tol-padded) bounding
    box; (-1, -1) if none. The points are binned (one bin each), and every segment meets the points
    of its bins."""
    ptr, points = _bin_points(v, lo, inv_cell, g)
    best_x, best_s = -1, -1
    for s in range(seg.shape[0]):
        i0, i1, j0, j1 = _segment_bin_box(v, seg, s, lo, inv_cell, g, tol)
        a, c = v[seg[s, 0]], v[seg[s, 1]]
        dx, dy = c[0] - a[0], c[1] - a[1]
        length = np.sqrt(dx * dx + dy * dy)
        for j in range(j0, j1 + 1):
            for i in range(i0, i1 + 1):
                b = j * g + i
                for t in range(ptr[b], ptr[b + 1]):
                    x = points[t]
                    if seg[s, 0] == x or seg[s, 1] == x or (best_x >= 0 and x >= best_x):
                        continue
                    along = ((v[x, 0] - a[0]) * dx + (v[x, 1] - a[1]) * dy) / length
                    across = abs((v[x, 0] - a[0]) * dy - (v[x, 1] - a[1]) * dx) / length
                    if across <= tol and tol < along < length - tol:
                        best_x, best_s = x, s
    return best_x, best_s


@numba.njit(cache=True)
def _first_boundary_crossing(v, seg, bins, items, lo, inv_cell, g):
    """First pair of boundary segments that meet other than at one shared end point."""
    for b in range(g * g):
        for t in range(bins[b], bins[b + 1]):
            s = items[t]
            a0, a1 = seg[s, 0], seg[s, 1]
            for u in range(t + 1, bins[b + 1]):
                r = items[u]
                c0, c1 = seg[r, 0], seg[r, 1]
                pa, pb, pc, pd = v[a0], v[a1], v[c0], v[c1]
                shared = (a0 == c0) + (a0 == c1) + (a1 == c0) + (a1 == c1)
                if shared >= 2:
                    return s, r
                if shared == 1:
                    # only collinear overlap (a spike doubling back) is wrong at a shared end
                    far_c = c1 if (c0 == a0 or c0 == a1) else c0
                    far_a = a1 if (a0 == c0 or a0 == c1) else a0
                    pf, pa_far = v[far_c], v[far_a]
                    if _orient(pa[0], pa[1], pb[0], pb[1], pf[0], pf[1]) == 0 and _on_segment(
                        pa[0], pa[1], pb[0], pb[1], pf[0], pf[1]
                    ):
                        return s, r
                    if _orient(pc[0], pc[1], pd[0], pd[1], pa_far[0], pa_far[1]) == 0 and _on_segment(
                        pc[0], pc[1], pd[0], pd[1], pa_far[0], pa_far[1]
                    ):
                        return s, r
                    continue
                if _segments_meet(pa[0], pa[1], pb[0], pb[1], pc[0], pc[1], pd[0], pd[1]):
                    return s, r
    return -1, -1


def _outside_winding_edge(v: np.ndarray, be: np.ndarray, length_tol: float) -> int:
    """First boundary edge whose outside has a non-zero winding number, or -1. The rays run along
    the mesh's thinner direction (coordinates turned by -90 degrees when it is wider than tall) and
    meet only the boundary edges binned along them: about B^1.5 work for B boundary edges, also on
    a long thin strip (all pairs: minutes at B = 10^5)."""
    width, height = extents(v) if v.size else (0.0, 0.0)
    w = np.ascontiguousarray(np.stack([v[:, 1], -v[:, 0]], axis=1) if width > height else v)
    grid = _grid_for(w, be.shape[0])
    bins, items = _bin_segments(w, be, *grid, length_tol)
    return _first_edge_with_outside_winding(w, be, bins, items, *grid)


@numba.njit(cache=True)
def _first_edge_with_outside_winding(v, seg, bins, items, lo, inv_cell, g):
    """First boundary edge whose right-hand side (outside) has non-zero winding number: a ray in +x
    from a point just outside it, crossing the edges binned in its row of bins (each counted once,
    in the bin of its crossing)."""
    for s in range(seg.shape[0]):
        a, b = v[seg[s, 0]], v[seg[s, 1]]
        dx, dy = b[0] - a[0], b[1] - a[1]
        px = 0.5 * (a[0] + b[0]) + 1e-6 * dy
        py = 0.5 * (a[1] + b[1]) - 1e-6 * dx
        j = _bin_range(py, lo[1], inv_cell, g)
        wind = 0
        for i in range(_bin_range(px, lo[0], inv_cell, g), g):
            bb = j * g + i
            for t in range(bins[bb], bins[bb + 1]):
                r = items[t]
                c, d = v[seg[r, 0]], v[seg[r, 1]]
                if (c[1] <= py) == (d[1] <= py):
                    continue
                crossing = c[0] + (py - c[1]) * (d[0] - c[0]) / (d[1] - c[1])
                if _bin_range(crossing, lo[0], inv_cell, g) != i:
                    continue
                if c[1] <= py:
                    if _orient(c[0], c[1], d[0], d[1], px, py) > 0:
                        wind += 1
                elif _orient(c[0], c[1], d[0], d[1], px, py) < 0:
                    wind -= 1
        if wind != 0:
            return s
    return -1


# -- boundary parts -------------------------------------------------------------------------
def _check_boundary_parts(mesh: Mesh) -> None:
    n = np.int64(mesh.n_vertices)
    be = mesh.boundary_edges
    forward = be[:, 0] * n + be[:, 1]
    for name, part in mesh.boundary.items():
        if part.shape[0] == 0:
            raise MeshError(f"boundary part '{name}' has no edge; give it edges or remove it")
        if ((part < 0) | (part >= n)).any():
            a, b = part[((part < 0) | (part >= n)).any(axis=1)][0]
            raise MeshError(f"boundary part '{name}' edge ({a}, {b}) refers to a vertex that does not exist")
        missing = ~np.isin(part[:, 0] * n + part[:, 1], forward)
        if missing.any():
            a, b = part[missing][0]
            if np.isin(b * n + a, forward):
                raise MeshError(
                    f"boundary part '{name}' edge ({a}, {b}) runs clockwise; list it as ({b}, {a}) (counter-clockwise)"
                )
            raise MeshError(f"boundary part '{name}' edge ({a}, {b}) is not a boundary edge of the mesh")
