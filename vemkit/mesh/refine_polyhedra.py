"""Local refinement of polyhedral meshes with hanging vertices: axis-aligned boxes split into 8.

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

Other cells (tetrahedra, prisms, Voronoi polyhedra) are refused in one line naming what refines.
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

#: the families whose cells this module splits
REFINABLE_FAMILIES = ("grid (hexahedra)", "octree")
#: relative tolerance of a vertex on the half-step lattice of a box (in units of half its size)
LATTICE_TOL = 1e-9

_LATTICE = np.stack(np.meshgrid(*[np.arange(3)] * 3, indexing="ij"), axis=-1).reshape(-1, 3)[:, ::-1]
# _LATTICE[9 k + 3 j + i] = (i, j, k): index of a lattice point from its half-step coordinates
_CORNERS = np.array([p for p in range(27) if (_LATTICE[p] != 1).all()])


class RefinementCounts(NamedTuple):
    """The sizes of a refinement, predicted before it is built."""

    cells: int
    vertices: int
    faces: int


class _Plan(NamedTuple):
    cells: np.ndarray  # (m,) the marked cells
    lower: np.ndarray  # (m, 3) their boxes
    upper: np.ndarray
    lattice: np.ndarray  # (m, 27) vertex id of every half-step lattice point (new ones numbered after old)
    points: np.ndarray  # (new, 3) coordinates of the new vertices
    sources: list  # per new vertex: the old corners it is the mean of
    split_edges: dict  # (min, max) old corner pair -> new midpoint id
    whole_sides: int  # number of distinct whole faces split into quarters


def _marked_cells(mesh, marked) -> np.ndarray:
    marked = np.asarray(marked)
    marked = np.flatnonzero(marked) if marked.dtype == bool else np.unique(marked.astype(np.int64))
    if marked.size and (marked.min() < 0 or marked.max() >= mesh.n_cells):
        raise InputError(f"refine_cells: cell indices must lie in [0, {mesh.n_cells})", key="marked")
    return marked


def _cell_box(mesh: PolyhedralMesh, c: int):
    """(lower, upper, vertex ids) of cell c, or a MeshError when it is not an axis-aligned box."""
    offsets, ids = mesh.cell_vertex_lists
    own = ids[offsets[c] : offsets[c + 1]]
    x = mesh.vertices[own]
    lower, upper = x.min(axis=0), x.max(axis=0)
    size = upper - lower
    signed = mesh.cell_face_list(c)
    faces = np.where(signed >= 0, signed, -signed - 1)
    normals = mesh.face_vector_areas[faces]
    aligned = (np.abs(normals) > 1e-12 * np.abs(normals).sum(axis=1, keepdims=True)).sum(axis=1) == 1
    on_side = np.isclose(x, lower, rtol=0, atol=LATTICE_TOL * size.max()) | np.isclose(
        x, upper, rtol=0, atol=LATTICE_TOL * size.max()
    )
    box = abs(mesh.cell_volumes[c] - np.prod(size)) <= 1e-9 * np.prod(size)
    if not (aligned.all() and on_side.any(axis=1).all() and box):
        family = mesh.meta.get("family", "this")
        raise MeshError(
            f"cell {c} of the {family} mesh is not an axis-aligned box; 3D refinement splits the cells of "
            f"the families {', '.join(REFINABLE_FAMILIES)}"
        )
    return lower, upper, own


def _half_steps(x, lower, upper):
    """Coordinates in half sizes of the box (0, 1, 2 on the lattice) and whether each is on it."""
    t = 2.0 * (x - lower) / (upper - lower)
    return t, (np.abs(t - np.round(t)) < LATTICE_TOL).all(axis=1)


def _plan(mesh: PolyhedralMesh, cells: np.ndarray) -> _Plan:
    """The lattice of every marked cell, its new vertices named once (module doc)."""
    n = mesh.n_vertices
    lower, upper = np.zeros((cells.size, 3)), np.zeros((cells.size, 3))
    lattice = np.full((cells.size, 27), -1, dtype=np.int64)
    new_of: dict = {}
    sources: list = []
    points: list = []
    for row, c in enumerate(cells):
        lower[row], upper[row], own = _cell_box(mesh, int(c))
        t, on = _half_steps(mesh.vertices[own], lower[row], upper[row])
        p = np.round(t[on]).astype(np.int64)
        lattice[row, 9 * p[:, 2] + 3 * p[:, 1] + p[:, 0]] = own[on]
        corners = lattice[row, _CORNERS]
        if (corners < 0).any():
            raise MeshError(f"cell {c} lacks a corner of its box; 3D refinement splits boxes")
        for q in np.flatnonzero(lattice[row] < 0):
            near = _LATTICE[_CORNERS]
            ends = corners[(np.abs(near - _LATTICE[q]) <= 1).all(axis=1)]  # the corners it is the mean of
            key = tuple(sorted(ends.tolist())) if ends.size < 8 else ("centre", int(c), -1)
            if key not in new_of:
                new_of[key] = n + len(points)
                sources.append(ends)
                points.append(mesh.vertices[ends].mean(axis=0) if ends.size < 8 else 0.5 * (lower[row] + upper[row]))
            lattice[row, q] = new_of[key]
    split_edges = {k: v for k, v in new_of.items() if len(k) == 2}  # the centres' keys have 3 entries
    whole_sides = sum(1 for k in new_of if len(k) == 4)
    pts = np.array(points, dtype=float).reshape(-1, 3)
    return _Plan(cells, lower, upper, lattice, pts, sources, split_edges, whole_sides)


def predict_refinement(mesh: PolyhedralMesh, marked) -> RefinementCounts:
    """The cells, vertices and faces of ``refine_cells(mesh, marked)``, without building it."""
    plan = _plan(mesh, _marked_cells(mesh, marked))
    m = plan.cells.size
    return RefinementCounts(
        mesh.n_cells + 7 * m, mesh.n_vertices + len(plan.points), mesh.n_faces + 12 * m + 3 * plan.whole_sides
    )


def _with_midpoints(mesh: PolyhedralMesh, split_edges: dict):
    """(offsets, vertices) of the faces with every new edge midpoint inserted between its corners."""
    offsets, ids = mesh.face_offsets, mesh.face_vertices
    following = np.arange(1, ids.size + 1, dtype=np.int64)
    following[offsets[1:] - 1] = offsets[:-1]
    n = np.int64(mesh.n_vertices)
    a, b = ids, ids[following]
    keys = np.minimum(a, b) * n + np.maximum(a, b)
    split_keys = np.array([lo * n + hi for lo, hi in split_edges], dtype=np.int64)
    mids = np.array(list(split_edges.values()), dtype=np.int64)
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


def _perimeter_polygon(ids, t, axis, level, low, high, outward):
    """The vertices (of ``ids`` at half-step coordinates ``t``) on the perimeter of the rectangle
    t[axis] = level, low <= t[b], t[d] <= high, in order, turning about +/- axis as ``outward``."""
    b, d = (axis + 1) % 3, (axis + 2) % 3
    tol = LATTICE_TOL
    plane = np.abs(t[:, axis] - level) < tol
    inside = plane & (t[:, b] > low[0] - tol) & (t[:, b] < high[0] + tol)
    inside &= (t[:, d] > low[1] - tol) & (t[:, d] < high[1] + tol)
    edge = (np.abs(t[:, b] - low[0]) < tol) | (np.abs(t[:, b] - high[0]) < tol)
    edge |= (np.abs(t[:, d] - low[1]) < tol) | (np.abs(t[:, d] - high[1]) < tol)
    keep = inside & edge
    centre = 0.5 * (np.asarray(low) + np.asarray(high))
    angle = np.arctan2(t[keep, d] - centre[1], t[keep, b] - centre[0])
    ring = ids[keep][np.argsort(angle)]
    return ring if outward > 0 else ring[::-1]


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
    ids = np.unique(np.concatenate([cycle for _, cycle in cycles] + [plan.lattice[row]]))
    x = np.concatenate([mesh.vertices, plan.points])[ids]
    t, _ = _half_steps(x, plan.lower[row], plan.upper[row])
    centres = np.array([t[np.searchsorted(ids, cycle)].mean(axis=0) for _, cycle in cycles])
    octant_of = np.floor(np.clip(centres, 0.0, 2.0 - 1e-6)).astype(np.int64)
    out = []
    for o in _LATTICE[_CORNERS] // 2:  # octant (ox, oy, oz) in {0, 1}^3
        child, child_labels = [], []
        for axis in range(3):
            b, d = (axis + 1) % 3, (axis + 2) % 3
            outward = 1 if o[axis] else -1
            child.append(_perimeter_polygon(ids, t, axis, 1, (o[b], o[d]), (o[b] + 1, o[d] + 1), -outward))
            child_labels.append(-1)  # towards the sibling across the mid-plane
        mine = np.flatnonzero((octant_of == o).all(axis=1))
        child.extend(cycles[k][1] for k in mine)
        child_labels.extend(labels[cycles[k][0]] for k in mine)
        out.append((child, child_labels))
    return out


def refine_cells(mesh: PolyhedralMesh, marked, *, max_hanging: int | None = None, circles=None) -> RefinedMesh:
    """Split the marked boxes into 8 (module doc); ``max_hanging`` and ``circles`` are not used yet
    (boxes have no curved sides) and must be None or empty."""
    if max_hanging is not None:
        raise InputError(
            "max_hanging: 3D refinement does not limit hanging vertices yet; leave it out", key="max_hanging"
        )
    if circles:
        raise InputError("circles: 3D refinement of boxes has no curved sides; leave it out", key="circles")
    cells = _marked_cells(mesh, marked)
    plan = _plan(mesh, cells)
    face_offsets, face_vertices = _with_midpoints(mesh, plan.split_edges)
    names = list(mesh.boundary)
    labels = np.full(mesh.n_faces, -1, dtype=np.int64)
    for k, name in enumerate(names):
        labels[np.asarray(mesh.boundary[name], dtype=np.int64)] = k
    split_faces = _split_faces(mesh, plan, face_offsets, face_vertices)
    row_of = np.full(mesh.n_cells, -1, dtype=np.int64)
    row_of[cells] = np.arange(cells.size)
    cell_sizes, soup, soup_labels, parent = [], [], [], []
    for c in range(mesh.n_cells):
        cycles = _cell_cycles(mesh, c, face_offsets, face_vertices, split_faces)
        pieces = (
            _children(mesh, plan, int(row_of[c]), cycles, labels)
            if row_of[c] >= 0
            else [([cycle for _, cycle in cycles], [labels[f] for f, _ in cycles])]
        )
        for child, child_labels in pieces:
            cell_sizes.append(len(child))
            soup.extend(child)
            soup_labels.extend(child_labels)
            parent.append(c)
    vertices = np.concatenate([mesh.vertices, plan.points])
    meta = dict(mesh.meta, refined_3d=int(mesh.meta.get("refined_3d", 0)) + 1)
    new = from_face_soup(
        vertices,
        cell_sizes,
        [len(f) for f in soup],
        np.concatenate(soup) if soup else np.zeros(0, np.int64),
        np.asarray(soup_labels, dtype=np.int64),
        names,
        meta,
    )
    return RefinedMesh(new, np.asarray(parent, dtype=np.int64), _prolongation(mesh, plan), cells, np.zeros(0, np.int64))


def _split_faces(mesh, plan: _Plan, face_offsets, face_vertices) -> dict:
    """Old face -> its 4 quarter cycles (as stored) for every whole side of a marked cell."""
    out: dict = {}
    for row, c in enumerate(plan.cells):
        signed = mesh.cell_face_list(c)
        faces = np.where(signed >= 0, signed, -signed - 1)
        cycles = [face_vertices[face_offsets[f] : face_offsets[f + 1]] for f in faces]
        ids = np.unique(np.concatenate(cycles + [plan.lattice[row]]))
        t, _ = _half_steps(np.concatenate([mesh.vertices, plan.points])[ids], plan.lower[row], plan.upper[row])
        for f, cycle in zip(faces.tolist(), cycles):
            tf = t[np.searchsorted(ids, cycle)]
            axis = int(np.argmin(np.ptp(tf, axis=0)))
            b, d = (axis + 1) % 3, (axis + 2) % 3
            if f in out or np.ptp(tf[:, b]) < 2 - LATTICE_TOL or np.ptp(tf[:, d]) < 2 - LATTICE_TOL:
                continue
            normal = np.sign(mesh.face_vector_areas[f, axis])
            level = float(np.round(tf[0, axis]))
            out[f] = [
                _perimeter_polygon(ids, t, axis, level, (lo_b, lo_d), (lo_b + 1, lo_d + 1), normal)
                for lo_b, lo_d in ((0, 0), (1, 0), (1, 1), (0, 1))
            ]
    return out


def _prolongation(mesh: PolyhedralMesh, plan: _Plan) -> sp.csr_matrix:
    """(new vertices, old vertices): old ones kept, a new one the mean of the corners it lies between."""
    n = mesh.n_vertices
    rows = [np.arange(n)] + [np.full(len(s), n + k) for k, s in enumerate(plan.sources)]
    cols = [np.arange(n)] + [np.asarray(s) for s in plan.sources]
    vals = [np.ones(n)] + [np.full(len(s), 1.0 / len(s)) for s in plan.sources]
    shape = (n + len(plan.sources), n)
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=shape)
