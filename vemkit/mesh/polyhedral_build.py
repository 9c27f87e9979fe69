"""Building a :class:`~vemkit.mesh.polyhedral.PolyhedralMesh` from every cell's outward faces, vectorized.

A family lists, cell after cell, the faces of each cell as vertex cycles pointing out of it (a "face
soup": a face shared by two cells appears twice, once in each orientation). ``from_face_soup``
stores every face once (the orientation of its first appearance: a boundary face, which appears
once, is therefore stored outward), signs the cells' face lists (``-(f + 1)``: face f reversed) and
names the boundary faces from a label per appearance. No Python loop over cells or faces: a face is
recognised by its sorted vertex list (rows padded with -1, sorted lexicographically), and two
appearances run the same way when the vertex after the smallest one is the same.
``from_numbered_soup`` does the same for a soup whose faces are already known by a number per
appearance (the refinement of polyhedra, which knows where every face comes from).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from vemkit.mesh.polyhedral import PolyhedralMesh
from vemkit.mesh.polyhedral_kernels import successor_of_min


def csr_rows(offsets: np.ndarray, values: np.ndarray, fill: int = -1) -> np.ndarray:
    """``(k, max size)`` table of the CSR segments, padded with ``fill``."""
    sizes = np.diff(offsets)
    width = int(sizes.max()) if sizes.size else 0
    out = np.full((sizes.size, width), fill, dtype=np.int64)
    rows = np.repeat(np.arange(sizes.size, dtype=np.int64), sizes)
    out[rows, np.arange(values.size, dtype=np.int64) - offsets[:-1][rows]] = values
    return out


def same_faces(offsets: np.ndarray, vertices: np.ndarray) -> np.ndarray:
    """A number per CSR cycle, equal for cycles of the same vertices (the sorted vertex lists, padded
    with -1, ranked lexicographically)."""
    table = csr_rows(offsets, vertices)
    ordered = np.sort(np.where(table >= 0, table, np.iinfo(np.int64).max), axis=1)
    order = np.lexsort(ordered.T[::-1]) if ordered.shape[0] else np.zeros(0, np.int64)
    s = ordered[order]
    new = np.ones(order.size, dtype=bool)
    new[1:] = (s[1:] != s[:-1]).any(axis=1)
    group = np.empty(order.size, dtype=np.int64)
    group[order] = np.cumsum(new) - 1
    return group


def from_face_soup(
    vertices, cell_sizes, face_sizes, face_vertices, labels=None, label_names=(), meta=None
) -> PolyhedralMesh:
    """The mesh of cells given by their outward faces.

    ``cell_sizes`` (M,): number of faces of each cell; ``face_sizes`` (O,) and ``face_vertices``: the
    O face appearances (cell by cell) as vertex cycles, outward; ``labels`` (O,): an index into
    ``label_names`` per appearance, or -1 (the boundary faces labelled k form the part
    ``label_names[k]``; labels on interior faces are ignored)."""
    face_sizes = np.asarray(face_sizes, dtype=np.int64)
    flat = np.asarray(face_vertices, dtype=np.int64)
    offsets = np.concatenate([[0], np.cumsum(face_sizes)]).astype(np.int64)
    return from_numbered_soup(
        vertices, cell_sizes, face_sizes, flat, same_faces(offsets, flat), labels, label_names, meta
    )


def from_numbered_soup(
    vertices, cell_sizes, face_sizes, face_vertices, face_ids, labels=None, label_names=(), meta=None
) -> PolyhedralMesh:
    """``from_face_soup`` of a soup whose faces are known: ``face_ids`` (O,) a number per appearance,
    equal for the appearances of one face (the same vertices, in the same or the opposite order)."""
    face_sizes = np.asarray(face_sizes, dtype=np.int64)
    flat = np.asarray(face_vertices, dtype=np.int64)
    offsets = np.concatenate([[0], np.cumsum(face_sizes)]).astype(np.int64)
    _, first, face_of = np.unique(np.asarray(face_ids, dtype=np.int64), return_index=True, return_inverse=True)
    # number the faces by first appearance, so that the numbering follows the cells
    rank = np.empty(first.size, dtype=np.int64)
    by_appearance = np.argsort(first, kind="stable")
    rank[by_appearance] = np.arange(first.size)
    face_of = rank[face_of.ravel()]
    first = first[by_appearance]
    succ = successor_of_min(offsets, flat)
    same = succ == succ[first][face_of]
    signed = np.where(same, face_of, -face_of - 1)
    stored_sizes = face_sizes[first]
    stored = flat[segments(offsets[first], stored_sizes)]
    uses = np.bincount(face_of, minlength=first.size)
    boundary = {}
    if labels is not None:
        labels = np.asarray(labels, dtype=np.int64)
        once = uses[face_of] == 1
        for k, name in enumerate(label_names):
            faces = face_of[once & (labels == k)]
            if faces.size or name not in boundary:
                boundary[name] = np.concatenate([boundary.get(name, np.zeros(0, np.int64)), faces])
    cell_offsets = np.concatenate([[0], np.cumsum(np.asarray(cell_sizes, dtype=np.int64))])
    return PolyhedralMesh(
        np.asarray(vertices, dtype=float),
        np.concatenate([[0], np.cumsum(stored_sizes)]),
        stored,
        cell_offsets,
        signed,
        {k: np.sort(v) for k, v in boundary.items()},
        meta or {},
    )


def segments(starts: np.ndarray, sizes: np.ndarray) -> np.ndarray:
    """The indices start, ..., start + size - 1 of every segment, one after the other."""
    sizes = np.asarray(sizes, dtype=np.int64)
    total = int(sizes.sum())
    return np.repeat(np.asarray(starts, dtype=np.int64) - np.cumsum(sizes) + sizes, sizes) + np.arange(total)


def tag_box_faces(mesh: PolyhedralMesh, lower, upper, sides, tol: float = 1e-10) -> PolyhedralMesh:
    """Name the boundary faces of a mesh of the box [lower, upper]: ``sides`` are the names of the
    faces x = x0, x = x1, y = y0, y = y1, z = z0, z = z1 (a face belongs to a side when all its
    vertices lie on that plane). Faces on no plane are left unnamed."""
    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    bf = mesh.boundary_faces
    owner = np.repeat(np.arange(mesh.n_faces), np.diff(mesh.face_offsets))
    scale = tol * float(np.max(upper - lower))
    parts = {}
    for k, name in enumerate(sides):
        axis, value = divmod(k, 2)[0], (lower, upper)[k % 2][k // 2]
        off = np.abs(mesh.vertices[mesh.face_vertices, axis] - value) > scale
        on = np.bincount(owner, weights=off, minlength=mesh.n_faces) == 0
        faces = bf[on[bf]]
        parts[name] = np.concatenate([parts.get(name, np.zeros(0, np.int64)), faces])
    parts = {k: np.sort(v) for k, v in parts.items()}
    return replace(mesh, boundary=parts, meta=dict(mesh.meta))
