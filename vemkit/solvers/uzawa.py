"""The paper's Uzawa iteration (Section 5, Steps 1-3, (5.4)-(5.6)) for the discrete contact problem.

Step 1  lambda^0 = 0, u^0 = 0.
Step 2  K u^n = f - sum_c w_c [p_nu(t_c^{n-1}) nu_c + p_tau(t_c^{n-1}) lambda_c^{n-1} tau_c],
        t^{n-1} = u_nu^{n-1} - g   (normal compliance and friction bound lagged: explicit in u^{n-1});
        lambda^n = P(lambda^{n-1} + rho k_tau u_tau^n),  P = projection onto [-1, 1].
Step 3  stop when ||u^n - u^{n-1}|| < eps_u ||u^n||  or  max|lambda^n - lambda^{n-1}| < eps_lambda
        (``stop="either"``, the paper's rule; ``stop="both"`` asks for both). The tests start at n = 2
        (n = 1 compares with the arbitrary initial guess); for a frictionless law lambda is no unknown
        and only the u test is used.

For the reduced law (m_tau = 0, the paper's) p_tau = k_tau and this is exactly (5.4)-(5.5). For
m_tau > 0 the friction bound in the explicit term is p_tau(u_nu^{n-1} - g), and the update of
lambda keeps the paper's form rho k_tau u_tau^n (so lambda = sign(u_tau) wherever the vertex slips,
also where p_tau = 0 and lambda has no force).

The matrix K never changes: one linear solver (factorization or AMG hierarchy) is built once and
reused. AMG-CG is warm-started from u^{n-1} + alpha (u^{n-1} - u^{n-2}) (alpha minimizing the energy
error along the last change) and solved to max(tol, INNER_FRACTION |u^{n-1} - u^{n-2}| / |u^{n-1}|);
when a stopping test passes on such an inexact solve, that solve is finished to tol and the test
repeated, so the iterates stopped on are those of exact solves (to tol).

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

The paper's rule stops on |Δλ| = 0 as soon as every vertex slips (λ = ±1 no longer changes), one
lagged normal-compliance step before u settles. Every stop is therefore checked with
contact_residual: a residual above acceptable_residual (sqrt of the loosest eps) raises a
ConvergenceError suggesting stop="both" or ssn; on the paper scene the default stops at residuals
4e-6 (2^-2) down to 2e-9 (2^-7).

The lagged normal compliance is a fixed-point iteration with contraction factor about
max p_nu' mu_nu (mu_nu: the same compliance for the normal direction): it diverges (or cycles)
when k_nu is large against E. That is detected (non-finite values, growing or stagnating
|u^n - u^{n-1}|) and reported as a ConvergenceError naming contact.normal.k; use the ssn solver.
"""

from __future__ import annotations

import time

import numpy as np

from vemkit.solvers.solution import (
    ContactSolution,
    contact_force_vector,
    contact_residual,
    history_arrays,
    residual_scale,
    young_modulus,
)
from vemkit.solvers.linear import linear_solver
from vemkit.exceptions import ConvergenceError, LinearSolveError

RHO_FACTOR = 1.5  # rho = RHO_FACTOR / (k_tau b mu_tau); stable below 2
STAGNATION_WINDOW = 200  # no new smallest |u^n - u^{n-1}| within this many iterations: stop
DIVERGENCE_GROWTH = 1e3  # |u^n - u^{n-1}| this many times its smallest value, and still growing
INNER_FRACTION = 1e-2  # AMG-CG tolerance: this fraction of the last relative change of u (at least tol)


def boundary_compliance(solver, problem, direction, iterations=20, rtol=1e-3):
    """Largest eigenvalue of W^1/2 C W^1/2, C_cd = d_c . K^-1 d_d (d = normal or tangent), by power iteration."""
    cb = problem.contact
    sqrt_w = np.sqrt(cb.weight)
    zero = np.zeros(cb.size)
    v = sqrt_w / np.linalg.norm(sqrt_w)
    estimate, solves = 0.0, 0
    for _ in range(iterations):
        load = sqrt_w * v
        rhs = cb.scatter(zero, load, problem.n_dofs) if direction == "tangent" else cb.scatter(load, zero, problem.n_dofs)
        x = solver.solve(rhs, tol=1e-6)
        solves += max(solver.iterations, 1)
        comp = cb.tangential_displacement(x) if direction == "tangent" else cb.normal_displacement(x)
        Sv = sqrt_w * comp
        new = float(v @ Sv)
        norm = np.linalg.norm(Sv)
        if norm == 0.0:
            return 0.0, solves
        v = Sv / norm
        if abs(new - estimate) <= rtol * abs(new):
            return new, solves
        estimate = new
    return estimate, solves


