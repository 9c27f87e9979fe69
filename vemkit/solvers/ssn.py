"""Semismooth Newton (primal-dual active set) solver for the discrete contact problem.

Unknowns u (free dofs) and the friction multiplier lambda (one per contact vertex c):

    R(u, lambda) = K u + sum_c w_c [p_nu(t_c) nu_c + b_c lambda_c tau_c] - f = 0,  t = u_nu - g, b = p_tau(t)
    C(u, lambda) = lambda - P(lambda + gamma u_tau) = 0,   P: projection onto [-1, 1].

C = 0 is |lambda| <= 1, lambda u_tau = |u_tau| for any gamma > 0. The choice only steers the active
sets: gamma_c = GAMMA_FACTOR kd_c / (|Gamma_C| b_ref), kd_c the stiffness diagonal in the tangential
direction, |Gamma_C| = sum_c w_c, b_ref = k_tau for the reduced law (the largest friction bound of
the starting point for m_tau > 0). It does not grow under refinement (the local choice
kd / (w b) ~ 1/h made the sets of mixed stick/slip cases flip-flop: 8 -> 19 iterations from 2^-4
to 2^-8, against 5-7 -> 7-9 with this one). Start: u = the plain linear solution,
lambda = P(kd u_tau / (w b_ref)) (the local trial multiplier, which finds the slip zone at once).

Newton step at (u, lambda), q = lambda + gamma u_tau: slip S = {|q| > 1}: lambda_new = sign(q);
stick A = {|q| <= 1}: u_tau,new = 0; normal compliance linearized, J = sum_c w_c p_nu' nu_c nu_c^T
(PSD, rank one per vertex; for m_nu < 1, p_nu' is capped at NORMAL_STIFFNESS_CAP x the local
stiffness, a modified Newton step). Stick constraints are eliminated: u_new = u' + Z y, u' = u with
u_tau zeroed on A, Z the orthonormal basis of {v : tau_c . v_c = 0 on A} (identity columns, one nu_c
column per stick vertex), so Z^T (K + J) Z y = Z^T r stays SPD; the stick multipliers follow from
the tangential equilibrium, lambda_c = tau_c . (r - (K + J) Z y)_c / (w_c b_c).
  direct: Z^T (K + J) Z is factorized at every step.
  AMG: CG on Z^T (K + J) Z preconditioned by Z^T M Z, M the V-cycle of the hierarchy built ONCE for
  K; rebuilt for K + J (+ a penalty on stick tangents) only when CG needs REBUILD_FACTOR times the
  iterations per decade of the first solve. Inexact Newton: CG tolerance eta = min(ETA_MAX,
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

Cheap path: if the contact forces vanish at the plain linear solution (no vertex penetrates and the
friction bound is zero there: frictionless, or m_tau > 0, with a never-closing gap) that solution
is returned with iterations = 0.
"""

from __future__ import annotations

import time
from types import SimpleNamespace

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from vemkit.solvers.solution import (
    ContactSolution,
    contact_residual,
    history_arrays,
    residual_scale,
    young_modulus,
)
from vemkit.solvers.linear import linear_solver
from vemkit.exceptions import ConvergenceError, LinearSolveError

NORMAL_STIFFNESS_CAP = 1e8  # for m_nu < 1: w p_nu' <= this times the stiffness diagonal
GAMMA_FACTOR = 0.5  # gamma = GAMMA_FACTOR kd / (|Gamma_C| b_ref), see the module docstring
ARMIJO = 1e-4
ROUNDING_FLOOR = 100.0  # accept a residual this many times eps * || |K| |u| + |f| + |J| |u| || (see converged)
MIN_STEP = 2.0**-30
MAX_EXPANSION = 64.0  # largest step length tried when the energy still falls steeply after a full step
EXPAND_SLOPE = 0.1  # ... "steeply": the slope at the full step is still this fraction of the initial one
ETA_MAX = 1e-3  # loosest relative CG tolerance of an inexact Newton step
INITIAL_TOL = 1e-2  # relative CG tolerance of the plain linear solve that starts the iteration
REBUILD_FACTOR = 3.0  # rebuild the AMG hierarchy when CG needs this many times the baseline iterations/decade
SHORT_STEP = 1e-2  # two accepted steps shorter than this with AMG: switch the Newton solves to direct
DIRECT_FALLBACK_LIMIT = 500_000  # ... if there are at most this many dofs
AMG_CONTRAST_LIMIT = 1e6  # w p_nu' / (stiffness diagonal) above which the Newton solves are direct
MIN_REBUILD_ITERATIONS = 20
MAX_REBUILDS = 10
CONTRAST_WARNING = 1e8  # failures with w p_nu' / kd above this are blamed on the conditioning
STICK_PENALTY = 1e3  # penalty (times the stiffness diagonal) on stick tangents in a rebuilt hierarchy


