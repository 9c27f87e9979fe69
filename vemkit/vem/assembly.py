"""One assembly for every element: local stiffness matrices (3.9) scattered straight into CSR.

The matrix lives on the free dofs of a :class:`~vemkit.vem.dofs.DofMap` (dof = d * free_index +
component, d the element's dimension); clamped nodes are eliminated while assembling, and with ``dofs.condensed`` each cell's
interior nodes (its last ``Element.condensed_nodes``, the k = 2 cell mean) are condensed out cell by
cell (the Schur complement, ``condense_interior``). The sparsity pattern (``vemkit.vem.pattern``) is
built once and every entry added in place: no COO triplets are ever formed.

The element is a parameter: the Numba functions below marked *template* are written once and
specialized per element (``specialized``), their calls ``workspace`` and ``cell_matrix`` bound to
that element's kernels and ``DIM`` to its dimension (a compile-time constant); the kernels receive
``element.geometry(mesh)`` (the vertex coordinates in 2D; the 3D element adds its cells' faces).
Compiled and cached on disk per element, as any ``cache=True`` kernel.
The rows are split into contiguous chunks, one thread each; a thread computes the cells that touch
its rows and writes only those rows, so no two threads write the same entry (cells straddling two
chunks are computed twice) and the sums are the same whatever the number of threads.
"""

from __future__ import annotations

import types

import numba
import numpy as np
import scipy.sparse as sp

from vemkit.vem.elements import Element, stabilization_code
from vemkit.vem.pattern import ROW_CHUNKS, chunk_rows, dof_pattern, node_cells

_SPECIALIZED: dict = {}


def specialized(template, element: Element, parallel: bool = False, **calls):
    """The Numba function of a template (a plain function of this module or another) for one
    element: the names ``workspace``, ``cell_matrix`` and ``DIM`` in its body (and any in ``calls``)
    are that element's. Cached on disk per element under the name ``<template>_<element>``."""
    key = (template.__module__, template.__name__, element.name)
    if key not in _SPECIALIZED:
        namespace = dict(
            template.__globals__,
            workspace=element.workspace,
            cell_matrix=element.cell_matrix,
            DIM=element.dimension,
            **calls,
        )
        function = types.FunctionType(
            template.__code__, namespace, f"{template.__name__}_{element.name}", template.__defaults__
        )
        function.__qualname__ = function.__name__
        function.__module__ = template.__module__
        function.__doc__ = template.__doc__
        _SPECIALIZED[key] = numba.njit(cache=True, parallel=parallel)(function)
    return _SPECIALIZED[key]


@numba.njit(cache=True)
def largest_cell(offsets):
    """The most nodes of a cell in a CSR list of cell nodes."""
    size = 0
    for c in range(offsets.shape[0] - 1):
        size = max(size, offsets[c + 1] - offsets[c])
    return size


