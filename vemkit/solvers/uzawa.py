"""The paper's Uzawa iteration (Section 5, Steps 1-3, (5.4)-(5.6)) for the discrete contact problem.

Step 1  lambda^0 = 0, u^0 = 0 (or a warm start ``initial = (u^0, lambda^0)``, e.g. the previous
        adaptive step's solution prolongated to the refined mesh; lambda^0 projected onto [-1, 1]).
        A warm start's first |u^n - u^{n-1}| can dip below its later values (measured on an adapted
        paper-scene mesh: 5.4e-9 at n = 3, then 6.0e-9 falling by 4e-4 per iteration), so there a
        new smallest residual also counts as progress for the stagnation test below.
Step 2  K u^n = f - sum_c w_c [p_nu(t_c^{n-1}) nu_c + p_tau(t_c^{n-1}) lambda_c^{n-1} tau_c],
        t^{n-1} = u_nu^{n-1} - g   (normal compliance and friction bound lagged: explicit in u^{n-1});
        lambda^n = P(lambda^{n-1} + rho k_tau u_tau^n),  P = projection onto [-1, 1] (3D: onto the unit
        disk of the tangent plane, lambda and u_tau two components in the vertex basis (t1, t2)).
Step 3  stop when ||u^n - u^{n-1}|| < eps_u ||u^n||  or  max|lambda^n - lambda^{n-1}| < eps_lambda
        (``stop="either"``, the paper's rule; ``stop="both"`` asks for both). The tests start at n = 2
        (n = 1 compares with the arbitrary initial guess); for a frictionless law lambda is no unknown
        and only the u test is used.

The contact forces are those of vemkit.solvers.solution.contact_force_vector: with
``contact_quadrature: gauss`` the lagged normal-compliance term is the Gauss edge integral of
vemkit.contact.boundary (still explicit in u^{n-1}); the friction term and lambda stay nodal.

For the reduced law (m_tau = 0, the paper's) p_tau = k_tau and this is exactly (5.4)-(5.5). For
m_tau > 0 the friction bound in the explicit term is p_tau(u_nu^{n-1} - g), and the update of
lambda keeps the paper's form rho k_tau u_tau^n (so lambda = sign(u_tau) wherever the vertex slips,
also where p_tau = 0 and lambda has no force).

The matrix K never changes: one linear solver (factorization or AMG hierarchy) is built once and
reused. AMG-CG is warm-started from u^{n-1} + alpha (u^{n-1} - u^{n-2}) (alpha minimizing the energy
error along the last change) and solved to max(floor, INNER_FRACTION |u^{n-1} - u^{n-2}| / |u^{n-1}|),
floor = inner_floor(tol, eps_u) = INNER_FRACTION min(tol, eps_u) (at least INNER_ROUNDING eps); when a
stopping test passes on such an inexact solve, that solve is finished to the floor and the test
repeated, so the iterates stopped on are those of solves to the floor. The floor was tol until the
3D sheared box (config/scenes/3d/sheared_box.yaml, hexahedra, stick and slip) showed why that is
too loose: late in the iteration the right-hand side changes by less than tol |rhs| per iteration, so
CG, warm-started at u^{n-1}, meets tol at its start and returns it unchanged (0 iterations); then
|u^n - u^{n-1}| = 0 fires the |Δu| stop on a lambda still moving (|Δλ| 2e-8), and the residual
(its complementarity part, |u_tau| at sticking vertices ~ |Δλ| / (rho k_tau), 50-100 x the
equilibrium part) was 5.5e-9 at n = 12, 1.3e-8 at n = 24 against the accepted 1e-9 (tol 1e-10, with
eps_u = 1e-12 and with the defaults 1e-10): ConvergenceError(inaccurate_stop). With the floor 1e-14
n = 12 stops by |Δu| after 463 iterations at residual 1.8e-10, n = 40 (105 903 DOFs) after 1 260 at
9.9e-10; 2D paper scene with AMG (n = 32 ... 256): the same iterations, 3-5 more CG iterations.

Default rho (``rho=None``). With lambda the only unknown, one Uzawa step is projected gradient
ascent on the dual problem whose Hessian is  k_tau b W^1/2 C W^1/2, C_cd = tau_c . K^-1 tau_d the
tangential compliance of the contact boundary, W = diag(w), b the friction bound. Its largest
eigenvalue mu_tau (a smooth mode, independent of h: W^1/2 C W^1/2 is the discrete
Neumann-to-Dirichlet map, O(1/E)) sets the stability limit rho < 2 / (k_tau b mu_tau). The default
rho = RHO_FACTOR / (k_tau b mu_tau), mu_tau from a few power iterations (one linear solve each);
b = k_tau for the reduced law, the largest current friction bound for m_tau > 0 (recomputed every
iteration). Measured on the paper scene: rho = 0.0081, 0.0076, 0.0074, 0.0073, 0.0073, 0.0073, 0.0073 at
h = 2^-2 ... 2^-8; RHO_FACTOR 0.5 / 1 / 1.5 / 1.9 took 259 / 129 / 86 / 68 iterations at 2^-6 (1.9 leaves no
margin for the power-iteration estimate, which is from below). The smallest eigenvalue is
O(h / E), so the iteration count grows like 1/h (paper scene: 3, 10, 24, 48, 86, 152, 267 at
h = 2^-2 ... 2^-8; where vertices stick, about 3000 at 2^-6).

``tol`` means what it says. The paper's rule stops on |Δλ| = 0 as soon as every vertex slips
(λ = ±1 no longer changes), one lagged normal-compliance step before u settles (residual 4e-6 at
2^-2 down to 2e-9 at 2^-7). So a stop is accepted only when contact_residual is at most
acceptable_residual: RESIDUAL_FACTOR x tol relative to the right-hand side of the linear solves
(themselves solved to tol), or the rounding floor of the residual evaluation. A stop refused is
recorded (history ``stop_refused`` = 1 at that iteration; info ``first_stop_refused``,
``stops_refused``) and the iteration goes on; if it then stagnates, stops moving (Δu = 0) or reaches
max_iterations, a ConvergenceError(reason="inaccurate_stop") suggests stop="both" or ssn. On the
paper scene with the defaults the paper's rule fires at n = 3, 10, 24, 48, 86, 152 (2^-2 ... 2^-7)
and the stop is accepted one or two iterations later; at tol = 1e-12 uzawa and ssn agree to 1e-10
on every mesh family.

The lagged normal compliance is a fixed-point iteration with contraction factor about
max p_nu' mu_nu (mu_nu: the same compliance for the normal direction): it diverges (or cycles)
when k_nu is large against E. That is detected (non-finite values, growing or stagnating
|u^n - u^{n-1}|) and reported as a ConvergenceError naming contact.normal.k; use the ssn solver.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from vemkit.exceptions import ConvergenceError, LinearSolveError, SceneError
from vemkit.solvers.linear import linear_solver
from vemkit.solvers.solution import (
    ContactSolution,
    contact_force_vector,
    contact_residual,
    history_arrays,
    relative_slip,
    residual_scale,
)
from vemkit.solvers.sparse_ops import abs_matvec
from vemkit.solvers.uzawa_failures import boundary_compliance, fail, refuse

RHO_FACTOR = 1.5  # rho = RHO_FACTOR / (k_tau b mu_tau); stable below 2
STAGNATION_WINDOW = 200  # no new smallest |u^n - u^{n-1}| within this many iterations: stop
DIVERGENCE_GROWTH = 1e3  # |u^n - u^{n-1}| this many times its smallest value, and still growing
INNER_FRACTION = 1e-2  # AMG-CG tolerance: this fraction of the last relative change of u (at least inner_floor)
INNER_ROUNDING = 10.0  # inner_floor is at least this many eps (CG's recursive residual still gets there)
RESIDUAL_FACTOR = 10.0  # a stop is accepted at contact_residual <= this x tol (see acceptable_residual)
ROUNDING_FLOOR = 100.0  # ... or at this many eps x the size of the residual's terms


def acceptable_residual(problem, u, forces, tol, K_abs=None) -> float:
    """The largest contact_residual a stopped iterate may have: what ``tol`` asks for.

    RESIDUAL_FACTOR x tol, measured against the right-hand side the linear solves were asked to
    solve to ``tol`` (f - contact forces, relative to the scale of contact_residual), or the rounding
    floor of the residual evaluation (ROUNDING_FLOOR eps || |K||u| + |f| + |forces| ||, as for ssn).
    """
    f = problem.load
    scale = residual_scale(float(np.linalg.norm(f)), float(np.linalg.norm(forces)))
    solve_level = tol * max(float(np.linalg.norm(f - forces)), scale) / scale
    Ku = abs_matvec(problem.stiffness, np.abs(u)) if K_abs is None else K_abs @ np.abs(u)
    size = float(np.linalg.norm(Ku + np.abs(f) + np.abs(forces)))
    return max(RESIDUAL_FACTOR * solve_level, ROUNDING_FLOOR * np.finfo(float).eps * size / scale)


def inner_floor(tol: float, eps_u: float) -> float:
    """The tolerance the AMG-CG solves of u^n tighten to: INNER_FRACTION x the finer of tol (the residual a
    stop must reach) and eps_u (the change the |Δu| test must see), at least INNER_ROUNDING eps. A solve
    to tol alone returns its warm start unchanged once the right-hand side moves by less than tol per
    iteration (module docstring)."""
    return max(INNER_FRACTION * min(tol, eps_u), INNER_ROUNDING * np.finfo(float).eps)


def _extrapolated_start(u, step, rhs_change, previous_rhs_change):
    """CG start u + alpha (u^{n-1} - u^{n-2}), alpha minimizing the energy error along that step.

    K u^j = rhs^j up to the solve tolerance, so K step = rhs^{n-1} - rhs^{n-2} and
    rhs^n - K u^{n-1} = rhs^n - rhs^{n-1}: no matrix product is needed.
    """
    if step is None:
        return u
    curvature = float(step @ previous_rhs_change)
    if not curvature > 0.0:
        return u
    return u + (float(step @ rhs_change) / curvature) * step


def _relative_change(new, old):
    scale = np.linalg.norm(new)
    diff = np.linalg.norm(new - old)
    return diff / scale if scale > 0.0 else (0.0 if diff == 0.0 else float("inf"))


@dataclass
class _Uzawa:
    """One Uzawa solve: the options, the linear solver of K, the iterate and the iteration's records."""

    problem: object
    solver: object  # linear solver of K, built once
    options: dict  # rho (None: the default), eps_u, eps_lambda, stop, max_iterations, tol
    start: float  # time.perf_counter() at the call
    u: np.ndarray  # u^{n-1}
    lam: np.ndarray  # lambda^{n-1}
    info: dict
    linear_total: int = 0
    n: int = 0  # the iteration under way
    mu_tau: float = 0.0
    rho: float = 0.0  # rho of the last iteration
    u_first: np.ndarray | None = None  # u^1, solved by _start
    forces: np.ndarray | None = None  # contact forces of (u^{n-1}, lambda^{n-1})
    du: float = 1.0  # |u^n - u^{n-1}| / |u^n| of the last iteration
    step: np.ndarray | None = None  # u^{n-1} - u^{n-2}
    previous_rhs: np.ndarray | None = None  # rhs^{n-1}
    previous_rhs_change: np.ndarray | None = None  # rhs^{n-1} - rhs^{n-2}
    records: list = field(default_factory=list)
    smallest_du: float = np.inf  # smallest |u^n - u^{n-1}| so far, at iteration smallest_at
    smallest_at: int = 0
    warm: bool = False  # started from ``initial``: a new smallest residual also counts as progress
    smallest_residual: float = np.inf
    growing: int = 0  # iterations in a row with a growing |u^n - u^{n-1}|
    du_abs: float = 0.0  # |u^n - u^{n-1}|
    du_abs_previous: float = np.inf
    refused: tuple | None = None  # (test, contact_residual, accepted level) of the last refused stop
    K_abs: object = None  # |K| for the rounding floor of acceptable_residual

    @property
    def inexact(self) -> bool:
        return self.solver.iterative


