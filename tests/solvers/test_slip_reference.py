"""The incremental friction law of a loading in steps (issue 21 item 4): the slip counted from a
reference u_tau^ref (the previous step's u_tau), an explicit argument of the public solve call and
of the independent check; and ssn on the coupled Coulomb law m_tau = m_nu = 1, k_tau = mu k_nu."""

import numpy as np
import pytest
from test_contact3d_solvers import SSN, UZAWA, sheared_box  # noqa: E402  (pytest puts tests/solvers on sys.path)

from vemkit.solvers.dispatch import solve
from vemkit.solvers.solution import STICK, contact_state
from vemkit.solvers.verification import verify_solution


def _coulomb_box(n, mu=0.3, family="hex"):
    return sheared_box(family, n, mu * 200.0, m=1.0)  # k_nu = 200, m_nu = 1: Coulomb


@pytest.mark.parametrize("family, n, friction, m", [("hex", 4, 3.0, 0.0), ("hex", 3, 60.0, 1.0)])
def test_a_reference_at_the_solution_sticks_everywhere_with_the_same_u(family, n, friction, m):
    problem = sheared_box(family, n, friction, m)
    cb = problem.contact
    static = solve(problem, SSN)
    reference = cb.tangential_displacement(static.u)
    for options in (SSN, UZAWA):
        step = solve(problem, options, slip_reference=reference)
        assert np.max(np.abs(step.u - static.u)) / np.max(np.abs(static.u)) < 1e-10
        state = contact_state(problem, step.u, step.multiplier, slip_reference=reference)
        touching = state.penetration > 0
        assert np.all(state.state[touching] == STICK) and touching.sum() > 10
        assert verify_solution(problem, step.u, step.multiplier, tol=1e-10, slip_reference=reference)["passed"]
    assert np.sum(contact_state(problem, static.u, static.multiplier).state == STICK) < touching.sum()


def test_both_solvers_agree_with_a_reference_and_the_check_needs_it():
    """A reference: the static solution's u_tau turned by 90 degrees, halved (a slip counted from it
    is not parallel to u_tau): the incremental problem has stick and slip; uzawa and ssn agree to
    1e-10, the check passes with the reference and fails without."""
    problem = sheared_box("hex", 4, 3.0)
    cb = problem.contact
    reference = 0.5 * cb.tangential_displacement(solve(problem, SSN).u) @ np.array([[0.0, 1.0], [-1.0, 0.0]])
    a = solve(problem, UZAWA, slip_reference=reference)
    b = solve(problem, SSN, slip_reference=reference)
    assert np.max(np.abs(a.u - b.u)) / np.max(np.abs(b.u)) < 1e-10
    assert np.max(np.abs(a.multiplier - b.multiplier)) < 1e-10
    assert verify_solution(problem, b.u, b.multiplier, tol=1e-10, slip_reference=reference)["passed"]
    assert not verify_solution(problem, b.u, b.multiplier, tol=1e-10)["passed"]
    counts = contact_state(problem, b.u, b.multiplier, slip_reference=reference).count()
    assert counts["stick"] > 0 and counts["slip"] > 0, counts


def test_ssn_on_coulomb_agrees_with_uzawa_and_newton_stays_bounded():
    """m_tau = m_nu = 1, k_tau = 0.3 k_nu (Coulomb): uzawa = ssn to 1e-10 at tol 1e-12 on n = 3;
    ssn's Newton iterations over n = 3, 5, 7 stay bounded."""
    problem = _coulomb_box(3)
    a, b = solve(problem, UZAWA), solve(problem, SSN)
    assert np.max(np.abs(a.u - b.u)) / np.max(np.abs(b.u)) < 1e-10
    assert np.max(np.abs(a.multiplier - b.multiplier)) < 1e-10
    iterations = [b.iterations]
    for n in (5, 7):
        problem = _coulomb_box(n)
        s = solve(problem, SSN)
        assert verify_solution(problem, s.u, s.multiplier, tol=1e-10)["passed"]
        iterations.append(s.iterations)
    assert max(iterations) <= 12, iterations
