"""From polygon pieces to a conforming mesh, and side names on any domain.

Families that cut shapes with shapely (clipped Voronoi cells, cut squares) get polygons whose
shared corners were computed separately and may differ in the last bits. ``conforming_mesh``
merges points closer than a tolerance, drops repeated points, inserts every vertex that lies on
another cell's edge into that edge (hanging nodes: docs/reference/mathematics.md wants them listed by both cells) and
orients every cell counter-clockwise. ``tag_sides`` names every boundary edge after the domain
segment it lies on; ``merge_small_cells`` joins cells below an area threshold to a neighbour.
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np
import shapely
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from vemkit.config.domain import PolygonalDomain
from vemkit.mesh.close_points import close_pairs
from vemkit.mesh.geometry import bin_boxes, counter_clockwise
from vemkit.mesh.mesh import Mesh


class Pieces(NamedTuple):
    """Polygons in CSR (offsets, refs) over a point pool (refs index pool rows)."""

    pool: np.ndarray
    offsets: np.ndarray
    refs: np.ndarray


def merged_mesh(cells: Pieces, tol: float, kept: list | None = None) -> Mesh:
    """Merge pool points closer than tol, drop repeats and unused points: a conforming mesh.

    Pieces that collapse to fewer than 3 points are dropped; ``kept`` (a list), if given, receives
    the boolean mask of the pieces that became cells."""
    used = np.flatnonzero(np.bincount(cells.refs, minlength=cells.pool.shape[0]))  # np.unique, faster
    pairs = close_pairs(cells.pool[used], tol)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(used.size, used.size))
    _, component = connected_components(graph, directed=False)
    # every component is represented by its first (lowest) member: earlier pool points win
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
    if kept is not None:
        kept.append(good)
    refs = refs[good[cell_of]]
    sizes = sizes[good]
    offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    key = np.sort(np.repeat(np.arange(sizes.size), sizes) * np.int64(vertices.shape[0]) + refs)
    if (key[1:] == key[:-1]).any():
        k = int(key[np.flatnonzero(key[1:] == key[:-1])[0]] // vertices.shape[0])
        raise RuntimeError(f"cell {k} pinches to a point after merging close vertices; try another seed or size")
    present = np.zeros(vertices.shape[0], dtype=bool)
    present[refs] = True
    renumber = np.cumsum(present) - 1
    return Mesh(vertices[present], offsets, renumber[refs], {}, {})


def conforming_mesh(pieces: Pieces, tol: float, kept: list | None = None) -> Mesh:
    """``merged_mesh``, then every vertex lying inside another cell's edge inserted into it, CCW."""
    mesh = merged_mesh(pieces, tol, kept)
    offsets, cell_vertices = insert_edge_vertices(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, tol)
    return Mesh(mesh.vertices, offsets, counter_clockwise(mesh.vertices, offsets, cell_vertices), {}, {})


def insert_edge_vertices(vertices, offsets, cell_vertices, tol):
    """CSR cells with every vertex within tol of an edge's interior inserted there, in order."""
    lo = vertices.min(axis=0)
    size = max(float(np.max(vertices.max(axis=0) - lo)), np.finfo(float).tiny)
    g = int(min(4096, max(1, np.sqrt(vertices.shape[0]))))
    inv = g / size
    cells = np.minimum(((vertices - lo) * inv).astype(np.int64), g - 1)
    boxes = np.stack([cells[:, 0], cells[:, 0], cells[:, 1], cells[:, 1]], axis=1)
    ptr, items = bin_boxes(boxes, g)
    counts = np.zeros(cell_vertices.size, dtype=np.int64)
    _edge_vertices(vertices, offsets, cell_vertices, ptr, items, lo, inv, g, tol, counts, np.zeros(0, np.int64))
    if not counts.any():
        return offsets, cell_vertices
    starts = np.concatenate([[0], np.cumsum(counts)])
    found = np.empty(starts[-1], dtype=np.int64)
    _edge_vertices(vertices, offsets, cell_vertices, ptr, items, lo, inv, g, tol, starts, found)
    sizes = np.diff(offsets) + np.add.reduceat(counts, offsets[:-1])
    out = np.empty(cell_vertices.size + found.size, dtype=np.int64)
    at = np.arange(cell_vertices.size) + starts[:-1]  # where every old vertex goes
    out[at] = cell_vertices
    extra = np.ones(out.size, dtype=bool)
    extra[at] = False
    out[extra] = found
    return np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64), out


