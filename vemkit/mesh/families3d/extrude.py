"""Prisms over a polygonal mesh (docs/reference/files.md): a 2D :class:`~vemkit.mesh.mesh.Mesh` extruded along z.

Every 2D cell K (any polygon: cut cells, holes around it, hanging nodes as extra vertices) becomes
``layers`` prisms K x [z_l, z_{l+1}], z_l = z0 + depth l / layers. A prism's faces are its two caps
(the polygon K at z_l, pointing down, and at z_{l+1}, pointing up) and one quadrilateral per edge
(a, b) of K: (a_l, b_l, b_{l+1}, a_{l+1}), which points out of K because K runs counter-clockwise.
A hanging node of the 2D mesh is a vertex of both neighbours' polygons, so the lateral faces of
both neighbours match and the prisms are closed. Lateral boundary faces keep the side name of
their 2D boundary edge; the end faces z = z0 and z = z0 + depth are named ``ends`` (default
``front``, ``back``). Vertex (l, v) is number l N + v (N 2D vertices); cell (l, K) is l M + K.
"""

from __future__ import annotations

import numpy as np

from vemkit.mesh.mesh import Mesh
from vemkit.mesh.polyhedral import PolyhedralMesh
from vemkit.mesh.polyhedral_build import from_face_soup

DEFAULT_ENDS = ("front", "back")


def _reversed_cells(mesh: Mesh) -> np.ndarray:
    """The cells' vertex lists, each reversed (clockwise), as one flat array."""
    sizes = mesh.cell_sizes
    start = np.repeat(mesh.cell_offsets[:-1], sizes)
    local = np.arange(mesh.cell_vertices.size) - start
    return mesh.cell_vertices[start + np.repeat(sizes, sizes) - 1 - local]


def _edge_labels(mesh: Mesh, names: list) -> np.ndarray:
    """The index in ``names`` of every half-edge's boundary part, or -1."""
    n = np.int64(mesh.n_vertices)
    he = mesh.half_edges
    key = he[:, 0] * n + he[:, 1]
    out = np.full(key.size, -1, dtype=np.int64)
    order = np.argsort(key)
    for k, name in enumerate(names):
        part = mesh.boundary[name]
        want = part[:, 0] * n + part[:, 1]
        pos = np.minimum(np.searchsorted(key, want, sorter=order), key.size - 1)
        hit = key[order[pos]] == want
        out[order[pos[hit]]] = k
    return out


def extrude(mesh: Mesh, layers: int, depth: float, z0: float = 0.0, ends=DEFAULT_ENDS) -> PolyhedralMesh:
    """The prisms over ``mesh`` in ``layers`` layers over z0 <= z <= z0 + depth (module doc)."""
    layers = int(layers)
    if layers < 1:
        raise ValueError(f"layers = {layers}: give at least one layer of prisms")
    if not depth > 0:
        raise ValueError(f"depth = {depth}: give a positive extrusion depth")
    ends = tuple(str(e) for e in ends)
    if len(ends) != 2:
        raise ValueError(f"ends = {ends}: give two names, for the faces z = z0 and z = z0 + depth")
    n, m = mesh.n_vertices, mesh.n_cells
    sizes = mesh.cell_sizes
    width = max(int(sizes.max()), 4)
    names = list(dict.fromkeys(list(mesh.boundary) + list(ends)))
    # one layer of prisms, vertex ids at level 0 (offset n for level 1): rows padded to width
    bottom = np.full((m, width), -1, np.int64)
    top = np.full((m, width), -1, np.int64)
    cell_of = np.repeat(np.arange(m), sizes)
    col = np.arange(mesh.cell_vertices.size) - np.repeat(mesh.cell_offsets[:-1], sizes)
    bottom[cell_of, col] = _reversed_cells(mesh)
    top[cell_of, col] = mesh.cell_vertices + n
    he = mesh.half_edges
    quads = np.full((he.shape[0], width), -1, np.int64)
    quads[:, :4] = np.stack([he[:, 0], he[:, 1], he[:, 1] + n, he[:, 0] + n], axis=1)
    rows = np.concatenate([bottom, top, quads])
    owner = np.concatenate([np.arange(m), np.arange(m), cell_of])
    kind = np.concatenate([np.zeros(m, int), np.ones(m, int), 2 + np.zeros(he.shape[0], int)])
    order = np.lexsort((kind, owner))  # per cell: bottom, top, then the edges in order
    rows, kind = rows[order], kind[order]
    lateral = np.concatenate([np.full(2 * m, -1), _edge_labels(mesh, list(mesh.boundary))])[order]
    soup, labels = [], []
    for layer in range(layers):
        soup.append(np.where(rows >= 0, rows + layer * n, -1))
        label = lateral.copy()
        if layer == 0:
            label[kind == 0] = names.index(ends[0])
        if layer == layers - 1:
            label[kind == 1] = names.index(ends[1])
        labels.append(label)
    table = np.concatenate(soup)
    z = z0 + depth * np.arange(layers + 1) / layers
    vertices = np.column_stack([np.tile(mesh.vertices, (layers + 1, 1)), np.repeat(z, n)])
    meta = {
        "family": "extrude",
        "base": dict(mesh.meta),
        "layers": layers,
        "depth": float(depth),
        "z0": float(z0),
        "ends": list(ends),
    }
    valid = table >= 0
    return from_face_soup(
        vertices,
        np.tile(sizes + 2, layers),
        valid.sum(axis=1),
        table[valid],
        np.concatenate(labels),
        tuple(names),
        meta,
    )
