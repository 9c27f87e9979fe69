"""Result of a contact solve, its failure mode, and independent checks of the discrete conditions.

The discrete problem ((5.2)-(5.3) with nodal quadrature) for the free-dof vector u and one friction
multiplier lambda_c per contact vertex c:

    K u + sum_c w_c [ p_nu(u_nu,c - g_c) nu_c + p_tau(u_nu,c - g_c) lambda_c tau_c ] = f,
    |lambda_c| <= 1,   lambda_c u_tau,c = |u_tau,c|.

The tangential stress is sigma_tau,c = -p_tau lambda_c and the normal pressure p_nu(u_nu,c - g_c),
so |sigma_tau| <= p_tau (2.7), and where the vertex slips the tangential stress opposes the slip
(2.8)-(2.9). ``contact_residual`` checks these conditions from u and lambda alone, whatever solver
produced them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

SEPARATED, STICK, SLIP = 0, 1, 2
STATE_NAMES = {SEPARATED: "separated", STICK: "stick", SLIP: "slip"}


@dataclass
class ContactSolution:
    u: np.ndarray  # free-dof displacement vector
    multiplier: np.ndarray  # (n_c,) friction multiplier lambda, |lambda| <= 1 (3D: (n_c, 2), in the unit disk)
    iterations: int  # nonlinear iterations (0: the plain linear solve was the solution)
    converged: bool
    method: str  # "uzawa" or "ssn"
    history: dict = field(default_factory=dict)  # name -> 1-D array, one entry per iteration
    linear_iterations: int = 0  # total inner (CG) iterations, or number of direct solves
    wall_time: float = 0.0  # seconds, including the linear solver setup
    info: dict = field(default_factory=dict)  # solver parameters actually used (rho, linear method, ...)


def history_arrays(records: list[dict]) -> dict:
    """Turn a list of per-iteration dicts into a dict of 1-D float arrays."""
    keys = []
    for record in records:
        keys.extend(k for k in record if k not in keys)
    return {k: np.array([r.get(k, np.nan) for r in records], dtype=float) for k in keys}


def globalization(solution: ContactSolution) -> str:
    """What the solver did beyond full Newton steps, in one line (the solution file's
    ``solver_globalization``): the damped steps of ssn's line search (``history["step"]`` < 1) and the
    shortest, a fallback of its linear solver, the coupled law's gamma rescaled at a stall, a warm start
    taken; "full steps" when none of these happened; "fixed point" for uzawa (no step length)."""
    steps = np.asarray(solution.history.get("step", []), dtype=float)
    if solution.method != "ssn":
        return "fixed point"
    parts = []
    damped = steps[steps < 1.0]
    if damped.size:
        parts.append(f"{damped.size} of {steps.size} steps damped by the line search (shortest {damped.min():.3g})")
    if solution.info.get("fallback"):
        parts.append(f"the Newton systems fell back to {solution.info['fallback']}")
    if solution.info.get("gamma_rescaled"):
        parts.append(f"gamma rescaled {solution.info['gamma_rescaled']} time(s) at a stall")
    if solution.info.get("warm_start"):
        parts.append("warm start taken")
    return "; ".join(parts) or "full steps"


def young_modulus(problem) -> float:
    """E recovered from the Lamé parameters of the paper's plane-stress C (for error messages)."""
    nu = problem.lam / (problem.lam + 2.0 * problem.mu)
    return 2.0 * problem.mu * (1.0 + nu)


def contact_force_vector(problem, u, multiplier):
    """Free-dof vector sum_c w_c [p_nu(u_nu,c - g_c) nu_c + p_tau(u_nu,c - g_c) lambda_c tau_c].

    With ``contact_quadrature: gauss`` the normal-compliance part is integrated with Gauss points on
    each Gamma_C edge (vemkit.contact.boundary); the friction part stays nodal.
    """
    cb = problem.contact
    if cb.size == 0:
        return np.zeros_like(u)
    return cb.contact_force(u, problem.law, multiplier)


def residual_scale(load_norm: float, contact_force_norm: float) -> float:
    """||f||, or ||f|| + ||contact forces|| when there is no load; 1 when both vanish."""
    scale = load_norm if load_norm > 0.0 else load_norm + contact_force_norm
    return scale if scale > 0.0 else 1.0