def _direction_diagonal(K, cb, direction):
    """d_c^T K_cc d_c at each contact vertex (the stiffness diagonal in direction d)."""
    i, j = cb.dofs[:, 0], cb.dofs[:, 1]
    Kii = np.asarray(K[i, i]).ravel()
    Kjj = np.asarray(K[j, j]).ravel()
    Kij = np.asarray(K[i, j]).ravel()
    return direction[:, 0] ** 2 * Kii + 2 * direction[:, 0] * direction[:, 1] * Kij + direction[:, 1] ** 2 * Kjj


def _rank_one_blocks(cb, values, left, n, right=None):
    """Sparse sum_c values_c left_c right_c^T on the contact dofs (right = left if not given)."""
    right = left if right is None else right
    rows = np.stack([cb.dofs[:, 0], cb.dofs[:, 0], cb.dofs[:, 1], cb.dofs[:, 1]], axis=1).ravel()
    cols = np.stack([cb.dofs[:, 0], cb.dofs[:, 1], cb.dofs[:, 0], cb.dofs[:, 1]], axis=1).ravel()
    a0, a1, b0, b1 = left[:, 0], left[:, 1], right[:, 0], right[:, 1]
    vals = (values[:, None] * np.stack([a0 * b0, a0 * b1, a1 * b0, a1 * b1], axis=1)).ravel()
    return sp.csr_matrix((vals, (rows, cols)), shape=(n, n))


def _stick_basis(cb, stick, n):
    """Orthonormal Z (n x (n - |stick|)) spanning {v : tau_c . v_c = 0 for stick c}: v_c = a nu_c there."""
    first, second = cb.dofs[stick, 0], cb.dofs[stick, 1]
    keep = np.ones(n, dtype=bool)
    keep[second] = False
    column = np.cumsum(keep) - 1
    rows = np.flatnonzero(keep)
    vals = np.ones(rows.size)
    vals[column[first]] = cb.normal[stick, 0]
    rows = np.concatenate([rows, second])
    cols = np.concatenate([np.arange(vals.size), column[first]])
    vals = np.concatenate([vals, cb.normal[stick, 1]])
    return sp.csr_matrix((vals, (rows, cols)), shape=(n, int(keep.sum())))


