"""The polygonal mesh: plain arrays, nothing else.

A mesh is
- ``vertices``: ``(N, 2)`` float64 coordinates;
- ``cell_offsets`` ``(M + 1,)`` and ``cell_vertices`` ``(offsets[-1],)`` int64: polygon ``K`` has the
  vertices ``cell_vertices[cell_offsets[K]:cell_offsets[K + 1]]`` in counter-clockwise order
  (CSR form). Every vertex of a polygon is listed, hanging nodes included (docs/reference/mathematics.md);
- ``boundary``: named boundary parts, each a ``(k, 2)`` int64 array of boundary edges given as
  vertex pairs ``(a, b)`` in the counter-clockwise order in which they appear in their cell;
- ``meta``: how the mesh was made (family, n, seed, ...), stored with every result.

Derived topology (``edges``, ``edge_cells``, ...) is computed on demand and cached. The members of
:class:`~vemkit.mesh.interface.MeshInterface` (the facets are the edges) are among them, as in 3D.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numba
import numpy as np

from vemkit.config.domain import UNIT_SQUARE_SIDE_LINES
from vemkit.exceptions import MeshError
from vemkit.mesh.geometry import areas_centroids, indexed_polygon_areas
from vemkit.mesh.interface import SharedMeshMembers


@dataclass(frozen=True, eq=False)
class Mesh(SharedMeshMembers):
    vertices: np.ndarray
    cell_offsets: np.ndarray
    cell_vertices: np.ndarray
    boundary: dict = field(default_factory=dict)
    meta: dict = field(default_factory=dict)

    dimension = 2
    array_fields = (("vertices", np.float64), ("cell_offsets", np.int64), ("cell_vertices", np.int64))
    boundary_part_shape = (-1, 2)  # vertex pairs

    # -- sizes -----------------------------------------------------------------------------
    @property
    def n_vertices(self) -> int:
        return self.vertices.shape[0]

    @property
    def n_cells(self) -> int:
        return self.cell_offsets.shape[0] - 1

    @property
    def n_dofs(self) -> int:
        """Two displacement components per vertex, interleaved: dof = 2 * vertex + component."""
        return 2 * self.n_vertices

    @cached_property
    def cell_sizes(self) -> np.ndarray:
        return np.diff(self.cell_offsets)

    @property
    def cell_vertex_lists(self) -> tuple[np.ndarray, np.ndarray]:
        """CSR (offsets, vertices) of every cell's vertices: ``(cell_offsets, cell_vertices)``, CCW."""
        return self.cell_offsets, self.cell_vertices

    def cell(self, k: int) -> np.ndarray:
        return self.cell_vertices[self.cell_offsets[k] : self.cell_offsets[k + 1]]

    # -- derived topology --------------------------------------------------------------------
    @cached_property
    def _plain_offsets(self) -> bool:
        """Whether the offsets are a plain CSR of all the cell vertices (from 0, increasing, to the end):
        the topology kernels' condition (``validate_mesh`` names what is wrong otherwise)."""
        o = self.cell_offsets
        return bool(o.size > 1 and o[0] == 0 and o[-1] == self.cell_vertices.size and (o[1:] > o[:-1]).all())

    @cached_property
    def half_edges(self) -> np.ndarray:
        """``(H, 2)`` directed edges ``(a, b)`` of every cell, in cell order (CCW)."""
        offsets = self.cell_offsets
        if self._plain_offsets:
            return half_edge_pairs(offsets, self.cell_vertices)
        nxt = np.arange(1, self.cell_vertices.size + 1, dtype=np.int64)  # validate_mesh names the bad offsets
        last = offsets[1:] - 1
        nxt[last] = offsets[:-1]
        return np.stack([self.cell_vertices, self.cell_vertices[nxt]], axis=1)

    @cached_property
    def half_edge_cells(self) -> np.ndarray:
        return np.repeat(np.arange(self.n_cells, dtype=np.int64), self.cell_sizes)

    @cached_property
    def _edge_table(self):
        """(edge of every half-edge, first half-edge of every edge): edges numbered in the order of
        their (smaller, larger) vertex pair (``edge_table_numpy``; ``edge_table`` in one pass)."""
        if self.cell_vertices.size and (self.cell_vertices.min() < 0 or self.cell_vertices.max() >= self.n_vertices):
            return edge_table_numpy(self.half_edges, self.n_vertices)  # validate_mesh names the bad index
        return edge_table(self.half_edges, self.n_vertices)

    @cached_property
    def half_edge_edge(self) -> np.ndarray:
        """Edge index of every half-edge."""
        return self._edge_table[0]

    @cached_property
    def edge_first_half_edges(self) -> np.ndarray:
        """``(E,)`` the first (smallest) index of every edge's half-edges."""
        return self._edge_table[1]

    @cached_property
    def edges(self) -> np.ndarray:
        """``(E, 2)`` undirected edges, each oriented as in its first cell."""
        return self.half_edges[self.edge_first_half_edges]

    @cached_property
    def edge_cells(self) -> np.ndarray:
        """``(E, 2)`` the one or two cells of every edge; ``-1`` where there is no second cell.

        Column 0 is the cell in which the edge runs as in ``edges``.
        """
        first = self.edge_first_half_edges
        if self._plain_offsets:
            return cells_of_edges(self.cell_offsets, self.half_edge_edge, first)
        out = np.full((first.shape[0], 2), -1, dtype=np.int64)
        out[:, 0] = self.half_edge_cells[first]
        other = np.ones(self.half_edges.shape[0], dtype=bool)
        other[first] = False
        out[self.half_edge_edge[other], 1] = self.half_edge_cells[other]
        return out

    @cached_property
    def boundary_edges(self) -> np.ndarray:
        """``(B, 2)`` edges that belong to one cell only, oriented CCW as in that cell."""
        return self.edges[self.edge_cells[:, 1] < 0]

    # -- geometry -------------------------------------------------------------------------
    @cached_property
    def cell_areas(self) -> np.ndarray:
        """Signed (shoelace) area of every cell: positive for counter-clockwise polygons."""
        return indexed_polygon_areas(self.vertices, self.cell_offsets, self.cell_vertices)

    @cached_property
    def cell_diameters(self) -> np.ndarray:
        """h_K = diam(K): the largest vertex-to-vertex distance of each cell."""
        out = np.zeros(self.n_cells)
        for size in np.unique(self.cell_sizes):
            cells = np.flatnonzero(self.cell_sizes == size)
            idx = self.cell_offsets[cells][:, None] + np.arange(size)
            pts = self.vertices[self.cell_vertices[idx]]
            d = np.linalg.norm(pts[:, :, None, :] - pts[:, None, :, :], axis=-1)
            out[cells] = d.reshape(len(cells), -1).max(axis=1)
        return out

    @property
    def h(self) -> float:
        return float(self.cell_diameters.max()) if self.n_cells else 0.0

    # -- the mesh interface (vemkit.mesh.interface): the facets are the edges -------------------
    @cached_property
    def facets(self) -> tuple[np.ndarray, np.ndarray]:
        """CSR (offsets, vertices) of the edges, each ``(a, b)`` as in ``edges``."""
        return np.arange(0, 2 * self.edges.shape[0] + 1, 2, dtype=np.int64), self.edges.ravel()

    @property
    def facet_cells(self) -> np.ndarray:
        """``edge_cells``: column 0 the cell in which the edge runs counter-clockwise (it points out of it)."""
        return self.edge_cells

    @cached_property
    def cell_facet_lists(self) -> tuple[np.ndarray, np.ndarray]:
        """CSR (``cell_offsets``, signed edges): a cell's half-edges in order, edge e where it runs as
        in ``edges``, ``-(e + 1)`` where it runs the other way."""
        forward = self.edge_first_half_edges[self.half_edge_edge] == np.arange(self.half_edge_edge.size)
        return self.cell_offsets, np.where(forward, self.half_edge_edge, -self.half_edge_edge - 1)

    @cached_property
    def facet_vector_areas(self) -> np.ndarray:
        """``(E, 2)``: the tangent b - a of every edge turned clockwise, |e| n_e (outward for column 0
        of ``edge_cells``)."""
        tangent = self.vertices[self.edges[:, 1]] - self.vertices[self.edges[:, 0]]
        return np.stack([tangent[:, 1], -tangent[:, 0]], axis=1)

    @cached_property
    def facet_centroids(self) -> np.ndarray:
        """``(E, 2)`` edge midpoints."""
        return 0.5 * (self.vertices[self.edges[:, 0]] + self.vertices[self.edges[:, 1]])

    @property
    def cell_volumes(self) -> np.ndarray:
        """``cell_areas`` (signed; positive counter-clockwise)."""
        return self.cell_areas

    @cached_property
    def cell_centroids(self) -> np.ndarray:
        """``(M, 2)`` area centroids (``geometry.areas_centroids``, the shoelace formula)."""
        return areas_centroids(self.vertices[self.cell_vertices], self.cell_offsets)[1]

    @cached_property
    def boundaries(self) -> dict:
        """``{side: edge ids}``: the named sides' vertex pairs as indices into ``edges``; MeshError
        naming the side of a pair that is no edge."""
        out = {}
        for name, pairs in self.boundary.items():
            try:
                out[name] = edge_indices(self, pairs)
            except MeshError as error:
                raise MeshError(f"boundary part {name!r}: {error}", key=name) from None
        return out

    def boundary_vertices(self, name: str) -> np.ndarray:
        """Sorted unique vertices of a named boundary part."""
        return np.unique(self.boundary[name])

    def side_edges(self, name: str) -> np.ndarray:
        """``(k, 2)`` the edges of a named side as vertex pairs: its ``boundary`` entry."""
        return self.boundary[name]

    def with_boundary(self, **parts) -> "Mesh":
        b = dict(self.boundary)
        b.update(parts)
        return Mesh(self.vertices, self.cell_offsets, self.cell_vertices, b, dict(self.meta))