@numba.njit(cache=True)
def _edge_vertices(v, offsets, cv, ptr, items, lo, inv, g, tol, slots, found):
    """Pass 1 (found empty): count, per half-edge, the vertices inside it (slots = counts).
    Pass 2: write them, ordered along the edge, at found[slots[h]:slots[h + 1]]."""
    count_only = found.shape[0] == 0
    for k in range(offsets.shape[0] - 1):
        s, m = offsets[k], offsets[k + 1] - offsets[k]
        for i in range(m):
            a, b = cv[s + i], cv[s + (i + 1) % m]
            ax, ay, dx, dy = v[a, 0], v[a, 1], v[b, 0] - v[a, 0], v[b, 1] - v[a, 1]
            length = np.sqrt(dx * dx + dy * dy)
            i0 = min(max(int((min(ax, ax + dx) - tol - lo[0]) * inv), 0), g - 1)
            i1 = min(max(int((max(ax, ax + dx) + tol - lo[0]) * inv), 0), g - 1)
            j0 = min(max(int((min(ay, ay + dy) - tol - lo[1]) * inv), 0), g - 1)
            j1 = min(max(int((max(ay, ay + dy) + tol - lo[1]) * inv), 0), g - 1)
            n = 0
            for j in range(j0, j1 + 1):
                for ii in range(i0, i1 + 1):
                    bb = j * g + ii
                    for t in range(ptr[bb], ptr[bb + 1]):
                        x = items[t]
                        if x == a or x == b:
                            continue
                        along = ((v[x, 0] - ax) * dx + (v[x, 1] - ay) * dy) / length
                        across = abs((v[x, 0] - ax) * dy - (v[x, 1] - ay) * dx) / length
                        if across <= tol and tol < along < length - tol:
                            if not count_only:  # insertion sort by position along the edge
                                p = slots[s + i] + n
                                while p > slots[s + i]:
                                    y = found[p - 1]
                                    if ((v[y, 0] - ax) * dx + (v[y, 1] - ay) * dy) / length <= along:
                                        break
                                    found[p] = y
                                    p -= 1
                                found[p] = x
                            n += 1
            if count_only:
                slots[s + i] = n


def tag_sides(mesh: Mesh, domain: PolygonalDomain, names=None) -> Mesh:
    """Name every boundary edge after the domain segment its midpoint is nearest to.

    Parts come in the order of ``names`` (default: the domain's side names as they appear);
    a mesh edge farther than 1e-7 x extent from every domain segment is a bug and raises.
    """
    be = mesh.boundary_edges
    v = mesh.vertices
    segments = shapely.linestrings(domain.points[domain.segments])
    midpoints = shapely.points(0.5 * (v[be[:, 0]] + v[be[:, 1]]))
    found, distance = shapely.STRtree(segments).query_nearest(midpoints, return_distance=True, all_matches=False)
    side = np.empty(be.shape[0], dtype=object)
    side[found[0]] = domain.segment_sides[found[1]]
    extent = float(np.max(np.ptp(domain.points, axis=0)))
    if found.shape[1] != be.shape[0] or distance.max(initial=0.0) > 1e-7 * extent:
        raise RuntimeError("a boundary edge of the mesh is not on the domain's boundary")
    order = dict.fromkeys(names if names is not None else domain.segment_sides)
    return mesh.with_boundary(**{name: be[side == name] for name in order if (side == name).any()})


def merge_small_cells(mesh: Mesh, threshold: np.ndarray) -> Mesh:
    """Join every cell whose area is below ``threshold[cell]`` to the neighbour it shares most
    boundary length with, smallest cells first; a joined cell still below its threshold (the
    larger of the two) is joined again. Only cells within two neighbour rings of a small cell
    take part.

    The union of two cells sharing a connected chain of edges is a simple polygon; pairs whose
    union would pinch at a vertex or enclose a hole are skipped (the next neighbour is tried).
    """
    area = mesh.cell_areas.copy()
    small = np.flatnonzero(area < threshold)
    if small.size == 0:
        return mesh
    active = _neighbour_rings(mesh, small, 2)
    cells = {int(k): mesh.cell(k).tolist() for k in active}
    owner = {(a, b): k for k, c in cells.items() for a, b in zip(c, c[1:] + c[:1])}
    limit = threshold.astype(float).copy()
    queue = sorted(small.tolist(), key=lambda k: area[k])
    removed = []
    while queue:
        k = queue.pop(0)
        if k not in cells or area[k] >= limit[k]:
            continue
        for j in _neighbours_by_shared_length(cells[k], owner, mesh.vertices):
            merged = _union(cells[k], cells[j])
            if merged is None:
                continue
            for a, b in zip(merged, merged[1:] + merged[:1]):
                owner[(a, b)] = j
            cells[j] = merged
            del cells[k]
            removed.append(k)
            area[j] += area[k]
            limit[j] = max(limit[j], limit[k])
            if area[j] < limit[j]:
                queue.insert(0, j)
            break
    return _replace_cells(mesh, cells, removed)


