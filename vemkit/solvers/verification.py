"""Trustworthy or clearly failed: the independent check of a solution and the guarded solve.

Every solve of the sweeps, the speed-accuracy study and the robustness matrix goes through
:func:`guarded_solve`, which returns an :class:`Outcome` instead of raising. An outcome is
``converged`` only if the solver returned AND the independent check (:func:`verify_solution`)
passed; otherwise it names one class of :data:`FAILURE_CLASSES`:

    diverged             non-finite values, or the iteration grew (ConvergenceError)
    stagnated            the iteration stopped making progress (ConvergenceError)
    max_iterations       the iteration limit was reached first (ConvergenceError)
    inaccurate_stop      the stopping rule fired but the solver's own residual test refused (Uzawa)
    other                any other ConvergenceError
    time_budget          the solve ran past its time budget (checked after every iteration)
    check_failed         the solver returned, but the independent check failed
    linear_solver_failed a linear solve failed (LinearSolveError, also when wrapped)
    invalid_input        the scene, an override or the contact law was rejected (InputError)
    unexpected_exception anything else (a bug): the message keeps the exception type

The class comes from the exception's type and its ``reason`` attribute (``vemkit.exceptions``),
never from its message.

The independent check uses only u and the friction multiplier lambda: ``contact_residual``
(equilibrium, |lambda| <= 1, lambda u_tau = |u_tau|) and, vertex by vertex, the contact conditions
read off the reaction R = f - K u - N(u) left once the normal-compliance force N(u) is removed
(N_c = w_c p_nu(u_nu,c - g_c) nu_c with nodal quadrature, the Gauss edge integral of
vemkit.contact.boundary otherwise); at a contact vertex R_c = w_c p_tau lambda_c tau_c, so
R_c . tau_c = -w_c sigma_tau,c:

    normal_law      (2.6)  |R_c . nu_c| / F  (the normal force is all normal compliance)
    friction_bound  (2.7)  (|R_c . tau_c| - w_c p_tau(u_nu - g))_+ / F
    slip_direction  (2.8)  where |u_tau| > tol max|u| and p_tau > 0: |R_c . tau_c - w_c p_tau sign(u_tau)| / F
    stick           (2.9)  where |R_c . tau_c| < w_c p_tau - tol F: |u_tau| / max|u|

F = ||f|| (||f|| + ||contact forces|| without load), the scale of ``contact_residual``.
In 3D (docs/reference/files.md) R_c . tau_c, u_tau and sign(u_tau) are vectors of the tangent plane in the vertex
basis (t1, t2): |.| is their norm, sign(u_tau) = u_tau / |u_tau| (the slip direction, which the
tangential force R_c . tau_c = w_c p_tau lambda_c must follow). The prescribed components of a
contact vertex (a roller meeting Gamma_C) are left out of R_c: the constraint takes their force.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from functools import cache

import numpy as np

from vemkit.exceptions import SOLVE_FAILURE_REASONS, InputError, LinearSolveError, SolveError, TimeBudgetExceeded
from vemkit.solvers.solution import contact_force_vector, contact_residual, relative_slip, residual_scale

FAILURE_CLASSES = SOLVE_FAILURE_REASONS + ("invalid_input", "unexpected_exception")
_NOT_CONVERGED = FAILURE_CLASSES[:7]
#: status code i <-> STATUS_MEANINGS[i] (netCDF flag_values / flag_meanings)
STATUS_MEANINGS = ("converged",) + tuple(
    ("not_converged_" if c in _NOT_CONVERGED else "error_") + c for c in FAILURE_CLASSES
)
CHECK_KEYS = (
    "equilibrium",
    "multiplier_bound",
    "complementarity",
    "normal_law",
    "friction_bound",
    "slip_direction",
    "stick",
)
DEFAULT_CHECK_TOL = 1e-6


def status_code(status: str) -> int:
    """0 for converged, 1 + the index of the failure class otherwise."""
    return 0 if status == "converged" else 1 + FAILURE_CLASSES.index(status)


def failure_class(exc: BaseException, phase: str = "solve") -> str:
    """The class of an exception from setting up (``phase="setup"``) or running a solve.

    By type and attributes only: a SolveError names its ``reason``; a LinearSolveError, or a
    ConvergenceError raised ``from`` one, is ``linear_solver_failed``; bad input is an InputError
    (or any ValueError while setting up); anything else is a bug.
    """
    if isinstance(exc, SolveError):
        if isinstance(exc, LinearSolveError) or isinstance(exc.__cause__, LinearSolveError):
            return "linear_solver_failed"
        return exc.reason
    if isinstance(exc, InputError) or (phase == "setup" and isinstance(exc, ValueError)):
        return "invalid_input"
    return "unexpected_exception"


def verify_solution(problem, u, multiplier, tol: float = DEFAULT_CHECK_TOL, slip_reference=None) -> dict:
    """The independent check of the module docstring: {measure: value, "worst": max, "passed": bool};
    u_tau the slip counted from ``slip_reference`` (a load step's incremental law, None: from the
    unloaded shape)."""
    u = np.asarray(u, dtype=float)
    lam = np.asarray(multiplier, dtype=float)
    out = {k: float(v) for k, v in contact_residual(problem, u, lam, slip_reference).items() if k != "worst"}
    cb, law = problem.contact, problem.law
    finite = np.all(np.isfinite(u)) and np.all(np.isfinite(lam))
    if not finite:
        out.update({k: float("inf") for k in CHECK_KEYS})
    elif cb.size == 0:
        out.update({k: 0.0 for k in CHECK_KEYS[3:]})
    else:
        f = problem.load
        # the reaction left for friction: f - K u - (normal-compliance force, nodal or gauss)
        reaction = f - problem.stiffness @ u - cb.normal_force(u, law)
        r = reaction[cb.dofs]  # (n_c, d)
        if cb.fixed is not None:  # a prescribed component's reaction is the constraint's
            r = np.where(cb.fixed, 0.0, r)
        r_nu = np.sum(r * cb.normal, axis=1)
        r_tau = np.stack([np.sum(r * t, axis=1) for t in cb.tangents], axis=1)  # (n_c, d - 1)
        scale = residual_scale(float(np.linalg.norm(f)), float(np.linalg.norm(contact_force_vector(problem, u, lam))))
        t = cb.normal_displacement(u) - cb.gap
        slip = relative_slip(cb, u, slip_reference)
        bound = cb.weight * law.friction_bound(t)
        umax = float(np.max(np.abs(u))) or 1.0
        slipping = (cb.magnitude(slip) > tol * umax) & (bound > 0.0)
        inside = cb.magnitude(r_tau) < bound - tol * scale
        out["normal_law"] = float(np.max(np.abs(r_nu))) / scale
        out["friction_bound"] = float(np.max(np.maximum(cb.magnitude(r_tau) - bound, 0.0))) / scale
        slide = cb.magnitude(r_tau - cb.times(bound, cb.direction(slip)))
        out["slip_direction"] = float(np.max(slide[slipping], initial=0.0)) / scale
        out["stick"] = float(np.max(cb.magnitude(slip)[inside], initial=0.0)) / umax
    out["worst"] = max(out[k] for k in CHECK_KEYS)
    out["passed"] = bool(out["worst"] <= tol)
    return out


@dataclass
class Outcome:
    """What became of one solve; ``solution`` is None unless the solver returned."""

    method: str
    status: str  # "converged" or a failure class
    message: str = ""
    solution: object = None
    checks: dict = field(default_factory=dict)
    wall_time: float = 0.0  # seconds around the solver call (with its linear solver set-up)
    iterations: int = -1

    @property
    def converged(self) -> bool:
        return self.status == "converged"

    @property
    def code(self) -> int:
        return status_code(self.status)


def failed(method: str, exc: BaseException, phase: str, wall_time: float = 0.0) -> Outcome:
    status = failure_class(exc, phase)
    message = " ".join(str(exc).split()) or type(exc).__name__
    if status == "unexpected_exception":
        message = f"{type(exc).__name__}: {message}"
    return Outcome(method, status, message, wall_time=wall_time, iterations=int(getattr(exc, "iterations", -1)))


@cache
def prebuilt_linear_supported() -> bool:
    """Whether the contact solvers take a prebuilt ``linear`` solver: both hand ``linear`` to
    ``vemkit.solvers.linear.linear_solver``, which returns a solver built earlier as it is (once it
    knows how; before, it rejected anything but a method name)."""
    import scipy.sparse as sp

    from vemkit.solvers.linear import linear_solver

    A = sp.identity(2, format="csr")
    built = linear_solver(A)
    try:
        return linear_solver(A, built) is built
    except (ValueError, TypeError):
        return False


def guarded_solve(
    problem,
    solver_options: dict,
    *,
    linear=None,
    time_budget: float | None = None,
    check_tol: float | None = DEFAULT_CHECK_TOL,
) -> Outcome:
    """Run the configured solver on ``problem``; never raises (see :class:`Outcome`).

    ``linear``: a prebuilt solver of ``problem.stiffness`` (``vemkit.solvers.linear.linear_solver``),
    used when the contact solver accepts one (:func:`prebuilt_linear_supported`).
    ``check_tol``: None records the independent check without judging it.
    """
    from vemkit.solvers.dispatch import solve

    options = dict(solver_options)
    method = str(options.get("method", "ssn"))
    if linear is not None and prebuilt_linear_supported():
        options["linear"] = linear
    start = time.perf_counter()

    def progress(_iteration, _record):
        if time_budget is not None and time.perf_counter() - start > time_budget:
            raise TimeBudgetExceeded(
                f"{method} ran past its time budget of {time_budget:g} s after {_iteration} iterations",
                solver=method,
                iterations=_iteration,
            )

    try:
        solution = solve(problem, options, progress=progress)
    except Exception as exc:  # noqa: BLE001 - every failure is classified, none escapes
        return failed(method, exc, "solve", time.perf_counter() - start)
    wall = time.perf_counter() - start
    checks = verify_solution(problem, solution.u, solution.multiplier, check_tol or DEFAULT_CHECK_TOL)
    outcome = Outcome(method, "converged", "", solution, checks, wall, int(solution.iterations))
    if check_tol is not None and not checks["passed"]:
        worst = max(CHECK_KEYS, key=lambda k: checks[k])
        outcome.status = "check_failed"
        outcome.message = (
            f"{method} reported convergence after {solution.iterations} iterations but the "
            f"independent check fails: {worst} = {checks[worst]:.1e} > {check_tol:.0e}"
        )
    return outcome
