"""The linear solvers behind one interface (vemkit/solvers/linear/): the registry, the capabilities the
contact solvers ask for instead of a backend's name, and the Newton systems with their fallback."""

import numpy as np
import pytest
import scipy.sparse as sp

import vemkit
from vemkit.exceptions import SceneError
from vemkit.solvers.linear import (
    AMGSolver,
    DirectSolver,
    LinearSolver,
    ReducedSolver,
    backends,
    linear_solver,
)
from vemkit.solvers.sparse_ops import SumOperator


@pytest.fixture(scope="module")
def problem():
    scene = vemkit.load_scene("config/scenes/paper.yaml", ["discretization.mesh.n=8"])
    return vemkit.scene_problem(scene)


def test_the_registry_maps_each_name_to_its_backend():
    from vemkit.solvers.linear.petsc import PETScSolver  # petsc4py is imported only when it solves

    assert backends() == {"amg": AMGSolver, "direct": DirectSolver, "petsc": PETScSolver}
    assert all(issubclass(backend, LinearSolver) for backend in backends().values())
    with pytest.raises(SceneError, match="use amg, direct, petsc or auto"):
        linear_solver(sp.identity(2, format="csr"), "cholesky")


def test_capabilities_instead_of_names(problem):
    K = problem.stiffness
    amg = linear_solver(K, "amg", near_nullspace=problem.near_nullspace)
    direct = linear_solver(K, "direct")
    assert amg.iterative and not direct.iterative
    assert linear_solver(K, "auto", near_nullspace=problem.near_nullspace).method == "direct"  # small: direct
    assert linear_solver(K, direct) is direct  # a prebuilt solver is reused
    x_amg = amg.solve(problem.load, tol=1e-12)
    x_direct = direct.solve(problem.load)
    assert np.abs(x_amg - x_direct).max() <= 1e-9 * np.abs(x_direct).max()


def test_newton_systems_fall_back_from_amg_to_direct_once(problem):
    K = problem.stiffness
    base = linear_solver(K, "amg", near_nullspace=problem.near_nullspace)
    reduced = ReducedSolver(problem, base, baseline=5.0)
    J = sp.diags(np.linspace(0.0, 1.0, K.shape[0])).tocsr()
    assert reduced.method == "amg" and isinstance(reduced.operator(K, J), SumOperator)
    rhs = problem.load
    y_amg, its = reduced.solve(reduced.operator(K, J), None, rhs, 1e-12, penalty=lambda: 0 * K)
    assert its > 0
    assert reduced.fall_back() == "direct" and reduced.method == "direct"
    assert reduced.fall_back() is None  # direct has no fallback: nothing changes
    A = reduced.operator(K, J, J)
    assert sp.issparse(A) and A.format == "csr"
    assert np.array_equal(A.toarray(), ((K + J) + J).toarray())
    y_direct, its = reduced.solve(reduced.operator(K, J), None, rhs, 1e-12, penalty=lambda: 0 * K)
    assert its == 1 and np.abs(y_amg - y_direct).max() <= 1e-9 * np.abs(y_direct).max()
