"""An iterate of the semismooth Newton method (vemkit.solvers.ssn) and its measures: the residuals,
the merit theta, the energy of the reduced law and its slope, and the convergence test."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vemkit.contact import ball
from vemkit.solvers.solution import relative_slip, residual_scale
from vemkit.solvers.sparse_ops import abs_matvec

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


def evaluate(newton, u, lam) -> Point:
    """Everything the step and the line search need at (u, lambda)."""
    problem = newton.problem
    K, f, cb, law, n = problem.stiffness, problem.load, problem.contact, problem.law, problem.n_dofs
    zero = newton.zero
    t = cb.normal_displacement(u) - cb.gap
    slip = relative_slip(cb, u, newton.slip_reference)
    Ku = K @ u
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
    """Relative residual <= tol, or at the rounding floor of its own evaluation (ill-conditioned cases)."""
    residual = np.sqrt(point.theta) / point.scale
    if newton.problem.contact.dimension == 3:  # and the slip direction resolved (disk_alignment)
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