class _ReducedSolver:
    """Solves Z^T A Z y = Z^T r for the Newton steps (direct, or CG with the projected AMG V-cycle)."""

    def __init__(self, problem, base, baseline):
        self.problem = problem
        self.method = base.method
        self.preconditioner = getattr(base, "preconditioner", None)
        self.rebuilds = 0
        self.baseline = baseline  # CG iterations per decade of residual reduction with K

    def solve(self, A, Z, rhs, eta, penalty, symmetric=True):
        """Z y with Z^T A Z y = Z^T rhs (Z None: no stick constraint, y solves A y = rhs)."""
        b = rhs if Z is None else Z.T @ rhs
        A_red = A if Z is None else (Z.T @ A @ Z).tocsr()
        lift = (lambda y: y) if Z is None else (lambda y: Z @ y)
        if self.method == "direct":
            if symmetric:
                return lift(linear_solver(A_red, "direct").solve(b)), 1
            y = spla.splu(A_red.tocsc()).solve(b)
            if not np.all(np.isfinite(y)):
                raise LinearSolveError("the direct solve of the Newton step produced non-finite values")
            return lift(y), 1
        if np.linalg.norm(b) == 0.0:
            return np.zeros(A.shape[0]), 0
        krylov = spla.cg if symmetric else _gmres
        y, its = self._krylov(krylov, A_red, Z, b, eta)
        decades = max(np.log10(1.0 / eta), 1.0)
        if its > max(REBUILD_FACTOR * self.baseline * decades, MIN_REBUILD_ITERATIONS) and self.rebuilds < MAX_REBUILDS:
            hierarchy = linear_solver(A + penalty(), "amg", near_nullspace=self.problem.near_nullspace)
            self.preconditioner = hierarchy.preconditioner
            self.rebuilds += 1
            y, more = self._krylov(krylov, A_red, Z, b, eta, x0=y)
            its += more
        return lift(y), its

    def _krylov(self, krylov, A_red, Z, b, eta, x0=None):
        full, M = self.preconditioner, self.preconditioner
        if Z is not None:
            M = spla.LinearOperator(A_red.shape, matvec=lambda v: Z.T @ (full @ (Z @ v)), dtype=float)
        count = [0]

        def callback(_):
            count[0] += 1

        y, info = krylov(A_red, b, x0=x0, rtol=eta, atol=0.0, maxiter=5000, M=M, callback=callback)
        if info != 0 or not np.all(np.isfinite(y)):
            raise LinearSolveError(
                f"AMG-preconditioned Krylov solve of the Newton step stopped after {count[0]} iterations; "
                f"try solver.linear=direct"
            )
        return y, count[0]


def _gmres(A, b, x0, rtol, atol, maxiter, M, callback):
    """GMRES (restart 50) with the cg call signature; callback once per inner iteration."""
    return spla.gmres(
        A, b, x0=x0, rtol=rtol, atol=atol, restart=50, maxiter=maxiter, M=M, callback=callback, callback_type="pr_norm"
    )


