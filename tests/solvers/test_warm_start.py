"""A warm start (``initial = (u0, lambda0)``) changes where the contact solvers begin, never what they find."""

import numpy as np
import pytest

from vemkit.contact.laws import ContactLaw
from vemkit.contact.problem import discrete_problem
from vemkit.mesh.families.square import square
from vemkit.solvers.dispatch import solve
from vemkit.solvers.solution import SLIP, STICK, contact_state

OPTIONS = {"ssn": {"method": "ssn", "tol": 1e-10}, "uzawa": {"method": "uzawa", "tol": 1e-10}}


def _paper(friction_k: float):
    """The paper's scene on square(8); friction k = 450 (the paper): every contact vertex slips; 1500: they stick."""
    return discrete_problem(
        square(8),
        2000.0,
        0.4,
        dirichlet=("right",),
        neumann={"left": lambda x, y: (200 * (5 - y), -200 + 0 * y), "top": lambda x, y: (0 * x, 0 * x)},
        contact=("bottom",),
        gap=lambda x, y: 0.1 + 0 * x,
        law=ContactLaw(10.0, 1.0, friction_k, 0.0),
    )


@pytest.mark.parametrize("friction_k, state", [(450.0, SLIP), (1500.0, STICK)])
@pytest.mark.parametrize("method", ["ssn", "uzawa"])
def test_started_at_the_solution_the_solver_stops_at_once_on_it(method, friction_k, state):
    problem = _paper(friction_k)
    cold = solve(problem, OPTIONS[method])
    assert np.sum(contact_state(problem, cold.u, cold.multiplier).state == state) >= 6
    warm = solve(problem, OPTIONS[method], initial=(cold.u, cold.multiplier))
    assert warm.iterations <= (0 if method == "ssn" else 2) < cold.iterations
    assert np.abs(warm.u - cold.u).max() <= 1e-8 * np.abs(cold.u).max()
    assert np.abs(warm.multiplier - cold.multiplier).max() <= 1e-6


def test_a_wild_warm_start_still_finds_the_solution():
    """ssn keeps the cold start when the warm one has the larger residual; Uzawa contracts from anywhere."""
    problem = _paper(1500.0)
    cold = solve(problem, OPTIONS["ssn"])
    rng = np.random.default_rng(7)
    wild = (100.0 * rng.normal(size=cold.u.size), rng.uniform(-3.0, 3.0, cold.multiplier.size))
    for method in ("ssn", "uzawa"):
        found = solve(problem, OPTIONS[method], initial=wild)
        assert np.abs(found.u - cold.u).max() <= 1e-7 * np.abs(cold.u).max(), method
    assert solve(problem, OPTIONS["ssn"], initial=wild).info["warm_start"] is False