def acceptable_residual(eps_u, eps_lambda, tol):
    """Largest contact_residual accepted at a stopped iterate: sqrt of the loosest stopping tolerance.

    The paper's rule may stop on |Δλ| = 0 (every vertex slipping) one lagged normal-compliance step
    before u has settled; that leaves a residual of about (contraction factor) x (last change), far
    below this bound unless the iteration has really not converged.
    """
    return max(np.sqrt(max(eps_u, eps_lambda)), 1e3 * tol)


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
) -> ContactSolution:
    """Steps 1-3 of the paper; see the module docstring. ``tol``: relative tolerance of each CG solve.

    progress(n, record) is called after every iteration with that iteration's history entries:
    du = |u^n - u^{n-1}| / |u^n|, dlambda = max |lambda^n - lambda^{n-1}|, residual = the relative
    equilibrium residual of (u^n, lambda^n) (exact up to the linear-solve tolerance), rho, and
    linear_iterations. Raises ConvergenceError (never returns NaN).
    """
    if stop not in ("either", "both"):
        raise ValueError(f"solver.stop = {stop!r}: use either or both")
    if rho is not None and not rho > 0.0:
        raise ValueError(f"solver.rho = {rho}: must be > 0")
    try:
        return _uzawa(problem, linear, rho, eps_u, eps_lambda, stop, max_iterations, tol, progress)
    except LinearSolveError as exc:
        raise ConvergenceError(f"uzawa: {exc}") from None


def _uzawa(problem, linear, rho, eps_u, eps_lambda, stop, max_iterations, tol, progress):
    start = time.perf_counter()
    K, f, cb, law = problem.stiffness, problem.load, problem.contact, problem.law
    solver = linear_solver(K, linear, near_nullspace=problem.near_nullspace, tol=tol)
    n_c = cb.size
    u = np.zeros(problem.n_dofs)
    lam = np.zeros(n_c)
    info = {"linear": solver.method, "stop": stop}
    linear_total = 0

    def finish(u, lam, iterations, records):
        return ContactSolution(
            u, lam, iterations, True, "uzawa", history_arrays(records), linear_total, time.perf_counter() - start, info
        )

    # Step 2 with n = 1 is the plain linear solve when the contact forces at u^0 = 0 vanish;
    # if the contact forces also vanish at u^1, u^1 is the solution (no contact iteration needed).
    rhs = f - contact_force_vector(problem, u, lam)
    u_first = solver.solve(rhs)
    linear_total += max(solver.iterations, 1)
    t_first = cb.normal_displacement(u_first) - cb.gap
    if n_c == 0 or (
        not np.any(law.normal_pressure(t_first)) and not np.any(law.friction_bound(t_first)) and not np.any(rhs - f)
    ):
        lam = np.sign(cb.tangential_displacement(u_first)) if n_c else lam
        info["rho"] = float("nan") if rho is None else float(rho)
        return finish(u_first, lam, 0, [])

    mu_tau = 0.0
    if rho is None and not law.frictionless:
        mu_tau, solves = boundary_compliance(solver, problem, "tangent")
        linear_total += solves
    info["mu_tau"] = mu_tau

    def step_length(bound):
        if rho is not None:
            return float(rho)
        b_scale = float(np.max(bound)) if np.max(bound) > 0.0 else law.k_friction
        return RHO_FACTOR / (law.k_friction * b_scale * mu_tau) if law.k_friction * mu_tau > 0.0 else 0.0

    inexact = solver.method == "amg"

    def solve_step(rhs, x0, lin_tol):
        """u^n from the lagged right-hand side (CG warm-started from x0)."""
        u_new = solver.solve(rhs, x0=x0, tol=lin_tol)
        return u_new, max(solver.iterations, 1)

    f_norm = float(np.linalg.norm(f))
    forces = f - rhs  # contact forces of (u^0, lambda^0)
    records = []
    smallest_du, smallest_at, growing = np.inf, 0, 0
    du_abs_prev, du = np.inf, 1.0
    step = None  # u^{n-1} - u^{n-2}
    previous_rhs = previous_rhs_change = np.zeros_like(f)  # rhs^{n-1} (K u^0 = 0), rhs^{n-1} - rhs^{n-2}
    stopped_by = None
    n = 0
    for n in range(1, max_iterations + 1):
        t_prev = cb.normal_displacement(u) - cb.gap
        bound = law.friction_bound(t_prev)
        rho_n = step_length(bound)
        rhs = f - forces
        lin_tol = max(tol, INNER_FRACTION * du) if inexact else tol
        if n == 1:
            u_new, lin_its = u_first, 1
        else:
            x0 = _extrapolated_start(u, step, rhs - previous_rhs, previous_rhs_change) if inexact else u
            u_new, lin_its = solve_step(rhs, x0, lin_tol)
            linear_total += lin_its
        while True:
            lam_new = np.clip(lam + rho_n * law.k_friction * cb.tangential_displacement(u_new), -1.0, 1.0)
            if not (np.all(np.isfinite(u_new)) and np.all(np.isfinite(lam_new))):
                _fail(problem, solver, u, n, "non-finite values", rho_n, mu_tau)
            du = _relative_change(u_new, u)
            dlam = float(np.max(np.abs(lam_new - lam))) if n_c else 0.0
            small_u = du < eps_u
            small_lam = dlam < eps_lambda and not law.frictionless
            both = small_u and (small_lam or law.frictionless)
            stopping = n >= 2 and (both if stop == "both" else (small_u or small_lam))
            if not (stopping and lin_tol > tol):
                break
            # the stopping test passed on an inexact solve: finish that solve to tol and test again
            u_new, extra = solve_step(rhs, u_new, tol)
            lin_its += extra
            linear_total += extra
            lin_tol = tol
        du_abs = float(np.linalg.norm(u_new - u))
        step = u_new - u
        previous_rhs_change, previous_rhs = rhs - previous_rhs, rhs
        u, lam = u_new, lam_new
        # K u^n = f - forces^{n-1}, so K u^n + forces^n - f = forces^n - forces^{n-1}
        new_forces = contact_force_vector(problem, u, lam)
        residual = float(np.linalg.norm(new_forces - forces)) / residual_scale(f_norm, float(np.linalg.norm(new_forces)))
        forces = new_forces
        record = {"du": du, "dlambda": dlam, "residual": residual, "rho": rho_n, "linear_iterations": lin_its}
        records.append(record)
        if progress is not None:
            progress(n, record)
        if stopping:
            stopped_by = "du" if small_u else "dlambda"
            break
        growing = growing + 1 if du_abs > du_abs_prev else 0
        du_abs_prev = du_abs
        if du_abs < smallest_du:
            smallest_du, smallest_at = du_abs, n
        if growing >= 5 and du_abs > DIVERGENCE_GROWTH * smallest_du:
            _fail(problem, solver, u, n, f"|Δu| grew {du_abs / smallest_du:.0e}×", rho_n, mu_tau)
        if n - smallest_at >= STAGNATION_WINDOW:
            _fail(problem, solver, u, n, f"|Δu| stagnated at {du:.1e}", rho_n, mu_tau)
    else:
        _fail(problem, solver, u, n, f"max_iterations = {max_iterations} reached at |Δu| = {du:.1e}", rho_n, mu_tau)

    info["rho"] = float(rho_n)
    if law.frictionless:  # lambda carries no force: the one consistent with the slip
        lam = np.sign(cb.tangential_displacement(u))
    info["stopped_by"] = stopped_by
    check = contact_residual(problem, u, lam)
    info["residual"] = check
    accept = acceptable_residual(eps_u, eps_lambda, tol)
    if check["worst"] > accept:
        raise ConvergenceError(
            f"uzawa stopped after {n} iterations by the {'|Δλ|' if stopped_by == 'dlambda' else '|Δu|'} test "
            f"but the discrete problem residual is {check['worst']:.1e} (accepted {accept:.0e}): "
            f"try --set solver.stop=both, smaller solver.eps_u/eps_lambda, or --set solver.method=ssn"
        )
    return finish(u, lam, n, records)


