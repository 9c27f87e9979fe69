"""An iterate of the semismooth Newton method (vemkit.solvers.ssn) and its measures: the residuals,
the merit theta, the energy of the reduced law and its slope, and the convergence test; in 3D also
the slip direction's test (``disk_alignment``), the multiplier re-aligned with the slip
(``aligned_multiplier``, ``final_multiplier``) and the local gamma of Coulomb's coupled law
(``coupled_gamma``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vemkit.contact import ball
from vemkit.solvers.solution import relative_slip, residual_scale
from vemkit.solvers.sparse_ops import abs_matvec, matvec

BOUND_FLOOR = 1e-3  # coupled_gamma: a vertex's friction bound counted as at least this times b_ref
ROUNDING_FLOOR = 100.0  # accept a residual this many times eps * || |K| |u| + |f| + |J| |u| || (see converged)


@dataclass
class Point:
    """An iterate (u, lambda) and everything the step and the line search need there."""

    u: np.ndarray
    lam: np.ndarray
    t: np.ndarray  # u_nu - g
    slip: np.ndarray  # u_tau
    gradient: np.ndarray  # gradient of the energy without the friction term
    R: np.ndarray  # the equilibrium residual
    q: np.ndarray  # lambda + gamma u_tau
    theta: float  # the residual merit ||R||^2 + ||w b_ref C||^2
    scale: float  # residual_scale
    energy: float = 0.0
    floor: float = 0.0
    verdict: bool | None = None  # converged(), once computed (it depends on the point only)


def evaluate(newton, u, lam) -> Point:
    """Everything the step and the line search need at (u, lambda)."""
    problem = newton.problem
    K, f, cb, law, n = problem.stiffness, problem.load, problem.contact, problem.law, problem.n_dofs
    zero = newton.zero
    t = cb.normal_displacement(u) - cb.gap
    slip = relative_slip(cb, u, newton.slip_reference)
    Ku = matvec(K, u)
    normal_force = cb.normal_force(u, law)
    friction_force = cb.scatter(zero, cb.times(cb.weight * law.friction_bound(t), lam), n)
    gradient = Ku + normal_force - f
    R = gradient + friction_force
    q = lam + cb.times(newton.gamma, slip)
    C = cb.times(complementarity_weight(newton, t), lam - cb.project(q))
    scale = residual_scale(newton.f_norm, float(np.linalg.norm(normal_force + friction_force)))
    point = Point(u, lam, t, slip, gradient, R, q, float(R @ R + ball.inner(C, C)), scale)
    if newton.energy_merit:
        friction = law.friction_coefficient * (cb.weight @ cb.magnitude(slip))
        point.energy = float(0.5 * (u @ Ku) - f @ u + cb.normal_energy(u, law) + friction)
    return point


def complementarity_weight(newton, t):
    """The weight of C in the merit: w b_ref for the reduced law; w p_tau(t) for m_tau > 0, so that
    C counts as the friction force it misplaces and a vertex without friction force (p_tau = 0, where
    lambda only follows the slip direction) does not count: with w b_ref there, its lambda moved
    by the step made the Newton direction no descent direction of theta (measured on the Hertz half
    sphere, a stall at a step length ~0)."""
    cb, law = newton.problem.contact, newton.problem.law
    return cb.weight * (newton.b_ref if law.reduced else law.friction_bound(t))


def converged(newton, point) -> bool:
    """Relative residual <= tol, or at the rounding floor of its own evaluation (ill-conditioned cases);
    in 3D also the slip direction resolved and lambda in the disk. Computed once per point."""
    if point.verdict is None:
        point.verdict = _converged(newton, point)
    return point.verdict


def _converged(newton, point) -> bool:
    residual = np.sqrt(point.theta) / point.scale
    if not newton.problem.contact.ball.direction_from_projection:  # and the slip direction resolved (disk_alignment)
        residual = max(residual, disk_alignment(newton, point))
        # and lambda in the unit disk to tol, as the independent check asks: neither the weighted C nor
        # the rounding floor below sees |lambda| > 1 where w b is small against the body's forces
        # (E = 2e9, k_tau = 3: |lambda| = 1 + 2.8e-4 was accepted after one step)
        excess = float(np.max(newton.problem.contact.magnitude(point.lam) - 1.0, initial=0.0))
        if excess > newton.tol:
            return False
    if residual <= newton.tol:
        return True
    problem = newton.problem
    cb, law = problem.contact, problem.law
    stiff = cb.weight * np.minimum(law.normal_stiffness(point.t), newton.stiffness_cap) * np.abs(point.t + cb.gap)
    size = (
        abs_matvec(problem.stiffness, np.abs(point.u))
        + np.abs(problem.load)
        + cb.scatter(stiff, newton.zero_tangential, problem.n_dofs)
    )
    point.floor = ROUNDING_FLOOR * np.finfo(float).eps * float(np.linalg.norm(size)) / point.scale
    return residual <= point.floor


def energy_slope(newton, point, du_tau, du) -> float:
    """Directional derivative of the energy at ``point`` along du (one-sided for |u_tau|)."""
    cb, law = newton.problem.contact, newton.problem.law
    friction = np.where(cb.magnitude(point.slip) != 0.0, cb.dot(cb.direction(point.slip), du_tau), cb.magnitude(du_tau))
    return float(point.gradient @ du + law.friction_coefficient * (cb.weight @ friction))


def disk_alignment(newton, point) -> float:
    """||w b (lambda - u_tau/|u_tau|)|| / scale over the sliding vertices (|q| > 1, |u_tau| > tol max|u|).

    Part of the convergence test in 3D: there C = lambda - P(q) measures the direction of lambda only
    through q = lambda + gamma u_tau, i.e. damped by gamma |u_tau| / (1 + gamma |u_tau|), which is tiny
    at a vertex that barely slides (measured: C ~ 1e-3 x the direction error on a Voronoi box); the
    slip direction (2.8) itself is asked for to tol, as the independent check does."""
    cb = newton.problem.contact
    # sliding as the independent check has it (|u_tau| > tol max|u|): a stick vertex's slip of
    # rounding size (u_tau - u_tau^ref after a stick step) has no direction to follow
    moving = cb.magnitude(point.slip) > newton.tol * float(np.max(np.abs(point.u), initial=0.0))
    sliding = (cb.magnitude(point.q) > 1.0) & moving
    miss = cb.magnitude(point.lam - cb.direction(point.slip))[sliding]
    return float(np.linalg.norm(complementarity_weight(newton, point.t)[sliding] * miss)) / point.scale


def coupled_gamma(kd_tau, weight, bound, b_ref, floor: float = BOUND_FLOOR):
    """gamma_c = kd_c / (w_c b_c) for Coulomb's coupled law (m_tau > 0): b_c the vertex's friction
    bound p_tau(t_c) at the start (at least BOUND_FLOOR b_ref; b_ref where it is 0), so gamma |u_tau|
    is the local trial ratio kd |u_tau| / (w b), the natural size of q - lambda at a sliding vertex.

    The global gamma of vemkit.solvers.ssn (0.1 kd / (L_C h b_ref)) is smaller by 0.1 h / L_C and by
    b_c / b_ref: on the Mindlin half sphere (Gamma_C the whole quarter sphere, L_C ~ 1.8, contact radius
    0.1) gamma |u_tau| was ~1e-6 at vertices sliding by 1e-4, so q ~ lambda and the slip direction was
    resolved only by re-aligning lambda, which cycled at h = 0.015 and 0.01 (measured: residual
    4e-6 <-> 1e-8 for 60 iterations). With this gamma: 6 Newton iterations per load step at h = 0.015
    and 0.01, and on the GetFEM box (m_tau = 1) 9-12 instead of 11-27 at 2 187 and 14 739 DOFs."""
    bound = np.where(bound > 0.0, np.maximum(bound, floor * b_ref), b_ref)
    return kd_tau / (weight * bound)


def aligned_multiplier(newton, point):
    """lambda = u_tau / |u_tau| at the sliding vertices (disk_alignment's), once the merit is
    converged and only the slip direction (2.8) is not; else None.

    At a vertex barely in contact (p_tau(t) ~ 1e-4 of the largest bound) gamma |u_tau| is ~1e-6, so
    |q| = |lambda + gamma u_tau| ~ 1 and P(q) ~ lambda whatever lambda's direction: Newton turns lambda
    towards the slip by ~gamma |u_tau| per step (measured on the Mindlin sphere: the direction error
    2.3e-2 -> 2.1e-2 in 20 steps, disk_alignment stalled at 3.5e-6). Setting the direction moves the
    friction force by disk_alignment x scale; the next Newton step restores the equilibrium.
    Only for the reduced law: with m_tau > 0 gamma is local (coupled_gamma), gamma |u_tau| ~ 1e-2, and
    the re-alignment fought the Newton step (a 3-cycle at a rim vertex of the Mindlin sphere, h = 0.01)."""
    if np.sqrt(point.theta) / point.scale > newton.tol or not newton.problem.law.reduced:
        return None  # m_tau > 0: the local gamma (coupled_gamma) lets Newton turn lambda itself
    return _slip_directions(newton, point, point.lam.copy())


def _slip_directions(newton, point, lam, every: bool = False):
    """``lam`` with u_tau / |u_tau| at disk_alignment's sliding vertices (|q| > 1, |u_tau| > tol max|u|;
    ``every``: at every vertex with |u_tau| > tol max|u|, as the independent check counts sliding)."""
    cb = newton.problem.contact
    moving = cb.magnitude(point.slip) > newton.tol * float(np.max(np.abs(point.u), initial=0.0))
    sliding = moving if every else (cb.magnitude(point.q) > 1.0) & moving
    lam[sliding] = cb.direction(point.slip[sliding])
    return lam


def final_multiplier(newton, point):
    """(lambda, how far it moves the friction force / scale) that ssn returns at a converged 3D point:
    P(lambda), and u_tau / |u_tau| at every vertex with |u_tau| > tol max|u|, so |lambda| <= 1 (2.7) and
    lambda . u_tau = |u_tau| (2.8) hold to rounding; ssn returns it if the move is <= tol, else goes on
    from it.

    The merit weighs C = lambda - P(q) by w p_tau(t) (ssn_point.complementarity_weight), so at a vertex barely
    in contact |lambda| may end above 1 (measured on the Mindlin sphere: 1.0096) or point away from a
    slip of 6e-6 max|u| (lambda . u_tau - |u_tau| = 1.2e-5 max|u|) while the merit is below tol.
    P(lambda) is no farther from lambda than P(q) is, and the sliding vertices' change is
    disk_alignment's miss (a vertex of the stick set that moves by more than tol max|u| -- its state
    changed in the last step -- may move more, hence the measure)."""
    cb = newton.problem.contact
    lam = _slip_directions(newton, point, cb.project(point.lam), every=True)
    move = complementarity_weight(newton, point.t) * cb.magnitude(lam - point.lam)
    return lam, float(np.linalg.norm(move)) / point.scale
