"""Local refinement of polyhedral meshes with hanging vertices: boxes and tetrahedra split into 8.

A marked cell that is an axis-aligned box (a hexahedron of the grid family, an octree cell, possibly
with hanging vertices already on its faces) becomes the 8 boxes of half its size. Its new vertices
are the 27-point lattice of half steps that is not there yet: the 12 edge midpoints, the 6 face
centres and the body centre (a point shared with a marked neighbour is made once: an edge midpoint is
named by the edge's two corners, a face centre by the side's four corners).

The mesh stays conforming in the VEM sense (docs/reference/files.md):
- a new edge midpoint is inserted between the edge's two corners into every face listing them in a
  row, so every cell around that edge (refined or not) gains it as a hanging vertex;
- a whole side of a marked cell (a face without vertices inside it) is split into its 4 quarter faces,
  and the neighbour across it lists those 4 faces instead of the old one;
- a side already split by smaller neighbours keeps its faces, each going to the child under it.
A child's face is the planar polygon of every vertex on its rectangle's perimeter, in order. All
faces are then stored once (``polyhedral_build.from_face_soup``); boundary faces keep their part's
name (a quarter face the name of the face it comes from).

Tetrahedra follow the same scheme by the red rule (``vemkit.mesh.refine_tetrahedra``). Other cells
(prisms over triangles or polygons, Voronoi polyhedra) are refused in one line naming the families
that refine (``REFINABLE_FAMILIES``; a prism over a rectangle is a box and refines).
``predict_refinement`` counts the cells, vertices and faces of a refinement before it is built.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from vemkit.exceptions import InputError, MeshError
from vemkit.mesh.polyhedral import PolyhedralMesh
from vemkit.mesh.polyhedral_build import from_face_soup
from vemkit.mesh.refine import RefinedMesh
from vemkit.mesh.refine_prisms import plan_prisms, prism_children, split_prism_sides
from vemkit.mesh.refine_tetrahedra import plan_tetrahedra, tetrahedron_children, whole_sides

#: the families whose cells this module splits
REFINABLE_FAMILIES = ("hex", "octree", "tet (box and gmsh tetrahedra)", "the extruded ones over convex polygons")
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


class RefinementCounts(NamedTuple):
    """The sizes of a refinement, predicted before it is built."""

    cells: int
    vertices: int
    faces: int


class _Plan(NamedTuple):
    cells: np.ndarray  # (m,) the marked cells
    lower: np.ndarray  # (m, 3) their boxes (None for tetrahedra and prisms)
    upper: np.ndarray
    lattice: np.ndarray  # (m, 27) vertex id of every half-step lattice point (new ones numbered after old);
    # tetrahedra: (m, 10) corners and edge midpoints; prisms: a list of (6 m_c + 3,) (refine_prisms)
    points: np.ndarray  # (new, 3) coordinates of the new vertices
    sources: list  # groups of (new ids, (k, s) old vertices, optional (k, s) weights; default the mean)
    split_edges: tuple  # (sorted min * N + max keys of the old corner pairs split, their midpoints)
    added_faces: int  # the children's inner faces and the pieces added by splitting whole sides
    kind: str = "box"  # "tet" (vemkit.mesh.refine_tetrahedra: the lattice is 4 corners and 6 midpoints)
    # or "prism" (vemkit.mesh.refine_prisms: a list of lattices, 6 m + 3 points each)


def _marked_cells(mesh, marked) -> np.ndarray:
    marked = np.asarray(marked)
    marked = np.flatnonzero(marked) if marked.dtype == bool else np.unique(marked.astype(np.int64))
    if marked.size and (marked.min() < 0 or marked.max() >= mesh.n_cells):
        raise InputError(f"refine_cells: cell indices must lie in [0, {mesh.n_cells})", key="marked")
    return marked


def _boxes(mesh: PolyhedralMesh, cells: np.ndarray):
    """(lower, upper, owner row, vertex ids) of the marked cells' vertices, or a MeshError naming the
    first one that is not an axis-aligned box."""
    offsets, ids = mesh.cell_vertex_lists
    sizes = offsets[cells + 1] - offsets[cells]
    row = np.repeat(np.arange(cells.size), sizes)
    own = ids[np.repeat(offsets[cells] - np.cumsum(sizes) + sizes, sizes) + np.arange(int(sizes.sum()))]
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
            f"splits the cells of the families {', '.join(REFINABLE_FAMILIES)}"
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
    signed = mesh.cell_faces[
        np.repeat(mesh.cell_offsets[cells] - np.cumsum(sizes) + sizes, sizes) + np.arange(row.size)
    ]
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


def _plan(mesh: PolyhedralMesh, cells: np.ndarray) -> _Plan:
    """The lattice of every marked cell, its new vertices named once (module doc)."""
    n = mesh.n_vertices
    lower, upper, row, own = _boxes(mesh, cells)
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
        unique, inverse = np.unique(ends, axis=0, return_inverse=True) if kind < 2 else (ends, np.arange(at_row.size))
        new_ids = next_id + np.arange(unique.shape[0])
        lattice[at_row, where[at_q]] = new_ids[inverse.ravel()]
        points.append(mesh.vertices[unique].mean(axis=1) if kind < 2 else 0.5 * (lower + upper)[at_row])
        sources.append((new_ids, unique))
        next_id += unique.shape[0]
        if kind == 0:
            split = (unique[:, 0] * np.int64(n) + unique[:, 1], new_ids)
        whole_sides += unique.shape[0] if kind == 1 else 0
    added = 12 * cells.size + 3 * whole_sides
    return _Plan(cells, lower, upper, lattice, np.concatenate(points), sources, split, added)


def _any_plan(mesh: PolyhedralMesh, cells: np.ndarray, curves=None) -> _Plan:
    """The plan of the boxes' rule, else of the tetrahedra's, else of the prisms' (a MeshError naming the
    families that refine)."""
    try:
        return _plan(mesh, cells)
    except MeshError:
        pass
    refinable = ", ".join(REFINABLE_FAMILIES)
    try:
        lattice, points, sources, split, sides = plan_tetrahedra(mesh, cells, refinable)
        return _Plan(cells, None, None, lattice, points, sources, split, 8 * cells.size + 3 * sides, "tet")
    except MeshError:
        lattices, points, sources, split, added, inner = plan_prisms(mesh, cells, refinable, curves)
        return _Plan(cells, None, None, lattices, points, sources, split, added + inner, "prism")


def predict_refinement(mesh: PolyhedralMesh, marked, circles=None) -> RefinementCounts:
    """The cells, vertices and faces of ``refine_cells(mesh, marked)``, without building it."""
    plan = _any_plan(mesh, _marked_cells(mesh, marked), circles)
    m = plan.cells.size
    children = sum(2 * ((lattice.size - 3) // 6) for lattice in plan.lattice) if plan.kind == "prism" else 8 * m
    return RefinementCounts(
        mesh.n_cells - m + children,
        mesh.n_vertices + len(plan.points),
        mesh.n_faces + plan.added_faces,
    )


def _with_midpoints(mesh: PolyhedralMesh, split_edges: tuple):
    """(offsets, vertices) of the faces with every new edge midpoint inserted between its corners."""
    offsets, ids = mesh.face_offsets, mesh.face_vertices
    following = np.arange(1, ids.size + 1, dtype=np.int64)
    following[offsets[1:] - 1] = offsets[:-1]
    n = np.int64(mesh.n_vertices)
    a, b = ids, ids[following]
    keys = np.minimum(a, b) * n + np.maximum(a, b)
    split_keys, mids = split_edges
    order = np.argsort(split_keys)
    split_keys, mids = split_keys[order], mids[order]
    at = np.clip(np.searchsorted(split_keys, keys), 0, max(split_keys.size - 1, 0))
    hit = split_keys[at] == keys if split_keys.size else np.zeros(keys.size, dtype=bool)
    out = np.empty(ids.size + int(hit.sum()), dtype=np.int64)
    position = np.arange(ids.size) + np.concatenate([[0], np.cumsum(hit)[:-1]])
    out[position] = ids
    out[position[hit] + 1] = mids[at[hit]]
    owner = np.repeat(np.arange(mesh.n_faces), np.diff(offsets))
    sizes = np.diff(offsets) + np.bincount(owner, weights=hit, minlength=mesh.n_faces).astype(np.int64)
    return np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64), out


def _perimeter_polygons(ids, t, axis, level, low, high, outward) -> list:
    """Per rectangle r (t[axis_r] = level_r, low_r <= (t[b], t[d]) <= high_r, b, d the next axes): the
    vertices (of ``ids`` at half-step coordinates ``t``) on its perimeter, in order about +axis_r
    (outward_r > 0) or -axis_r. All arguments but ids and t are per rectangle."""
    axis = np.asarray(axis)
    b, d = (axis + 1) % 3, (axis + 2) % 3
    low, high = np.asarray(low, float), np.asarray(high, float)
    tol = LATTICE_TOL
    ta, tb, td = t[:, axis].T, t[:, b].T, t[:, d].T  # (R, k)
    keep = np.abs(ta - np.asarray(level, float)[:, None]) < tol
    keep &= (tb > low[:, :1] - tol) & (tb < high[:, :1] + tol) & (td > low[:, 1:] - tol) & (td < high[:, 1:] + tol)
    on_b = (np.abs(tb - low[:, :1]) < tol) | (np.abs(tb - high[:, :1]) < tol)
    keep &= on_b | (np.abs(td - low[:, 1:]) < tol) | (np.abs(td - high[:, 1:]) < tol)
    centre = 0.5 * (low + high)
    angle = np.where(keep, np.arctan2(td - centre[:, 1:], tb - centre[:, :1]), np.inf)
    order = np.argsort(angle, axis=1)
    counts = keep.sum(axis=1)
    rings = [ids[order[r, : counts[r]]] for r in range(axis.size)]
    return [ring if w > 0 else ring[::-1] for ring, w in zip(rings, outward)]


#: the 12 quarters of the 3 mid-planes of a box (axis, lower corner in the next two axes)
_INNER = np.array([(axis, qb, qd) for axis in range(3) for qb in (0, 1) for qd in (0, 1)])


def _cell_cycles(mesh, c: int, face_offsets, face_vertices, split_faces: dict):
    """(face, outward cycle) of every face of cell c, a split face as its 4 quarters."""
    out = []
    for s in mesh.cell_face_list(c):
        f = int(s if s >= 0 else -s - 1)
        for cycle in split_faces.get(f, [face_vertices[face_offsets[f] : face_offsets[f + 1]]]):
            out.append((f, cycle if s >= 0 else cycle[::-1]))
    return out


def _children(mesh, plan: _Plan, row: int, cycles: list, labels):
    """The outward faces (vertex cycles) and labels of the 8 children of marked cell ``plan.cells[row]``;
    ``cycles``: its (face, outward cycle) with its whole sides already split."""
    flat = np.concatenate([cycle for _, cycle in cycles])
    ids = np.unique(np.concatenate([flat, plan.lattice[row]]))
    x = np.concatenate([mesh.vertices, plan.points])[ids]
    t, _ = _half_steps(x, plan.lower[row], plan.upper[row])
    starts = np.cumsum([0] + [cycle.size for _, cycle in cycles[:-1]])
    sizes = np.array([cycle.size for _, cycle in cycles])
    centres = np.add.reduceat(t[np.searchsorted(ids, flat)], starts, axis=0) / sizes[:, None]
    octant_of = np.floor(np.clip(centres, 0.0, 2.0 - 1e-6)).astype(np.int64)
    inner = _perimeter_polygons(
        ids, t, _INNER[:, 0], np.ones(12), _INNER[:, 1:], _INNER[:, 1:] + 1, np.ones(12, dtype=np.int64)
    )  # turning about +axis: outward for the child below the mid-plane
    out = []
    for o in _LATTICE[_CORNERS] // 2:  # octant (ox, oy, oz) in {0, 1}^3
        child, child_labels = [], []
        for axis in range(3):
            ring = inner[4 * axis + 2 * o[(axis + 1) % 3] + o[(axis + 2) % 3]]
            child.append(ring[::-1] if o[axis] else ring)  # towards the sibling across the mid-plane
            child_labels.append(-1)
        mine = np.flatnonzero((octant_of == o).all(axis=1))
        child.extend(cycles[k][1] for k in mine)
        child_labels.extend(labels[cycles[k][0]] for k in mine)
        out.append((child, child_labels))
    return out


def refine_cells(mesh: PolyhedralMesh, marked, *, max_hanging: int | None = None, circles=None) -> RefinedMesh:
    """Split the marked cells (module doc). ``circles``: the curved pieces of an extruded body's base
    (``vemkit.mesh.curves``; default the base mesh's ``circles``), followed by prisms' new boundary
    vertices; ``max_hanging`` is not supported in 3D yet and must be None."""
    if max_hanging is not None:
        raise InputError(
            "max_hanging: 3D refinement does not limit hanging vertices yet; leave it out", key="max_hanging"
        )
    cells = _marked_cells(mesh, marked)
    plan = _any_plan(mesh, cells, circles)
    face_offsets, face_vertices = _with_midpoints(mesh, plan.split_edges)
    names = list(mesh.boundary)
    labels = np.full(mesh.n_faces, -1, dtype=np.int64)
    for k, name in enumerate(names):
        labels[np.asarray(mesh.boundary[name], dtype=np.int64)] = k
    split = {"box": _split_faces, "tet": _split_by(whole_sides), "prism": _split_by(split_prism_sides)}[plan.kind]
    split_faces = split(mesh, plan, face_offsets, face_vertices)
    x = np.concatenate([mesh.vertices, plan.points])
    row_of = np.full(mesh.n_cells, -1, dtype=np.int64)
    row_of[cells] = np.arange(cells.size)
    cell_sizes, soup, soup_labels, parent = [], [], [], []
    for c in range(mesh.n_cells):
        cycles = _cell_cycles(mesh, c, face_offsets, face_vertices, split_faces)
        for child, child_labels in _pieces(mesh, plan, int(row_of[c]), cycles, labels, x):
            cell_sizes.append(len(child))
            soup.extend(child)
            soup_labels.extend(child_labels)
            parent.append(c)
    meta = dict(mesh.meta, refined_3d=int(mesh.meta.get("refined_3d", 0)) + 1)
    new = from_face_soup(
        x,
        cell_sizes,
        [len(f) for f in soup],
        np.concatenate(soup) if soup else np.zeros(0, np.int64),
        np.asarray(soup_labels, dtype=np.int64),
        names,
        meta,
    )
    return RefinedMesh(new, np.asarray(parent, dtype=np.int64), _prolongation(mesh, plan), cells, np.zeros(0, np.int64))


def _pieces(mesh, plan: _Plan, row: int, cycles: list, labels, x) -> list:
    """(outward faces, labels) of the cells a cell becomes: its children (``row``: its row in the
    plan), or itself with its split faces' pieces (row -1)."""
    if row < 0:
        return [([cycle for _, cycle in cycles], [labels[f] for f, _ in cycles])]
    if plan.kind == "box":
        return _children(mesh, plan, row, cycles, labels)
    rule = tetrahedron_children if plan.kind == "tet" else prism_children
    return rule(mesh, plan.lattice[row], cycles, labels, x)


def _split_faces(mesh, plan: _Plan, face_offsets, face_vertices) -> dict:
    """Old face -> its 4 quarter cycles (as stored) for every whole side of a marked cell."""
    out: dict = {}
    points = np.concatenate([mesh.vertices, plan.points])
    quarters = np.array([(0, 0), (1, 0), (1, 1), (0, 1)])
    done = np.zeros(mesh.n_faces, dtype=bool)  # split already (by the marked cell across)
    for row, c in enumerate(plan.cells):
        signed = mesh.cell_face_list(c)
        faces = np.where(signed >= 0, signed, -signed - 1)
        cycles = [face_vertices[face_offsets[f] : face_offsets[f + 1]] for f in faces]
        flat = np.concatenate(cycles)
        ids = np.unique(np.concatenate([flat, plan.lattice[row]]))
        t, _ = _half_steps(points[ids], plan.lower[row], plan.upper[row])
        tf = t[np.searchsorted(ids, flat)]
        starts = np.cumsum([0] + [cycle.size for cycle in cycles[:-1]])
        span = np.maximum.reduceat(tf, starts, axis=0) - np.minimum.reduceat(tf, starts, axis=0)
        whole = (np.sort(span, axis=1)[:, 1:] > 2 - LATTICE_TOL).all(axis=1)
        whole &= ~done[faces]
        if not whole.any():
            continue
        axis = np.repeat(np.argmin(span[whole], axis=1), 4)
        level = np.round(tf[starts[whole], axis[::4]]).repeat(4)
        normal = np.sign(mesh.face_vector_areas[faces[whole], axis[::4]]).repeat(4)
        low = np.tile(quarters, (int(whole.sum()), 1))
        rings = _perimeter_polygons(ids, t, axis, level, low, low + 1, normal)
        for k, f in enumerate(faces[whole].tolist()):
            out[f] = rings[4 * k : 4 * k + 4]
        done[faces[whole]] = True
    return out


def _split_by(sides_of):
    """The splitter of whole sides by a rule's ``sides_of(mesh, lattice, cell, face_offsets, face_vertices, x)``
    (pairs of a face and its pieces as stored): old face -> its pieces, each face split once."""

    def split(mesh, plan: _Plan, face_offsets, face_vertices) -> dict:
        x = np.concatenate([mesh.vertices, plan.points])
        out: dict = {}
        for row, c in enumerate(plan.cells.tolist()):
            for f, rings in sides_of(mesh, plan.lattice[row], c, face_offsets, face_vertices, x):
                out.setdefault(f, rings)
        return out

    return split


def _prolongation(mesh: PolyhedralMesh, plan: _Plan) -> sp.csr_matrix:
    """(new vertices, old vertices): old ones kept, a new one the mean of the corners it lies between."""
    n = mesh.n_vertices
    rows = [np.arange(n)] + [np.repeat(source[0], source[1].shape[1]) for source in plan.sources]
    cols = [np.arange(n)] + [source[1].ravel() for source in plan.sources]
    vals = [np.ones(n)] + [  # the means of the corners, or the weights given (the prisms' centroids)
        source[2].ravel() if len(source) > 2 else np.full(source[1].size, 1.0 / source[1].shape[1])
        for source in plan.sources
    ]
    shape = (n + plan.points.shape[0], n)
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=shape)