def solve_uzawa(
    problem,
    *,
    linear="auto",
    rho=None,
    eps_u=1e-10,
    eps_lambda=1e-10,
    stop="either",
    max_iterations=10000,
    tol=1e-10,
    progress=None,
    initial=None,
    slip_reference=None,
) -> ContactSolution:
    """Steps 1-3 of the paper; see the module docstring. ``tol``: relative tolerance of each linear
    solve and of the residual a stop must reach (acceptable_residual).

    progress(n, record) is called after every iteration with that iteration's history entries:
    du = |u^n - u^{n-1}| / |u^n|, dlambda = max |lambda^n - lambda^{n-1}|, residual = the relative
    equilibrium residual of (u^n, lambda^n) (exact up to the linear-solve tolerance), rho, and
    linear_iterations. ``initial``: None (Step 1) or (u^0 free-dof vector, lambda^0 per contact
    vertex). ``slip_reference``: as vemkit.solvers.ssn.solve_ssn (a load step's incremental law: (5.5)
    with u_tau^n - u_tau^ref). Raises ConvergenceError (never returns NaN).
    """
    if stop not in ("either", "both"):
        raise SceneError(f"solver.stop = {stop!r}: use either or both", key="solver.stop")
    if rho is not None and not rho > 0.0:
        raise SceneError(f"solver.rho = {rho}: must be > 0", key="solver.rho")
    options = dict(rho=rho, eps_u=eps_u, eps_lambda=eps_lambda, stop=stop, max_iterations=max_iterations, tol=tol)
    options["slip_reference"] = slip_reference
    state = None
    try:
        state = _start(problem, linear, options, initial)
        if state.n == 0:  # no contact force: the plain linear solution
            return _finish(state, 0)
        return _iterate(state, progress)
    except LinearSolveError as exc:
        raise ConvergenceError(
            f"uzawa: {exc}",
            solver="uzawa",
            reason="linear_solver_failed",
            iterations=state.n if state is not None else 0,
        ) from exc