def solve_ssn(problem, *, linear="auto", tol=1e-10, max_iterations=50, progress=None) -> ContactSolution:
    """Semismooth Newton for (5.2)-(5.3); see the module docstring. ``tol``: relative residual.

    progress(k, record) is called after every Newton iteration with that iteration's history entries.
    Raises ConvergenceError (never returns NaN).
    """
    start = time.perf_counter()
    K, f, cb, law = problem.stiffness, problem.load, problem.contact, problem.law
    n, n_c = problem.n_dofs, cb.size
    try:
        base = linear_solver(K, linear, near_nullspace=problem.near_nullspace, tol=tol)
        # the plain linear solution (only a starting guess: an AMG solve to INITIAL_TOL is enough)
        u = base.solve(f, tol=max(INITIAL_TOL, tol))
    except LinearSolveError as exc:
        raise ConvergenceError(f"ssn: {exc}") from None
    linear_total = max(base.iterations, 1)
    baseline = max(base.iterations, 1) / max(np.log10(1.0 / max(INITIAL_TOL, tol)), 1.0)
    info = {"linear": base.method}
    f_norm = float(np.linalg.norm(f))

    def finish(u, lam, iterations, records, converged=True):
        info["residual"] = contact_residual(problem, u, lam)
        info["amg_rebuilds"] = reduced.rebuilds if reduced is not None else 0
        return ContactSolution(
            u, lam, iterations, converged, "ssn", history_arrays(records), linear_total, time.perf_counter() - start, info
        )

    reduced = None
    t = cb.normal_displacement(u) - cb.gap
    if n_c == 0 or (not np.any(law.normal_pressure(t)) and not np.any(law.friction_bound(t))):
        if base.method == "amg" and INITIAL_TOL > tol:
            u = base.solve(f, x0=u, tol=tol)
            linear_total += base.iterations
        return finish(u, np.sign(cb.tangential_displacement(u)), 0, [])

    kd_tau = _direction_diagonal(K, cb, cb.tangent)
    kd_nu = _direction_diagonal(K, cb, cb.normal)
    reduced = _ReducedSolver(problem, base, baseline)
    short_steps = 0
    # p_nu' is unbounded at 0 only for m_nu < 1: cap it there (a modified Newton step)
    stiffness_cap = NORMAL_STIFFNESS_CAP * kd_nu / cb.weight if 0.0 < law.m_normal < 1.0 else np.inf
    contrast = float(np.max(cb.weight * np.minimum(law.normal_stiffness(np.abs(t)), stiffness_cap) / kd_nu))
    info["contact_stiffness_contrast"] = contrast
    if reduced.method == "amg" and contrast > AMG_CONTRAST_LIMIT and n <= DIRECT_FALLBACK_LIMIT:
        reduced.method = info["fallback"] = "direct"
    b_lin = law.friction_bound(t)
    b_ref = law.k_friction if law.reduced else (float(np.max(b_lin)) if np.max(b_lin) > 0 else law.k_friction)
    b_ref = b_ref if b_ref > 0.0 else 1.0
    gamma = GAMMA_FACTOR * kd_tau / (np.sum(cb.weight) * b_ref)
    merit_weight = cb.weight * b_ref
    zero = np.zeros(n_c)

    def evaluate(u, lam):
        """Everything the step and the line search need at (u, lambda)."""
        point = SimpleNamespace(u=u, lam=lam, energy=0.0, floor=0.0)
        point.t = cb.normal_displacement(u) - cb.gap
        point.slip = cb.tangential_displacement(u)
        Ku = K @ u
        normal_force = cb.scatter(cb.weight * law.normal_pressure(point.t), zero, n)
        friction_force = cb.scatter(zero, cb.weight * law.friction_bound(point.t) * point.lam, n)
        point.gradient = Ku + normal_force - f  # gradient of the energy without the friction term
        point.R = point.gradient + friction_force
        point.q = point.lam + gamma * point.slip
        C = merit_weight * (point.lam - np.clip(point.q, -1.0, 1.0))
        point.theta = float(point.R @ point.R + C @ C)
        point.scale = residual_scale(f_norm, float(np.linalg.norm(normal_force + friction_force)))
        if energy_merit:
            friction = law.k_friction * (cb.weight @ np.abs(point.slip))
            point.energy = float(0.5 * (u @ Ku) - f @ u + cb.weight @ _normal_energy(law, point.t) + friction)
        return point

    K_abs = abs(K)

    def converged(point):
        """Relative residual <= tol, or at the rounding floor of its own evaluation (ill-conditioned cases)."""
        residual = np.sqrt(point.theta) / point.scale
        if residual <= tol:
            return True
        stiff = cb.weight * np.minimum(law.normal_stiffness(point.t), stiffness_cap) * np.abs(point.t + cb.gap)
        size = K_abs @ np.abs(point.u) + np.abs(f) + cb.scatter(stiff, zero, n)
        point.floor = ROUNDING_FLOOR * np.finfo(float).eps * float(np.linalg.norm(size)) / point.scale
        return residual <= point.floor

    def slope(point, du_tau, du):
        """Directional derivative of the energy at ``point`` along du (one-sided for |u_tau|)."""
        friction = np.where(point.slip != 0.0, np.sign(point.slip) * du_tau, np.abs(du_tau))
        return float(point.gradient @ du + law.k_friction * (cb.weight @ friction))

    energy_merit = law.reduced  # m_tau = 0 or k_tau = 0: the problem minimizes a convex energy
    # start: the plain linear solution and the multiplier its slip would need at the local stiffness
    point = evaluate(u, np.clip(kd_tau * cb.tangential_displacement(u) / (cb.weight * b_ref), -1.0, 1.0))
    records = []
    previous_state = None
    eta, theta_previous = ETA_MAX, point.theta
    for k in range(1, max_iterations + 1):
        if converged(point):
            return finish(point.u, point.lam, k - 1, records)
        u, lam, t, q = point.u, point.lam, point.t, point.q
        bound = law.friction_bound(t)
        frictional = bound > 0.0
        slip = frictional & (np.abs(q) > 1.0)
        stick = frictional & ~slip
        state = np.where(t > 0.0, 3, 0) + np.where(slip, 1, np.where(stick, 2, 0))
        changes = n_c if previous_state is None else int(np.sum(state != previous_state))
        previous_state = state
        sign = np.sign(q)
        stick_shift = cb.scatter(zero, np.where(stick, -point.slip, 0.0), n)
        friction_now = cb.scatter(zero, cb.weight * bound * lam, n)
        slip_force = cb.scatter(zero, np.where(slip, cb.weight * bound * sign, 0.0), n)
        Z = _stick_basis(cb, np.flatnonzero(stick), n) if np.any(stick) else None

        def penalty():  # for a rebuilt AMG hierarchy: stick tangents nearly clamped
            return _rank_one_blocks(cb, np.where(stick, STICK_PENALTY * kd_tau, 0.0), cb.tangent, n)

        # the Newton system: K + J (+ the friction-bound derivative w p_tau' lambda tau nu^T, m_tau > 0)
        A = K + _rank_one_blocks(cb, cb.weight * np.minimum(law.normal_stiffness(t), stiffness_cap), cb.normal, n)
        if not law.reduced:
            lam_hat = np.where(slip, sign, np.where(stick, lam, 0.0))
            A = A + _rank_one_blocks(cb, cb.weight * law.friction_bound_derivative(t) * lam_hat, cb.tangent, n, cb.normal)
        A = A.tocsr()
        rhs = -(point.R - friction_now) - A @ stick_shift - slip_force
        if base.method == "amg" and k > 1:
            eta = min(ETA_MAX, 0.9 * point.theta / theta_previous)  # Eisenstat-Walker, choice 2
        eta = min(max(eta, 0.1 * tol * point.scale / max(np.linalg.norm(rhs), np.finfo(float).tiny), 1e-14), ETA_MAX)
        try:
            correction, its = reduced.solve(A, Z, rhs, eta, penalty, symmetric=law.reduced)
        except LinearSolveError as exc:
            raise ConvergenceError(f"ssn: {exc}") from None
        linear_total += its
        du = stick_shift + correction
        stick_force = cb.tangential_displacement(rhs - A @ correction)
        lam_new = np.where(slip, sign, lam)
        lam_new = np.where(stick, stick_force / (cb.weight * np.where(stick, bound, 1.0)), lam_new)
        slip_new = point.slip + cb.tangential_displacement(du)
        lam_new = np.where(frictional, lam_new, np.where(slip_new != 0.0, np.sign(slip_new), lam))
        if not (np.all(np.isfinite(du)) and np.all(np.isfinite(lam_new))):
            _fail(problem, k, "non-finite Newton step", records, max(contrast, 2 * CONTRAST_WARNING))
        dlam = lam_new - lam
        full = evaluate(u + du, lam_new)
        du_tau = cb.tangential_displacement(du)

        def trial(alpha):
            return full if alpha == 1.0 else evaluate(u + alpha * du, lam + alpha * dlam)

        d0 = slope(point, du_tau, du) if energy_merit else 0.0
        alpha, new = _line_search(point, trial, lambda p: slope(p, du_tau, du), d0, energy_merit)
        theta_previous = point.theta
        point = new
        short_steps = short_steps + 1 if alpha < SHORT_STEP else 0
        if reduced.method == "amg" and short_steps >= 2 and n <= DIRECT_FALLBACK_LIMIT:
            # inexact CG steps of a badly conditioned K + J (k_nu w >> K) stall the line search
            reduced.method = info["fallback"] = "direct"
        record = {
            "residual": np.sqrt(point.theta) / point.scale,
            "du": float(alpha * np.linalg.norm(du) / max(np.linalg.norm(point.u), np.finfo(float).tiny)),
            "dlambda": float(np.max(np.abs(point.lam - lam))),
            "step": alpha,
            "active_changes": changes,
            "linear_iterations": its,
        }
        if base.method == "amg":
            record["eta"] = eta
        records.append(record)
        if progress is not None:
            progress(k, record)
    if converged(point):
        return finish(point.u, point.lam, max_iterations, records)
    _fail(problem, max_iterations, f"residual {np.sqrt(point.theta) / point.scale:.1e} > tol {tol:.0e}", records, contrast)


