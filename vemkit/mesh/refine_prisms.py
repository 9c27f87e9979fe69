"""Refinement of prisms (extruded bodies) with hanging vertices, the prism rule of
``vemkit.mesh.refine_polyhedra``: the 2D rule on the base and two in depth.

A marked prism K x [z0, z1] (K a convex polygon with geometric corners c_0 ... c_{m-1}, counter-
clockwise from +z: the vertices on 3 of the prism's planes) becomes 2m prisms Q_i x [z0, zm] and
Q_i x [zm, z1], Q_i = [c_i, s_i, z, s_{i-1}] the quadrilaterals of the 2D rule (``vemkit.mesh.refine``:
s_i the midpoint of c_i c_{i+1}, z the centroid of K) and zm the mid-depth. A new point is made once:
an edge midpoint named by its two corners, a face centre by the face's corners. Missing edge
midpoints are inserted into every face listing the two corners in a row; a whole side (a lateral
rectangle, or a cap) is split into its 4 quarters (or the m quadrilaterals Q_i); a side already split
keeps its faces, each going to the child it lies on. A child's face is the polygon of its corners with
every vertex of the parent lying on its edges inserted in order. On a curved side (a circular hole or
an arc of the base, ``vemkit.mesh.curves``) the new points of a whole lateral side move radially onto
the circle, all three together, where every cell along its cap edges splits there too; otherwise they
stay on the chord (so that no face bends).

The plan, the whole sides and the children of all marked prisms are made at once by the Numba kernels
of ``refine_prisms_kernels``, whose twins are the cell-by-cell functions of ``refine_prisms_reference``.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from vemkit.exceptions import MeshError
from vemkit.mesh.curves import as_pieces, on_curves
from vemkit.mesh.polyhedral_build import segments
from vemkit.mesh.refine_boxes import unique_rows
from vemkit.mesh.refine_prisms_kernels import prisms_children as children_kernel
from vemkit.mesh.refine_prisms_kernels import prisms_plan as plan_kernel
from vemkit.mesh.refine_prisms_kernels import prisms_sides as sides_kernel
from vemkit.mesh.refine_tetrahedra import TOL


def _centroid_weights(x2):
    """Weights of the corners of a convex polygon (k, 2) giving its area centroid (the fan from
    corner 0: every triangle's area over 3 to each of its corners), so that prolongation is exact."""
    e1, e2 = x2[1:-1] - x2[0], x2[2:] - x2[0]
    area = 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    w = np.zeros(x2.shape[0])
    w[0] = area.sum()
    w[1:-1] += area
    w[2:] += area
    return w / (3.0 * area.sum())


def plan_prisms(mesh, cells: np.ndarray, refinable: str, curves=None):
    """(lattices, new points, sources, split edges, faces added by splits, inner faces) of the marked
    prisms; a lattice is B, T, V, SB, ST, SM (m each: corners, vertical midpoints, edge midpoints
    at the bottom, top and mid-depth) then ZB, ZT, ZM (the centroids of the caps and of the prism).
    A point is a vertex of the cell there already, else new, named by its group of corners and
    numbered in order of first request (``refine_prisms_kernels.prisms_plan``)."""
    n, vertices = mesh.n_vertices, mesh.vertices
    status, corner_start, corners, near, keys, kind = _requests(mesh, cells)
    if status.any():
        row = int(np.flatnonzero(status)[0])
        raise MeshError(
            f"cell {cells[row]} of the {mesh.meta.get('family', 'given')} mesh is not an axis-aligned box, a "
            f"tetrahedron or a prism along z over a convex polygon; 3D refinement splits the cells of the families "
            f"{refinable}"
            if status[row] == 1
            else f"cell {cells[row]} has a lateral face across its mid-depth without being a whole side (the hanging "
            "vertices of an extruded mesh with hanging nodes); 3D refinement splits prisms whose lateral faces are "
            "whole sides or lie in one half of the depth"
        )
    m = np.diff(corner_start) // 2
    new = near < 0
    unique, inverse = unique_rows(keys[new])
    first = np.full(unique.shape[0], near.size, dtype=np.int64)
    np.minimum.at(first, inverse, np.flatnonzero(new))
    rank = np.empty(unique.shape[0], dtype=np.int64)
    rank[np.argsort(first)] = np.arange(unique.shape[0])
    values = near.copy()
    values[new] = n + rank[inverse]
    request_start = np.concatenate([[0], np.cumsum(4 * m + 3)])
    lattices = [
        np.concatenate(
            [corners[corner_start[r] : corner_start[r + 1]], values[request_start[r] : request_start[r + 1]]]
        )
        for r in range(cells.size)
    ]
    created = np.sort(first)  # the requests that make the new points, in order
    row_of = np.repeat(np.arange(cells.size), 4 * m + 3)
    points, sources = _new_points(
        vertices, corners, corner_start, row_of[created], created - request_start[row_of[created]], m, n
    )
    pairs = kind[created] == 0
    edges = np.sort(keys[created[pairs], :2], axis=1)
    mids = n + np.flatnonzero(pairs)
    edge_keys = edges[:, 0] * np.int64(n) + edges[:, 1]
    order = np.argsort(edge_keys)
    pieces = np.where(kind[created] == 1, 3, np.where(kind[created] == 2, m[row_of[created]] - 1, 0))
    points = _onto_curves(mesh, cells, lattices, points, curves)
    return lattices, points, sources, (edge_keys[order], mids[order]), int(pieces.sum()), int(3 * m.sum())


def _requests(mesh, cells):
    """``refine_prisms_kernels.prisms_plan`` of the marked cells."""
    sizes = mesh.cell_offsets[cells + 1] - mesh.cell_offsets[cells]
    signed = mesh.cell_faces[segments(mesh.cell_offsets[cells], sizes)]
    faces = np.where(signed >= 0, signed, -signed - 1)
    normals = mesh.face_vector_areas[faces] * np.where(signed >= 0, 1.0, -1.0)[:, None]
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    offsets, ids = mesh.cell_vertex_lists
    own_sizes = offsets[cells + 1] - offsets[cells]
    own = ids[segments(offsets[cells], own_sizes)]
    width = 2 * int(own_sizes.max(initial=1)) + 1
    args = (mesh.face_offsets, mesh.face_vertices, np.concatenate([[0], np.cumsum(own_sizes)]), own)
    cell_start = np.concatenate([[0], np.cumsum(sizes)])
    return plan_kernel(cells.astype(np.int64), cell_start, faces, normals, *args, mesh.vertices, width, TOL)


def _new_points(vertices, corners, corner_start, rows, positions, m, n):
    """(points, sources) of the new points, made by the requests (row, position after the corners):
    the mean of a group's corners, or the area centroid of a cap or of the prism, as ``weights @ x``
    (batched: the same numbers as point by point; a pair's mean as 0.5 a + 0.5 b, the same number)."""
    size, start = m[rows], corner_start[rows]
    i = positions % np.maximum(size, 1)
    j, which = (i + 1) % np.maximum(size, 1), positions // np.maximum(size, 1)
    lower = corners[np.minimum(start[:, None] + np.stack([i, j], axis=1), corners.size - 1)]
    upper = corners[np.minimum((start + size)[:, None] + np.stack([i, j], axis=1), corners.size - 1)]
    points = np.empty((rows.size, 3))
    pair = positions < 3 * size
    ends = np.stack(
        [
            np.where(which == 2, upper[:, 0], lower[:, 0]),
            np.choose(which.clip(0, 2), [upper[:, 0], lower[:, 1], upper[:, 1]]),
        ],
        axis=1,
    )[pair]
    points[pair] = 0.5 * vertices[ends[:, 0]] + 0.5 * vertices[ends[:, 1]]
    sources = [(n + np.flatnonzero(pair), ends, np.full(ends.shape, 0.5))]
    lateral = np.flatnonzero(~pair & (positions < 4 * size))
    groups = [(lateral, np.concatenate([lower, upper], axis=1)[lateral], None)]
    for mr in np.unique(size[positions >= 4 * size]).tolist():
        for k in range(3):  # the bottom cap, the top cap, the prism
            made = np.flatnonzero((size == mr) & (positions == 4 * mr + k))
            bottom = corners[start[made, None] + np.arange(mr)]
            top = corners[start[made, None] + mr + np.arange(mr)]
            real = [bottom, top, np.concatenate([bottom, top], axis=1)][k]
            groups.append((made, real, _centroid_weights_batched(vertices[real[:, :mr], :2])))
    for made, real, w in groups:
        weights = (
            np.full(real.shape, 0.25)
            if w is None
            else (w if w.shape == real.shape else np.concatenate([w, w], axis=1) / 2)
        )
        points[made] = (weights[:, None, :] @ vertices[real])[:, 0]
        sources.append((n + made, real, weights))
    return points, sources


def _centroid_weights_batched(x2):
    """``_centroid_weights`` of every polygon of x2 (N, k, 2) at once, the same numbers."""
    e1, e2 = x2[:, 1:-1] - x2[:, :1], x2[:, 2:] - x2[:, :1]
    area = 0.5 * (e1[..., 0] * e2[..., 1] - e1[..., 1] * e2[..., 0])
    w = np.zeros(x2.shape[:2])
    w[:, 0] = area.sum(axis=1)
    w[:, 1:-1] += area
    w[:, 2:] += area
    return w / (3.0 * area.sum(axis=1))[:, None]


def _onto_curves(mesh, cells: np.ndarray, lattices: list, points: np.ndarray, curves) -> np.ndarray:
    """``points`` with the new points of the whole lateral sides on curved boundary pieces (the 2D
    mesh's ``circles`` or ``curves``: ``vemkit.mesh.curves``' pieces in the xy plane) moved radially onto their circle: the edge midpoints
    s_i at both caps and the face centre between them, together (so that the quarters stay planar),
    and only where every cell along those edges splits its side there too (else a neighbour's face
    would bend): a point moves when as many moving sides pass through it as cells hold its edge."""
    pieces = as_pieces(mesh.meta.get("base", {}).get("circles") if curves is None else curves)
    if not pieces:
        return points
    n = mesh.n_vertices
    part_of = np.full(mesh.n_faces, -1, dtype=np.int64)
    names = list(mesh.boundary)
    for k, name in enumerate(names):
        part_of[mesh.boundary[name]] = k
    triples, sides, ends = [], [], []
    for c, lattice in zip(cells.tolist(), lattices):
        m = (lattice.size - 3) // 6
        for s in mesh.cell_face_list(c).tolist():
            f = s if s >= 0 else -s - 1
            i = next((i for i in range(m) if np.isin(lattice[[i, (i + 1) % m]], mesh.face(f)).all()), None)
            if (
                i is None
                or part_of[f] < 0
                or np.abs(mesh.face_vector_areas[f, 2]) > 1e-9 * np.abs(mesh.face_vector_areas[f]).sum()
                or lattice[5 * m + i] < n
            ):
                continue  # not a whole lateral boundary side (a new centre)
            triples.append(lattice[[3 * m + i, 5 * m + i, 4 * m + i]])
            sides.append(names[part_of[f]])
            ends.append(lattice[[i, (i + 1) % m, m + i, m + (i + 1) % m]])
    if not triples:
        return points
    triples, ends = np.array(triples), np.array(ends)
    around = _cells_around(mesh, ends)  # (k, 2): cells along the bottom and the top edge
    cap_points = triples[:, [0, 2]]
    uses = np.bincount(cap_points.ravel(), minlength=n + points.shape[0])  # sides through each point
    moves = (cap_points >= n).all(axis=1) & (uses[cap_points] == around).all(axis=1)
    while True:  # a cap midpoint moves only if every side through it moves
        blocked = np.unique(triples[~moves][:, [0, 2]])
        still = moves & ~np.isin(triples[:, [0, 2]], blocked).any(axis=1)
        if (still == moves).all():
            break
        moves = still
    out = points.copy()
    for side in set(sides):
        rows = np.flatnonzero(moves & (np.array(sides) == side))
        if not rows.size:
            continue
        chord = ends[rows, :2]
        fake = SimpleNamespace(n_vertices=n, boundary={side: chord})  # the chords of this side, as 2D edges
        xy = on_curves(fake, chord, mesh.vertices[chord, :2].mean(axis=1), pieces)
        for column in range(3):
            out[triples[rows, column] - n, :2] = xy
    return out


def _cells_around(mesh, caps: np.ndarray) -> np.ndarray:
    """Per row of ``caps`` (k, 4): (bottom edge, top edge) vertex pairs; the number of cells with a face
    along each of the two edges (the cell itself and the one across its cap, if any)."""
    offsets, ids = mesh.face_offsets, mesh.face_vertices
    following = np.arange(1, ids.size + 1, dtype=np.int64)
    following[offsets[1:] - 1] = offsets[:-1]
    n = np.int64(mesh.n_vertices)
    keys = np.minimum(ids, ids[following]) * n + np.maximum(ids, ids[following])
    order = np.argsort(keys, kind="stable")
    keys, faces = keys[order], np.repeat(np.arange(mesh.n_faces), np.diff(offsets))[order]
    out = np.zeros((caps.shape[0], 2), dtype=np.int64)
    for r, (a, b, c, d) in enumerate(caps.tolist()):
        for e, (u, v) in enumerate(((a, b), (c, d))):
            key = min(u, v) * n + max(u, v)
            around = mesh.face_cells[faces[np.searchsorted(keys, key) : np.searchsorted(keys, key, side="right")]]
            out[r, e] = np.unique(around[around >= 0]).size
    return out


def _lattice_table(lattices: list):
    """(offsets, flat) of the prisms' lattices (6 m + 3 ids each)."""
    offsets = np.concatenate([[0], np.cumsum([lattice.size for lattice in lattices])]).astype(np.int64)
    return offsets, np.concatenate(lattices).astype(np.int64) if lattices else np.zeros(0, np.int64)


def split_prisms_sides(mesh, lattices: list, cells, face_offsets, face_vertices, x):
    """(faces, (sizes, flat vertices, pieces per face) of their pieces, as stored) of the whole sides of
    the marked prisms (``refine_prisms_kernels.prisms_sides``; its twin:
    ``refine_prisms_reference.split_prism_sides``
    cell by cell), each split once (by the first marked prism it is a whole side of)."""
    sizes = mesh.cell_offsets[cells + 1] - mesh.cell_offsets[cells]
    signed = mesh.cell_faces[segments(mesh.cell_offsets[cells], sizes)]
    faces = np.where(signed >= 0, signed, -signed - 1)
    cell_start = np.concatenate([[0], np.cumsum(sizes)])
    args = (cell_start, faces, face_offsets, face_vertices, mesh.face_vector_areas, x, TOL)
    _, found, counts, piece_sizes, flat = sides_kernel(*_lattice_table(lattices), *args)
    first = np.sort(np.unique(found, return_index=True)[1])
    pieces = segments(np.concatenate([[0], np.cumsum(counts)])[first], counts[first])
    piece_offsets = np.concatenate([[0], np.cumsum(piece_sizes)])
    flat = flat[segments(piece_offsets[pieces], piece_sizes[pieces])]
    return found[first], (piece_sizes[pieces], flat, counts[first])


def prisms_children(lattices: list, x, row_start, cycle_offsets, cycle_vertices):
    """The children of all marked prisms at once (``refine_prisms_kernels.prisms_children``; its
    twin: ``refine_prisms_reference.prism_children``): per face of a child (row, child, the parent's cycle it is
    or -1), and the new faces' (sizes, flat vertices)."""
    return children_kernel(*_lattice_table(lattices), row_start, cycle_offsets, cycle_vertices, x, TOL)
