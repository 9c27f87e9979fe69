"""Global stiffness matrix: element kernels of ``vemkit.vem.element`` scattered straight into CSR.

Clamped vertices (Dirichlet, u = 0, (2.4)) are eliminated while assembling: the matrix lives on
the free vertices only, dof = 2 * free_index + component. The sparsity pattern is built once
from vertex adjacency (vertices sharing a cell) and every entry is added in place, so no COO
triplets are ever formed.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numba
import numpy as np
import scipy.sparse as sp

from vemkit.mesh.mesh import Mesh
from vemkit.vem.element import element_stiffness, stabilization_code


@dataclass(frozen=True)
class DofMap:
    """Which vertices carry unknowns. ``free_index[v]`` is -1 for a clamped vertex (u = 0, eliminated).

    ``fixed_dofs``: dofs of kept vertices whose value is prescribed (a roller's component, a
    nonzero prescribed displacement), held at ``fixed_values`` by identity rows
    (:mod:`vemkit.vem.constraints`); the unknown vector carries these values.
    """

    free_vertices: np.ndarray
    free_index: np.ndarray
    fixed_dofs: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    fixed_values: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def n_free(self) -> int:
        return 2 * self.free_vertices.size

    def unconstrained_vertices(self) -> np.ndarray:
        """(n_vertices,) bool: both components of the vertex are unknowns (no Dirichlet data)."""
        free = self.free_index >= 0
        held = np.unique(self.fixed_dofs // 2)
        free[self.free_vertices[held]] = False
        return free

    def prescribed_displacement(self) -> np.ndarray:
        """(n_vertices, 2) the Dirichlet displacement: the fixed values, zero elsewhere."""
        u = np.zeros((self.free_index.size, 2))
        u.reshape(-1)[2 * self.free_vertices[self.fixed_dofs // 2] + self.fixed_dofs % 2] = self.fixed_values
        return u

    @classmethod
    def from_clamped(cls, n_vertices: int, clamped_vertices) -> "DofMap":
        free = np.ones(n_vertices, dtype=bool)
        free[np.asarray(clamped_vertices, dtype=np.int64)] = False
        free_vertices = np.flatnonzero(free)
        free_index = np.full(n_vertices, -1, dtype=np.int64)
        free_index[free_vertices] = np.arange(free_vertices.size)
        return cls(free_vertices, free_index)

    def expand(self, u_free: np.ndarray) -> np.ndarray:
        """Free-dof vector -> (n_vertices, 2) displacement, zero at clamped vertices."""
        u = np.zeros((self.free_index.size, 2))
        u[self.free_vertices] = np.asarray(u_free).reshape(-1, 2)
        return u

    def restrict(self, u_vertices: np.ndarray) -> np.ndarray:
        """(n_vertices, 2) -> free-dof vector."""
        return np.ascontiguousarray(np.asarray(u_vertices)[self.free_vertices]).ravel()


@numba.njit(cache=True)
def vertex_cells(offsets, cell_vertices, n_vertices):
    """CSR (ptr, cells) of the cells around every vertex."""
    n_cells = offsets.shape[0] - 1
    ptr = np.zeros(n_vertices + 1, dtype=np.int64)
    for p in range(cell_vertices.shape[0]):
        ptr[cell_vertices[p] + 1] += 1
    for v in range(n_vertices):
        ptr[v + 1] += ptr[v]
    cells = np.empty(cell_vertices.shape[0], dtype=np.int64)
    fill = ptr[:-1].copy()
    for c in range(n_cells):
        for p in range(offsets[c], offsets[c + 1]):
            v = cell_vertices[p]
            cells[fill[v]] = c
            fill[v] += 1
    return ptr, cells


@numba.njit(cache=True)
def sort_prefix(buf, k):
    """Sort buf[:k] in place (insertion sort: the rows of a sparsity pattern hold a few dozen columns)."""
    for i in range(1, k):
        x = buf[i]
        j = i - 1
        while j >= 0 and buf[j] > x:
            buf[j + 1] = buf[j]
            j -= 1
        buf[j + 1] = x


@numba.njit(cache=True)
def _neighbours(v, offsets, cell_vertices, vc_ptr, vc, free_index, buf):
    """Sorted unique free neighbours of vertex v (itself included) into buf; returns their count."""
    k = 0
    for t in range(vc_ptr[v], vc_ptr[v + 1]):
        c = vc[t]
        for p in range(offsets[c], offsets[c + 1]):
            col = free_index[cell_vertices[p]]
            if col >= 0:
                buf[k] = col
                k += 1
    if k == 0:
        return 0
    sort_prefix(buf, k)  # k is small (sum of the cell sizes around v)
    u = 1
    for i in range(1, k):
        if buf[i] != buf[u - 1]:
            buf[u] = buf[i]
            u += 1
    return u


@numba.njit(cache=True, parallel=True)
def vertex_adjacency(offsets, cell_vertices, vc_ptr, vc, free_vertices):
    """CSR pattern (sorted columns) of free vertices that share a cell, diagonal included."""
    n_free = free_vertices.shape[0]
    n_vertices = vc_ptr.shape[0] - 1
    free_index = np.full(n_vertices, -1, dtype=np.int64)
    for r in range(n_free):
        free_index[free_vertices[r]] = r
    maxbuf = 0
    for v in range(n_vertices):
        size = 0
        for t in range(vc_ptr[v], vc_ptr[v + 1]):
            size += offsets[vc[t] + 1] - offsets[vc[t]]
        maxbuf = max(maxbuf, size)
    n_chunks = 64
    indptr = np.zeros(n_free + 1, dtype=np.int64)
    for chunk in numba.prange(n_chunks):
        buf = np.empty(maxbuf, dtype=np.int64)
        for r in range(chunk * n_free // n_chunks, (chunk + 1) * n_free // n_chunks):
            indptr[r + 1] = _neighbours(free_vertices[r], offsets, cell_vertices, vc_ptr, vc, free_index, buf)
    for r in range(n_free):
        indptr[r + 1] += indptr[r]
    indices = np.empty(indptr[n_free], dtype=np.int64)
    for chunk in numba.prange(n_chunks):
        buf = np.empty(maxbuf, dtype=np.int64)
        for r in range(chunk * n_free // n_chunks, (chunk + 1) * n_free // n_chunks):
            k = _neighbours(free_vertices[r], offsets, cell_vertices, vc_ptr, vc, free_index, buf)
            indices[indptr[r] : indptr[r] + k] = buf[:k]
    return indptr, indices


@numba.njit(cache=True, parallel=True)
def dof_pattern(vindptr, vindices):
    """Expand the vertex pattern to 2 x 2 blocks: row 2r + a holds (2c, 2c + 1) for each c."""
    n = vindptr.shape[0] - 1
    indptr = np.empty(2 * n + 1, dtype=np.int64)
    indptr[0] = 0
    for r in range(n):
        deg = vindptr[r + 1] - vindptr[r]
        indptr[2 * r + 1] = indptr[2 * r] + 2 * deg
        indptr[2 * r + 2] = indptr[2 * r + 1] + 2 * deg
    indices = np.empty(indptr[2 * n], dtype=np.int32)
    for r in numba.prange(n):
        for a in range(2):
            k = indptr[2 * r + a]
            for t in range(vindptr[r], vindptr[r + 1]):
                indices[k] = 2 * vindices[t]
                indices[k + 1] = 2 * vindices[t] + 1
                k += 2
    return indptr, indices


@numba.njit(cache=True)
def _find(vindices, lo, hi, col):
    while lo < hi:
        mid = (lo + hi) >> 1
        if vindices[mid] < col:
            lo = mid + 1
        else:
            hi = mid
    return lo


ROW_CHUNKS = 8  # threads' shares of the rows in the parallel assembly


@numba.njit(cache=True)
def chunk_rows(chunk, n_rows):
    """The rows [lo, hi) of one of the ROW_CHUNKS contiguous shares."""
    return chunk * n_rows // ROW_CHUNKS, (chunk + 1) * n_rows // ROW_CHUNKS


@numba.njit(cache=True, inline="always")
def add_block(data, p0, p1, K, i, j):
    """The 2 x 2 block (vertex or node i, j) of an element matrix K into the CSR data of the two
    scalar rows of i, at positions p0 (first component's row) and p1 (second's)."""
    data[p0] += K[2 * i, 2 * j]
    data[p0 + 1] += K[2 * i, 2 * j + 1]
    data[p1] += K[2 * i + 1, 2 * j]
    data[p1 + 1] += K[2 * i + 1, 2 * j + 1]


@numba.njit(cache=True)
def cells_of_rows(row_lo, row_hi, free_items, item_ptr, item_cells, offsets, ids, free_index):
    """The cells touching the rows [row_lo, row_hi) (rows: free vertices or nodes ``free_items``;
    ``item_ptr``/``item_cells`` the cells around each), each once: at its first row in the range, in
    the order of the rows. A thread that owns these rows computes exactly these cells."""
    out = []
    for r0 in range(row_lo, row_hi):
        item = free_items[r0]
        for t in range(item_ptr[item], item_ptr[item + 1]):
            c = item_cells[t]
            first = True
            for i in range(offsets[c], offsets[c + 1]):
                if row_lo <= free_index[ids[i]] < r0:
                    first = False
                    break
            if first:
                out.append(c)
    return out


@numba.njit(cache=True)
def _scatter_rows(row_lo, row_hi, vertices, offsets, cell_vertices, free_index, free_vertices, vc_ptr, vc, vindptr, vindices, lam, mu, stab, nmax, data):
    """Add the rows row_lo <= r < row_hi of every element stiffness touching them."""
    K = np.empty((2 * nmax, 2 * nmax))
    B = np.empty((3, 2 * nmax))
    P = np.empty((6, 2 * nmax))
    R = np.empty((2 * nmax, 2 * nmax))
    px = np.empty(nmax)
    py = np.empty(nmax)
    rows = np.empty(nmax, dtype=np.int64)
    for c in cells_of_rows(row_lo, row_hi, free_vertices, vc_ptr, vc, offsets, cell_vertices, free_index):
        start = offsets[c]
        n = offsets[c + 1] - start
        for i in range(n):
            rows[i] = free_index[cell_vertices[start + i]]
            px[i] = vertices[cell_vertices[start + i], 0]
            py[i] = vertices[cell_vertices[start + i], 1]
        m = 2 * n
        element_stiffness(px[:n], py[:n], lam, mu, stab, K[:m, :m], B[:, :m], P[:, :m], R[:m, :m])
        for i in range(n):
            r = rows[i]
            if r < row_lo or r >= row_hi:
                continue
            lo = vindptr[r]
            hi = vindptr[r + 1]
            deg2 = 2 * (hi - lo)
            base = 4 * lo
            for j in range(n):
                col = rows[j]
                if col < 0:
                    continue
                k = _find(vindices, lo, hi, col) - lo
                add_block(data, base + 2 * k, base + deg2 + 2 * k, K, i, j)


@numba.njit(cache=True, parallel=True)
def scatter_stiffness(vertices, offsets, cell_vertices, free_index, free_vertices, vc_ptr, vc, vindptr, vindices, lam, mu, stab, data):
    """Add every element stiffness (3.9) into the CSR ``data`` of ``dof_pattern``.

    The rows are split into contiguous chunks, one thread each; a thread computes the cells that
    touch its rows and writes only those rows, so no two threads write the same entry (cells
    straddling two chunks are computed twice).
    """
    nmax = 0
    for c in range(offsets.shape[0] - 1):
        nmax = max(nmax, offsets[c + 1] - offsets[c])
    for chunk in numba.prange(ROW_CHUNKS):
        lo, hi = chunk_rows(chunk, free_vertices.shape[0])
        _scatter_rows(lo, hi, vertices, offsets, cell_vertices, free_index, free_vertices, vc_ptr, vc, vindptr,
                      vindices, lam, mu, stab, nmax, data)


def sorted_csr(data, indices, indptr, n: int) -> sp.csr_matrix:
    """The n x n CSR matrix of an assembled pattern (sorted column indices; 32-bit indptr if it fits)."""
    if indptr[-1] < np.iinfo(np.int32).max:
        indptr = indptr.astype(np.int32)
    A = sp.csr_matrix((data, indices, indptr), shape=(n, n))
    A.has_sorted_indices = True
    return A


def stiffness_matrix(mesh: Mesh, lam: float, mu: float, stabilization: str, dofs: DofMap | None = None):
    """The global VEM stiffness matrix on the free dofs (CSR, symmetric positive definite when
    at least one vertex set is clamped so that rigid motions are excluded)."""
    if dofs is None:
        dofs = DofMap.from_clamped(mesh.n_vertices, [])
    stab = stabilization_code(stabilization)
    vc_ptr, vc = vertex_cells(mesh.cell_offsets, mesh.cell_vertices, mesh.n_vertices)
    vindptr, vindices = vertex_adjacency(mesh.cell_offsets, mesh.cell_vertices, vc_ptr, vc, dofs.free_vertices)
    indptr, indices = dof_pattern(vindptr, vindices)
    data = np.zeros(indices.shape[0])
    scatter_stiffness(
        mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, dofs.free_index,
        dofs.free_vertices, vc_ptr, vc, vindptr, vindices, float(lam), float(mu), stab, data,
    )
    return sorted_csr(data, indices, indptr, dofs.n_free)
