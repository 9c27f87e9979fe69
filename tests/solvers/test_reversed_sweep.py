"""The backward Gauss-Seidel sweep on the rows stored last first (vemkit.solvers.reversed_sweep) is
pyamg's backward sweep to the last bit, also after the values change."""

import numpy as np
import pytest
import scipy.sparse as sp
from pyamg.relaxation.relaxation import gauss_seidel

from vemkit.solvers.reversed_sweep import ReversedRows


def _matrix(n, seed, dtype):
    rng = np.random.default_rng(seed)
    M = sp.random(n, n, density=0.1, random_state=rng, format="csr")
    A = (M + M.T + sp.diags(rng.uniform(1.0, 2.0, n))).tocsr().astype(dtype)
    A.sort_indices()
    A.data[A.indptr[3] : A.indptr[4]] = 0.0  # a row with a zero diagonal: x_3 stays where it is
    return A


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_the_sweep_is_pyamgs_backward_gauss_seidel(dtype):
    rng = np.random.default_rng(1)
    A = _matrix(120, 2, dtype)
    b, x0 = rng.standard_normal(120).astype(dtype), rng.standard_normal(120).astype(dtype)
    reversed_rows = ReversedRows(A)
    for _ in range(2):  # the values changed in the pattern, then refreshed
        theirs, ours = x0.copy(), x0.copy()
        gauss_seidel(A, theirs, b, sweep="backward")
        reversed_rows.backward_sweep(A, ours, b)
        assert np.array_equal(ours, theirs) and ours[3] == x0[3]
        A.data *= rng.uniform(0.5, 1.5, A.nnz).astype(dtype)
        reversed_rows.refresh(A)


def test_a_refresh_of_the_changed_positions_only_is_a_whole_refresh():
    rng = np.random.default_rng(5)
    A = _matrix(80, 6, np.float32)
    partial, whole = ReversedRows(A), ReversedRows(A)
    changed, more = np.unique(rng.integers(0, A.nnz, 50)), np.unique(rng.integers(0, A.nnz, 30))
    A.data[changed] += 1.0
    A.data[more] -= 2.0
    partial.refresh(A, changed, more)
    whole.refresh(A)
    assert np.array_equal(partial.data, whole.data)


def test_a_new_pattern_is_copied_again():
    A, B = _matrix(60, 3, np.float32), _matrix(60, 4, np.float32)
    reversed_rows = ReversedRows(A)
    reversed_rows.refresh(B)
    b = np.ones(60, dtype=np.float32)
    theirs, ours = np.zeros(60, np.float32), np.zeros(60, np.float32)
    gauss_seidel(B, theirs, b, sweep="backward")
    reversed_rows.backward_sweep(B, ours, b)
    assert np.array_equal(ours, theirs)
