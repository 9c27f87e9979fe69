"""Global k = 2 stiffness matrix: the degrees of freedom of Section 3.1 numbered and assembled into CSR.

Nodes: every vertex (node v), every edge (node N_v + e, e the index in ``mesh.edges``) and every
cell (node N_v + N_e + c); each node carries the two components of its degree of freedom (vertex
value, edge mean, cell mean; see ``vemkit.vem.element_k2``), scalar dof = 2 * free_index + component.
Cell c lists its 2n + 1 nodes as its n vertices (CCW), its n edges (edge i from vertex i to i + 1:
``mesh.half_edge_edge``) and itself, which is the local order of the element kernel.

Clamped nodes (Dirichlet, (2.4)) are eliminated while assembling, exactly as for k = 1
(``vemkit.vem.assembly``; the pattern is built by ``vemkit.vem.pattern_k2``): a Dirichlet side
clamps its vertices and its edges. Prescribed non-zero values enter the load through
``dirichlet_lift``; ``interpolate_k2`` gives the degrees of freedom of a field (Dirichlet data,
exact solutions).

Dof order: ``NodeMapK2.from_clamped_edges`` numbers the free nodes in the order in which they first
appear in the cells taken along a Morton curve (locality for the parallel row-chunk scatter and
the caches); ``NodeMapK2.natural`` keeps the node order. Vectors always go through ``restrict`` and
``expand``.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numba
import numpy as np

from vemkit.mesh.mesh import Mesh
from vemkit.vem.assembly import ROW_CHUNKS, add_block, cells_of_rows, chunk_rows, sorted_csr, vertex_cells
from vemkit.vem.element import stabilization_code
from vemkit.vem.element_k2 import largest_cell
from vemkit.vem.pattern_k2 import dof_pattern_k2
from vemkit.vem.stiffness_k2 import element_stiffness_k2, stiffness_workspace


_CELL_NODES: "weakref.WeakKeyDictionary[Mesh, tuple]" = weakref.WeakKeyDictionary()


def cell_nodes(mesh: Mesh) -> tuple[np.ndarray, np.ndarray]:
    """CSR (offsets, nodes) of the 2n + 1 nodes of every cell in the kernel's local order (cached
    per mesh, read-only)."""
    if mesh not in _CELL_NODES:
        offsets, nodes = _cell_nodes(mesh)
        offsets.flags.writeable = False
        nodes.flags.writeable = False
        _CELL_NODES[mesh] = (offsets, nodes)
    return _CELL_NODES[mesh]


def _cell_nodes(mesh: Mesh) -> tuple[np.ndarray, np.ndarray]:
    nv, ne = mesh.n_vertices, mesh.edges.shape[0]
    sizes = mesh.cell_sizes
    offsets = np.concatenate([[0], np.cumsum(2 * sizes + 1)]).astype(np.int64)
    nodes = np.empty(offsets[-1], dtype=np.int64)
    # position of half-edge p (cell c, local i) in the node list: offsets2[c] + i and + n + i
    cell_of = mesh.half_edge_cells
    local = np.arange(mesh.cell_vertices.size) - mesh.cell_offsets[cell_of]
    nodes[offsets[cell_of] + local] = mesh.cell_vertices
    nodes[offsets[cell_of] + sizes[cell_of] + local] = nv + mesh.half_edge_edge
    nodes[offsets[1:] - 1] = nv + ne + np.arange(mesh.n_cells)
    return offsets, nodes


def edge_indices(mesh: Mesh, pairs) -> np.ndarray:
    """Index in ``mesh.edges`` of every vertex pair (k, 2), in either orientation."""
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    nv = np.int64(mesh.n_vertices)
    keys = np.minimum(mesh.edges[:, 0], mesh.edges[:, 1]) * nv + np.maximum(mesh.edges[:, 0], mesh.edges[:, 1])
    order = np.argsort(keys)
    want = np.minimum(pairs[:, 0], pairs[:, 1]) * nv + np.maximum(pairs[:, 0], pairs[:, 1])
    pos = np.minimum(np.searchsorted(keys, want, sorter=order), keys.size - 1)
    found = order[pos] if keys.size else np.zeros(0, dtype=np.int64)
    if np.any(keys[found] != want):
        bad = pairs[np.flatnonzero(keys[found] != want)[0]]
        raise ValueError(f"({bad[0]}, {bad[1]}) is not an edge of the mesh")
    return found


def morton_order(mesh: Mesh) -> np.ndarray:
    """The cells sorted along a Z-order (Morton) curve of their vertex means: neighbours stay near."""
    count = np.maximum(mesh.cell_sizes, 1)
    centre = np.stack([np.bincount(mesh.half_edge_cells, mesh.vertices[mesh.cell_vertices, k], mesh.n_cells) / count
                       for k in range(2)], axis=1)
    lo, hi = centre.min(axis=0), centre.max(axis=0)
    q = ((centre - lo) / np.maximum(hi - lo, 1e-300) * 65535).astype(np.uint64)
    code = np.zeros(mesh.n_cells, dtype=np.uint64)
    for bit in range(16):
        for k in range(2):
            code |= ((q[:, k] >> np.uint64(bit)) & np.uint64(1)) << np.uint64(2 * bit + k)
    return np.argsort(code, kind="stable")


@numba.njit(cache=True)
def first_appearance(nodes, n_nodes):
    """The nodes in the order of their first appearance in a list of cell nodes: the dof numbering.

    Rows of one cell then lie close together, so the row chunks of the parallel assembly share few
    cells (vertices, edges and cells numbered apart would make every cell straddle three chunks),
    and with the cells in Morton order the rows a cell writes stay in cache."""
    seen = np.zeros(n_nodes, dtype=np.bool_)
    order = np.empty(n_nodes, dtype=np.int64)
    k = 0
    for p in range(nodes.shape[0]):
        if not seen[nodes[p]]:
            seen[nodes[p]] = True
            order[k] = nodes[p]
            k += 1
    return order[:k]


@dataclass(frozen=True)
class NodeMapK2:
    """Which k = 2 nodes carry unknowns. ``free_index[node]`` is -1 for a clamped node."""

    n_vertices: int
    n_edges: int
    n_cells: int
    free_nodes: np.ndarray
    free_index: np.ndarray
    condensed: bool = False  # cell nodes eliminated by static condensation (``condense_load``, ``recover_cell_means``)

    @property
    def n_nodes(self) -> int:
        return self.n_vertices + self.n_edges + self.n_cells

    @property
    def n_free(self) -> int:
        return 2 * self.free_nodes.size

    @classmethod
    def from_clamped_edges(cls, mesh: Mesh, clamped_edges=()) -> "NodeMapK2":
        """Clamp the vertices and the edge nodes of the given boundary edges (vertex pairs (k, 2)).

        The free nodes are numbered in the order of their first appearance in the cells (see
        ``first_appearance``): always go through ``restrict`` / ``expand``."""
        nv, ne, nc = mesh.n_vertices, mesh.edges.shape[0], mesh.n_cells
        pairs = np.asarray(clamped_edges, dtype=np.int64).reshape(-1, 2)
        clamped = np.zeros(nv + ne + nc, dtype=bool)
        if pairs.size:
            clamped[pairs.ravel()] = True
            clamped[nv + edge_indices(mesh, pairs)] = True
        return cls.from_clamped_nodes(mesh, clamped)

    @classmethod
    def from_clamped_nodes(cls, mesh: Mesh, clamped: np.ndarray, condensed: bool = False) -> "NodeMapK2":
        """Clamp the nodes where the (n_nodes,) mask ``clamped`` is True (numbering as above).

        ``condensed``: the cell nodes carry no unknowns either; they are eliminated cell by cell
        (static condensation, exact: a cell node couples only with the nodes of its own cell)."""
        nv, ne, nc = mesh.n_vertices, mesh.edges.shape[0], mesh.n_cells
        free = ~np.asarray(clamped, dtype=bool)
        if condensed:
            free[nv + ne:] = False
        offsets, nodes = cell_nodes(mesh)
        cells = morton_order(mesh)
        sizes = offsets[cells + 1] - offsets[cells]
        idx = np.repeat(offsets[cells] - np.cumsum(sizes) + sizes, sizes) + np.arange(int(sizes.sum()))
        order = first_appearance(nodes[idx], free.size)
        free_nodes = order[free[order]]
        free_index = np.full(free.size, -1, dtype=np.int64)
        free_index[free_nodes] = np.arange(free_nodes.size)
        return cls(nv, ne, nc, free_nodes, free_index, condensed)

    @classmethod
    def natural(cls, mesh: Mesh) -> "NodeMapK2":
        """Every node free, dof = 2 * node + component (vertices, then edges, then cells)."""
        nv, ne, nc = mesh.n_vertices, mesh.edges.shape[0], mesh.n_cells
        every = np.arange(nv + ne + nc, dtype=np.int64)
        return cls(nv, ne, nc, every, every.copy())

    @classmethod
    def from_sides(cls, mesh: Mesh, sides) -> "NodeMapK2":
        """Clamp the named boundary parts (as ``dirichlet: [right]`` in a scene)."""
        edges = [mesh.boundary[s] for s in sides]
        return cls.from_clamped_edges(mesh, np.concatenate(edges) if edges else np.zeros((0, 2), np.int64))

    @property
    def clamped_nodes(self) -> np.ndarray:
        return np.flatnonzero(self.free_index < 0)

    def expand(self, u_free: np.ndarray, clamped_values: np.ndarray | None = None) -> np.ndarray:
        """Free-dof vector -> (n_nodes, 2), clamped nodes zero or taken from ``clamped_values`` (n_nodes, 2)."""
        u = np.zeros((self.n_nodes, 2)) if clamped_values is None else np.array(clamped_values, float)
        u[self.free_nodes] = np.asarray(u_free).reshape(-1, 2)
        return u

    def restrict(self, node_values: np.ndarray) -> np.ndarray:
        """(n_nodes, 2) -> free-dof vector."""
        return np.ascontiguousarray(np.asarray(node_values)[self.free_nodes]).ravel()


@numba.njit(cache=True)
def _cell_stiffness(c, vertices, offsets, nodes, lam, mu, stab, px, py, K, work):
    """Element matrix of cell c into K (the kernel's local order); returns its vertex count n."""
    start = offsets[c]
    n = (offsets[c + 1] - start - 1) // 2
    for i in range(n):
        px[i] = vertices[nodes[start + i], 0]
        py[i] = vertices[nodes[start + i], 1]
    # the work arrays are passed whole (C-contiguous, faster loops); the kernel uses their leading part
    element_stiffness_k2(px[:n], py[:n], lam, mu, stab, K, work)
    return n


@numba.njit(cache=True)
def condense_cell(K, n):
    """Static condensation of the cell node (local node 2n, scalars 4n, 4n + 1) in the element matrix
    K: K_bb -= K_bc K_cc^-1 K_cb on the 4n boundary scalars (vertices and edges)."""
    c = 4 * n
    a, b, d, e = K[c, c], K[c, c + 1], K[c + 1, c], K[c + 1, c + 1]
    det = a * e - b * d
    for i in range(c):
        w0 = (K[i, c] * e - K[i, c + 1] * d) / det  # (K_bc K_cc^-1)[i, :]
        w1 = (K[i, c + 1] * a - K[i, c] * b) / det
        for j in range(c):
            K[i, j] -= w0 * K[c, j] + w1 * K[c + 1, j]


@numba.njit(cache=True)
def _element_workspace(nmax):
    """(K, work, px, py): the work arrays of one k = 2 element stiffness for up to nmax vertices."""
    mmax = 4 * nmax + 2
    return np.empty((mmax, mmax)), stiffness_workspace(nmax), np.empty(nmax), np.empty(nmax)


@numba.njit(cache=True)
def _scatter_rows_k2(row_lo, row_hi, vertices, offsets, nodes, free_index, free_nodes, nc_ptr, nc, indptr, indices, lam, mu, stab, condense, nmax, data):
    """Add the rows row_lo <= r < row_hi of every element stiffness touching them (as for k = 1)."""
    K, work, px, py = _element_workspace(nmax)
    rows = np.empty(2 * nmax + 1, dtype=np.int64)
    order = np.empty(2 * nmax + 1, dtype=np.int64)
    for c in cells_of_rows(row_lo, row_hi, free_nodes, nc_ptr, nc, offsets, nodes, free_index):
        start = offsets[c]
        size = offsets[c + 1] - start
        for i in range(size):
            rows[i] = free_index[nodes[start + i]]
        n = _cell_stiffness(c, vertices, offsets, nodes, lam, mu, stab, px, py, K, work)
        if condense:
            condense_cell(K, n)
        _add_rows(row_lo, row_hi, rows, size, order, K, indptr, indices, data)


@numba.njit(cache=True)
def _add_rows(row_lo, row_hi, rows, size, order, K, indptr, indices, data):
    """data += the rows of K whose node rows lie in [row_lo, row_hi): the cell's free columns are
    sorted once, then each CSR row is found by one merge walk along its sorted column list (the
    even entries 2c of the scalar row 2r)."""
    count = 0
    for j in range(size):  # insertion sort of the free local columns by global row
        if rows[j] < 0:
            continue
        t = count
        while t > 0 and rows[order[t - 1]] > rows[j]:
            order[t] = order[t - 1]
            t -= 1
        order[t] = j
        count += 1
    for i in range(size):
        r = rows[i]
        if r < row_lo or r >= row_hi:
            continue
        q = indptr[2 * r]
        deg2 = indptr[2 * r + 1] - q
        for s in range(count):
            j = order[s]
            while indices[q] < 2 * rows[j]:
                q += 2
            add_block(data, q, q + deg2, K, i, j)


@numba.njit(cache=True, parallel=True)
def scatter_stiffness_k2(vertices, offsets, nodes, free_index, free_nodes, nc_ptr, nc, indptr, indices, lam, mu, stab, condense, data):
    """Every k = 2 element stiffness (3.9) added into the CSR ``data`` (zeroed): contiguous row
    chunks, one thread each, a thread writing only its own rows (cells straddling two chunks are
    computed twice)."""
    nmax = largest_cell(offsets)
    for chunk in numba.prange(ROW_CHUNKS):
        lo, hi = chunk_rows(chunk, free_nodes.shape[0])
        _scatter_rows_k2(lo, hi, vertices, offsets, nodes, free_index, free_nodes, nc_ptr, nc, indptr, indices,
                         lam, mu, stab, condense, nmax, data)


def stiffness_matrix_k2(mesh: Mesh, lam: float, mu: float, stabilization: str, nodes: NodeMapK2 | None = None):
    """The global k = 2 VEM stiffness matrix on the free dofs of ``nodes`` (CSR), in their order.

    ``nodes`` None: every node free in the natural order (``NodeMapK2.natural``). With
    ``nodes.condensed`` it is the Schur complement on the vertex and edge dofs (``condense_cell``)."""
    if nodes is None:
        nodes = NodeMapK2.natural(mesh)
    stab = stabilization_code(stabilization)
    offsets, cn = cell_nodes(mesh)
    nc_ptr, nc = vertex_cells(offsets, cn, nodes.n_nodes)
    indptr, indices = dof_pattern_k2(offsets, cn, nc_ptr, nc, nodes.free_nodes, nodes.free_index)
    data = np.zeros(indices.shape[0])  # fresh zero pages from the system: no zeroing pass
    scatter_stiffness_k2(mesh.vertices, offsets, cn, nodes.free_index, nodes.free_nodes, nc_ptr, nc,
                         indptr, indices, float(lam), float(mu), stab, nodes.condensed, data)
    return sorted_csr(data, indices, indptr, nodes.n_free)


@numba.njit(cache=True)
def _lift(vertices, offsets, nodes, free_index, values, lam, mu, stab, condense, out):
    """out[free] -= K_fc u_c over the cells that touch a clamped node with a non-zero value."""
    nmax = largest_cell(offsets)
    K, work, px, py = _element_workspace(nmax)
    for c in range(offsets.shape[0] - 1):
        start = offsets[c]
        size = offsets[c + 1] - start
        touched = False
        for i in range(size):
            g = nodes[start + i]
            if free_index[g] < 0 and (values[g, 0] != 0.0 or values[g, 1] != 0.0):
                touched = True
        if not touched:
            continue
        n = _cell_stiffness(c, vertices, offsets, nodes, lam, mu, stab, px, py, K, work)
        if condense:
            condense_cell(K, n)
        for i in range(size):
            r = free_index[nodes[start + i]]
            if r < 0:
                continue
            for j in range(size):
                g = nodes[start + j]
                if free_index[g] >= 0:
                    continue
                for a in range(2):
                    for b in range(2):
                        out[2 * r + a] -= K[2 * i + a, 2 * j + b] * values[g, b]


def dirichlet_lift(mesh: Mesh, lam: float, mu: float, stabilization: str, nodes: NodeMapK2, values) -> np.ndarray:
    """-K_fc u_c on the free dofs: add it to the load when the clamped nodes carry the values
    ``values`` (n_nodes, 2) (e.g. ``interpolate_k2`` of the prescribed displacement) instead of 0."""
    offsets, cn = cell_nodes(mesh)
    out = np.zeros(nodes.n_free)
    vals = np.ascontiguousarray(values, dtype=float).reshape(nodes.n_nodes, 2)
    _lift(mesh.vertices, offsets, cn, nodes.free_index, vals, float(lam), float(mu), stabilization_code(stabilization),
          nodes.condensed, out)
    return out


def interpolate_k2(mesh: Mesh, field, points: int = 5) -> np.ndarray:
    """(n_nodes, 2) degrees of freedom of a field(x, y) -> (f1, f2): vertex values, edge means
    (Gauss-Legendre, ``points`` per edge) and cell means (degree-5 rule on a cell triangulation)."""
    from vemkit.mesh.triangulate import triangulate_cells
    from vemkit.vem.load import cell_averages, edge_quadrature

    def stacked(x, y):
        f1, f2 = field(x, y)
        return np.stack([np.broadcast_to(f1, np.shape(x)), np.broadcast_to(f2, np.shape(x))], axis=-1)

    t, w = edge_quadrature(points)
    pa, pb = mesh.vertices[mesh.edges[:, 0]], mesh.vertices[mesh.edges[:, 1]]
    x = pa[:, None, :] * (1 - t)[None, :, None] + pb[:, None, :] * t[None, :, None]
    edge_means = np.einsum("q,eqc->ec", w, stacked(x[..., 0], x[..., 1]))
    triangles, parent = triangulate_cells(mesh)
    cell_means = cell_averages(mesh, field, triangles, parent)
    return np.concatenate([stacked(mesh.vertices[:, 0], mesh.vertices[:, 1]), edge_means, cell_means])