def _start(problem, linear, options, initial=None) -> _Uzawa:
    """Step 1 and the first solve of Step 2 (u^1 is the solution if no contact force acts at u^0 or u^1)."""
    start = time.perf_counter()
    cb, law = problem.contact, problem.law
    solver = linear_solver(problem.stiffness, linear, near_nullspace=problem.near_nullspace, tol=options["tol"])
    u0, lam0 = (
        (np.zeros(problem.n_dofs), cb.zero_multiplier())
        if initial is None
        else (np.asarray(initial[0], float), cb.project(initial[1]))
    )
    state = _Uzawa(
        problem,
        solver,
        options,
        start,
        u0,
        lam0,
        {"linear": solver.method, "stop": options["stop"]},
        warm=initial is not None,
    )
    rhs = problem.load - contact_force_vector(problem, state.u, state.lam)
    u_first = solver.solve(rhs, x0=None if initial is None else u0)
    state.linear_total += max(solver.iterations, 1)
    t_first = cb.normal_displacement(u_first) - cb.gap
    if cb.size == 0 or (
        not np.any(law.normal_pressure(t_first))
        and not np.any(law.friction_bound(t_first))
        and not np.any(rhs - problem.load)
    ):
        state.u = u_first
        state.lam = cb.direction(relative_slip(cb, u_first, options["slip_reference"])) if cb.size else state.lam
        state.info["rho"] = float("nan") if options["rho"] is None else float(options["rho"])
        return state
    if options["rho"] is None and not law.frictionless:
        state.mu_tau, solves = boundary_compliance(solver, problem, "tangent")
        state.linear_total += solves
    state.info["mu_tau"] = state.mu_tau
    state.forces = problem.load - rhs  # contact forces of (u^0, lambda^0)
    state.previous_rhs_change = np.zeros_like(problem.load)
    state.previous_rhs = np.zeros_like(problem.load) if initial is None else problem.stiffness @ u0  # K u^0
    state.u_first = u_first
    state.n = 1
    return state


