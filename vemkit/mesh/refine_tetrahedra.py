"""Red refinement of tetrahedra with hanging vertices (Bey 1995), the tetrahedral rule of
``vemkit.mesh.refine_polyhedra``.

A marked tetrahedron x0 x1 x2 x3 (its corners: the vertices on 3 of its 4 planes; hanging vertices
of refined neighbours may sit on its edges and sides) becomes 8: the 4 corner tetrahedra
(x_i, m_ij, m_ik, m_il) and the octahedron of the 6 edge midpoints m_ij cut along its shortest
diagonal into 4. A missing midpoint is made once (named by its edge's two corners) and inserted into
every face listing the two corners in a row; a whole side is split into its 4 triangles (the 3
corner ones and the middle one); a side already split keeps its faces, each going to the child it
lies on. A child's face is the triangle of its corners with every vertex of the parent lying on
its edges inserted in order (so hanging vertices of finer neighbours are kept).

All marked tetrahedra are handled at once: the plan over flat arrays, the whole sides and the
children by the Numba kernels of ``refine_polyhedra_kernels`` (``split_tetrahedra_sides``,
``tetrahedra_children``), whose twins are the cell-by-cell ``whole_sides`` and ``tetrahedron_children``.
"""

from __future__ import annotations

import numpy as np

from vemkit.exceptions import MeshError
from vemkit.mesh.polyhedral_build import segments
from vemkit.mesh.refine_polyhedra_kernels import tetrahedra_children as children_kernel
from vemkit.mesh.refine_polyhedra_kernels import tetrahedra_sides as sides_kernel

#: the 6 edges of a tetrahedron as corner pairs; lattice point 4 + k is the midpoint of _EDGES[k]
_EDGES = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
_MID = {pair: 4 + k for k, pair in enumerate(_EDGES)} | {pair[::-1]: 4 + k for k, pair in enumerate(_EDGES)}
#: barycentric coordinates of the 10 lattice points (4 corners, 6 midpoints)
_BARY = np.vstack([np.eye(4), [(np.eye(4)[i] + np.eye(4)[j]) / 2 for i, j in _EDGES]])
TOL = 1e-9


def plane_labels(normals: np.ndarray) -> np.ndarray:
    """A label per unit outward normal, equal for the faces of one plane of a convex cell (normals
    within 1e-9 of each other; not a rounding, which could split one plane in two)."""
    labels = np.full(normals.shape[0], -1, dtype=np.int64)
    for k in range(normals.shape[0]):
        if labels[k] < 0:
            labels[(labels < 0) & (normals @ normals[k] > 1 - 1e-9)] = labels.max() + 1
    return labels


def _cell_entries(mesh, cells: np.ndarray):
    """(row, signed face) of every face of the given cells, cell after cell."""
    sizes = mesh.cell_offsets[cells + 1] - mesh.cell_offsets[cells]
    return np.repeat(np.arange(cells.size), sizes), mesh.cell_faces[segments(mesh.cell_offsets[cells], sizes)]


def _plane_numbers(row, normals, m: int):
    """Per face of the marked cells (rows in order), ``plane_labels`` of its cell's unit outward normals,
    and the number of planes of each cell."""
    start = np.searchsorted(row, np.arange(m))
    column = np.arange(row.size) - start[row]
    width = int(column.max()) + 1
    padded = np.full((m, width, 3), np.nan)
    padded[row, column] = normals
    close = np.einsum("rjc,rkc->rjk", padded, padded) > 1 - 1e-9
    labels, count = np.full((m, width), -1, dtype=np.int64), np.zeros(m, dtype=np.int64)
    for j in range(width):  # the first face without a plane starts the next one (plane_labels)
        leads = labels[:, j] < 0
        leads &= ~np.isnan(padded[:, j, 0])
        labels = np.where(leads[:, None] & (labels < 0) & close[:, j, :], count[:, None], labels)
        count += leads
    return labels[row, column], count