def from_polygons(vertices, polygons, boundary=None, meta=None) -> Mesh:
    """Build a mesh from a list of vertex-index sequences (one per polygon)."""
    sizes = np.array([len(p) for p in polygons], dtype=np.int64)
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    flat = np.concatenate([np.asarray(p, dtype=np.int64) for p in polygons]) if len(polygons) else np.zeros(0, np.int64)
    return Mesh(np.asarray(vertices, float), offsets, flat, boundary or {}, meta or {})


def tag_box_boundary(mesh: Mesh, lower=(0.0, 0.0), upper=(1.0, 1.0), tol=1e-12) -> Mesh:
    """Name the boundary edges of a mesh of the box [lower, upper]: left, right, bottom, top.

    An edge belongs to a side when both its vertices lie on that side.
    """
    be = mesh.boundary_edges
    p, q = mesh.vertices[be[:, 0]], mesh.vertices[be[:, 1]]
    scale = tol * max(1.0, float(np.max(np.abs(np.subtract(upper, lower)))))
    parts = {}
    for name, (axis, fraction) in UNIT_SQUARE_SIDE_LINES.items():  # left, right, bottom, top
        value = lower[axis] + fraction * (upper[axis] - lower[axis])
        on = (np.abs(p[:, axis] - value) <= scale) & (np.abs(q[:, axis] - value) <= scale)
        parts[name] = be[on]
    return mesh.with_boundary(**parts)


