"""The finest level of the smoothed aggregation hierarchy, built without pyamg's temporaries.

pyamg smooths the tentative prolongator T as P = T - omega D^-1 A T with "local" weighting
(D_i = sum_j |a_ij|) by forming |A|, D^-1 A and omega D^-1 A (three copies of A) and a BSR product;
at 2.1 M DOFs (the paper scene at h = 2^-10, A with 38 M entries) that was 5.5 of the 9 s of the
set-up and the peak of the solve's memory. :func:`smoothed_prolongator` computes the same P row by
row in one parallel Numba pass (the same products, summed in the same order), and
:func:`finest_level` gives the level with its Galerkin operator R A P (3 x 3 BSR, as pyamg's).
The aggregates and T are pyamg's (``standard_aggregation`` on A itself, the strength ``None`` of
``vemkit.solvers.linear.AMGSolver``, and ``fit_candidates``): the hierarchy below is pyamg's own.
"""

from __future__ import annotations

import numba
import numpy as np
import scipy.sparse as sp

from vemkit.solvers.sparse_ops import to_blocks


@numba.njit(cache=True)
def _row_aggregates(i, indptr, indices, agg, found):
    """The distinct aggregates of row i's columns (and of i), ascending, into ``found``; their count."""
    count = 0
    for p in range(indptr[i], indptr[i + 1] + 1):
        a = agg[i] if p == indptr[i + 1] else agg[indices[p]]
        if a < 0:
            continue
        seen = False
        for t in range(count):
            if found[t] == a:
                seen = True
                break
        if not seen:
            t = count
            while t > 0 and found[t - 1] > a:  # insertion: ascending
                found[t] = found[t - 1]
                t -= 1
            found[t] = a
            count += 1
    return count


CHUNKS = 64  # row chunks of the parallel loops (scratch arrays once per chunk, not per row)


