"""Why the Uzawa iteration (vemkit.solvers.uzawa) failed: the boundary compliances behind its step
length and its contraction factors, and the one-line ConvergenceErrors naming the likely culprit.

The lagged normal compliance contracts by about max p_nu' mu_nu and the friction step by
rho k_tau^2 mu_tau (mu: largest eigenvalue of the boundary compliance W^1/2 C W^1/2, C_cd = d_c . K^-1
d_d for d = nu or tau); a failure names the factor that is >= 1 (or close to it).
"""

from __future__ import annotations

import numpy as np

from vemkit.contact import ball
from vemkit.exceptions import ConvergenceError
from vemkit.solvers.solution import young_modulus


def boundary_compliance(solver, problem, direction, iterations=20, rtol=1e-3):
    """Largest eigenvalue of W^1/2 C W^1/2, C_cd = d_c . K^-1 d_d (d = normal or tangent), by power iteration."""
    cb = problem.contact
    sqrt_w = np.sqrt(cb.weight)
    zero = np.zeros(cb.size)
    tangent = direction == "tangent"
    # the tangential components of every vertex (vemkit.contact.ball: the disk's start is random)
    v = cb.ball.power_start(sqrt_w) if tangent else sqrt_w / np.linalg.norm(sqrt_w)
    estimate, solves = 0.0, 0
    for _ in range(iterations):
        load = cb.times(sqrt_w, v) if tangent else sqrt_w * v
        rhs = (
            cb.scatter(zero, load, problem.n_dofs)
            if tangent
            else cb.scatter(load, cb.zero_multiplier(), problem.n_dofs)
        )
        x = solver.solve(rhs, tol=1e-6)
        solves += max(solver.iterations, 1)
        Sv = cb.times(sqrt_w, cb.tangential_displacement(x)) if tangent else sqrt_w * cb.normal_displacement(x)
        new = ball.inner(v, Sv) if tangent else float(v @ Sv)
        norm = np.linalg.norm(Sv)
        if norm == 0.0:
            return 0.0, solves
        v = Sv / norm
        if abs(new - estimate) <= rtol * abs(new):
            return new, solves
        estimate = new
    return estimate, solves


def refuse(state):
    """Raise the inaccurate_stop error: a stopping test fired, but the residual never reached the level."""
    stopped_by, check, accept = state.refused
    raise ConvergenceError(
        f"uzawa stopped after {state.n} iterations by the {'|Δλ|' if stopped_by == 'dlambda' else '|Δu|'} test "
        f"but the discrete problem residual is {check['worst']:.1e} (accepted {accept:.0e}): "
        f"try --set solver.stop=both, smaller solver.eps_u/eps_lambda, or --set solver.method=ssn",
        solver="uzawa",
        reason="inaccurate_stop",
        iterations=state.n,
    )


def fail(state, what, reason):
    """Raise a ConvergenceError (``reason``) naming the most likely culprit, from estimates of the two
    contraction factors (lagged normal compliance, friction step rho)."""
    problem, solver, u, n, rho_n, mu_tau = state.problem, state.solver, state.u, state.n, state.rho, state.mu_tau
    law, cb = problem.law, problem.contact
    E = young_modulus(problem)
    mu_nu, _ = boundary_compliance(solver, problem, "normal", iterations=10)
    t = cb.normal_displacement(u) - cb.gap if np.all(np.isfinite(u)) else np.full(cb.size, np.inf)
    normal_factor = law.lagged_stiffness(t) * mu_nu
    if mu_tau == 0.0 and not law.frictionless:
        mu_tau, _ = boundary_compliance(solver, problem, "tangent", iterations=10)
    k_tau = law.friction_coefficient
    friction_factor = rho_n * k_tau * k_tau * mu_tau
    verb = "diverged" if reason == "diverged" else "did not converge"
    head = f"uzawa {verb} after {n} iterations ({what})"
    typed = dict(solver="uzawa", reason=reason, iterations=n)
    if normal_factor >= 0.5:
        raise ConvergenceError(
            f"{head}: the lagged normal compliance is unstable for {law.normal_text} "
            f"against E = {E:g} (contraction estimate {normal_factor:.1e} >= 1); "
            f"try --set solver.method=ssn",
            **typed,
        )
    if friction_factor >= 1.9:
        raise ConvergenceError(
            f"{head}: solver.rho = {rho_n:.3g} is too large for contact.friction.k = {k_tau:g} "
            f"(stable below {2.0 / (k_tau**2 * mu_tau):.3g}); try a smaller solver.rho or solver.method=ssn",
            **typed,
        )
    if not law.reduced:
        raise ConvergenceError(
            f"{head}: the lagged friction bound of {law.friction_text} does not settle; try --set solver.method=ssn",
            **typed,
        )
    raise ConvergenceError(
        f"{head}: try a larger solver.max_iterations, a smaller solver.rho, or --set solver.method=ssn",
        **typed,
    )
