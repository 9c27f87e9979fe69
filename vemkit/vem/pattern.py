"""Sparsity pattern of the global matrix of any element, straight at the dof level.

Free node r couples with every free node of the cells around it (the cells' node lists of
``Element.cell_nodes``). A row's candidates hold each neighbour once per shared cell (a vertex row of
a k = 2 quadrilateral mesh has 4 x 9 of them), so the duplicates are dropped by a sparse set as they
come, only the distinct columns are sorted, and the int32 dof indices (d x d blocks) are written
directly (d the element's dimension), by numpy-allocated memory (huge pages). The rows are split
into ``ROW_CHUNKS`` contiguous shares, one thread each (the same shares as the parallel assembly
of ``vemkit.vem.assembly``).
"""

from __future__ import annotations

import numba
import numpy as np

ROW_CHUNKS = 8  # threads' shares of the rows in the parallel pattern and assembly


@numba.njit(cache=True)
def chunk_rows(chunk, n_rows):
    """The rows [lo, hi) of one of the ROW_CHUNKS contiguous shares."""
    return chunk * n_rows // ROW_CHUNKS, (chunk + 1) * n_rows // ROW_CHUNKS


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
def node_cells(offsets, nodes, n_nodes):
    """CSR (ptr, cells) of the cells around every node (cells in increasing order)."""
    n_cells = offsets.shape[0] - 1
    ptr = np.zeros(n_nodes + 1, dtype=np.int64)
    for p in range(nodes.shape[0]):
        ptr[nodes[p] + 1] += 1
    for v in range(n_nodes):
        ptr[v + 1] += ptr[v]
    cells = np.empty(nodes.shape[0], dtype=np.int64)
    fill = ptr[:-1].copy()
    for c in range(n_cells):
        for p in range(offsets[c], offsets[c + 1]):
            v = nodes[p]
            cells[fill[v]] = c
            fill[v] += 1
    return ptr, cells


@numba.njit(cache=True)
def _row_columns(r, free_nodes, free_index, nc_ptr, nc, offsets, nodes, where, buf):
    """The distinct free columns of node row r (the free nodes of the cells around it) into buf,
    unsorted; returns their count. ``where`` is the index of a sparse set (Briggs and Torczon): an
    entry counts only if it points back at itself, so the array is never cleared."""
    g = free_nodes[r]
    k = 0
    for t in range(nc_ptr[g], nc_ptr[g + 1]):
        c = nc[t]
        for p in range(offsets[c], offsets[c + 1]):
            col = free_index[nodes[p]]
            if col < 0:
                continue
            s = where[col]
            if 0 <= s < k and buf[s] == col:
                continue
            where[col] = k
            buf[k] = col
            k += 1
    return k


@numba.njit(cache=True)
def _row_buffers(lo, hi, free_nodes, nc_ptr, nc, offsets, n_free):
    """(where, buf) of ``_row_columns`` for the rows [lo, hi): buf holds the longest candidate list."""
    size = 1
    for r in range(lo, hi):
        g = free_nodes[r]
        total = 0
        for t in range(nc_ptr[g], nc_ptr[g + 1]):
            total += offsets[nc[t] + 1] - offsets[nc[t]]
        size = max(size, total)
    return np.empty(n_free, dtype=np.int64), np.empty(size, dtype=np.int64)


@numba.njit(cache=True)
def _sorted_row(r, free_nodes, free_index, nc_ptr, nc, offsets, nodes, where, buf, indptr, indices, dim):
    """Row r's columns, sorted (insertion sort: a row holds a few dozen), as the d x d dof blocks of
    the scalar rows d r ... d r + d - 1."""
    k = _row_columns(r, free_nodes, free_index, nc_ptr, nc, offsets, nodes, where, buf)
    sort_prefix(buf, k)
    for a in range(dim):
        q = indptr[dim * r + a]
        for t in range(k):
            for b in range(dim):
                indices[q + dim * t + b] = dim * buf[t] + b


@numba.njit(cache=True, parallel=True)
def _pattern_rows(offsets, nodes, nc_ptr, nc, free_nodes, free_index, dim):
    """indptr of ``dof_pattern``: d times the number of distinct free nodes around each free node."""
    n_free = free_nodes.shape[0]
    degree = np.empty(n_free, dtype=np.int64)
    for chunk in numba.prange(ROW_CHUNKS):
        lo, hi = chunk_rows(chunk, n_free)
        where, buf = _row_buffers(lo, hi, free_nodes, nc_ptr, nc, offsets, n_free)
        for r in range(lo, hi):
            degree[r] = _row_columns(r, free_nodes, free_index, nc_ptr, nc, offsets, nodes, where, buf)
    indptr = np.empty(dim * n_free + 1, dtype=np.int64)
    indptr[0] = 0
    for r in range(n_free):
        for a in range(dim):
            indptr[dim * r + a + 1] = indptr[dim * r + a] + dim * degree[r]
    return indptr


@numba.njit(cache=True, parallel=True)
def _pattern_columns(offsets, nodes, nc_ptr, nc, free_nodes, free_index, indptr, indices, dim):
    """The sorted columns of ``dof_pattern`` into indices, each thread its own contiguous rows."""
    n_free = free_nodes.shape[0]
    for chunk in numba.prange(ROW_CHUNKS):
        lo, hi = chunk_rows(chunk, n_free)
        where, buf = _row_buffers(lo, hi, free_nodes, nc_ptr, nc, offsets, n_free)
        for r in range(lo, hi):
            _sorted_row(r, free_nodes, free_index, nc_ptr, nc, offsets, nodes, where, buf, indptr, indices, dim)


def dof_pattern(offsets, nodes, nc_ptr, nc, free_nodes, free_index, dim=2):
    """CSR pattern (indptr, int32 indices, sorted) of the global matrix, d = ``dim`` components per
    node: scalar rows d r + a hold (d c, ..., d c + d - 1) for every free node c sharing a cell with
    the free node r. The indices are allocated here, by numpy (large arrays on huge pages: fewer
    page faults when first written)."""
    indptr = _pattern_rows(offsets, nodes, nc_ptr, nc, free_nodes, free_index, dim)
    indices = np.empty(indptr[-1], dtype=np.int32)
    _pattern_columns(offsets, nodes, nc_ptr, nc, free_nodes, free_index, indptr, indices, dim)
    return indptr, indices