def _normal_energy(law, t):
    """P_nu(t) with P_nu' = p_nu: k t_+^(m+1) / (m+1), or k t for m = 0 (constant pressure)."""
    if law.m_normal == 0.0:
        return law.k_normal * t
    return law.k_normal * np.maximum(t, 0.0) ** (law.m_normal + 1.0) / (law.m_normal + 1.0)


def _line_search(point, trial, slope, d0, energy_merit):
    """Step length along the Newton direction; returns (alpha, the point reached).

    The full step is taken when it reduces the residual merit theta (fast local convergence).
    Otherwise, for the reduced law, Armijo backtracking on the convex energy, which the Newton
    direction descends (d0 < 0); after an accepted full step that still descends steeply the step is
    doubled while the energy keeps falling (a power law m_nu > 1 approached from deep penetration
    needs steps of about m_nu). Without an energy (m_tau > 0) backtracking on theta. If nothing
    decreases, the full step is taken (an active-set change may need it).
    """
    full = trial(1.0)
    descent = energy_merit and d0 < 0.0
    if descent and full.energy <= point.energy + ARMIJO * d0:
        alpha, best = 1.0, full
        low, low_slope = 1.0, slope(full)
        while low < MAX_EXPANSION and low_slope < EXPAND_SLOPE * d0:
            high = 2.0 * low
            candidate = trial(high)
            high_slope = slope(candidate)
            if candidate.energy < best.energy:
                alpha, best = high, candidate
            if high_slope >= 0.0 or not candidate.energy < best.energy:
                # the minimizer along the line lies in (low, high): one secant step on the slope
                secant = low - low_slope * (high - low) / (high_slope - low_slope)
                if low < secant < high:
                    candidate = trial(secant)
                    if candidate.energy < best.energy:
                        alpha, best = secant, candidate
                break
            low, low_slope = high, high_slope
        return alpha, best
    if full.theta <= (1.0 - ARMIJO) * point.theta:
        return 1.0, full
    alpha = 0.5
    while alpha >= MIN_STEP:
        candidate = trial(alpha)
        if descent:
            if candidate.energy <= point.energy + ARMIJO * alpha * d0:
                return alpha, candidate
        elif candidate.theta <= (1.0 - ARMIJO * alpha) * point.theta:
            return alpha, candidate
        alpha *= 0.5
    return 1.0, full