def edge_indices(mesh: Mesh, pairs) -> np.ndarray:
    """Index in ``mesh.edges`` of every vertex pair (k, 2), in either orientation; MeshError (a
    ValueError) naming a pair that is no edge."""
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    nv = np.int64(mesh.n_vertices)
    keys = np.minimum(mesh.edges[:, 0], mesh.edges[:, 1]) * nv + np.maximum(mesh.edges[:, 0], mesh.edges[:, 1])
    order = np.argsort(keys)
    want = np.minimum(pairs[:, 0], pairs[:, 1]) * nv + np.maximum(pairs[:, 0], pairs[:, 1])
    pos = np.minimum(np.searchsorted(keys, want, sorter=order), keys.size - 1)
    found = order[pos] if keys.size else np.zeros(0, dtype=np.int64)
    if np.any(keys[found] != want):
        bad = pairs[np.flatnonzero(keys[found] != want)[0]]
        raise MeshError(f"({bad[0]}, {bad[1]}) is not an edge of the mesh")
    return found


def edge_table_numpy(half_edges: np.ndarray, n_vertices: int):
    """``Mesh._edge_table`` by a stable sort of the keys low * N + high (the twin of ``edge_table``)."""
    lo = np.minimum(half_edges[:, 0], half_edges[:, 1])
    hi = np.maximum(half_edges[:, 0], half_edges[:, 1])
    key = lo * np.int64(n_vertices) + hi
    order = np.argsort(key, kind="stable")
    skey = key[order]
    first = np.ones(skey.size, dtype=bool)
    first[1:] = skey[1:] != skey[:-1]
    edge_of_sorted = np.cumsum(first) - 1
    half_edge_edge = np.empty_like(edge_of_sorted)
    half_edge_edge[order] = edge_of_sorted
    return half_edge_edge, order[first]


