"""The nodal (3 x 3 block) Gauss-Seidel smoother (vemkit.solvers.nodal_smoother): it is block
Gauss-Seidel (pyamg's, on the BSR form, to rounding), its forward/backward V-cycle is symmetric, and
it makes the updated hierarchy robust to the stiff rank-one slip-direction blocks of the 3D Newton
steps, which scalar Gauss-Seidel is not."""

import numpy as np
import pytest
import scipy.sparse.linalg as spla
from pyamg.relaxation.relaxation import block_gauss_seidel
from test_amg_update import _box_problem

from vemkit.contact.boundary import rank_one_blocks
from vemkit.solvers.amg_update import BoundaryUpdatedHierarchy
from vemkit.solvers.linear import linear_solver
from vemkit.solvers.nodal_smoother import NodalBlocks, block_residual, diagonal_blocks, nodal_gauss_seidel


def _stiff_slip_term(problem, size, seed=0):
    """w b slope (e1 t1 + e2 t2)(...)^T at every contact vertex, slope ~ ``size`` x the stiffness
    diagonal, e a random unit direction in the tangent plane (a turning slip)."""
    cb, n, K = problem.contact, problem.n_dofs, problem.stiffness
    angle = np.random.default_rng(seed).uniform(0, 2 * np.pi, cb.size)
    direction = cb.tangent * np.cos(angle)[:, None] + cb.tangent2 * np.sin(angle)[:, None]
    return rank_one_blocks(cb, np.full(cb.size, size * K.diagonal().max()), direction, n).tocsr()


@pytest.mark.parametrize("forward", [True, False])
def test_the_sweep_is_pyamgs_block_gauss_seidel(forward):
    problem = _box_problem(5)
    A = (problem.stiffness + _stiff_slip_term(problem, 1e4)).tocsr()
    A.sort_indices()
    rng = np.random.default_rng(1)
    b, x0 = rng.normal(size=A.shape[0]), rng.normal(size=A.shape[0])
    ours, theirs = x0.copy(), x0.copy()
    nodal_gauss_seidel(A, ours, b, np.linalg.inv(diagonal_blocks(A)), forward=forward)
    block_gauss_seidel(A.tobsr(blocksize=(3, 3)), theirs, b, sweep="forward" if forward else "backward", blocksize=3)
    assert np.max(np.abs(ours - theirs)) <= 1e-10 * np.max(np.abs(theirs))


@pytest.mark.parametrize("forward", [True, False])
def test_the_block_sweep_is_the_scalar_one(forward):
    """On the 3 x 3 BSR form (blocks filled with K's unstored zeros) the sweep is the CSR one to rounding."""
    problem = _box_problem(5)
    A = (problem.stiffness + _stiff_slip_term(problem, 1e4)).tocsr()
    A.sort_indices()
    rng = np.random.default_rng(5)
    b, x0 = rng.normal(size=A.shape[0]), rng.normal(size=A.shape[0])
    inverses = np.linalg.inv(diagonal_blocks(A))
    scalar, blocks = x0.copy(), x0.copy()
    nodal_gauss_seidel(A, scalar, b, inverses, forward=forward)
    nodal_gauss_seidel(A.tobsr(blocksize=(3, 3)), blocks, b, inverses, forward=forward)
    assert np.max(np.abs(scalar - blocks)) <= 1e-10 * np.max(np.abs(scalar))


def test_the_blocks_of_k_plus_d_are_updated_where_d_lives():
    problem = _box_problem(4)
    K, D = problem.stiffness.tocsr(), _stiff_slip_term(problem, 10.0)
    blocks = NodalBlocks(K)
    expected = np.linalg.inv(diagonal_blocks((K + D).tocsr()))
    assert np.allclose(blocks.with_term(D), expected, rtol=1e-12, atol=0.0)
    assert np.array_equal(blocks.with_term(D * 0.0), blocks.inverses)  # K's own, untouched


def _cg_iterations(A, b, M):
    count = [0]
    spla.cg(A, b, rtol=1e-8, atol=0.0, M=M, maxiter=3000, callback=lambda _: count.__setitem__(0, count[0] + 1))
    return count[0]


def test_the_nodal_cycle_is_symmetric_and_robust_to_stiff_slip_blocks():
    """CG on K + D with D the slip-direction blocks at 1 ... 1e6 times K's diagonal: with the nodal
    smoother the iterations stay near those of a mild D; with scalar Gauss-Seidel they grow."""
    problem = _box_problem(10)
    K, n = problem.stiffness, problem.n_dofs
    hierarchy = linear_solver(K, "amg", near_nullspace=problem.near_nullspace).hierarchy
    nodal, scalar = BoundaryUpdatedHierarchy(hierarchy, nodal=True), BoundaryUpdatedHierarchy(hierarchy)
    rng = np.random.default_rng(2)
    u, v = rng.normal(size=n), rng.normal(size=n)
    counts = {}
    for size in (1.0, 1e6):
        D = _stiff_slip_term(problem, size)
        A = (K + D).tocsr()
        M = nodal.preconditioner(D)
        assert abs(u @ (M @ v) - v @ (M @ u)) <= 1e-10 * np.linalg.norm(u) * np.linalg.norm(M @ v)
        b = A @ rng.normal(size=n)
        counts[size] = (_cg_iterations(A, b, M), _cg_iterations(A, b, scalar.preconditioner(D)))
    (mild_nodal, _), (stiff_nodal, stiff_scalar) = counts[1.0], counts[1e6]
    assert stiff_nodal <= mild_nodal + 3, counts
    assert stiff_scalar >= 2 * stiff_nodal, counts


def test_the_block_residual_is_b_minus_a_x():
    problem = _box_problem(5)
    A = (problem.stiffness + _stiff_slip_term(problem, 1e4)).tocsr().tobsr(blocksize=(3, 3))
    rng = np.random.default_rng(7)
    x, b = rng.normal(size=A.shape[0]), rng.normal(size=A.shape[0])
    expected = b - A @ x
    assert np.max(np.abs(block_residual(A, x, b) - expected)) <= 1e-12 * np.max(np.abs(expected))