def _finish(state, iterations):
    return ContactSolution(
        state.u,
        state.lam,
        iterations,
        True,
        "uzawa",
        history_arrays(state.records),
        state.linear_total,
        time.perf_counter() - state.start,
        state.info,
    )


def _step_length(state, bound) -> float:
    """rho of this iteration: the given one, or RHO_FACTOR / (k_tau b mu_tau) (module docstring)."""
    law, rho = state.problem.law, state.options["rho"]
    if rho is not None:
        return float(rho)
    k_tau = law.friction_coefficient
    b_scale = float(np.max(bound)) if np.max(bound) > 0.0 else k_tau
    return RHO_FACTOR / (k_tau * b_scale * state.mu_tau) if k_tau * state.mu_tau > 0.0 else 0.0


def _iterate(state, progress):
    """Steps 2-3 until a stopping test passes (n = 1, 2, ...); then the residual check."""
    max_iterations = state.options["max_iterations"]
    for n in range(1, max_iterations + 1):
        state.n = n
        stopped_by = _uzawa_iteration(state)
        check = _stop_check(state, stopped_by) if stopped_by is not None else None
        if progress is not None:
            progress(n, state.records[-1])
        if check is not None:
            return _accept(state, stopped_by, check)
        _watch_progress(state)
    if state.refused is not None:
        refuse(state)
    fail(state, f"max_iterations = {max_iterations} reached at |Δu| = {state.du:.1e}", "max_iterations")


