"""Sparse operations of the contact solvers that keep the stiffness matrix's own arrays.

At 2.1 M DOFs (the paper scene at h = 2^-10) K holds 38 M entries, 450 MB: ``abs(K)`` and
``K + J`` (J the contact Jacobian, a few thousand entries) each made a new matrix of that size and
``Z^T (K + J) Z`` a third, every Newton step. Here:

- :func:`abs_matvec` is |K| |x| without forming |K| (the rounding floor of the residual);
- :func:`matvec` is K x with its rows split over the Numba threads: scipy's sums, bit for bit;
- :func:`to_blocks` is scipy's ``tobsr`` of a CSR matrix (the same blocks in the same order), its
  block rows split over the threads;
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

from vemkit.exceptions import InputError


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


# the positions and columns read as unsigned: Numba then drops its test of every signed index for
# wraparound, which doubled the loop's time (benchmarks/threads.py). Not fastmath: each row summed in
# scipy's order (csr_matvec), so the product is scipy's to the last bit whatever the number of threads.
@numba.njit(cache=True, parallel=True)
def _matvec(indptr, indices, data, x, out):
    for i in numba.prange(out.shape[0]):
        s = out[i]
        p, end = np.uint64(indptr[i]), np.uint64(indptr[i + 1])
        while p < end:
            s += data[p] * x[np.uint64(indices[p])]
            p += np.uint64(1)
        out[i] = s


PARALLEL_NNZ = 1_000_000  # below this many entries scipy's serial product (no kernel to load, no threads)


def matvec(A, x) -> np.ndarray:
    """A x for a sparse matrix A and a vector x: scipy's product, bit for bit, by the row-parallel
    kernel when A is a large CSR matrix (the 3D contact steps' K at 10^6 DOFs, 7e7 entries: 42 ms by
    scipy, 25 ms on two threads)."""
    x = np.ravel(x)
    if getattr(A, "format", None) != "csr" or A.nnz < PARALLEL_NNZ or x.dtype != A.dtype or x.shape != (A.shape[1],):
        return A @ x
    out = np.zeros(A.shape[0], dtype=A.dtype)
    _matvec(A.indptr, A.indices, A.data, np.ascontiguousarray(x), out)
    return out


#: block rows per pair of chunks of the parallel conversion (an even number of chunks, at most 64): each
#: chunk fills its scratch arrays, two of the block columns' count, once
BLOCK_CHUNK_ROWS = 16_384


@numba.njit(cache=True)
def _block_row(indptr, indices, R, C, bi, stamp, where, first, data, b_indices, b_data):
    """Block row ``bi``: its block columns in the order scipy's csr_tobsr meets them (its rows one
    after the other), at first, first + 1, ...; their count. With ``data``: its values added to the
    blocks (flat ``b_data``, zeros: duplicates summed as scipy sums them), the block columns written."""
    count = 0
    for r in range(R):
        i = R * bi + r
        for p in range(indptr[i], indptr[i + 1]):
            j = indices[p]
            bj = j // C
            if stamp[bj] != bi:
                stamp[bj] = bi
                where[bj] = first + count
                count += 1
                if data.size:
                    b_indices[where[bj]] = bj
            if data.size:
                b_data[(where[bj] * R + r) * C + j - bj * C] += data[p]
    return count


@numba.njit(cache=True, parallel=True)
def _blocks(indptr, indices, data, R, C, n_block_columns, b_indptr, b_indices, b_data, chunks):
    """Counts the blocks of each block row into b_indptr[1:] (``data`` empty), or fills them."""
    rows = b_indptr.shape[0] - 1
    for chunk in numba.prange(chunks):
        stamp = np.full(n_block_columns, -1, dtype=np.int64)
        where = np.empty(n_block_columns, dtype=np.int64)
        for bi in range(chunk * rows // chunks, (chunk + 1) * rows // chunks):
            first = b_indptr[bi] if data.size else 0
            count = _block_row(indptr, indices, R, C, bi, stamp, where, first, data, b_indices, b_data)
            if not data.size:
                b_indptr[bi + 1] = count


def to_blocks(A, R: int, C: int):
    """The CSR matrix A as BSR with R x C blocks: scipy's ``A.tobsr(blocksize=(R, C))`` (the same
    arrays: the blocks of a block row in the order its rows meet them), on the Numba threads (K's
    3 x 3 blocks at 10^6 DOFs in 3D, best of four: 0.42 s by scipy, 0.38 s here; the set-up converts
    K in row blocks, its P and the Newton cycle's K and P: ~2.4 s by scipy in all)."""
    A = A.tocsr()
    rows, columns = A.shape
    if rows % R or columns % C:
        raise InputError(f"a {rows} x {columns} matrix has no {R} x {C} blocks; give a blocksize dividing its shape")
    n_block_columns = columns // C
    indptr = np.zeros(rows // R + 1, dtype=np.int64)
    chunks = min(64, 2 * max(1, rows // R // BLOCK_CHUNK_ROWS))
    _blocks(A.indptr, A.indices, A.data[:0], R, C, n_block_columns, indptr, indptr[:0], A.data[:0], chunks)
    np.cumsum(indptr, out=indptr)
    index_type = np.int32 if max(int(indptr[-1]), n_block_columns) < np.iinfo(np.int32).max else np.int64
    indices = np.empty(int(indptr[-1]), dtype=index_type)
    data = np.zeros((indices.size, R, C), dtype=A.dtype)
    _blocks(A.indptr, A.indices, A.data, R, C, n_block_columns, indptr, indices, data.reshape(-1), chunks)
    return sp.bsr_matrix((data, indices, indptr.astype(index_type)), shape=A.shape)


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
        return matvec(self.K, x) + self.J @ x

    def _rmatvec(self, x):
        x = np.ravel(x)
        return self.K.T @ x + self.J.T @ x

    def matrix(self):
        return add_in_pattern(self.K, self.J)


def as_matrix(A):
    """A sparse matrix of A (a :class:`SumOperator` formed, anything else as it is)."""
    return A.matrix() if isinstance(A, SumOperator) else A
