"""Semismooth Newton (primal-dual active set) solver for the discrete contact problem.

Unknowns u (free dofs) and the friction multiplier lambda (one per contact vertex c):

    R(u, lambda) = K u + sum_c w_c [p_nu(t_c) nu_c + b_c lambda_c tau_c] - f = 0,  t = u_nu - g, b = p_tau(t)
    C(u, lambda) = lambda - P(lambda + gamma u_tau) = 0,   P: projection onto [-1, 1].

On a 3D body (docs/reference/files.md) lambda and u_tau have two components in the vertex basis (t1, t2), P is the
projection onto the unit disk; the Newton step (both dimensions) is vemkit.solvers.ssn_friction.

C = 0 is |lambda| <= 1, lambda u_tau = |u_tau| for any gamma > 0. The choice only steers the active
sets: gamma_c = GAMMA_FACTOR[d] kd_c / (L_C h^(d-2) b_ref), kd_c the stiffness diagonal in the tangential
direction, L_C = |Gamma_C|^(1/(d-1)) the size of Gamma_C (|Gamma_C| = sum_c w_c), h = (|Gamma_C| /
n_c)^(1/(d-1)) the mean vertex spacing on it, b_ref = k_tau for the reduced law (the largest friction
bound of the starting point for m_tau > 0). Since kd ~ E h^(d-2), gamma neither grows nor shrinks
under refinement: in 2D it is GAMMA_FACTOR kd / (|Gamma_C| b_ref) (the local choice kd / (w b) ~ 1/h
made the sets of mixed stick/slip cases flip-flop: 8 -> 19 iterations from 2^-4 to 2^-8, against
5-7 -> 7-9 with this one); in 3D the same formula without h (kd / (|Gamma_C| b_ref) ~ h) let q follow
the old lambda ever more closely: 7, 8, 9, 11, 13-17, 14, 29 Newton iterations at n = 8 ... 86 on
the sheared box (config/scenes/3d/sheared_box.yaml), against 7 at n = 16, 8 at 32, 9 at 48 and 64
with h. 3D with m_tau > 0 (Coulomb's coupled law): the local gamma_c = kd_c / (w_c b_c), b_c the
vertex's own bound at the start (vemkit.solvers.ssn_point.coupled_gamma; the global one left
gamma |u_tau| ~ 1e-6 at the sliding vertices of the Mindlin sphere, so q did not see the slip
direction). Start: u = the plain linear solution,
lambda = P(kd u_tau / (w b_ref)) (the local trial multiplier, which finds the slip zone at once);
or, given ``initial = (u0, lambda0)`` (a warm start, e.g. the previous adaptive step's solution
prolongated to the refined mesh), (u0, P(lambda0)) when its residual merit theta is below that of
the cold start (the plain solution is computed either way: it decides the cheap path below and the
scalings gamma, b_ref).

Newton step at (u, lambda), q = lambda + gamma u_tau: slip S = {|q| > 1}: lambda_new = sign(q);
stick A = {|q| <= 1}: u_tau,new = 0; normal compliance linearized, J = sum_c w_c p_nu' nu_c nu_c^T
(PSD, rank one per vertex; for m_nu < 1, p_nu' is capped at NORMAL_STIFFNESS_CAP x the local
stiffness, a modified Newton step). With ``contact_quadrature: gauss`` the normal-compliance force,
its energy and J = sum_e sum_q |e| w_q p_nu'(t_eq) phi_a phi_b nu_e nu_e^T (coupling the two ends of
each Gamma_C edge, still PSD) come from vemkit.contact.boundary; the friction term stays nodal.
Stick constraints are eliminated: u_new = u' + Z y, u' = u with u_tau zeroed on A, Z the
orthonormal basis of {v : tau_c . v_c = 0 on A} (identity columns, one nu_c column per stick
vertex), so Z^T (K + J) Z y = Z^T r stays SPD; the stick multipliers follow from the tangential
equilibrium, lambda_c = tau_c . (r - (K + J) Z y)_c / (w_c b_c).
  direct: Z^T (K + J) Z is factorized at every step.
  AMG: CG on Z^T (K + J) Z preconditioned by Z^T M Z, M the V-cycle of the hierarchy built ONCE for
  K; rebuilt for K + J (+ a penalty on stick tangents) only when CG needs REBUILD_FACTOR times the
  iterations per decade of the first solve (3D: every level follows K + J + penalty at every step,
  vemkit.solvers.amg_update, the finest smoothed by vertices and the cycle in single precision,
  vemkit.solvers.nodal_smoother, linear.CYCLE_PRECISION). Inexact Newton: CG tolerance eta = min(ETA_MAX,
  0.9 (theta_k / theta_{k-1})) (Eisenstat-Walker), never tighter than needed for tol. If the
  contact is far stiffer than the body (w p_nu' / kd > AMG_CONTRAST_LIMIT at the start) or the
  inexact steps stall the line search, the Newton solves switch to direct (info["fallback"]).

m_tau > 0 (the friction bound depends on u): joint Newton; the Jacobian also holds
d/du [w b(t) lambda tau] = w p_tau'(t) lambda tau nu^T, which is unsymmetric, so the steps are
solved by sparse LU (direct) or GMRES with the same preconditioner (AMG). Vertices with b = 0
carry no friction force: lambda_c = sign(u_tau,c) there.

Globalisation. For the reduced law (m_tau = 0 or k_tau = 0) the solution minimizes the convex
energy 1/2 u.Ku - f.u + sum_c w_c [P_nu(t_c) + k_tau |u_tau,c|]: the full step is taken when it
reduces the residual merit theta = ||R||^2 + ||w b_ref C||^2, otherwise Armijo backtracking on
the energy, with step doubling plus a secant step while the energy still falls steeply (a power
law m_nu > 1 approached from deep penetration needs steps of about m_nu). For m_tau > 0,
backtracking on theta. Convergence: theta^1/2 <= tol * ||f||, or at the rounding floor of the
residual evaluation (ROUNDING_FLOOR eps || |K||u| + |f| + |J||u| ||, reached only when the contact is
~1e9 times stiffer than the body); otherwise a one-line ConvergenceError naming the likely culprit.

The linear algebra of the steps and the line search are in vemkit.solvers.ssn_steps, an iterate and its
merit in vemkit.solvers.ssn_point, the failure messages in vemkit.solvers.ssn_failures.

Cheap path: if the contact forces vanish at the plain linear solution (no vertex penetrates and the
friction bound is zero there: frictionless, or m_tau > 0, with a never-closing gap) that solution
is returned with iterations = 0.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from vemkit.exceptions import ConvergenceError, LinearSolveError
from vemkit.solvers.linear import ReducedSolver, linear_solver
from vemkit.solvers.solution import ContactSolution, contact_residual, history_arrays, relative_slip
from vemkit.solvers.ssn_failures import CONTRAST_WARNING, fail
from vemkit.solvers.ssn_friction import friction_direction
from vemkit.solvers.ssn_point import (
    Point,
    aligned_multiplier,
    converged,
    coupled_gamma,
    energy_slope,
    evaluate,
    final_multiplier,
)
from vemkit.solvers.ssn_steps import direction_diagonal, line_search, tangential_diagonal

NORMAL_STIFFNESS_CAP = 1e8  # for m_nu < 1: w p_nu' <= this times the stiffness diagonal
# gamma = GAMMA_FACTOR[d] kd / (L_C h^(d-2) b_ref), see the module docstring; in 3D 0.1 keeps the
# coarse meshes' gamma where 0.5 without h had it (4x less at n_c = 16) -- 0.2 lost 1e-10 agreement of
# uzawa and ssn on a 3 x 3 x 3 Voronoi box with m_tau = 1, 0.5 stalled a load step at 9e-12 > 1e-12
GAMMA_FACTOR = {2: 0.5, 3: 0.1}
ETA_MAX = 1e-3  # loosest relative CG tolerance of an inexact Newton step
INITIAL_TOL = 1e-2  # relative CG tolerance of the plain linear solve that starts the iteration
STALL_STEPS = 3  # damped steps in a row on settled active sets: the coupled law's gamma rescaled ...
GAMMA_RESCALE = 10.0  # ... if it grows by this factor at a vertex at least
RESCALED_FLOOR = 1e-6  # ... its bounds counted as at least this times b_ref (1e-3 at the start)
SHORT_STEP = 1e-2  # two accepted steps shorter than this with AMG: switch the Newton solves to direct
# ... if there are at most this many dofs, by dimension: a sparse LU of 3D elasticity fills in far more
# (measured: 122 244 DOFs of a refined 3D contact mesh took 560 s direct, the cold AMG solve 8 s)
DIRECT_FALLBACK_LIMIT = {2: 500_000, 3: 60_000}
AMG_CONTRAST_LIMIT = 1e6  # w p_nu' / (stiffness diagonal) above which the Newton solves are direct


@dataclass
class _Newton:
    """One semismooth Newton solve: the problem, the scalings fixed at the start, the running counters."""

    problem: object
    tol: float
    base: object  # the linear solver of K (the plain solution; direct factors or the AMG hierarchy)
    baseline: float  # CG iterations per decade of the plain solve
    start: float  # time.perf_counter() at the call
    linear_total: int
    info: dict
    f_norm: float
    reduced: ReducedSolver | None = None
    kd_tau: np.ndarray | None = None  # stiffness diagonal in the tangential direction per contact vertex
    stiffness_cap: object = np.inf  # cap of p_nu' per contact vertex (m_nu < 1)
    contrast: float = 0.0  # max w p_nu' / kd_nu at the start
    b_ref: float = 1.0  # reference friction bound
    gamma: np.ndarray | None = None  # the complementarity parameter per contact vertex
    energy_merit: bool = False  # the reduced law: line search on the convex energy
    records: list = field(default_factory=list)  # history, one dict per iteration
    previous_state: np.ndarray | None = None  # contact/stick/slip codes of the last step
    short_steps: int = 0
    settled_damped: int = 0  # damped steps in a row that left the active sets as they were
    eta: float = ETA_MAX  # relative tolerance of the last inexact step
    theta_previous: float = 0.0
    slip_reference: np.ndarray | None = None  # u_tau^ref: the slip is u_tau - u_tau^ref (a load step)

    @property
    def zero(self):
        return np.zeros(self.problem.contact.size)

    @property
    def zero_tangential(self):
        return self.problem.contact.zero_multiplier()


def solve_ssn(
    problem, *, linear="auto", tol=1e-10, max_iterations=50, progress=None, initial=None, slip_reference=None
) -> ContactSolution:
    """Semismooth Newton for (5.2)-(5.3); see the module docstring. ``tol``: relative residual.

    ``slip_reference``: None, or u_tau^ref per contact vertex (``cb.tangential_displacement`` of the
    previous load step's u): the incremental (backward-Euler) friction law of a loading in steps,
    lambda . (u_tau - u_tau^ref) = |u_tau - u_tau^ref|, stick where u_tau = u_tau^ref.

    progress(k, record) is called after every Newton iteration with that iteration's history entries.
    ``initial``: None, or (u0 free-dof vector, lambda0 per contact vertex), a warm start (module docstring).
    Raises ConvergenceError (never returns NaN).
    """
    newton, u = _plain_start(problem, linear, tol, None if initial is None else initial[0])
    newton.slip_reference = None if slip_reference is None else np.asarray(slip_reference, dtype=float)
    cb, law = problem.contact, problem.law
    t = cb.normal_displacement(u) - cb.gap
    if cb.size == 0 or (not np.any(law.normal_pressure(t)) and not np.any(law.friction_bound(t))):
        return _plain_solution(newton, u)
    _prepare(newton, t)
    # start: the plain linear solution and the multiplier its slip would need at the local stiffness
    slip = cb.tangential(relative_slip(cb, u, slip_reference))
    trial = cb.ball.trial_multiplier(newton.kd_tau, slip, cb.weight * newton.b_ref)
    point = evaluate(newton, u, cb.project(trial))
    if initial is not None:
        warm = evaluate(newton, np.asarray(initial[0], float), cb.project(initial[1]))
        newton.info["warm_start"] = bool(warm.theta < point.theta)
        point = warm if warm.theta < point.theta else point
    newton.theta_previous = point.theta
    for k in range(1, max_iterations + 1):
        if converged(newton, point):
            lam, move = _returned_multiplier(newton, point)
            if move <= newton.tol:
                return _finish(newton, point.u, lam, k - 1)
            point = evaluate(newton, point.u, lam)  # 3D: go on from the multiplier of the law
        point = _newton_iteration(newton, point, k)
        if not converged(newton, point):  # 2D: never both (converged is the merit test there)
            lam = aligned_multiplier(newton, point)  # 3D: the slip direction, when only it is left
            point = point if lam is None else evaluate(newton, point.u, lam)
        if progress is not None:
            progress(k, newton.records[-1])
    lam, move = _returned_multiplier(newton, point)
    if converged(newton, point) and move <= newton.tol:
        return _finish(newton, point.u, lam, max_iterations)
    fail(
        problem,
        max_iterations,
        f"residual {np.sqrt(point.theta) / point.scale:.1e} > tol {tol:.0e}",
        newton.records,
        newton.contrast,
        reason="max_iterations",
    )


def _plain_start(problem, linear, tol, x0=None):
    """The linear solver of K and the plain linear solution (a starting guess: AMG to INITIAL_TOL,
    CG from ``x0`` when given)."""
    start = time.perf_counter()
    try:
        base = linear_solver(problem.stiffness, linear, near_nullspace=problem.near_nullspace, tol=tol)
        u = base.solve(problem.load, x0=None if x0 is None else np.asarray(x0, float), tol=max(INITIAL_TOL, tol))
    except LinearSolveError as exc:
        raise ConvergenceError(f"ssn: {exc}", solver="ssn", reason="linear_solver_failed", iterations=0) from exc
    baseline = max(base.iterations, 1) / max(np.log10(1.0 / max(INITIAL_TOL, tol)), 1.0)
    newton = _Newton(
        problem,
        tol,
        base,
        baseline,
        start,
        max(base.iterations, 1),
        {"linear": base.method},
        float(np.linalg.norm(problem.load)),
    )
    return newton, u


def _plain_solution(newton, u):
    """No contact force at the plain linear solution: it is the solution (finished to tol with AMG)."""
    base, tol = newton.base, newton.tol
    if base.iterative and INITIAL_TOL > tol:
        u = base.solve(newton.problem.load, x0=u, tol=tol)
        newton.linear_total += base.iterations
    cb = newton.problem.contact
    return _finish(newton, u, cb.direction(relative_slip(cb, u, newton.slip_reference)), 0)


def _returned_multiplier(newton, point):
    """(lambda, its move) of a converged point: P(q) where the projection gives the slip's direction
    (the interval, vemkit.contact.ball), else in the disk and along the slip (ssn_point.final_multiplier)."""
    if newton.problem.contact.ball.direction_from_projection:
        return point.lam, 0.0
    return final_multiplier(newton, point)


def _finish(newton, u, lam, iterations):
    info = newton.info
    info["residual"] = contact_residual(newton.problem, u, lam, newton.slip_reference)
    info["amg_rebuilds"] = newton.reduced.rebuilds if newton.reduced is not None else 0
    return ContactSolution(
        u,
        lam,
        iterations,
        True,
        "ssn",
        history_arrays(newton.records),
        newton.linear_total,
        time.perf_counter() - newton.start,
        info,
    )


def _prepare(newton, t):
    """The scalings of the module docstring at the plain solution (penetration t): gamma, b_ref, caps."""
    problem = newton.problem
    K, cb, law, n = problem.stiffness, problem.contact, problem.law, problem.n_dofs
    newton.kd_tau = tangential_diagonal(K, cb)
    kd_nu = direction_diagonal(K, cb, cb.normal)
    newton.reduced = ReducedSolver(problem, newton.base, newton.baseline)
    # p_nu' is unbounded at 0 only for m_nu < 1: cap it there (a modified Newton step)
    cap = NORMAL_STIFFNESS_CAP * kd_nu / cb.weight if law.normal_stiffness_unbounded else np.inf
    newton.stiffness_cap = cap
    newton.contrast = float(np.max(cb.weight * np.minimum(law.normal_stiffness(np.abs(t)), cap) / kd_nu))
    newton.info["contact_stiffness_contrast"] = newton.contrast
    if newton.contrast > AMG_CONTRAST_LIMIT and n <= DIRECT_FALLBACK_LIMIT[cb.dimension]:
        _fall_back(newton)
    b_lin = law.friction_bound(t)
    k_tau = law.friction_coefficient
    b_ref = k_tau if law.reduced else (float(np.max(b_lin)) if np.max(b_lin) > 0 else k_tau)
    newton.b_ref = b_ref if b_ref > 0.0 else 1.0
    if not (
        law.reduced or cb.ball.direction_from_projection
    ):  # Coulomb's coupled law in the disk: ssn_point.coupled_gamma
        newton.gamma = coupled_gamma(newton.kd_tau, cb.weight, b_lin, newton.b_ref)
    else:
        newton.gamma = GAMMA_FACTOR[cb.dimension] * newton.kd_tau / (_gamma_length(cb) * newton.b_ref)
    newton.energy_merit = law.reduced  # m_tau = 0 or k_tau = 0: the problem minimizes a convex energy


def _fall_back(newton):
    """Newton solves on the backend's fallback (AMG: direct), recorded in info["fallback"]; nothing
    when the backend has none."""
    fallback = newton.reduced.fall_back()
    if fallback is not None:
        newton.info["fallback"] = fallback


def _gamma_length(cb) -> float:
    """L_C h^(d-2) of the module docstring, sqrt(|Gamma_C|^2 / n_c^(d-2)) with h ~ (|Gamma_C| / n_c)^(1/(d-1)):
    |Gamma_C| in 2D (exactly: sqrt(a * a) = a in binary floating point), |Gamma_C| / sqrt(n_c) in 3D."""
    area = float(np.sum(cb.weight))
    return float(np.sqrt(area * area / cb.size ** (cb.dimension - 2)))


def _newton_iteration(newton, point, k) -> Point:
    """One Newton step from ``point`` with its line search; appends the history record."""
    problem = newton.problem
    cb, n = problem.contact, problem.n_dofs
    du, lam_new, its, changes = _newton_direction(newton, point, k)
    if not (np.all(np.isfinite(du)) and np.all(np.isfinite(lam_new))):
        fail(
            problem,
            k,
            "non-finite Newton step",
            newton.records,
            max(newton.contrast, 2 * CONTRAST_WARNING),
            reason="diverged",
        )
    u, lam = point.u, point.lam
    dlam = lam_new - lam
    full = evaluate(newton, u + du, lam_new)
    du_tau = cb.tangential_displacement(du)

    def trial(alpha):
        return full if alpha == 1.0 else evaluate(newton, u + alpha * du, lam + alpha * dlam)

    d0 = energy_slope(newton, point, du_tau, du) if newton.energy_merit else 0.0
    alpha, new = line_search(point, trial, lambda p: energy_slope(newton, p, du_tau, du), d0, newton.energy_merit)
    newton.theta_previous = point.theta
    newton.short_steps = newton.short_steps + 1 if alpha < SHORT_STEP else 0
    if newton.short_steps >= 2 and n <= DIRECT_FALLBACK_LIMIT[cb.dimension]:
        # inexact CG steps of a badly conditioned K + J (k_nu w >> K) stall the line search
        _fall_back(newton)
    new = _rescaled_at_a_stall(newton, new, alpha, changes)
    record = {
        "residual": np.sqrt(new.theta) / new.scale,
        "du": float(alpha * np.linalg.norm(du) / max(np.linalg.norm(new.u), np.finfo(float).tiny)),
        "dlambda": float(np.max(cb.magnitude(new.lam - lam))),
        "step": alpha,
        "active_changes": changes,
        "linear_iterations": its,
    }
    if newton.base.iterative:
        record["eta"] = newton.eta
    newton.records.append(record)
    return new


def _rescaled_at_a_stall(newton, point, alpha, changes) -> Point:
    """``point`` as it is, or re-evaluated with the coupled law's gamma_c taken at its friction bounds
    when STALL_STEPS damped steps in a row left the active sets as they were.

    gamma_c = kd / (w b_c) is set once from the bounds at the start (ssn_point.coupled_gamma); at a
    vertex that ends barely in contact its bound falls by orders (measured on the GetFEM box at
    k_nu = 1e5 E, n = 20: b_c from 1e5 to 2, t ~ 1e-8), so gamma_c |u_tau| ~ 1e-6, q = lambda + gamma_c
    u_tau hardly sees the slip direction, and Newton's step, exact or not, was cut to 1/16 ... 1/64
    for 40 iterations at a merit of 2e-9. The new gamma_c keeps the solution (C = 0 for any gamma > 0)
    and restores the scale of q. Its bounds are floored at RESCALED_FLOOR b_ref, not at the start's
    1e-3 b_ref: at k_nu = 1e7 E (n = 12) the stalled vertices had t ~ 1e-10, bounds 1e-7 b_ref, and
    the start's floor left gamma_c as it was (stalled at 3e-9). Measured floors 1e-3 / 1e-6 / 1e-7 /
    1e-9: that box 50+ (failed) / 22 / 21 / 21 iterations, the box at 1e12 E (n = 8) 29 / 27 / 26 / -,
    the stability study's 3D hexahedra at k_nu = 1e5 E, mu = 0.3: 53 / 43 / 45 / 100+ (failed: a
    gamma_c too large at vertices with no bound left makes q follow the slip's noise). Counted in
    info["gamma_rescaled"] (the solution file's ``solver_globalization``)."""
    newton.settled_damped = newton.settled_damped + 1 if alpha < 1.0 and changes == 0 else 0
    cb, law = newton.problem.contact, newton.problem.law
    if newton.settled_damped < STALL_STEPS or law.reduced or cb.ball.direction_from_projection:
        return point
    newton.settled_damped = 0
    gamma = coupled_gamma(newton.kd_tau, cb.weight, law.friction_bound(point.t), newton.b_ref, RESCALED_FLOOR)
    if not np.max(gamma / newton.gamma) >= GAMMA_RESCALE:  # the bounds have not fallen: nothing to restore
        return point
    newton.gamma = gamma
    newton.info["gamma_rescaled"] = newton.info.get("gamma_rescaled", 0) + 1
    return evaluate(newton, point.u, point.lam)


def _active_sets(newton, point):
    """Frictional, slip S = {|q| > 1} and stick A = {|q| <= 1} vertices; counts the changes of state."""
    cb, law = newton.problem.contact, newton.problem.law
    bound = law.friction_bound(point.t)
    frictional = bound > 0.0
    slip = frictional & (cb.magnitude(point.q) > 1.0)
    stick = frictional & ~slip
    state = np.where(point.t > 0.0, 3, 0) + np.where(slip, 1, np.where(stick, 2, 0))
    changes = cb.size if newton.previous_state is None else int(np.sum(state != newton.previous_state))
    newton.previous_state = state
    return bound, frictional, slip, stick, changes


def _newton_direction(newton, point, k):
    """(du, lambda_new, linear iterations, active-set changes) of the Newton step at ``point``: the
    friction part on the unit ball of R^(d-1) (vemkit.solvers.ssn_friction)."""
    return friction_direction(newton, point, k, _active_sets(newton, point), _solve_newton_system)


def _solve_newton_system(newton, point, k, A, Z, rhs, penalty):
    """Z y with Z^T A Z y = Z^T rhs; inexact (Eisenstat-Walker) with AMG, never looser than tol needs."""
    tol = newton.tol
    if newton.base.iterative and k > 1:
        newton.eta = min(ETA_MAX, 0.9 * point.theta / newton.theta_previous)  # Eisenstat-Walker, choice 2
    floor = 0.1 * tol * point.scale / max(np.linalg.norm(rhs), np.finfo(float).tiny)
    newton.eta = min(max(newton.eta, floor, 1e-14), ETA_MAX)
    try:
        # and never beyond an absolute linear residual of 0.1 tol: the rhs holds the slip vertices' whole
        # friction force, so eta alone asked 1e-3 of it at the last steps (the 3D box at 1e6 DOFs: 35
        # and 57 CG iterations for a merit of 2e-9 and 1.5e-10)
        correction, its = newton.reduced.solve(
            A, Z, rhs, newton.eta, penalty, symmetric=newton.problem.law.reduced, atol=0.1 * tol * point.scale
        )
    except LinearSolveError as exc:
        raise ConvergenceError(f"ssn: {exc}", solver="ssn", reason="linear_solver_failed", iterations=k) from exc
    newton.linear_total += its
    return correction, its
