"""vemkit's finest AMG level (vemkit.solvers.amg_setup): the Galerkin operator by row blocks on
threads is P^T A P, the same sums whatever the thread count."""

import numpy as np
from conftest import family_mesh, paper_problem

from vemkit.solvers import amg_setup


def test_the_galerkin_operator_by_row_blocks_on_threads_is_pt_a_p(monkeypatch):
    problem = paper_problem(family_mesh("square", 40))
    A = problem.stiffness.tocsr()
    P, _, _, _ = amg_setup.finest_level(A, problem.near_nullspace)
    monkeypatch.setattr(amg_setup, "RAP_ROWS", A.shape[0] // 7)  # seven row blocks
    reference = (P.T @ A @ P).toarray()
    threaded = amg_setup.galerkin(A, P)
    assert np.max(np.abs(threaded.toarray() - reference)) <= 1e-12 * np.max(np.abs(reference))
    monkeypatch.setattr(amg_setup, "GALERKIN_THREADS", 1)
    serial = amg_setup.galerkin(A, P)
    assert np.array_equal(serial.indptr, threaded.indptr) and np.array_equal(serial.indices, threaded.indices)
    assert np.array_equal(serial.data, threaded.data)  # summed in block order either way