def _fail(problem, k, what, records, contrast=0.0):
    """Raise a one-line ConvergenceError naming the likely culprit from the iteration history."""
    law, E = problem.law, young_modulus(problem)
    head = f"ssn did not converge after {k} iterations ({what})"
    if contrast > CONTRAST_WARNING:
        culprit = (
            f"contact.normal.k = {law.k_normal:g} makes the contact {contrast:.0e} times stiffer than the body "
            f"(E = {E:g}), beyond what double precision resolves; lower contact.normal.k or rescale E"
        )
    elif not law.reduced:
        culprit = (
            f"the friction bound of contact.friction.m = {law.m_friction:g} (k = {law.k_friction:g} against "
            f"contact.normal.k = {law.k_normal:g}) couples too strongly to the penetration; try a smaller friction.k"
        )
    elif any(r["active_changes"] > 0 for r in records[-5:]):
        culprit = (
            f"the stick/slip/contact sets keep changing (contact.friction.k = {law.k_friction:g}, "
            f"contact.normal.k = {law.k_normal:g}, E = {E:g}); try a larger solver.max_iterations or solver.linear=direct"
        )
    else:
        culprit = (
            f"the normal compliance contact.normal.m = {law.m_normal:g} (k = {law.k_normal:g}, E = {E:g}) "
            f"converges slowly; try a larger solver.max_iterations"
        )
    raise ConvergenceError(f"{head}: {culprit}")
