"""The box rule of ``vemkit.mesh.refine_polyhedra``, vectorized over the marked boxes.

A marked axis-aligned box (a hexahedron of the grid family, an octree cell, possibly with hanging
vertices already on its faces) becomes the 8 boxes of half its size. Its new vertices are the 27-point
lattice of half steps that is not there yet: the 12 edge midpoints, the 6 face centres and the body
centre (a point shared with a marked neighbour is made once: an edge midpoint is named by the edge's
two corners, a face centre by the side's four corners). A whole side (a face without vertices inside
it) is split into its 4 quarter faces; a side already split by smaller neighbours keeps its faces, each
going to the child under it. A child's face is the planar polygon of every vertex on its rectangle's
perimeter, in order (by angle about the rectangle's centre).

Every step runs on all marked boxes at once over flat arrays (no Python loop over cells): a box's
"pool" is the sorted set of the vertices of its faces and of its lattice, with their coordinates in
half steps of the box (0, 1, 2 on the lattice); a rectangle's polygon is the pool's vertices on its
perimeter sorted by angle.
"""

from __future__ import annotations

import numpy as np

from vemkit.exceptions import MeshError
from vemkit.mesh.polyhedral import PolyhedralMesh
from vemkit.mesh.polyhedral_build import segments
from vemkit.mesh.refine_polyhedra_kernels import rectangle_rings

#: relative tolerance of a vertex on the half-step lattice of a box (in units of half its size)
LATTICE_TOL = 1e-9

_LATTICE = np.stack(np.meshgrid(*[np.arange(3)] * 3, indexing="ij"), axis=-1).reshape(-1, 3)[:, ::-1]
# _LATTICE[9 k + 3 j + i] = (i, j, k): index of a lattice point from its half-step coordinates
_CORNERS = np.array([p for p in range(27) if (_LATTICE[p] != 1).all()])
#: the lattice points of each kind of new vertex (1, 2 or 3 coordinates at the middle) and, per point,
#: the positions in _CORNERS of the box corners it is the mean of
_KINDS = [np.array([p for p in range(27) if (_LATTICE[p] == 1).sum() == k]) for k in (1, 2, 3)]
_ENDS = [
    np.array([np.flatnonzero((np.abs(_LATTICE[_CORNERS] - _LATTICE[p]) <= 1).all(axis=1)) for p in where])
    for where in _KINDS
]
#: the 12 quarters of the 3 mid-planes of a box (axis, lower corner in the next two axes)
_INNER = np.array([(axis, qb, qd) for axis in range(3) for qb in (0, 1) for qd in (0, 1)])
#: the octants of the 8 children (ox, oy, oz), child k = ox + 2 oy + 4 oz
_OCTANTS = _LATTICE[_CORNERS] // 2
#: the quarters of a whole side, in the order of its 4 pieces
_QUARTERS = np.array([(0, 0), (1, 0), (1, 1), (0, 1)])


def cycles_of(offsets: np.ndarray, vertices: np.ndarray, ids: np.ndarray, reverse: np.ndarray):
    """(sizes, flat vertices) of the CSR cycles ``ids``, each reversed where ``reverse``."""
    sizes = offsets[ids + 1] - offsets[ids]
    local = segments(np.zeros(ids.size, dtype=np.int64), sizes)
    flip = np.repeat(reverse, sizes)
    local[flip] = np.repeat(sizes, sizes)[flip] - 1 - local[flip]
    return sizes, vertices[np.repeat(offsets[ids], sizes) + local]


def unique_rows(table: np.ndarray):
    """(the distinct rows of an integer table, in lexicographic order; the row of each), as
    ``np.unique(table, axis=0, return_inverse=True)``."""
    order = np.lexsort(table.T[::-1])
    ordered = table[order]
    new = np.ones(order.size, dtype=bool)
    new[1:] = (ordered[1:] != ordered[:-1]).any(axis=1)
    inverse = np.empty(order.size, dtype=np.int64)
    inverse[order] = np.cumsum(new) - 1
    return ordered[new], inverse