@numba.njit(cache=True)
def half_edge_pairs(offsets, cell_vertices):
    """``Mesh.half_edges`` of CSR cells (offsets from 0 to len(cell_vertices), increasing): each
    vertex paired with the next of its cell, the last with the first."""
    out = np.empty((cell_vertices.shape[0], 2), dtype=np.int64)
    for k in range(offsets.shape[0] - 1):
        s, e = offsets[k], offsets[k + 1]
        for h in range(s, e):
            out[h, 0] = cell_vertices[h]
            out[h, 1] = cell_vertices[h + 1 if h + 1 < e else s]
    return out


@numba.njit(cache=True)
def cells_of_edges(offsets, half_edge_edge, edge_first_half_edges):
    """``Mesh.edge_cells`` of plain CSR cells: column 0 the cell of an edge's first half-edge, column 1
    the cell of its other one (the last, if more), -1 if none."""
    out = np.full((edge_first_half_edges.shape[0], 2), -1, dtype=np.int64)
    for k in range(offsets.shape[0] - 1):
        for h in range(offsets[k], offsets[k + 1]):
            e = half_edge_edge[h]
            out[e, 0 if edge_first_half_edges[e] == h else 1] = k
    return out


#: a vertex's half-edges are ordered by insertion up to this many, by a merge sort above
INSERTION_SORT_MAX = 32


@numba.njit(cache=True)
def edge_table(half_edges, n_vertices):
    """``edge_table_numpy`` by buckets: the half-edges by their smaller vertex (in index order), each
    bucket ordered stably by the larger vertex; the same order as the stable sort of the keys."""
    h = half_edges.shape[0]
    lo = np.minimum(half_edges[:, 0], half_edges[:, 1])
    hi = np.maximum(half_edges[:, 0], half_edges[:, 1])
    ptr = np.zeros(n_vertices + 1, dtype=np.int64)
    for i in range(h):
        ptr[lo[i] + 1] += 1
    for v in range(n_vertices):
        ptr[v + 1] += ptr[v]
    order = np.empty(h, dtype=np.int64)
    fill = ptr[:-1].copy()
    for i in range(h):
        order[fill[lo[i]]] = i
        fill[lo[i]] += 1
    for v in range(n_vertices):
        s, e = ptr[v], ptr[v + 1]
        if e - s > INSERTION_SORT_MAX:
            order[s:e] = order[s:e][np.argsort(hi[order[s:e]], kind="mergesort")]
            continue
        for t in range(s + 1, e):
            item, u = order[t], t
            while u > s and hi[order[u - 1]] > hi[item]:
                order[u] = order[u - 1]
                u -= 1
            order[u] = item
    half_edge_edge = np.empty(h, dtype=np.int64)
    firsts = np.empty(h, dtype=np.int64)
    edge = -1
    for t in range(h):
        i = order[t]
        if t == 0 or lo[i] != lo[order[t - 1]] or hi[i] != hi[order[t - 1]]:
            edge += 1
            firsts[edge] = i
        half_edge_edge[i] = edge
    return half_edge_edge, firsts[: edge + 1].copy()
