"""vemkit's finest AMG level (vemkit.solvers.amg_setup): the Galerkin operator summed over row
blocks is P^T A P."""

import numpy as np
from conftest import family_mesh, paper_problem

from vemkit.solvers import amg_setup


def test_the_galerkin_operator_by_row_blocks_is_pt_a_p(monkeypatch):
    problem = paper_problem(family_mesh("square", 40))
    A = problem.stiffness.tocsr()
    P, _, _, _ = amg_setup.finest_level(A, problem.near_nullspace)
    monkeypatch.setattr(amg_setup, "RAP_ROWS", A.shape[0] // 7)  # seven row blocks
    reference = (P.T @ A @ P).toarray()
    blocks = amg_setup.galerkin(A, P).toarray()
    assert np.max(np.abs(blocks - reference)) <= 1e-12 * np.max(np.abs(reference))
    assert not np.array_equal(blocks, np.zeros_like(blocks))


def test_the_3d_finest_level_is_pyamgs_block_level():
    """3D (3 x 3 blocks, six rigid modes): the same aggregates and P as pyamg's block set-up, to the
    last bit, and its Galerkin operator to rounding; R is P^T."""
    import pyamg
    from test_amg_update import _box_problem

    from vemkit.solvers.linear.amg import AMG_OPTIONS, BLOCK_MAX_COARSE

    problem = _box_problem(12)
    A = problem.stiffness.tocsr()
    options = dict(AMG_OPTIONS, max_coarse=BLOCK_MAX_COARSE, max_levels=2)
    theirs = pyamg.smoothed_aggregation_solver(A.tobsr(blocksize=(3, 3)), B=problem.near_nullspace, **options)
    P, R, A_coarse, B_coarse = amg_setup.block_finest_level(A, problem.near_nullspace)
    P_theirs, coarse_theirs = theirs.levels[0].P.tocsr(), theirs.levels[1].A.toarray()
    assert P.shape == P_theirs.shape and (P != P_theirs).nnz == 0
    assert np.array_equal(R.toarray(), P.toarray().T)
    assert np.max(np.abs(A_coarse.toarray() - coarse_theirs)) <= 1e-13 * np.max(np.abs(coarse_theirs))
    assert np.array_equal(B_coarse, theirs.levels[1].B)


def test_the_block_galerkin_operator_is_pt_a_p(monkeypatch):
    from test_amg_update import _box_problem

    A = _box_problem(8).stiffness.tocsr()
    P, _, _, _ = amg_setup.block_finest_level(A, _box_problem(8).near_nullspace)
    monkeypatch.setattr(amg_setup, "RAP_ROWS", A.shape[0] // 5)  # five row blocks
    reference = (P.T @ A @ P).toarray()
    blocks = amg_setup.block_galerkin(A, P, 6)
    assert blocks.blocksize == (6, 6)
    assert np.max(np.abs(blocks.toarray() - reference)) <= 1e-12 * np.max(np.abs(reference))