def _fail(problem, solver, u, n, what, rho_n, mu_tau):
    """Raise a ConvergenceError naming the most likely culprit (estimates of the two contraction factors)."""
    law, cb = problem.law, problem.contact
    E = young_modulus(problem)
    mu_nu, _ = boundary_compliance(solver, problem, "normal", iterations=10)
    t = cb.normal_displacement(u) - cb.gap if np.all(np.isfinite(u)) else np.full(cb.size, np.inf)
    slope = law.normal_stiffness(np.where(np.isfinite(t), np.abs(t), 1.0))
    k_eff = float(np.max(slope)) if slope.size else 0.0
    if law.m_normal == 1.0 or not np.isfinite(k_eff):
        k_eff = law.k_normal
    normal_factor = k_eff * mu_nu
    if mu_tau == 0.0 and not law.frictionless:
        mu_tau, _ = boundary_compliance(solver, problem, "tangent", iterations=10)
    friction_factor = rho_n * law.k_friction * law.k_friction * mu_tau
    verb = "diverged" if what.startswith(("non-finite", "|Δu| grew")) else "did not converge"
    head = f"uzawa {verb} after {n} iterations ({what})"
    if normal_factor >= 0.5:
        raise ConvergenceError(
            f"{head}: the lagged normal compliance is unstable for contact.normal.k = {law.k_normal:g} "
            f"(m = {law.m_normal:g}) against E = {E:g} (contraction estimate {normal_factor:.1e} >= 1); "
            f"try --set solver.method=ssn"
        )
    if friction_factor >= 1.9:
        raise ConvergenceError(
            f"{head}: solver.rho = {rho_n:.3g} is too large for contact.friction.k = {law.k_friction:g} "
            f"(stable below {2.0 / (law.k_friction ** 2 * mu_tau):.3g}); try a smaller solver.rho or solver.method=ssn"
        )
    if not law.reduced:
        raise ConvergenceError(
            f"{head}: the lagged friction bound of contact.friction.m = {law.m_friction:g} "
            f"(k = {law.k_friction:g}) does not settle; try --set solver.method=ssn"
        )
    raise ConvergenceError(
        f"{head}: try a larger solver.max_iterations, a smaller solver.rho, or --set solver.method=ssn"
    )