def boxes(mesh: PolyhedralMesh, cells: np.ndarray, refinable: str):
    """(lower, upper, owner row, vertex ids) of the marked cells' vertices, or a MeshError naming the
    first one that is not an axis-aligned box."""
    offsets, ids = mesh.cell_vertex_lists
    sizes = offsets[cells + 1] - offsets[cells]
    row = np.repeat(np.arange(cells.size), sizes)
    own = ids[segments(offsets[cells], sizes)]
    x = mesh.vertices[own]
    starts = np.cumsum(sizes) - sizes
    lower, upper = np.minimum.reduceat(x, starts, axis=0), np.maximum.reduceat(x, starts, axis=0)
    size = upper - lower
    tol = LATTICE_TOL * size.max(axis=1)[row, None]
    on_side = ((np.abs(x - lower[row]) <= tol) | (np.abs(x - upper[row]) <= tol)).any(axis=1)
    normals = np.abs(mesh.face_vector_areas)
    aligned = (normals > 1e-12 * normals.sum(axis=1, keepdims=True)).sum(axis=1) == 1
    face_rows = np.repeat(np.arange(mesh.n_cells), np.diff(mesh.cell_offsets))
    tilted = np.bincount(
        face_rows, weights=~aligned[np.abs(mesh.cell_faces + (mesh.cell_faces < 0))], minlength=mesh.n_cells
    )
    box = np.abs(mesh.cell_volumes[cells] - np.prod(size, axis=1)) <= 1e-9 * np.prod(size, axis=1)
    box &= (tilted[cells] == 0) & (np.bincount(row, weights=~on_side, minlength=cells.size) == 0)
    if not box.all():
        c = int(cells[np.argmin(box)])
        raise MeshError(
            f"cell {c} of the {mesh.meta.get('family', 'given')} mesh is not an axis-aligned box; 3D refinement "
            f"splits the cells of the families {refinable}"
        )
    return lower, upper, row, own


def _half_steps(x, lower, upper):
    """Coordinates in half sizes of the box (0, 1, 2 on the lattice) and whether each is on it."""
    t = 2.0 * (x - lower) / (upper - lower)
    return t, (np.abs(t - np.round(t)) < LATTICE_TOL).all(axis=1)


def _check_face_pieces(mesh: PolyhedralMesh, cells: np.ndarray, lower, upper) -> None:
    """Every face of a marked box is a whole side or lies in one quarter of it; a MeshError otherwise
    (a strip across a mid-plane: the anisotropic hanging vertices of an extruded quadtree)."""
    sizes = mesh.cell_offsets[cells + 1] - mesh.cell_offsets[cells]
    row = np.repeat(np.arange(cells.size), sizes)
    signed = mesh.cell_faces[segments(mesh.cell_offsets[cells], sizes)]
    faces = np.where(signed >= 0, signed, -signed - 1)
    counts = mesh.face_offsets[faces + 1] - mesh.face_offsets[faces]
    owner = np.repeat(row, counts)
    t = 2.0 * (mesh.vertices[mesh.face_vertex_ids(faces)] - lower[owner]) / (upper - lower)[owner]
    starts = np.cumsum(counts) - counts
    low, high = np.minimum.reduceat(t, starts, axis=0), np.maximum.reduceat(t, starts, axis=0)
    across = (low < 1 - LATTICE_TOL) & (high > 1 + LATTICE_TOL)
    whole = (high - low > 2 - LATTICE_TOL).sum(axis=1) == 2
    bad = np.flatnonzero(across.any(axis=1) & ~whole)
    if bad.size:
        raise MeshError(
            f"cell {cells[row[bad[0]]]} has face {faces[bad[0]]} across a mid-plane of its box without being a "
            "whole side (anisotropic hanging vertices, as in an extruded quadtree); 3D refinement splits boxes "
            "whose faces are whole sides or lie in a quarter of one"
        )


