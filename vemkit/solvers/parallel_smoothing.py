"""The finest AMG level's Gauss-Seidel sweeps and products on every core (Numba ``prange``).

pyamg's Gauss-Seidel and scipy's CSR product run on one core: at 10^6 DOFs in 3D (80 M entries) they
are three of the four passes over K in every preconditioned CG iteration. Here:

- :func:`matvec`: y = A x, rows in parallel (each row summed in order: the same bits as scipy's);
- :func:`hybrid_gauss_seidel`: the rows cut into ``chunks`` contiguous blocks, Gauss-Seidel inside
  each block, Jacobi between blocks (the values of the other blocks from the start of the sweep), with
  the l1 diagonal (Baker, Falgout, Kolev and Yang, "Multigrid smoothers for ultraparallel computing",
  SIAM J. Sci. Comput. 33, 2011): row i's diagonal is a_ii + sum over the other blocks' columns of
  |a_ij|. The forward sweep is x <- x + M^-1 (b - A x) with M = D + D_l1 + L_block, the backward one
  with M^T, and M + M^T - A = D + 2 D_l1 - A_between is positive definite, so the V-cycle with a
  forward sweep before and a backward one after stays a symmetric positive definite preconditioner
  (the l1 term guarantees what plain hybrid Gauss-Seidel does not). One chunk is pyamg's Gauss-Seidel
  to the last bit (the same sums in the same order). The values of the other blocks are read from a
  copy made at the start of the sweep, so the result does not depend on the threads' timing: it
  depends on ``chunks`` only (:func:`smoothing_chunks`, the number of Numba threads).
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, parallel=True)
def _matvec(indptr, indices, data, x, out):
    for i in numba.prange(out.shape[0]):
        s = 0.0
        for p in range(indptr[i], indptr[i + 1]):
            s += data[p] * x[indices[p]]
        out[i] = s


@numba.njit(cache=True, parallel=True)
def _hybrid_sweep(indptr, indices, data, x, b, bounds, forward):
    before = x.copy()
    for c in numba.prange(bounds.shape[0] - 1):
        lo, hi = bounds[c], bounds[c + 1]
        for step in range(hi - lo):
            i = lo + step if forward else hi - 1 - step
            rsum = 0.0
            diag = 0.0
            l1 = 0.0
            for p in range(indptr[i], indptr[i + 1]):
                j = indices[p]
                if j == i:
                    diag = data[p]
                elif lo <= j < hi:
                    rsum += data[p] * x[j]
                else:  # another block's column: its value at the start of the sweep (Jacobi)
                    rsum += data[p] * before[j]
                    l1 += abs(data[p])
            if diag != 0.0:
                x[i] = (b[i] - rsum + l1 * before[i]) / (diag + l1)


def smoothing_chunks() -> int:
    """The blocks of a hybrid sweep: one per Numba thread (one thread: exactly Gauss-Seidel)."""
    return max(int(numba.get_num_threads()), 1)


def matvec(A, x) -> np.ndarray:
    """A x for a CSR matrix A, rows in parallel."""
    out = np.empty(A.shape[0])
    _matvec(A.indptr, A.indices, A.data, np.ascontiguousarray(x, dtype=float), out)
    return out


def hybrid_gauss_seidel(A, x, b, forward: bool = True, chunks: int | None = None) -> None:
    """One l1 hybrid Gauss-Seidel sweep on x in place (see the module docstring); A CSR, x float64."""
    n = A.shape[0]
    chunks = smoothing_chunks() if chunks is None else int(chunks)
    bounds = np.linspace(0, n, max(min(chunks, n), 1) + 1).astype(np.int64)
    _hybrid_sweep(A.indptr, A.indices, A.data, x, np.ascontiguousarray(b, dtype=float), bounds, forward)


PARALLEL_LIMIT = 200_000  # rows: below, one core's sweep is as fast (threads cost more than they give)


def product(A, x) -> np.ndarray:
    """A @ x: rows in parallel for a large CSR matrix (the same bits), scipy's otherwise."""
    if A.format == "csr" and A.shape[0] >= PARALLEL_LIMIT and smoothing_chunks() > 1:
        return matvec(A, x)
    return A @ x


def parallel_operator(A):
    """A as the operator of a Krylov solve: its products by :func:`product` (A itself when small)."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    if not sp.issparse(A) or A.format != "csr" or A.shape[0] < PARALLEL_LIMIT or smoothing_chunks() == 1:
        return A
    return spla.LinearOperator(A.shape, matvec=lambda x: matvec(A, np.ravel(x)), rmatvec=lambda x: A.T @ x, dtype=float)


def finest_smoothers(rows: int):
    """(presmoother, postsmoother) for the finest level of ``vemkit.solvers.linear.v_cycle``: hybrid
    forward and backward sweeps, or None (keep pyamg's) below PARALLEL_LIMIT rows or on one thread."""
    if rows < PARALLEL_LIMIT or smoothing_chunks() == 1:
        return None

    def presmoother(A, x, b):
        hybrid_gauss_seidel(A, x, b, forward=True)

    def postsmoother(A, x, b):
        hybrid_gauss_seidel(A, x, b, forward=False)

    return presmoother, postsmoother