def _uzawa_iteration(state):
    """One pass of Step 2 (u^n, lambda^n) and the Step 3 tests; returns "du"/"dlambda" if one stops it."""
    problem, options = state.problem, state.options
    cb, law, tol = problem.contact, problem.law, options["tol"]
    n, u, lam = state.n, state.u, state.lam
    state.rho = _step_length(state, law.friction_bound(cb.normal_displacement(u) - cb.gap))
    rhs = problem.load - state.forces
    floor = inner_floor(tol, options["eps_u"]) if state.inexact else tol
    lin_tol = max(floor, INNER_FRACTION * state.du) if state.inexact else floor
    if n == 1:
        u_new, lin_its = state.u_first, 1
    else:
        x0 = u
        if state.inexact:
            x0 = _extrapolated_start(u, state.step, rhs - state.previous_rhs, state.previous_rhs_change)
        u_new, lin_its = _solve_step(state, rhs, x0, lin_tol)
    while True:
        lam_new = cb.project(
            lam + state.rho * law.friction_coefficient * relative_slip(cb, u_new, options["slip_reference"])
        )  # (5.5)
        if not (np.all(np.isfinite(u_new)) and np.all(np.isfinite(lam_new))):
            fail(state, "non-finite values", "diverged")
        state.du = _relative_change(u_new, u)
        dlam = float(np.max(cb.magnitude(lam_new - lam))) if cb.size else 0.0
        small_u = state.du < options["eps_u"]
        small_lam = dlam < options["eps_lambda"] and not law.frictionless
        both = small_u and (small_lam or law.frictionless)
        stopping = n >= 2 and (both if options["stop"] == "both" else (small_u or small_lam))
        if not (stopping and lin_tol > floor):
            break
        # the stopping test passed on an inexact solve: finish that solve to the floor and test again
        u_new, extra = _solve_step(state, rhs, u_new, floor)
        lin_its += extra
        lin_tol = floor
    _advance(state, u_new, lam_new, rhs, dlam, lin_its)
    return ("du" if small_u else "dlambda") if stopping else None