def plan_boxes(mesh: PolyhedralMesh, cells: np.ndarray, refinable: str):
    """(lower, upper, lattice (m, 27) vertex ids, new points, sources, split edges, number of whole
    sides) of the marked boxes (``refine_polyhedra._Plan``'s fields; module doc)."""
    n = mesh.n_vertices
    lower, upper, row, own = boxes(mesh, cells, refinable)
    lattice = np.full((cells.size, 27), -1, dtype=np.int64)
    t, on = _half_steps(mesh.vertices[own], lower[row], upper[row])
    p = np.round(t[on]).astype(np.int64)
    lattice[row[on], 9 * p[:, 2] + 3 * p[:, 1] + p[:, 0]] = own[on]
    corners = lattice[:, _CORNERS]
    if (corners < 0).any():
        raise MeshError(f"cell {cells[np.argmax((corners < 0).any(axis=1))]} lacks a corner of its box")
    _check_face_pieces(mesh, cells, lower, upper)
    points, sources, next_id, whole_sides, split = [], [], n, 0, (np.zeros(0, np.int64),) * 2
    for kind, where in enumerate(_KINDS):  # edge midpoints, face centres, body centres
        missing = lattice[:, where] < 0
        at_row, at_q = np.nonzero(missing)
        ends = np.sort(corners[at_row[:, None], _ENDS[kind][at_q]], axis=1)
        unique, inverse = unique_rows(ends) if kind < 2 else (ends, np.arange(at_row.size))
        new_ids = next_id + np.arange(unique.shape[0])
        lattice[at_row, where[at_q]] = new_ids[inverse.ravel()]
        points.append(mesh.vertices[unique].mean(axis=1) if kind < 2 else 0.5 * (lower + upper)[at_row])
        sources.append((new_ids, unique))
        next_id += unique.shape[0]
        if kind == 0:
            split = (unique[:, 0] * np.int64(n) + unique[:, 1], new_ids)
        whole_sides += unique.shape[0] if kind == 1 else 0
    return lower, upper, lattice, np.concatenate(points), sources, split, whole_sides


class _Pools:
    """Per marked box (row), the sorted distinct vertices of the given cycles and of its lattice, and
    their half-step coordinates ``t``; ``find(row, vertex)`` is the position in the pool."""

    def __init__(self, row: np.ndarray, vertex: np.ndarray, lattice, lower, upper, x):
        self.scale, self.rows = np.int64(x.shape[0]), lattice.shape[0]
        rows = np.concatenate([row, np.repeat(np.arange(lattice.shape[0]), lattice.shape[1])])
        keys = np.sort(rows * self.scale + np.concatenate([vertex, lattice.ravel()]))
        self.keys = keys[np.concatenate([[True], keys[1:] != keys[:-1]])[: keys.size]]
        self.row, self.vertex = self.keys // self.scale, self.keys % self.scale
        self.t = 2.0 * (x[self.vertex] - lower[self.row]) / (upper[self.row] - lower[self.row])

    def find(self, row, vertex):
        return np.searchsorted(self.keys, row * self.scale + vertex)


def _rectangle_rings(pools: _Pools, row, axis, level, low, high, outward):
    """(sizes, flat vertices) per rectangle r of box row_r (t[axis_r] = level_r, low_r <= (t[b], t[d])
    <= high_r, b, d the next axes): the pool's vertices on its perimeter, in order about +axis_r
    (outward_r > 0) or -axis_r. All arguments are per rectangle. Runs the Numba kernel."""
    start = np.searchsorted(pools.row, np.arange(pools.rows + 1))
    args = (
        row.astype(np.int64),
        axis.astype(np.int64),
        np.asarray(level, float),
        low,
        high,
        np.asarray(outward, float),
    )
    return rectangle_rings(start, pools.t, pools.vertex, *args, LATTICE_TOL)


def rectangle_rings_numpy(pools: _Pools, row, axis, level, low, high, outward):
    """The numpy twin of ``_rectangle_rings`` (``refine_polyhedra_kernels.rectangle_rings``)."""
    tol, t = LATTICE_TOL, pools.t
    entry, entry_axis = np.nonzero(np.abs(t - np.round(t)) < tol)  # pool entries on a lattice plane
    entry_level = np.round(t[entry, entry_axis]).astype(np.int64)
    plane = (pools.row[entry] * 3 + entry_axis) * 5 + np.clip(entry_level, -1, 3) + 1
    by_plane = np.argsort(plane, kind="stable")
    plane, entry = plane[by_plane], entry[by_plane]
    wanted = (row * 3 + axis) * 5 + np.round(level).astype(np.int64) + 1
    first, last = np.searchsorted(plane, wanted), np.searchsorted(plane, wanted, side="right")
    rect = np.repeat(np.arange(row.size), last - first)
    at = entry[segments(first, last - first)]
    b, d = (axis[rect] + 1) % 3, (axis[rect] + 2) % 3
    tb, td = t[at, b], t[at, d]
    lb, ld, hb, hd = low[rect, 0], low[rect, 1], high[rect, 0], high[rect, 1]
    keep = (tb > lb - tol) & (tb < hb + tol) & (td > ld - tol) & (td < hd + tol)
    on_b = (np.abs(tb - lb) < tol) | (np.abs(tb - hb) < tol)
    keep &= on_b | (np.abs(td - ld) < tol) | (np.abs(td - hd) < tol)
    centre = 0.5 * (low + high)
    angle = np.arctan2(td - centre[rect, 1], tb - centre[rect, 0])
    rect, at, angle = rect[keep], at[keep], angle[keep]
    order = np.lexsort((angle, rect))
    sizes = np.bincount(rect, minlength=row.size)
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    return cycles_of(offsets, pools.vertex[at[order]], np.arange(row.size), outward <= 0)


