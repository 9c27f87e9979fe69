"""The plain numpy twins of the Numba kernels of ``polyhedral_kernels`` (the original vectorized
implementations of :class:`~vemkit.mesh.polyhedral.PolyhedralMesh`'s derived topology and face
geometry): the tests pin the kernels to them."""

from __future__ import annotations

import numpy as np


def segment_sum(values: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Sums of the rows of ``values`` over the CSR segments ``offsets`` (an empty segment sums to 0)."""
    m = offsets.size - 1
    owner = np.repeat(np.arange(m, dtype=np.int64), np.diff(offsets))
    cols = values.reshape(values.shape[0], -1)
    out = np.stack([np.bincount(owner, weights=cols[:, j], minlength=m) for j in range(cols.shape[1])], axis=1)
    return out.reshape((m,) + values.shape[1:])


def cell_vertex_lists_reference(mesh) -> tuple[np.ndarray, np.ndarray]:
    """CSR (offsets, vertices): the distinct vertices of every cell, in order of first appearance
    along its faces (faces as stored), by a sort of (cell, vertex) keys."""
    faces = np.where(mesh.cell_faces >= 0, mesh.cell_faces, -mesh.cell_faces - 1)
    sizes = np.diff(mesh.face_offsets)[faces]
    entry = np.repeat(np.arange(faces.size, dtype=np.int64), sizes)
    local = np.arange(entry.size, dtype=np.int64) - np.repeat(np.cumsum(sizes) - sizes, sizes)
    ids = mesh.face_vertices[mesh.face_offsets[faces][entry] + local]
    cells = np.repeat(np.arange(mesh.n_cells, dtype=np.int64), np.diff(mesh.cell_offsets))[entry]
    _, first = np.unique(cells * np.int64(max(mesh.n_vertices, 1)) + ids, return_index=True)
    first = np.sort(first)
    counts = np.bincount(cells[first], minlength=mesh.n_cells)
    return np.concatenate([[0], np.cumsum(counts)]).astype(np.int64), ids[first]


def face_geometry_reference(vertices, face_offsets, face_vertices) -> tuple[np.ndarray, np.ndarray]:
    """((F, 3) |F| n_F, (F, 3) area centroids) of every face as stored: half the sum of the cross
    products about the vertex mean; the centroid by the fan triangles from the vertex mean, signed
    along the face normal (non-convex planar faces too)."""
    n_faces = face_offsets.size - 1
    sizes = np.diff(face_offsets)
    owner = np.repeat(np.arange(n_faces, dtype=np.int64), sizes)
    nxt = np.arange(1, face_vertices.size + 1, dtype=np.int64)
    nxt[face_offsets[1:][sizes > 0] - 1] = face_offsets[:-1][sizes > 0]
    p = vertices[face_vertices]
    mean = segment_sum(p, face_offsets) / np.maximum(sizes, 1)[:, None]
    q = p - mean[owner]
    cross = np.cross(q, q[nxt])
    va = 0.5 * segment_sum(cross, face_offsets)
    unit = va / np.maximum(np.linalg.norm(va, axis=1), np.finfo(float).tiny)[:, None]
    a = np.einsum("ij,ij->i", cross, unit[owner])
    total = np.bincount(owner, weights=a, minlength=n_faces)
    moment = segment_sum((q + q[nxt]) / 3.0 * a[:, None], face_offsets)
    ok = np.abs(total) > 0
    shift = np.zeros_like(mean)
    shift[ok] = moment[ok] / total[ok, None]
    return va, mean + shift


def successor_of_min_reference(offsets: np.ndarray, vertices: np.ndarray) -> np.ndarray:
    """The vertex after the smallest one in every CSR cycle (cycles padded to a table)."""
    sizes = np.diff(offsets)
    rows = np.repeat(np.arange(sizes.size, dtype=np.int64), sizes)
    table = np.full((sizes.size, int(sizes.max()) if sizes.size else 0), -1, dtype=np.int64)
    table[rows, np.arange(vertices.size, dtype=np.int64) - offsets[:-1][rows]] = vertices
    at = np.argmin(np.where(table >= 0, table, np.iinfo(np.int64).max), axis=1)
    return table[np.arange(table.shape[0]), (at + 1) % np.maximum(sizes, 1)]
