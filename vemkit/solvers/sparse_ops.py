"""Sparse operations of the contact solvers that keep the stiffness matrix's own arrays.

At 2.1 M DOFs (the paper scene at h = 2^-10) K holds 38 M entries, 450 MB: ``abs(K)`` and
``K + J`` (J the contact Jacobian, a few thousand entries) each made a new matrix of that size and
``Z^T (K + J) Z`` a third, every Newton step. Here:

- :func:`abs_matvec` is |K| |x| without forming |K| (the rounding floor of the residual);
- :func:`add_in_pattern` is K + J as K's index arrays with a copy of its values, J added in place
  (J's entries lie on K's pattern: the contact blocks couple dofs of one node, or of the two ends
  of a Gamma_C edge, which share a cell); K + J by scipy when one does not;
- :func:`reduced_operator` is y -> Z^T A Z y, three sparse products, for the Krylov solves;
- :class:`SumOperator` is K + J as K x + J x, a matrix only when a direct solve or a rebuilt
  hierarchy asks for one (:func:`as_matrix`): the Krylov steps never copy K's 38 M values.
"""

from __future__ import annotations

import numba
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


@numba.njit(cache=True, parallel=True)
def _abs_matvec(indptr, indices, data, x, out):
    for i in numba.prange(out.shape[0]):
        s = 0.0
        for p in range(indptr[i], indptr[i + 1]):
            s += abs(data[p]) * x[indices[p]]
        out[i] = s


def abs_matvec(A, x) -> np.ndarray:
    """|A| x for a CSR matrix A (entrywise absolute values; no copy of A), or for a matrix split
    across MPI ranks (``vemkit.vem.distributed_matrix``) by its own ``abs_matvec``."""
    if getattr(A, "distributed", False):
        return A.abs_matvec(x)
    A = A.tocsr()
    x = np.ascontiguousarray(x, dtype=float)
    if A.nnz < 1_000_000:  # small: scipy, no kernel to load
        return abs(A) @ x
    out = np.empty(A.shape[0])
    _abs_matvec(A.indptr, A.indices, A.data, x, out)
    return out


def add_in_pattern(K, J):
    """K + J (both square CSR) as a CSR matrix on K's index arrays when J's entries lie on K's
    pattern (K's column indices sorted), else scipy's K + J."""
    K = K.tocsr()
    J = J.tocsr()
    if not K.has_sorted_indices:
        return (K + J).tocsr()
    J.sum_duplicates()
    rows = np.repeat(np.arange(J.shape[0]), np.diff(J.indptr))
    positions = np.empty(J.nnz, dtype=np.int64)
    for r in np.unique(rows):
        lo, hi = K.indptr[r], K.indptr[r + 1]
        sel = slice(J.indptr[r], J.indptr[r + 1])
        at = lo + np.searchsorted(K.indices[lo:hi], J.indices[sel])
        if np.any(at >= hi) or np.any(K.indices[np.minimum(at, hi - 1)] != J.indices[sel]):
            return (K + J).tocsr()
        positions[sel] = at
    data = K.data.copy()
    data[positions] += J.data  # one position per entry of J (duplicates summed)
    A = sp.csr_matrix((data, K.indices, K.indptr), shape=K.shape)
    A.has_sorted_indices = True
    return A


def reduced_operator(A, Z):
    """y -> Z^T A Z y as a LinearOperator (Z^T A Z never formed)."""
    ZT = Z.T.tocsr()
    return spla.LinearOperator((Z.shape[1], Z.shape[1]), matvec=lambda y: ZT @ (A @ (Z @ np.ravel(y))), dtype=float)


class SumOperator(spla.LinearOperator):
    """K + J (square, CSR) applied as K x + J x; ``matrix()`` forms it (:func:`add_in_pattern`)."""

    def __init__(self, K, J):
        super().__init__(dtype=float, shape=K.shape)
        self.K, self.J = K, J.tocsr()

    def _matvec(self, x):
        x = np.ravel(x)
        return self.K @ x + self.J @ x

    def _rmatvec(self, x):
        x = np.ravel(x)
        return self.K.T @ x + self.J.T @ x

    def matrix(self):
        return add_in_pattern(self.K, self.J)


def as_matrix(A):
    """A sparse matrix of A (a :class:`SumOperator` formed, anything else as it is)."""
    return A.matrix() if isinstance(A, SumOperator) else A