def relative_slip(cb, u, slip_reference=None):
    """The slip u_tau - u_tau^ref at the contact vertices: counted from ``slip_reference`` (the
    previous load step's u_tau, the incremental friction law of a loading in steps), from the
    unloaded shape when None (the static law (2.8)-(2.9))."""
    slip = cb.tangential_displacement(u)
    return slip if slip_reference is None else slip - np.asarray(slip_reference, dtype=float)


def contact_residual(problem, u, multiplier, slip_reference=None) -> dict:
    """How well (u, lambda) satisfies the discrete problem, each measure dimensionless.

    equilibrium      ||K u + contact forces - f|| / ||f||  (||f|| + ||contact forces|| if f = 0)
    multiplier_bound max_c (|lambda_c| - 1)_+                      (|sigma_tau| <= p_tau, (2.7))
    complementarity  max_c |lambda_c . u_tau,c - |u_tau,c|| / max|u| (sigma_tau opposes slip, (2.8))
    (3D: lambda_c and u_tau,c vectors of the tangent plane, |.| the Euclidean norm; with |lambda| <= 1,
    lambda . u_tau = |u_tau| is lambda = u_tau / |u_tau| wherever u_tau != 0)
    max of the three under ``worst``; non-finite input gives inf everywhere. u_tau is the slip
    counted from ``slip_reference`` (``relative_slip``).
    """
    u = np.asarray(u, dtype=float)
    lam = np.asarray(multiplier, dtype=float)
    if not (np.all(np.isfinite(u)) and np.all(np.isfinite(lam))):
        inf = float("inf")
        return {"equilibrium": inf, "multiplier_bound": inf, "complementarity": inf, "worst": inf}
    K, f, cb = problem.stiffness, problem.load, problem.contact
    forces = contact_force_vector(problem, u, lam)
    scale = residual_scale(float(np.linalg.norm(f)), float(np.linalg.norm(forces)))
    equilibrium = float(np.linalg.norm(K @ u + forces - f)) / scale
    if cb.size:
        slip = relative_slip(cb, u, slip_reference)
        umax = float(np.max(np.abs(u))) if u.size else 0.0
        bound = float(np.max(np.maximum(cb.magnitude(lam) - 1.0, 0.0)))
        compl = float(np.max(np.abs(cb.dot(lam, slip) - cb.magnitude(slip)))) / (umax if umax > 0.0 else 1.0)
    else:
        bound = compl = 0.0
    return {
        "equilibrium": equilibrium,
        "multiplier_bound": bound,
        "complementarity": compl,
        "worst": max(equilibrium, bound, compl),
    }


@dataclass
class ContactState:
    """Per contact vertex: state code and the derived contact quantities.

    state: SEPARATED (0) if u_nu - g <= 0 (no normal pressure; note that with the reduced law
    m_tau = 0 the friction bound k_tau still acts there), otherwise STICK (1) if
    |u_tau| <= tol * max|u|, otherwise SLIP (2).
    """

    state: np.ndarray  # (n_c,) int8 codes
    normal_pressure: np.ndarray  # p_nu(u_nu - g) >= 0
    tangential_stress: np.ndarray  # sigma_tau = -p_tau(u_nu - g) * lambda
    friction_bound: np.ndarray  # p_tau(u_nu - g)
    slip: np.ndarray  # u_tau
    penetration: np.ndarray  # u_nu - g (> 0: penetration into the foundation)

    def count(self) -> dict:
        return {name: int(np.sum(self.state == code)) for code, name in STATE_NAMES.items()}


def contact_state(problem, u, multiplier, tol: float = 1e-8, slip_reference=None) -> ContactState:
    """Classify the contact vertices and return the derived quantities (see ``ContactState``); the
    slip counted from ``slip_reference`` (``relative_slip``)."""
    cb, law = problem.contact, problem.law
    u = np.asarray(u, dtype=float)
    penetration = cb.normal_displacement(u) - cb.gap
    slip = relative_slip(cb, u, slip_reference)
    bound = law.friction_bound(penetration)
    scale = float(np.max(np.abs(u))) if u.size else 0.0
    state = np.where(penetration <= 0.0, SEPARATED, np.where(cb.magnitude(slip) <= tol * scale, STICK, SLIP))
    return ContactState(
        state.astype(np.int8),
        law.normal_pressure(penetration),
        cb.times(-bound, multiplier),
        bound,
        slip,
        penetration,
    )
