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