@numba.njit(cache=True, parallel=True)
def _count(indptr, indices, agg, widest, out):
    n = indptr.shape[0] - 1
    for chunk in numba.prange(CHUNKS):
        found = np.empty(widest, dtype=np.int64)
        for i in range(chunk * n // CHUNKS, (chunk + 1) * n // CHUNKS):
            out[i + 1] = _row_aggregates(i, indptr, indices, agg, found)


@numba.njit(cache=True, parallel=True)
def _fill(indptr, indices, data, agg, tvalues, omega, widest, k, p_ptr, p_indices, p_data):
    """Row i of P = T - omega D^-1 A T, D_i = sum_j |a_ij| (T row j: ``tvalues[j]`` at columns
    k agg[j] ... k agg[j] + k - 1): pyamg's scale_rows, omega * and product order."""
    n = indptr.shape[0] - 1
    for chunk in numba.prange(CHUNKS):
        found = np.empty(widest, dtype=np.int64)
        acc = np.empty((widest, k))
        for i in range(chunk * n // CHUNKS, (chunk + 1) * n // CHUNKS):
            _fill_row(i, indptr, indices, data, agg, tvalues, omega, k, found, acc, p_ptr, p_indices, p_data)


@numba.njit(cache=True)
def _fill_row(i, indptr, indices, data, agg, tvalues, omega, k, found, acc, p_ptr, p_indices, p_data):
    count = _row_aggregates(i, indptr, indices, agg, found)
    d = 0.0
    for p in range(indptr[i], indptr[i + 1]):
        d += abs(data[p])
    dinv = 1.0 / d if d != 0.0 else 0.0
    acc[:count, :] = 0.0
    for p in range(indptr[i], indptr[i + 1]):
        j = indices[p]
        a = agg[j]
        if a < 0:
            continue
        s = omega * (data[p] * dinv)
        t = 0
        while found[t] != a:
            t += 1
        for c in range(k):
            acc[t, c] += s * tvalues[j, c]
    start = p_ptr[i]
    for t in range(count):
        for c in range(k):
            value = -acc[t, c]
            if found[t] == agg[i]:
                value = tvalues[i, c] - acc[t, c]
            p_indices[start + k * t + c] = k * found[t] + c
            p_data[start + k * t + c] = value


def smoothed_prolongator(A, aggregates, tvalues, n_aggregates: int, omega: float = 4.0 / 3.0):
    """P = T - omega D^-1 A T (CSR, sorted columns), T[i, k agg_i + c] = tvalues[i, c] (agg_i = -1:
    a zero row), D the row sums of |A| ("local" weighting)."""
    A = A.tocsr()
    k = tvalues.shape[1]
    agg = np.ascontiguousarray(aggregates, dtype=np.int64)
    widest = int(np.max(np.diff(A.indptr))) + 1
    counts = np.zeros(A.shape[0] + 1, dtype=np.int64)
    _count(A.indptr, A.indices, agg, widest, counts)
    p_ptr = np.cumsum(counts * k)
    nnz = int(p_ptr[-1])
    index_type = np.int32 if max(nnz, k * n_aggregates) < np.iinfo(np.int32).max else np.int64
    p_indices = np.empty(nnz, dtype=index_type)
    p_data = np.empty(nnz)
    _fill(
        A.indptr,
        A.indices,
        A.data,
        agg,
        np.ascontiguousarray(tvalues, dtype=float),
        float(omega),
        widest,
        k,
        p_ptr,
        p_indices,
        p_data,
    )
    P = sp.csr_matrix((p_data, p_indices, p_ptr.astype(index_type)), shape=(A.shape[0], k * n_aggregates))
    P.has_sorted_indices = True
    return P


def finest_level(A, B, omega: float = 4.0 / 3.0):
    """(P, R, A_coarse, B_coarse) of the finest level: pyamg's standard aggregates of A and
    tentative prolongator, the smoothed P of :func:`smoothed_prolongator`, R = P^T (a transposed
    view, CSC: no second copy of P) and the Galerkin operator R A P (:func:`galerkin`) as 3 x 3
    (k x k) BSR for the coarser levels."""
    from pyamg.aggregation import fit_candidates, standard_aggregation

    A = A.tocsr()
    AggOp, _ = standard_aggregation(A)
    AggOp = AggOp.tocsr()
    T, B_coarse = fit_candidates(AggOp, np.asarray(B, dtype=float))
    k = B_coarse.shape[1]
    n_aggregates = AggOp.shape[1]
    aggregates = np.full(A.shape[0], -1, dtype=np.int64)
    rows = np.repeat(np.arange(A.shape[0]), np.diff(AggOp.indptr))
    aggregates[rows] = AggOp.indices
    # T (BSR, 1 x k blocks, one block per aggregated row): its values per fine row
    T = T.tobsr(blocksize=(1, k))
    tvalues = np.zeros((A.shape[0], k))
    block_rows = np.repeat(np.arange(A.shape[0]), np.diff(T.indptr))
    tvalues[block_rows] = T.data[:, 0, :]
    P = smoothed_prolongator(A, aggregates, tvalues, n_aggregates, omega)
    del T, AggOp
    A_coarse = galerkin(A, P).tobsr(blocksize=(k, k))
    A_coarse.sort_indices()
    return P, P.T, A_coarse, B_coarse


def block_finest_level(A, B, omega: float = 4.0 / 3.0):
    """(P, R, A_coarse, B_coarse) of the finest level of pyamg's 3 x 3 block hierarchy (3D, six rigid
    modes; ``vemkit.solvers.linear.amg``'s block set-up), without its float64 BSR copies of A (four
    alive at once in the Jacobi smoothing: 3.3 of the solve's 3.3 GiB at 10^6 DOFs). The aggregates
    are pyamg's: "symmetric" strength at theta = 0 is every block of A.tobsr((3, 3)) (its block
    pattern, found on one byte per entry), ``standard_aggregation`` of it, ``fit_candidates``; P is
    :func:`smoothed_prolongator` (pyamg's "local" Jacobi: the same products and sums), R = P^T a view,
    A_coarse = :func:`block_galerkin`, 6 x 6 BSR (pyamg's to rounding: other association of R A P)."""
    from pyamg.aggregation import fit_candidates, standard_aggregation

    A = A.tocsr()
    ones = sp.csr_matrix((np.ones(A.nnz, dtype=np.int8), A.indices, A.indptr), shape=A.shape)
    blocks = to_blocks(ones, 3, 3)  # the block pattern in the order pyamg sees it
    del ones
    nodes = A.shape[0] // 3
    strength = sp.csr_array((np.ones(blocks.indices.size), blocks.indices, blocks.indptr), shape=(nodes, nodes))
    del blocks
    AggOp, _ = standard_aggregation(strength)
    del strength
    AggOp = AggOp.tocsr()
    T, B_coarse = fit_candidates(AggOp, np.asarray(B, dtype=float))
    k = B_coarse.shape[1]
    node_aggregate = np.full(nodes, -1, dtype=np.int64)
    node_aggregate[np.repeat(np.arange(nodes), np.diff(AggOp.indptr))] = AggOp.indices
    T = T.tobsr(blocksize=(1, k))
    tvalues = np.zeros((A.shape[0], k))
    tvalues[np.repeat(np.arange(A.shape[0]), np.diff(T.indptr))] = T.data[:, 0, :]
    del T
    P = smoothed_prolongator(A, np.repeat(node_aggregate, 3), tvalues, AggOp.shape[1], omega)
    A_coarse = block_galerkin(A, P, k)
    A_coarse.sort_indices()
    return P, P.T, A_coarse, B_coarse


def _rows(A, lo: int, hi: int):
    """The rows lo <= r < hi of the CSR matrix A on views of its arrays (``A[lo:hi]`` copies them)."""
    start, stop = A.indptr[lo], A.indptr[hi]
    return sp.csr_matrix(
        (A.data[start:stop], A.indices[start:stop], A.indptr[lo : hi + 1] - start), shape=(hi - lo, A.shape[1])
    )


def _block_rows(M, lo: int, hi: int):
    """The block rows lo <= r < hi of the BSR matrix M (views of its arrays)."""
    start, stop = M.indptr[lo], M.indptr[hi]
    shape = (M.blocksize[0] * (hi - lo), M.shape[1])
    return sp.bsr_matrix((M.data[start:stop], M.indices[start:stop], M.indptr[lo : hi + 1] - start), shape=shape)


def block_galerkin(A, P, k: int):
    """P^T A P (k x k BSR) as :func:`galerkin` sums it, by row blocks, with the blocks of 3D: A in 3 x 3,
    P in 3 x k (one block row of A converted at a time). At 4.2e5 DOFs 2.2 -> 1.2 s. The products of
    two row blocks run at once (scipy's sparse products release the GIL), their sum in the order of
    the blocks: the same operator as one after the other."""
    from concurrent.futures import ThreadPoolExecutor

    P_blocks = to_blocks(P, 3, k)
    nodes = A.shape[0] // 3
    chunks = max(1, A.shape[0] // BLOCK_RAP_ROWS)
    total, pending = None, []

    def part(lo, hi, A_blocks):
        return _block_rows(P_blocks, lo, hi).T @ (A_blocks @ P_blocks)

    with ThreadPoolExecutor(max_workers=GALERKIN_THREADS) as pool:
        for c in range(chunks):
            lo, hi = c * nodes // chunks, (c + 1) * nodes // chunks
            pending.append(pool.submit(part, lo, hi, to_blocks(_rows(A, 3 * lo, 3 * hi), 3, 3)))
            while len(pending) >= GALERKIN_THREADS or (pending and c == chunks - 1):
                done = pending.pop(0).result()
                total = done if total is None else total + done
    return total


GALERKIN_THREADS = 2  # row blocks of the block Galerkin product in flight
#: rows of A per partial product of the block Galerkin operator: two in flight of half RAP_ROWS cost the
#: set-up's peak what one of RAP_ROWS did (10^6 DOFs, 3D: 2.14 GiB; 2.57 GiB with two of RAP_ROWS)
BLOCK_RAP_ROWS = 125_000


RAP_ROWS = 250_000  # rows of A per partial product of the Galerkin operator


def galerkin(A, P):
    """P^T A P as the sum over row blocks r of P_r^T (A_r P): A P (as large as A) is never formed
    whole. At 2.1 M DOFs: 3.2 -> 2.3 s CPU, the set-up's peak +622 -> +174 MiB."""
    n = A.shape[0]
    chunks = max(1, n // RAP_ROWS)
    total = None
    for c in range(chunks):
        lo, hi = c * n // chunks, (c + 1) * n // chunks
        part = P[lo:hi].T.tocsr() @ (A[lo:hi] @ P)
        total = part if total is None else total + part
    return total
