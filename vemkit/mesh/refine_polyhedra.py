"""Local refinement of polyhedral meshes with hanging vertices: boxes and tetrahedra split into 8.

A marked cell that is an axis-aligned box (a hexahedron of the grid family, an octree cell, possibly
with hanging vertices already on its faces) becomes the 8 boxes of half its size
(``vemkit.mesh.refine_boxes``: its new vertices are the 27-point lattice of half steps that is not
there yet, a point shared with a marked neighbour made once). Tetrahedra follow the same scheme by
the red rule (``vemkit.mesh.refine_tetrahedra``), prisms of extruded bodies by the 2D rule on their
base (``vemkit.mesh.refine_prisms``). Other cells (Voronoi polyhedra) are refused in one line naming
the families that refine (``REFINABLE_FAMILIES``).

The mesh stays conforming in the VEM sense (docs/reference/files.md):
- a new edge midpoint is inserted between the edge's two corners into every face listing them in a
  row, so every cell around that edge (refined or not) gains it as a hanging vertex;
- a whole side of a marked cell (a face without vertices inside it) is split into its pieces (4
  quarters of a box's side), and the neighbour across it lists those pieces instead of the old face;
- a side already split by smaller neighbours keeps its faces, each going to the child under it.
A child's face is the planar polygon of every vertex on its perimeter, in order. Boundary faces keep
their part's name (a piece the name of the face it comes from).

The refined mesh is built from a table of vertex cycles (the faces with their midpoints, the pieces of
split faces, the children's new faces): an unmarked cell's faces are copied in bulk over the CSR arrays
(no Python loop over cells), a marked cell's replaced by its children's, and every face is stored once
(``polyhedral_build.from_numbered_soup``: known by its cycle, a rule's new face by its vertices).
``predict_refinement`` counts the cells, vertices and faces of a refinement before it is built.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from vemkit.exceptions import InputError, MeshError
from vemkit.mesh.polyhedral import PolyhedralMesh
from vemkit.mesh.polyhedral_build import from_numbered_soup, same_faces, segments
from vemkit.mesh.refine import RefinedMesh
from vemkit.mesh.refine_boxes import box_children, cycles_of, plan_boxes, split_box_sides
from vemkit.mesh.refine_prisms import plan_prisms, prisms_children, split_prisms_sides
from vemkit.mesh.refine_tetrahedra import plan_tetrahedra, split_tetrahedra_sides, tetrahedra_children

#: the families whose cells this module splits
REFINABLE_FAMILIES = ("hex", "octree", "tet (box and gmsh tetrahedra)", "the extruded ones over convex polygons")


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


def _any_plan(mesh: PolyhedralMesh, cells: np.ndarray, curves=None) -> _Plan:
    """The plan of the boxes' rule, else of the tetrahedra's, else of the prisms' (a MeshError naming the
    families that refine)."""
    refinable = ", ".join(REFINABLE_FAMILIES)
    try:
        lower, upper, lattice, points, sources, split, sides = plan_boxes(mesh, cells, refinable)
        return _Plan(cells, lower, upper, lattice, points, sources, split, 12 * cells.size + 3 * sides)
    except MeshError:
        pass
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
    """(offsets, vertices) of the faces with every new edge midpoint inserted between its corners
    (looked up only for the face edges whose two ends are ends of split edges)."""
    offsets, ids = mesh.face_offsets, mesh.face_vertices
    following = np.arange(1, ids.size + 1, dtype=np.int64)
    following[offsets[1:] - 1] = offsets[:-1]
    n = np.int64(mesh.n_vertices)
    split_keys, mids = split_edges
    order = np.argsort(split_keys)
    split_keys, mids = split_keys[order], mids[order]
    ends = np.zeros(mesh.n_vertices, dtype=bool)
    ends[split_keys // n], ends[split_keys % n] = True, True
    near = np.flatnonzero(ends[ids] & ends[ids[following]])
    a, b = ids[near], ids[following[near]]
    keys = np.minimum(a, b) * n + np.maximum(a, b)
    at = np.clip(np.searchsorted(split_keys, keys), 0, max(split_keys.size - 1, 0))
    found = split_keys[at] == keys if split_keys.size else np.zeros(keys.size, dtype=bool)
    hit = np.zeros(ids.size, dtype=bool)
    hit[near[found]] = True
    out = np.empty(ids.size + int(found.sum()), dtype=np.int64)
    position = np.arange(ids.size) + np.concatenate([[0], np.cumsum(hit)[:-1]])
    out[position] = ids
    out[position[near[found]] + 1] = mids[at[found]]
    owner = np.repeat(np.arange(mesh.n_faces), np.diff(offsets))
    sizes = np.diff(offsets) + np.bincount(owner[hit], minlength=mesh.n_faces)
    return np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64), out


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
    labels = np.full(mesh.n_faces, -1, dtype=np.int64)
    for k, name in enumerate(mesh.boundary):
        labels[np.asarray(mesh.boundary[name], dtype=np.int64)] = k
    x = np.concatenate([mesh.vertices, plan.points])
    if plan.kind == "box":
        split = split_box_sides(mesh, plan, face_offsets, face_vertices, x)
    elif plan.kind == "tet":
        split = split_tetrahedra_sides(mesh, plan.lattice, cells, face_offsets, face_vertices, x)
    else:
        split = split_prisms_sides(mesh, plan.lattice, cells, face_offsets, face_vertices, x)
    new, children = _refined_mesh(mesh, plan, labels, _cycle_table(mesh, face_offsets, face_vertices, *split), x)
    parent = np.repeat(np.arange(mesh.n_cells), children)
    return RefinedMesh(new, parent, _prolongation(mesh, plan), cells, np.zeros(0, np.int64))


def _refined_mesh(mesh, plan: _Plan, labels, cycles, x):
    """(the refined mesh, the number of cells each old one becomes): the unmarked cells' faces (as
    cycles of the table, split faces as their pieces) copied in bulk, the marked cells' children by
    their rule, in the order of the old cells; every face is a cycle of the table, or for the
    tetrahedra's and prisms' rules the same vertices as another one."""
    table, face_cycles = cycles
    cells = plan.cells
    unmarked = np.ones(mesh.n_cells, dtype=bool)
    unmarked[cells] = False
    kept = _appearances(mesh, np.flatnonzero(unmarked), face_cycles)
    children = np.ones(mesh.n_cells, dtype=np.int64)
    children[cells] = [2 * ((lattice.size - 3) // 6) for lattice in plan.lattice] if plan.kind == "prism" else 8
    first_child = np.cumsum(children) - children
    row, cycle, reverse, face = _appearances(mesh, cells, face_cycles)
    known = table[0].size - 1  # cycles known by number; the rules' new faces by their vertices
    args = (row, cycle, reverse, labels[face], *table, x)
    table, (row, child, cycle, reverse, face_labels) = (
        _box_pieces(plan, *args) if plan.kind == "box" else _rule_pieces(plan, *args)
    )
    face_id = _face_numbers(table, known)
    new_cell = np.concatenate([first_child[np.flatnonzero(unmarked)][kept[0]], first_child[cells][row] + child])
    order = np.argsort(new_cell, kind="stable")
    cycle = np.concatenate([kept[1], cycle])[order]
    face_sizes, soup = cycles_of(*table, cycle, np.concatenate([kept[2], reverse])[order])
    new = from_numbered_soup(
        x,
        np.bincount(new_cell, minlength=int(children.sum())),
        face_sizes,
        soup,
        face_id[cycle],
        np.concatenate([labels[kept[3]], face_labels])[order],
        list(mesh.boundary),
        dict(mesh.meta, refined_3d=int(mesh.meta.get("refined_3d", 0)) + 1),
    )
    return new, children


def _face_numbers(table, known: int) -> np.ndarray:
    """A number per cycle of the table, equal for cycles of one face: its own for the ``known`` first
    ones (the old faces and their pieces), one per vertex set for the rest (the children's new faces,
    inside their parents: the two sides of a face between siblings)."""
    offsets, vertices = table
    out = np.arange(offsets.size - 1)
    out[known:] = known + same_faces(offsets[known:] - offsets[known], vertices[offsets[known] :])
    return out


def _cycle_table(mesh, face_offsets, face_vertices, split_faces, pieces):
    """((offsets, vertices) of the faces with midpoints followed by the pieces of the split faces, and
    (offsets, ids) of every old face's cycles: itself, or its pieces); ``pieces``: (sizes, flat) of the
    split faces' pieces, face after face, as many per face as ``pieces_per_face`` (4 or given)."""
    sizes, flat, per_face = pieces
    n = mesh.n_faces
    counts = np.ones(n, dtype=np.int64)
    counts[split_faces] = per_face
    offsets = np.concatenate([[0], np.cumsum(counts)])
    ids = np.empty(int(offsets[-1]), dtype=np.int64)
    whole = counts == 1
    whole[split_faces] = False
    ids[offsets[:-1][whole]] = np.flatnonzero(whole)
    ids[segments(offsets[split_faces], per_face)] = n + np.arange(int(np.sum(per_face)))
    table = (np.concatenate([face_offsets, face_offsets[-1] + np.cumsum(sizes)]), np.concatenate([face_vertices, flat]))
    return table, (offsets, ids)


def _appearances(mesh, cells: np.ndarray, face_cycles):
    """Per face of the given cells, in order (a split face as its pieces): (row of its cell in
    ``cells``, cycle in the table, reversed, old face)."""
    sizes = mesh.cell_offsets[cells + 1] - mesh.cell_offsets[cells]
    signed = mesh.cell_faces[segments(mesh.cell_offsets[cells], sizes)]
    faces = np.where(signed >= 0, signed, -signed - 1)
    offsets, ids = face_cycles
    pieces = offsets[faces + 1] - offsets[faces]
    row = np.repeat(np.repeat(np.arange(cells.size), sizes), pieces)
    return row, ids[segments(offsets[faces], pieces)], np.repeat(signed < 0, pieces), np.repeat(faces, pieces)


def _box_pieces(plan, row, cycle, reverse, labels, table_offsets, table_vertices, x):
    """The table with the boxes' inner faces added, and the children's faces (``box_children``)."""
    inner, (row, child, cycle, reverse, labels) = box_children(
        plan, row, cycle, reverse, labels, table_offsets, table_vertices, x
    )
    base = table_offsets.size - 1
    cycle = np.where(cycle >= 0, cycle, base - 1 - cycle)
    table = (
        np.concatenate([table_offsets, table_offsets[-1] + np.cumsum(inner[0])]),
        np.concatenate([table_vertices, inner[1]]),
    )
    return table, (row, child, cycle, reverse, labels)


def _rule_pieces(plan, row, cycle, reverse, labels, table_offsets, table_vertices, x):
    """The table with the new faces of the tetrahedra's or prisms' children added, and the children's
    faces (``refine_tetrahedra.tetrahedra_children``, ``refine_prisms.prisms_children``: all marked
    cells at once)."""
    sizes, flat = cycles_of(table_offsets, table_vertices, cycle, reverse)
    row_start = np.concatenate([[0], np.cumsum(np.bincount(row, minlength=plan.cells.size))])
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    rule = tetrahedra_children if plan.kind == "tet" else prisms_children
    rows, child, source, new_sizes, new_flat = rule(plan.lattice, x, row_start, offsets, flat)
    new = source < 0
    cycle = np.where(new, table_offsets.size - 2 + np.cumsum(new), cycle[source])
    table = (
        np.concatenate([table_offsets, table_offsets[-1] + np.cumsum(new_sizes)]),
        np.concatenate([table_vertices, new_flat]),
    )
    return table, (rows, child, cycle, np.where(new, False, reverse[source]), np.where(new, -1, labels[source]))


def _split_by(mesh, plan: _Plan, sides_of, face_offsets, face_vertices, x):
    """(faces, (sizes, flat, pieces per face)) of the whole sides split by a rule's ``sides_of(mesh,
    lattice, cell, face_offsets, face_vertices, x)`` (pairs of a face and its pieces as stored), each
    face split once: the cell-by-cell twin of the rules' kernels of whole sides (the tests run it)."""
    out: dict = {}
    for row, c in enumerate(plan.cells.tolist()):
        for f, rings in sides_of(mesh, plan.lattice[row], c, face_offsets, face_vertices, x):
            out.setdefault(f, rings)
    rings = [ring for f in out for ring in out[f]]
    sizes = np.array([ring.size for ring in rings], dtype=np.int64)
    flat = np.concatenate(rings) if rings else np.zeros(0, np.int64)
    return np.array(list(out), dtype=np.int64), (sizes, flat, np.array([len(r) for r in out.values()], np.int64))


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
