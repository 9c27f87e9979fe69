"""The kernels of vemkit.solvers.sparse_ops are scipy's operations to the last bit: K x by rows on the
threads, and the conversion to blocks (the same blocks in the same order, duplicates summed)."""

import numpy as np
import pytest
import scipy.sparse as sp

from vemkit.solvers import sparse_ops


def _random_csr(rows, columns, seed, dtype=np.float64, duplicates=0):
    rng = np.random.default_rng(seed)
    M = sp.random(rows, columns, density=0.2, random_state=rng, format="coo", dtype=dtype)
    row, col, val = M.row, M.col, M.data
    if duplicates:  # repeated entries, rows unsorted: scipy sums them where it meets them
        pick = rng.integers(0, M.nnz, duplicates)
        row, col, val = np.r_[row, row[pick]], np.r_[col, col[pick]], np.r_[val, -val[pick] / 3].astype(dtype)
    order = rng.permutation(row.size)
    A = sp.csr_matrix((val[order], (row[order], col[order])), shape=(rows, columns))
    A = sp.csr_matrix((A.data, A.indices, A.indptr), shape=A.shape)  # keep the coo order (unsorted rows)
    return A


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_the_parallel_product_is_scipys_bit_for_bit(monkeypatch, dtype):
    monkeypatch.setattr(sparse_ops, "PARALLEL_NNZ", 0)  # the kernel for any size
    A = _random_csr(300, 200, 1, dtype)
    x = np.random.default_rng(2).standard_normal(200).astype(dtype)
    product = sparse_ops.matvec(A, x)
    assert product.dtype == dtype and np.array_equal(product, A @ x)
    assert np.array_equal(sparse_ops.matvec(A, x[:, None]), A @ x)  # a column is a vector
    # anything else is scipy's own product
    assert np.array_equal(sparse_ops.matvec(A.tocsc(), x), A @ x)


@pytest.mark.parametrize("blocksize", [(3, 3), (3, 6), (2, 4)])
def test_the_blocks_are_scipys_tobsr(blocksize):
    R, C = blocksize
    for seed, duplicates in ((3, 0), (4, 40)):
        A = _random_csr(12 * R, 10 * C, seed, duplicates=duplicates)
        ours, theirs = sparse_ops.to_blocks(A, R, C), A.tobsr(blocksize=blocksize)
        assert ours.blocksize == blocksize
        for name in ("indptr", "indices", "data"):
            assert np.array_equal(getattr(ours, name), getattr(theirs, name))
        assert np.array_equal(ours.toarray(), A.toarray())


def test_a_blocksize_that_does_not_divide_the_shape_is_refused():
    with pytest.raises(ValueError, match="blocksize"):
        sparse_ops.to_blocks(_random_csr(10, 9, 5), 3, 3)