def _tetrahedra_corners(mesh, cells: np.ndarray, refinable: str) -> np.ndarray:
    """(m, 4) corners of the marked cells (the vertices on 3 of the 4 planes of its faces, in order of
    first appearance along its faces), positively oriented; a MeshError names the first cell that is
    not a tetrahedron."""
    m = cells.size
    row, signed = _cell_entries(mesh, cells)
    faces = np.where(signed >= 0, signed, -signed - 1)
    normals = mesh.face_vector_areas[faces] * np.where(signed >= 0, 1.0, -1.0)[:, None]
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    plane, planes = _plane_numbers(row, normals, m)
    counts = mesh.face_offsets[faces + 1] - mesh.face_offsets[faces]
    vertex = mesh.face_vertex_ids(faces)
    owner = np.repeat(row, counts)
    scale = np.int64(mesh.n_vertices)
    incidence = np.unique((owner * scale + vertex) * 4 + np.repeat(plane, counts).clip(0, 3))
    keys, on_planes = np.unique(incidence // 4, return_counts=True)
    first = np.unique(owner * scale + vertex, return_index=True)[1]  # first appearance of each (row, vertex)
    corner = on_planes == 3
    order = np.argsort(first[corner], kind="stable")
    corners = (keys[corner] % scale)[order]
    corner_rows = (keys[corner] // scale)[order]
    ok = (planes == 4) & (np.bincount(corner_rows, minlength=m) == 4)
    if not ok.all():
        raise MeshError(
            f"cell {cells[np.argmin(ok)]} of the {mesh.meta.get('family', 'given')} mesh is neither an axis-aligned "
            f"box nor a tetrahedron; 3D refinement splits the cells of the families {refinable}"
        )
    corners = corners[np.argsort(corner_rows, kind="stable")].reshape(m, 4)
    x = mesh.vertices[corners]
    turned = np.linalg.det(x[:, 1:] - x[:, :1]) < 0
    corners[turned] = corners[turned][:, [1, 0, 2, 3]]
    return corners


def plan_tetrahedra(mesh, cells: np.ndarray, refinable: str):
    """(lattice (m, 10) vertex ids, new points, sources, split edges, number of whole sides) of the
    marked tetrahedra (``refine_polyhedra._Plan``'s fields): an edge midpoint is a vertex of the cell
    there already, else new, numbered in order of first request (row by row, edge by edge)."""
    n, vertices = mesh.n_vertices, mesh.vertices
    _tetrahedra_corners(mesh, cells[:1], refinable)  # the first cell first: most meshes refused by it
    corners = _tetrahedra_corners(mesh, cells, refinable)
    offsets, ids = mesh.cell_vertex_lists
    sizes = offsets[cells + 1] - offsets[cells]
    owner, own = np.repeat(np.arange(cells.size), sizes), ids[segments(offsets[cells], sizes)]
    lattice = np.concatenate([corners, np.full((cells.size, 6), -1, dtype=np.int64)], axis=1)
    for k, (i, j) in enumerate(_EDGES):
        a, b = vertices[corners[:, i]], vertices[corners[:, j]]
        mid, length = 0.5 * (a + b), np.linalg.norm(a - b, axis=1)
        near = np.flatnonzero(np.linalg.norm(vertices[own] - mid[owner], axis=1) < TOL * length[owner])
        rows, at = np.unique(owner[near], return_index=True)
        lattice[rows, 4 + k] = own[near[at]]
    pairs = np.stack([corners[:, [i for i, _ in _EDGES]], corners[:, [j for _, j in _EDGES]]], axis=-1)
    keys = (pairs.min(axis=-1) * np.int64(n) + pairs.max(axis=-1))[lattice[:, 4:] < 0]  # row by row
    unique, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    rank = np.empty(unique.size, dtype=np.int64)
    rank[np.argsort(first)] = np.arange(unique.size)
    lattice[:, 4:][lattice[:, 4:] < 0] = n + rank[inverse.ravel()]
    by_id = unique[np.argsort(first)]
    ends = np.stack([by_id // n, by_id % n], axis=1).reshape(-1, 2)
    new_ids = n + np.arange(ends.shape[0])
    row, signed = _cell_entries(mesh, cells)
    faces = np.where(signed >= 0, signed, -signed - 1)
    counts = mesh.face_offsets[faces + 1] - mesh.face_offsets[faces]
    is_corner = (mesh.face_vertex_ids(faces)[:, None] == np.repeat(corners[row], counts, axis=0)).any(axis=1)
    on_three = np.add.reduceat(is_corner.astype(np.int64), np.cumsum(counts) - counts) == 3
    return lattice, vertices[ends].mean(axis=1), [(new_ids, ends)], (unique, n + rank), np.unique(faces[on_three]).size


def _on_edges(corners, pool, x):
    """The cycle of ``corners`` (vertex ids) with the vertices of ``pool`` lying inside its edges inserted."""
    a, b = x[corners], x[np.append(corners[1:], corners[0])]
    d = b - a  # (3, 3): edge vectors
    rel = x[pool][None, :, :] - a[:, None, :]  # (3, k, 3)
    length2 = (d * d).sum(axis=1)
    s = np.einsum("ekc,ec->ek", rel, d) / length2[:, None]
    off = ((rel - s[:, :, None] * d[:, None, :]) ** 2).sum(axis=2)
    inside = (s > TOL) & (s < 1 - TOL) & (off < TOL * TOL * length2[:, None])
    if not inside.any():
        return np.asarray(corners, dtype=np.int64)
    out = []
    for e in range(len(corners)):
        out.append(corners[e])
        out.extend(pool[inside[e]][np.argsort(s[e, inside[e]])].tolist())
    return np.array(out, dtype=np.int64)


def _normal(x, ids):
    """The (unnormalized) normal of the triangle x[ids]."""
    u, v = x[ids[1]] - x[ids[0]], x[ids[2]] - x[ids[0]]
    return np.array([u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]])


def whole_sides(mesh, lattice_row, cell: int, face_offsets, face_vertices, x):
    """(face, 4 triangles as stored) of the sides of a marked tetrahedron that are one face."""
    signed = mesh.cell_face_list(cell)
    faces = np.where(signed >= 0, signed, -signed - 1)
    corners = set(lattice_row[:4].tolist())
    pool = np.unique(np.concatenate([face_vertices[face_offsets[f] : face_offsets[f + 1]] for f in faces]))
    pool = np.union1d(pool, lattice_row)
    for f in faces.tolist():
        cycle = face_vertices[face_offsets[f] : face_offsets[f + 1]]
        mine = [v for v in cycle.tolist() if v in corners]
        if len(mine) < 3:
            continue
        p = [int(np.flatnonzero(lattice_row == v)[0]) for v in mine]
        triangles = [[p[0], _MID[p[0], p[1]], _MID[p[0], p[2]]], [p[1], _MID[p[1], p[2]], _MID[p[1], p[0]]]]
        triangles += [
            [p[2], _MID[p[2], p[0]], _MID[p[2], p[1]]],
            [_MID[p[0], p[1]], _MID[p[1], p[2]], _MID[p[2], p[0]]],
        ]
        rings = []
        for tri in triangles:
            ids = lattice_row[tri]
            ids = ids if _normal(x, ids) @ mesh.face_vector_areas[f] > 0 else ids[::-1]
            rings.append(_on_edges(ids, pool, x))
        yield f, rings


_DIAGONALS = [((0, 1), (2, 3)), ((0, 2), (1, 3)), ((0, 3), (1, 2))]  # the octahedron's, as edge pairs


_MID_TABLE = np.full((4, 4), -1, dtype=np.int64)
for (_i, _j), _k in _MID.items():
    _MID_TABLE[_i, _j] = _k


def split_tetrahedra_sides(mesh, lattice, cells, face_offsets, face_vertices, x):
    """(faces, (sizes, flat vertices, 4 per face) of their triangles, as stored) of the whole sides of
    the marked tetrahedra (``refine_polyhedra_kernels.tetrahedra_sides``; its twin: ``whole_sides``
    cell by cell), each split once (by the first marked tetrahedron it is a side of)."""
    sizes = mesh.cell_offsets[cells + 1] - mesh.cell_offsets[cells]
    signed = mesh.cell_faces[segments(mesh.cell_offsets[cells], sizes)]
    faces = np.where(signed >= 0, signed, -signed - 1)
    cell_start = np.concatenate([[0], np.cumsum(sizes)])
    args = (cell_start, faces, face_offsets, face_vertices, mesh.face_vector_areas, x, TOL)
    _, found, piece_sizes, flat = sides_kernel(lattice, _MID_TABLE, *args)
    first = np.sort(np.unique(found, return_index=True)[1])
    pieces = segments(4 * first, np.full(first.size, 4))
    piece_offsets = np.concatenate([[0], np.cumsum(piece_sizes)])
    flat = flat[segments(piece_offsets[pieces], piece_sizes[pieces])]
    return found[first], (piece_sizes[pieces], flat, np.full(first.size, 4, dtype=np.int64))


def _shortest_diagonal(x, lattice_row) -> int:
    """The octahedron's shortest diagonal (the first of equal ones), an index into _DIAGONALS."""
    length = [np.linalg.norm(x[lattice_row[_MID[a]]] - x[lattice_row[_MID[b]]]) for a, b in _DIAGONALS]
    return int(np.argmin(length))


def _children_of(diagonal: int) -> list:
    """The 8 children as lattice positions (4 each): the corner tetrahedra and the octahedron's 4
    around the given diagonal."""
    out = [[i] + [_MID[i, j] for j in range(4) if j != i] for i in range(4)]
    a, b = _DIAGONALS[diagonal]
    ring = [_MID[p] for p in _EDGES if p not in (a, b)]
    ordered = [ring[0]]  # the ring around the diagonal: neighbours share a corner
    while len(ordered) < 4:
        last = set(_EDGES[ordered[-1] - 4])
        ordered.append(next(q for q in ring if q not in ordered and last & set(_EDGES[q - 4])))
    out += [[_MID[a], _MID[b], ordered[k], ordered[(k + 1) % 4]] for k in range(4)]
    return out


def _children_corners(x, lattice_row):
    """The 8 children as lattice positions (4 each), the octahedron cut along its shortest diagonal."""
    return _children_of(_shortest_diagonal(x, lattice_row))


#: per diagonal and child: its lattice positions, the map from the parent's barycentric coordinates
#: to its own, and per left-out corner whether the face opposite is new (not on a side of the parent)
_CHILDREN = np.array([_children_of(k) for k in range(3)], dtype=np.int64)
_TO_CHILD = np.linalg.inv(np.swapaxes(_BARY[_CHILDREN], -1, -2))
_NEW_FACE = np.array(
    [
        [[not (np.abs(_BARY[np.delete(child, skip)]) < TOL).all(axis=0).any() for skip in range(4)] for child in row]
        for row in _CHILDREN
    ]
)


def tetrahedra_children(lattice, x, row_start, cycle_offsets, cycle_vertices):
    """The children of all marked tetrahedra at once (``refine_polyhedra_kernels.tetrahedra_children``;
    its twin: ``tetrahedron_children`` cell by cell): per face of a child (row, child, the parent's
    cycle it is or -1), and the new faces' (sizes, flat vertices)."""
    diagonal = np.array([_shortest_diagonal(x, row) for row in lattice], dtype=np.int64)
    args = (_CHILDREN, _TO_CHILD, _NEW_FACE, row_start, cycle_offsets, cycle_vertices, x, TOL)
    return children_kernel(lattice, diagonal, *args)


def tetrahedron_children(mesh, lattice_row, cycles: list, labels, x):
    """The outward faces and labels of the 8 children of a marked tetrahedron; ``cycles``: its
    (face, outward cycle) with its whole sides already split."""
    pool = np.union1d(np.concatenate([cycle for _, cycle in cycles]), lattice_row)
    corner_x = x[lattice_row[:4]]
    to_bary = np.linalg.inv(np.vstack([corner_x.T, np.ones(4)]))
    centres = np.array([x[cycle].mean(axis=0) for _, cycle in cycles])
    bary = (to_bary @ np.vstack([centres.T, np.ones(len(cycles))])).T  # (faces, 4)
    out = []
    for child in _children_corners(x, lattice_row):
        cb = _BARY[child]  # (4, 4) barycentric coordinates of the child's corners
        inside = np.linalg.solve(cb.T, bary.T).T  # the face centres in the child's barycentric coordinates
        faces, face_labels = [], []
        mine = np.flatnonzero((inside > -TOL).all(axis=1))
        faces += [cycles[k][1] for k in mine]
        face_labels += [labels[cycles[k][0]] for k in mine]
        for skip in range(4):
            tri = [child[q] for q in range(4) if q != skip]
            if (np.abs(_BARY[tri]) < TOL).all(axis=0).any():  # on a side of the parent: its faces are there
                continue
            ids = lattice_row[tri]
            outward = _normal(x, ids) @ (x[ids].mean(axis=0) - x[lattice_row[child]].mean(axis=0)) > 0
            ids = ids if outward else ids[::-1]
            faces.append(_on_edges(ids, pool, x))
            face_labels.append(-1)
        out.append((faces, face_labels))
    return out