def split_box_sides(mesh, plan, face_offsets, face_vertices, x):
    """(faces, (sizes, flat vertices, 4 per face) of their quarters, as stored) of the whole sides of
    the marked boxes, each split once (by the first marked box it is a whole side of)."""
    cells = plan.cells
    sizes = mesh.cell_offsets[cells + 1] - mesh.cell_offsets[cells]
    row = np.repeat(np.arange(cells.size), sizes)
    signed = mesh.cell_faces[segments(mesh.cell_offsets[cells], sizes)]
    faces = np.where(signed >= 0, signed, -signed - 1)
    counts, flat = cycles_of(face_offsets, face_vertices, faces, np.zeros(faces.size, dtype=bool))
    pools = _Pools(np.repeat(row, counts), flat, plan.lattice, plan.lower, plan.upper, x)
    tf = pools.t[pools.find(np.repeat(row, counts), flat)]
    starts = np.cumsum(counts) - counts
    span = np.maximum.reduceat(tf, starts, axis=0) - np.minimum.reduceat(tf, starts, axis=0)
    whole = np.flatnonzero((np.sort(span, axis=1)[:, 1:] > 2 - LATTICE_TOL).all(axis=1))
    whole = whole[np.sort(np.unique(faces[whole], return_index=True)[1])]  # the first box of each face
    axis = np.argmin(span[whole], axis=1)
    level = np.round(tf[starts[whole], axis])
    normal = np.sign(mesh.face_vector_areas[faces[whole], axis])
    low = np.tile(_QUARTERS, (whole.size, 1)).astype(float)
    rings = _rectangle_rings(
        pools, row[whole].repeat(4), axis.repeat(4), level.repeat(4), low, low + 1, normal.repeat(4)
    )
    return faces[whole], (*rings, np.full(whole.size, 4, dtype=np.int64))


def box_children(plan, app_row, app_cycle, app_rev, app_label, cycle_offsets, cycle_vertices, x):
    """The children of the marked boxes: (their inner faces as (sizes, flat vertices), 12 per box), and
    per appearance of a child's face, child by child (row, child, cycle or -1 - inner face, reversed,
    label); ``app_*``: the boxes' faces (rows in order) as cycles of the table, whole sides split."""
    sizes, flat = cycles_of(cycle_offsets, cycle_vertices, app_cycle, app_rev)
    owner = np.repeat(app_row, sizes)
    pools = _Pools(owner, flat, plan.lattice, plan.lower, plan.upper, x)
    tf = pools.t[pools.find(owner, flat)]
    centres = np.add.reduceat(tf, np.cumsum(sizes) - sizes, axis=0) / sizes[:, None]
    octant = np.floor(np.clip(centres, 0.0, 2.0 - 1e-6)).astype(np.int64)
    child_of = octant @ np.array([1, 2, 4])
    m = plan.cells.size
    ones = np.ones(12 * m)
    low = np.tile(_INNER[:, 1:], (m, 1)).astype(float)
    inner = _rectangle_rings(pools, np.repeat(np.arange(m), 12), np.tile(_INNER[:, 0], m), ones, low, low + 1, ones)
    # the 3 inner faces of child o (towards its siblings across the mid-planes), turning about +axis
    axis = np.arange(3)
    which = 4 * axis + 2 * _OCTANTS[:, (axis + 1) % 3] + _OCTANTS[:, (axis + 2) % 3]  # (8, 3)
    inner_row = np.repeat(np.arange(m), 24)
    inner_child = np.tile(np.repeat(np.arange(8), 3), m)
    inner_id = 12 * inner_row + np.tile(which.ravel(), m)
    inner_rev = np.tile(_OCTANTS.ravel() == 1, m)
    row = np.concatenate([inner_row, app_row])
    child = np.concatenate([inner_child, child_of])
    order = np.lexsort((np.arange(row.size), child, row))
    cycle = np.concatenate([-1 - inner_id, app_cycle])
    rev = np.concatenate([inner_rev, app_rev])
    label = np.concatenate([np.full(inner_id.size, -1, dtype=np.int64), app_label])
    return inner, (row[order], child[order], cycle[order], rev[order], label[order])