def _neighbour_rings(mesh: Mesh, cells: np.ndarray, rings: int) -> np.ndarray:
    inner = mesh.edge_cells[mesh.edge_cells[:, 1] >= 0]
    chosen = np.zeros(mesh.n_cells, dtype=bool)
    chosen[cells] = True
    for _ in range(rings):
        touch = chosen[inner[:, 0]] | chosen[inner[:, 1]]
        chosen[inner[touch].ravel()] = True
    return np.flatnonzero(chosen)


def _replace_cells(mesh: Mesh, cells: dict, removed: list) -> Mesh:
    """The mesh with the cells in ``cells`` replaced by their new vertex lists and ``removed`` gone."""
    changed = np.array(sorted(cells), dtype=np.int64)
    untouched = np.ones(mesh.n_cells, dtype=bool)
    untouched[changed] = False
    untouched[removed] = False
    keep = untouched[mesh.half_edge_cells]
    new_sizes = np.array([len(cells[k]) for k in changed.tolist()], dtype=np.int64)
    owner = np.concatenate([mesh.half_edge_cells[keep], np.repeat(changed, new_sizes)])
    refs = np.concatenate([mesh.cell_vertices[keep], np.concatenate([cells[k] for k in changed.tolist()])])
    order = np.argsort(owner, kind="stable")
    owner, refs = owner[order], refs[order]
    sizes = np.bincount(owner, minlength=mesh.n_cells)
    sizes = sizes[sizes > 0]
    used = np.zeros(mesh.n_vertices, dtype=bool)
    used[refs] = True
    renumber = np.cumsum(used) - 1
    return Mesh(mesh.vertices[used], np.concatenate([[0], np.cumsum(sizes)]), renumber[refs], {}, dict(mesh.meta))


def _neighbours_by_shared_length(cell: list, owner: dict, vertices: np.ndarray) -> list:
    shared = {}
    for a, b in zip(cell, cell[1:] + cell[:1]):
        j = owner.get((b, a))
        if j is not None:
            shared[j] = shared.get(j, 0.0) + float(np.hypot(*(vertices[b] - vertices[a])))
    return sorted(shared, key=lambda j: -shared[j])


def _union(p: list, q: list):
    """The vertex loop of the union of two CCW cells sharing edges, or None if it is not one simple loop."""
    edges_p = set(zip(p, p[1:] + p[:1]))
    edges_q = set(zip(q, q[1:] + q[:1]))
    kept = [(a, b) for a, b in edges_p if (b, a) not in edges_q] + [(a, b) for a, b in edges_q if (b, a) not in edges_p]
    following = {}
    for a, b in kept:
        if a in following:
            return None  # two edges leave a: the union pinches at vertex a
        following[a] = b
    start = next(x for x in p + q if x in following)
    loop = [start]
    while len(loop) <= len(kept):
        nxt = following.get(loop[-1])
        if nxt is None:
            return None
        if nxt == start:
            break
        loop.append(nxt)
    return loop if len(loop) == len(kept) else None


def without_holes(polygons: np.ndarray, parents: np.ndarray | None = None):
    """shapely Polygons with every polygon that has holes cut in two by the vertical line through a
    point of its first hole, until no piece has a hole (a cell must be a simple polygon).

    With ``parents`` (an index per polygon) returns (pieces, the parent of every piece)."""
    index = np.arange(len(polygons)) if parents is None else np.asarray(parents)
    holed = shapely.get_num_interior_rings(polygons) > 0
    if not holed.any():
        return polygons if parents is None else (polygons, index)
    out, out_index = [polygons[~holed]], [index[~holed]]
    for polygon, parent in zip(polygons[holed], index[holed]):
        x = shapely.Polygon(polygon.interiors[0]).point_on_surface().x
        x0, y0, x1, y1 = polygon.bounds
        halves = shapely.intersection(
            polygon, [shapely.box(x0 - 1, y0 - 1, x, y1 + 1), shapely.box(x, y0 - 1, x1 + 1, y1 + 1)]
        )
        parts = shapely.get_parts(halves)
        parts = without_holes(parts[shapely.get_type_id(parts) == shapely.GeometryType.POLYGON])
        out.append(parts)
        out_index.append(np.full(len(parts), parent))
    polygons, index = np.concatenate(out), np.concatenate(out_index)
    return polygons if parents is None else (polygons, index)