@numba.njit(cache=True)
def cells_of_rows(row_lo, row_hi, free_items, item_ptr, item_cells, offsets, ids, free_index):
    """The cells touching the rows [row_lo, row_hi) (rows: free nodes ``free_items``;
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


@numba.njit(cache=True, inline="always")
def add_block(data, p, stride, K, i, j, dim):
    """The d x d block (node i, j) of an element matrix K into the CSR data of the d scalar rows of
    i: component a's row holds the block's row at p + a * stride (every row of a node has the same
    columns)."""
    for a in range(dim):
        for b in range(dim):
            data[p + a * stride + b] += K[dim * i + a, dim * j + b]


@numba.njit(cache=True)
def condense_interior(K, size):
    """Static condensation of a cell's last node (its interior node, scalars c0 = 2 (size - 1) and
    c0 + 1) in the element matrix K: K_bb -= K_bc K_cc^-1 K_cb on the boundary scalars."""
    c = 2 * (size - 1)
    a, b, d, e = K[c, c], K[c, c + 1], K[c + 1, c], K[c + 1, c + 1]
    det = a * e - b * d
    for i in range(c):
        w0 = (K[i, c] * e - K[i, c + 1] * d) / det  # (K_bc K_cc^-1)[i, :]
        w1 = (K[i, c + 1] * a - K[i, c] * b) / det
        for j in range(c):
            K[i, j] -= w0 * K[c, j] + w1 * K[c + 1, j]


def add_rows(row_lo, row_hi, rows, size, order, K, indptr, indices, data):
    """*Template.* data += the rows of K whose node rows lie in [row_lo, row_hi): the cell's free
    columns are sorted once, then each CSR row is found by one merge walk along its sorted column
    list (the entries d c of the scalar row d r, d = DIM, a compile-time constant: the d x d blocks
    unroll)."""
    dim = DIM  # noqa: F821 (bound by ``specialized``)
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
        q = indptr[dim * r]
        stride = indptr[dim * r + 1] - q
        for s in range(count):
            j = order[s]
            while indices[q] < dim * rows[j]:
                q += dim
            add_block(data, q, stride, K, i, j, dim)


def scatter_rows(row_lo, row_hi, geometry, cells, pattern, material, max_nodes, data):
    """*Template.* Add the rows row_lo <= r < row_hi of every element stiffness touching them (the
    tuples ``cells``, ``pattern`` and ``material`` of ``stiffness_matrix``)."""
    offsets, nodes = cells
    free_index, free_nodes, nc_ptr, nc, indptr, indices = pattern
    lam, mu, stab, condense = material
    work = workspace(max_nodes)  # noqa: F821 (bound by ``specialized``)
    rows = np.empty(max_nodes, dtype=np.int64)
    order = np.empty(max_nodes, dtype=np.int64)
    for c in cells_of_rows(row_lo, row_hi, free_nodes, nc_ptr, nc, offsets, nodes, free_index):
        start = offsets[c]
        size = offsets[c + 1] - start
        for i in range(size):
            rows[i] = free_index[nodes[start + i]]
        K = cell_matrix(c, geometry, offsets, nodes, lam, mu, stab, work)  # noqa: F821
        if condense:
            condense_interior(K, size)
        add_rows(row_lo, row_hi, rows, size, order, K, indptr, indices, data)  # noqa: F821 (specialized)


def scatter_stiffness(geometry, cells, pattern, material, data):
    """*Template* (parallel). Every element stiffness (3.9) added into the CSR ``data`` (zeroed)."""
    max_nodes = largest_cell(cells[0])
    n_rows = pattern[1].shape[0]
    for chunk in numba.prange(ROW_CHUNKS):
        lo, hi = chunk_rows(chunk, n_rows)
        scatter_rows(lo, hi, geometry, cells, pattern, material, max_nodes, data)


def scatter_kernel(element: Element):
    """The parallel scatter of ``element`` (``scatter_stiffness`` specialized)."""
    rows = specialized(scatter_rows, element, add_rows=specialized(add_rows, element))
    return specialized(scatter_stiffness, element, parallel=True, scatter_rows=rows)


def sorted_csr(data, indices, indptr, n: int) -> sp.csr_matrix:
    """The n x n CSR matrix of an assembled pattern (sorted column indices; 32-bit indptr if it fits)."""
    if indptr[-1] < np.iinfo(np.int32).max:
        indptr = indptr.astype(np.int32)
    A = sp.csr_matrix((data, indices, indptr), shape=(n, n))
    A.has_sorted_indices = True
    return A


def material_of(lam: float, mu: float, stabilization: str, dofs) -> tuple:
    """The ``material`` argument of the templates: (lam, mu, stabilization code, whether ``dofs``
    condense the interior nodes). Beside it they take ``element.geometry(mesh)`` and ``cells``, the
    space's CSR (offsets, nodes) (``cell_matrix``'s arguments; a parallel loop takes no nested tuple)."""
    return float(lam), float(mu), stabilization_code(stabilization), dofs.condensed


def stiffness_matrix(space, lam: float, mu: float, stabilization: str, dofs=None) -> sp.csr_matrix:
    """The global VEM stiffness matrix of ``space`` (a :class:`~vemkit.vem.space.VirtualElementSpace`)
    on the free dofs of ``dofs`` (default: every node free, ``space.numbering()``), in their order;
    with ``dofs.condensed`` the Schur complement on the non-interior dofs. Symmetric positive
    definite when the constraints exclude the rigid motions."""
    dofs = space.numbering() if dofs is None else dofs
    offsets, nodes = cells = space.cell_nodes
    nc_ptr, nc = node_cells(offsets, nodes, dofs.n_nodes)
    dim = space.element.dimension
    indptr, indices = dof_pattern(offsets, nodes, nc_ptr, nc, dofs.free_nodes, dofs.free_index, dim)
    data = np.zeros(indices.shape[0])  # fresh zero pages from the system: no zeroing pass
    pattern = (dofs.free_index, dofs.free_nodes, nc_ptr, nc, indptr, indices)
    geometry = space.element.geometry(space.mesh)
    scatter_kernel(space.element)(geometry, cells, pattern, material_of(lam, mu, stabilization, dofs), data)
    return sorted_csr(data, indices, indptr, dofs.n_free)


def lift(geometry, cells, material, free_index, values, out):
    """*Template.* out[free] -= K_fc u_c over the cells that touch a clamped node with a non-zero value."""
    offsets, nodes = cells
    lam, mu, stab, condense = material
    work = workspace(largest_cell(offsets))  # noqa: F821
    for c in range(offsets.shape[0] - 1):
        start = offsets[c]
        size = offsets[c + 1] - start
        touched = False
        for i in range(size):
            g = nodes[start + i]
            for a in range(DIM):  # noqa: F821
                if free_index[g] < 0 and values[g, a] != 0.0:
                    touched = True
        if not touched:
            continue
        K = cell_matrix(c, geometry, offsets, nodes, lam, mu, stab, work)  # noqa: F821
        if condense:
            condense_interior(K, size)
        for i in range(size):
            r = free_index[nodes[start + i]]
            if r < 0:
                continue
            for j in range(size):
                g = nodes[start + j]
                if free_index[g] >= 0:
                    continue
                for a in range(DIM):  # noqa: F821
                    for b in range(DIM):  # noqa: F821
                        out[DIM * r + a] -= K[DIM * i + a, DIM * j + b] * values[g, b]  # noqa: F821


def dirichlet_lift(space, lam: float, mu: float, stabilization: str, dofs, values) -> np.ndarray:
    """-K_fc u_c on the free dofs: add it to the load when the clamped nodes carry the values
    ``values`` (n_nodes, d) (e.g. ``space.interpolate`` of the prescribed displacement) instead of 0."""
    out = np.zeros(dofs.n_free)
    vals = np.ascontiguousarray(values, dtype=float).reshape(dofs.n_nodes, space.element.dimension)
    geometry = space.element.geometry(space.mesh)
    specialized(lift, space.element)(
        geometry, space.cell_nodes, material_of(lam, mu, stabilization, dofs), dofs.free_index, vals, out
    )
    return out