def _solve_step(state, rhs, x0, lin_tol):
    """u^n from the lagged right-hand side (CG warm-started from x0)."""
    u_new = state.solver.solve(rhs, x0=x0, tol=lin_tol)
    its = max(state.solver.iterations, 1)
    state.linear_total += its
    return u_new, its


def _advance(state, u_new, lam_new, rhs, dlam, lin_its):
    """Make (u^n, lambda^n) the current iterate and record the iteration."""
    problem = state.problem
    state.du_abs = float(np.linalg.norm(u_new - state.u))
    state.step = u_new - state.u
    state.previous_rhs_change, state.previous_rhs = rhs - state.previous_rhs, rhs
    state.u, state.lam = u_new, lam_new
    # K u^n = f - forces^{n-1}, so K u^n + forces^n - f = forces^n - forces^{n-1}
    new_forces = contact_force_vector(problem, state.u, state.lam)
    scale = residual_scale(float(np.linalg.norm(problem.load)), float(np.linalg.norm(new_forces)))
    residual = float(np.linalg.norm(new_forces - state.forces)) / scale
    state.forces = new_forces
    state.records.append(
        {
            "du": state.du,
            "dlambda": dlam,
            "residual": residual,
            "rho": state.rho,
            "linear_iterations": lin_its,
            "stop_refused": 0.0,
        }
    )


def _watch_progress(state):
    """Raise when |u^n - u^{n-1}| keeps growing (diverged) or makes no new low (stagnated)."""
    du_abs = state.du_abs
    state.growing = state.growing + 1 if du_abs > state.du_abs_previous else 0
    state.du_abs_previous = du_abs
    if du_abs < state.smallest_du:
        state.smallest_du, state.smallest_at = du_abs, state.n
    if state.warm and state.records[-1]["residual"] < state.smallest_residual:
        state.smallest_residual, state.smallest_at = state.records[-1]["residual"], state.n
    if state.growing >= 5 and du_abs > DIVERGENCE_GROWTH * state.smallest_du:
        fail(state, f"|Δu| grew {du_abs / state.smallest_du:.0e}×", "diverged")
    if state.refused is not None and (du_abs == 0.0 or state.n - state.smallest_at >= STAGNATION_WINDOW):
        refuse(state)  # a stop was refused and the iteration cannot lower the residual any more
    if state.n - state.smallest_at >= STAGNATION_WINDOW:
        fail(state, f"|Δu| stagnated at {state.du:.1e}", "stagnated")


def _stop_check(state, stopped_by):
    """contact_residual of the iterate a stopping test has fired on, if it is below acceptable_residual.

    Otherwise None: the iteration goes on, the refusal is recorded (history ``stop_refused`` = 1,
    info ``stops_refused``, ``first_stop_refused``) and remembered for the error if it never gets there.
    """
    problem, n = state.problem, state.n
    lam = state.lam
    if problem.law.frictionless:  # lambda carries no force: the one consistent with the slip
        lam = problem.contact.direction(relative_slip(problem.contact, state.u, state.options["slip_reference"]))
    check = contact_residual(problem, state.u, lam, state.options["slip_reference"])
    level = acceptable_residual(problem, state.u, state.forces, state.options["tol"], state.K_abs)
    if check["worst"] <= level:
        state.lam = lam
        return check
    state.records[-1]["stop_refused"] = 1.0
    state.info["stops_refused"] = state.info.get("stops_refused", 0) + 1
    state.info.setdefault("first_stop_refused", n)
    state.refused = (stopped_by, check, level)
    return None


def _accept(state, stopped_by, check):
    state.info["rho"] = float(state.rho)
    state.info["stopped_by"] = stopped_by
    state.info["residual"] = check
    return _finish(state, state.n)
