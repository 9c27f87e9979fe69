"""pyamg's backward Gauss-Seidel sweep, bit for bit, on a copy of the matrix whose rows are stored last first.

The 3D contact steps' V-cycle (vemkit.solvers.amg_update) smooths the levels below the finest by
pyamg's scalar Gauss-Seidel: forward before the coarse correction, backward after. pyamg's backward
sweep visits the rows last first but reads each row's entries in their order, so its memory stream
goes forward within a row and back between rows: at 10^6 DOFs (the second level, 1.2e7 entries in
float32) 26 ms against 12 ms forward. :class:`ReversedRows` holds the rows in the order the backward
sweep visits them, each row's entries in its own order, so the sweep reads its arrays front to back
(~9 ms): the same sums in the same order, x_i = (b_i - sum_{j != i} a_ij x_j) / a_ii, x_i left
where a_ii = 0 (tests/solvers/test_reversed_sweep.py). The copy costs the level's index arrays and
values once more (at 10^6 DOFs 92 MB); its values follow the level's at each Newton step where
they changed (:meth:`refresh`).
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def _sweep_rows(indptr, indices, data, x, b, rows):
    """pyamg's update of rows[0], rows[1], ... in turn, the entries of rows[k] at indptr[k]:indptr[k + 1]."""
    zero = np.zeros(1, dtype=data.dtype)[0]
    for k in range(rows.shape[0]):
        i = rows[k]
        rsum, diag = zero, zero
        p, end = np.uint64(indptr[k]), np.uint64(indptr[k + 1])  # unsigned: no wraparound test per entry
        while p < end:
            j = indices[p]
            if j == i:
                diag = data[p]
            else:
                rsum += data[p] * x[np.uint64(j)]
            p += np.uint64(1)
        if diag != 0:
            x[i] = (b[i] - rsum) / diag


@numba.njit(cache=True)
def _reversed_copy(indptr, source, reversed_indptr, target):
    """target: the rows of ``source`` (CSR values on indptr) last first, each row's entries in order."""
    n = indptr.shape[0] - 1
    for k in range(n):
        row = n - 1 - k
        start = indptr[row]
        for t in range(reversed_indptr[k + 1] - reversed_indptr[k]):
            target[reversed_indptr[k] + t] = source[start + t]


class ReversedRows:
    """A square CSR matrix's rows last first (its values in :meth:`refresh`) and pyamg's backward sweep on them."""

    def __init__(self, A):
        self._build(A)

    def _build(self, A):
        n = A.shape[0]
        self.pattern = A.indptr
        self.indptr = np.concatenate([[0], np.cumsum(np.diff(A.indptr)[::-1])]).astype(np.int64)
        self.indices = np.empty(A.nnz, dtype=A.indices.dtype)
        _reversed_copy(A.indptr, A.indices, self.indptr, self.indices)
        self.data = np.empty(A.nnz, dtype=A.dtype)
        self.rows = np.arange(n - 1, -1, -1, dtype=np.int64)
        self.refresh(A)

    def refresh(self, A, *changed):
        """The values of A: all of them, or only those at the positions in the arrays ``changed`` (into
        A.data; the rest as at the last refresh); its rows copied again when A's pattern is another
        (a widened level)."""
        if A.indptr is not self.pattern:
            self._build(A)  # all of its values too
            return
        if not changed:
            _reversed_copy(A.indptr, A.data, self.indptr, self.data)
        for positions in changed:
            rows = np.searchsorted(A.indptr, positions, side="right") - 1
            self.data[self.indptr[A.shape[0] - 1 - rows] + positions - A.indptr[rows]] = A.data[positions]

    def backward_sweep(self, A, x, b):
        """One backward Gauss-Seidel sweep on x in place: pyamg's ``gauss_seidel(A, x, b, sweep="backward")``
        (A: the matrix last refreshed from; the signature of pyamg's smoothers)."""
        _sweep_rows(self.indptr, self.indices, self.data, x, b, self.rows)
