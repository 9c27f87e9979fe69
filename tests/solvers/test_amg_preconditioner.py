"""The AMG V-cycle preconditioner of vemkit.solvers.linear: what CG needs of it (symmetric, positive
definite) and agreement with pyamg's own cycle on the same hierarchy; AMG-CG meets its tolerance."""

from pathlib import Path

import numpy as np
from conftest import family_mesh, paper_problem

from vemkit.solvers.linear import (
    CYCLE_PRECISION,
    FINEST_OWN,
    AMGSolver,
    linear_solver,
    smoothed_aggregation,
    v_cycle_preconditioner,
)

ROOT = Path(__file__).resolve().parents[2]


def _amg(n):
    problem = paper_problem(family_mesh("triangle-delaunay", n))
    return problem, AMGSolver(problem.stiffness, problem.near_nullspace, tol=1e-10)


def test_v_cycle_is_symmetric_positive_definite_and_equals_pyamgs_cycle():
    """In double precision the cycle is pyamg's own, to round-off."""
    problem = paper_problem(family_mesh("triangle-delaunay", 160))  # ~50 000 unknowns: three levels
    hierarchy = smoothed_aggregation(problem.stiffness.tocsr(), problem.near_nullspace)
    assert len(hierarchy.levels) >= 3  # a real multilevel cycle, coarse levels included
    rng = np.random.default_rng(0)
    x, y = rng.standard_normal((2, problem.n_dofs))
    M = v_cycle_preconditioner(hierarchy, np.float64)
    Mx, My = M @ x, M @ y
    assert abs(x @ My - y @ Mx) <= 1e-12 * np.linalg.norm(x) * np.linalg.norm(My)
    assert x @ Mx > 0.0 and y @ My > 0.0
    reference = hierarchy.aspreconditioner(cycle="V")  # pyamg's cycle through the same levels
    assert np.allclose(Mx, reference @ x, rtol=0.0, atol=1e-12 * np.abs(Mx).max())


def test_the_single_precision_cycle_is_the_double_one_to_its_rounding_and_cg_needs_as_many_iterations():
    """The default cycle runs in float32 (CYCLE_PRECISION): the double cycle's vector to ~1e-6 (not
    to the last bit: it is not the double cycle), symmetric and positive to that rounding, and CG, in
    double, meets 1e-10 in the same iterations +- 1, on a mesh whose finest level is vemkit's own."""
    assert CYCLE_PRECISION == np.float32
    problem, amg = _amg(160)
    assert problem.n_dofs > FINEST_OWN
    rng = np.random.default_rng(1)
    x, y = rng.standard_normal((2, problem.n_dofs))
    double = v_cycle_preconditioner(smoothed_aggregation(problem.stiffness.tocsr(), problem.near_nullspace), np.float64)
    Mx, My = amg.preconditioner @ x, amg.preconditioner @ y
    assert Mx.dtype == np.float64
    assert 1e-9 < np.max(np.abs(Mx - double @ x)) / np.max(np.abs(Mx)) < 1e-5
    assert abs(x @ My - y @ Mx) <= 1e-5 * np.linalg.norm(x) * np.linalg.norm(My)
    assert x @ Mx > 0.0 and y @ My > 0.0
    u = amg.solve(problem.load)
    single_iterations = amg.iterations
    assert amg.residual <= 1e-10
    amg.preconditioner = double
    reference = amg.solve(problem.load)
    assert abs(single_iterations - amg.iterations) <= 1, (single_iterations, amg.iterations)
    assert np.linalg.norm(u - reference) <= 1e-8 * np.linalg.norm(reference)


def test_amg_cg_meets_its_tolerance_and_agrees_with_the_direct_solve():
    problem, amg = _amg(60)
    u = amg.solve(problem.load)
    assert amg.residual <= 2e-10 and 0 < amg.iterations < 100
    direct = linear_solver(problem.stiffness, "direct").solve(problem.load)
    assert np.linalg.norm(u - direct) <= 1e-8 * np.linalg.norm(direct)


def test_auto_solves_a_3d_body_by_amg_from_a_few_thousand_unknowns_and_agrees_with_direct():
    """``auto`` in 3D switches at DIRECT_LIMIT_3D (a 2D body of the same size is solved directly),
    and the two solvers give the same displacement."""
    from vemkit.config.scene import load_scene
    from vemkit.contact.problem import scene_problem
    from vemkit.solvers.linear import DIRECT_LIMIT, DIRECT_LIMIT_3D

    box = scene_problem(load_scene(ROOT / "config/scenes/3d/sheared_box.yaml", ["discretization.mesh.n=10"]))
    assert DIRECT_LIMIT_3D < box.n_dofs < DIRECT_LIMIT
    auto = linear_solver(box.stiffness, "auto", near_nullspace=box.near_nullspace, tol=1e-12)
    assert auto.method == "amg"
    assert linear_solver(box.stiffness, "auto").method == "direct"  # no 3D near-nullspace: the 2D limit
    direct = linear_solver(box.stiffness, "direct").solve(box.load)
    assert np.linalg.norm(auto.solve(box.load) - direct) <= 1e-10 * np.linalg.norm(direct)
