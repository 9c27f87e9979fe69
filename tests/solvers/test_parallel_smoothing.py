"""The finest AMG level on both cores (vemkit.solvers.parallel_smoothing): one block is pyamg's
Gauss-Seidel to the last bit, several blocks are the l1 hybrid sweep (checked against a plain
loop), the product is scipy's to the last bit, and the V-cycle with the hybrid sweeps stays a symmetric
positive definite preconditioner that CG converges with nearly as fast as with Gauss-Seidel (16 and
18 iterations on 3 549 DOFs with two blocks, whose interface is a large part of so small a mesh)."""

import numpy as np
import pytest
import scipy.sparse.linalg as spla
from pyamg.relaxation.relaxation import gauss_seidel

from vemkit.config.scene import scene_from_dict
from vemkit.contact.problem import scene_problem
from vemkit.solvers.linear import linear_solver, v_cycle
from vemkit.solvers.parallel_smoothing import hybrid_gauss_seidel, matvec


def _box(family, n):
    data = {
        "model": "3d",
        "domain": {"box": [[0, 0, 0], [1, 1, 0.5]]},
        "material": {"E": 1000.0, "nu": 0.3},
        "boundary": {"dirichlet": {"bottom": [0.0, 0.0, 0.0]}, "neumann": {"top": {"traction": [1.0, 0.0, -2.0]}}},
        "discretization": {"mesh": {"family": family, "n": n}},
    }
    return scene_problem(scene_from_dict(data))


@pytest.fixture(scope="module")
def problem():
    return _box("voronoi", 5)


def _reference_sweep(A, x, b, chunks, forward):
    """The l1 hybrid sweep, row by row in plain Python."""
    n = A.shape[0]
    bounds = np.linspace(0, n, chunks + 1).astype(int)
    before = x.copy()
    for lo, hi in zip(bounds[:-1], bounds[1:]):
        for i in range(lo, hi) if forward else range(hi - 1, lo - 1, -1):
            row = slice(A.indptr[i], A.indptr[i + 1])
            cols, vals = A.indices[row], A.data[row]
            inside = (cols >= lo) & (cols < hi) & (cols != i)
            outside = (cols < lo) | (cols >= hi)
            l1 = np.abs(vals[outside]).sum()
            rsum = vals[inside] @ x[cols[inside]] + vals[outside] @ before[cols[outside]]
            x[i] = (b[i] - rsum + l1 * before[i]) / (vals[cols == i][0] + l1)


@pytest.mark.parametrize("forward", [True, False])
def test_one_block_is_pyamgs_gauss_seidel_and_several_the_l1_hybrid_sweep(problem, forward):
    K = problem.stiffness.tocsr()
    rng = np.random.default_rng(1)
    b, x0 = rng.normal(size=K.shape[0]), rng.normal(size=K.shape[0])
    ours, theirs = x0.copy(), x0.copy()
    hybrid_gauss_seidel(K, ours, b, forward=forward, chunks=1)
    gauss_seidel(K, theirs, b, sweep="forward" if forward else "backward")
    assert np.array_equal(ours, theirs)
    ours, reference = x0.copy(), x0.copy()
    hybrid_gauss_seidel(K, ours, b, forward=forward, chunks=3)
    _reference_sweep(K, reference, b, 3, forward)
    np.testing.assert_allclose(ours, reference, rtol=1e-12, atol=1e-12 * np.abs(reference).max())
    assert not np.allclose(ours, theirs)  # the blocks do change the sweep


def test_the_parallel_product_is_scipys_to_the_last_bit(problem):
    K = problem.stiffness.tocsr()
    x = np.random.default_rng(2).normal(size=K.shape[0])
    assert np.array_equal(matvec(K, x), K @ x)


def test_the_v_cycle_with_hybrid_sweeps_is_spd_and_as_good_as_gauss_seidel():
    problem = _box("hex", 14)
    K = problem.stiffness.tocsr()
    hierarchy = linear_solver(K, "amg", near_nullspace=problem.near_nullspace).hierarchy
    levels = hierarchy.levels
    assert len(levels) >= 2
    gs = (levels[0].presmoother, levels[0].postsmoother)

    def operator():
        return spla.LinearOperator(
            K.shape, matvec=lambda r: v_cycle(levels, hierarchy.coarse_solver, 0, np.ravel(r)), dtype=float
        )

    def iterations(M):
        count = [0]
        spla.cg(K, problem.load, rtol=1e-10, M=M, callback=lambda _: count.__setitem__(0, count[0] + 1))
        return count[0]

    plain = iterations(operator())
    levels[0].presmoother = lambda A, x, b: hybrid_gauss_seidel(A, x, b, forward=True, chunks=2)
    levels[0].postsmoother = lambda A, x, b: hybrid_gauss_seidel(A, x, b, forward=False, chunks=2)
    try:
        M = operator()
        rng = np.random.default_rng(3)
        u, v = rng.normal(size=K.shape[0]), rng.normal(size=K.shape[0])
        assert abs(v @ (M @ u) - u @ (M @ v)) <= 1e-10 * abs(u @ (M @ v))
        assert all(w @ (M @ w) > 0 for w in (u, v))
        hybrid = iterations(M)
    finally:
        levels[0].presmoother, levels[0].postsmoother = gs
    assert hybrid <= 1.25 * plain + 1, (hybrid, plain)
