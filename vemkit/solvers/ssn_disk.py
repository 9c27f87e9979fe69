"""The semismooth Newton step of vemkit.solvers.ssn on a 3D body: Coulomb friction in the unit disk.

The complementarity function is that of 2D, C = lambda - P(q), q = lambda + gamma u_tau, with P the
projection onto the unit disk of the tangent plane (lambda, u_tau: two components in the vertex
basis (t1, t2), ``vemkit.contact.rules``); the contact problem (5.2)-(5.3) with the reduced law
(m_tau = 0 or k_tau = 0, the friction bound b = p_tau independent of u; for m_tau > 0 the Jacobian
also holds w p_tau'(t) (t1, t2) lambda_hat nu^T, lambda_hat the new multiplier's part that does not
depend on du, and is unsymmetric, as in 2D). Generalized Newton on
C = 0 with the derivative P'(q) = 0 (stick, |q| <= 1) or (I - n n^T)/|q| (slip, n = q/|q|):

- stick A = {|q| <= 1}: u_tau,new = 0 (both tangents; eliminated by Z, v_c = a nu_c), the stick
  multiplier from the tangential equilibrium, as in 2D;
- slip S = {|q| > 1}: lambda_new = base + slope e (e . du_tau) (``ssn_steps.disk_slip_step``), so the
  friction force w b (t1, t2) lambda_new adds the symmetric PSD rank-one Jacobian
  w b slope (e1 t1 + e2 t2)(e1 t1 + e2 t2)^T per slip vertex: the Newton system Z^T (K + J) Z stays
  SPD (CG with AMG, or direct). This is the semismooth Newton method of the primal-dual active set
  family for 3D Coulomb (Hueber, Stadler, Wohlmuth, SIAM J. Sci. Comput. 30, 2008), here on the
  projection form of the complementarity function; in 2D, I - n n^T = 0 and it is the 2D step.

A stick vertex with a prescribed component (a symmetry roller meeting Gamma_C) keeps it exactly when
that component is orthogonal to nu (a symmetry plane crosses Gamma_C at right angles: the extruded
body's end faces, a quarter model's planes), since the column nu_c of Z has no entry there; otherwise
the step moves it and only the converged residual (which holds its row) restores it.
"""

from __future__ import annotations

import numpy as np

from vemkit.contact.boundary import rank_one_blocks
from vemkit.solvers.ssn_point import complementarity_weight
from vemkit.solvers.ssn_steps import disk_slip_step, stick_basis, stick_multiplier, stick_shift

STICK_PENALTY = 1e3  # as vemkit.solvers.ssn: penalty on stick tangents in a rebuilt AMG hierarchy
BOUND_FLOOR = 1e-3  # coupled_gamma: a vertex's friction bound counted as at least this times b_ref


def coupled_gamma(kd_tau, weight, bound, b_ref):
    """gamma_c = kd_c / (w_c b_c) for Coulomb's coupled law (m_tau > 0): b_c the vertex's friction
    bound p_tau(t_c) at the start (at least BOUND_FLOOR b_ref; b_ref where it is 0), so gamma |u_tau|
    is the local trial ratio kd |u_tau| / (w b), the natural size of q - lambda at a sliding vertex.

    The global gamma of vemkit.solvers.ssn (0.1 kd / (L_C h b_ref)) is smaller by 0.1 h / L_C and by
    b_c / b_ref: on the Mindlin half sphere (Gamma_C the whole quarter sphere, L_C ~ 1.8, contact radius
    0.1) gamma |u_tau| was ~1e-6 at vertices sliding by 1e-4, so q ~ lambda and the slip direction was
    resolved only by re-aligning lambda, which cycled at h = 0.015 and 0.01 (measured: residual
    4e-6 <-> 1e-8 for 60 iterations). With this gamma: 6 Newton iterations per load step at h = 0.015
    and 0.01, and on the GetFEM box (m_tau = 1) 9-12 instead of 11-27 at 2 187 and 14 739 DOFs."""
    bound = np.where(bound > 0.0, np.maximum(bound, BOUND_FLOOR * b_ref), b_ref)
    return kd_tau / (weight * bound)


def disk_direction(newton, point, k, sets, solve):
    """(du, lambda_new, linear iterations, active-set changes) of the 3D Newton step at ``point``;
    ``sets``: ssn._active_sets at the point, ``solve``: ssn._solve_newton_system."""
    problem = newton.problem
    K, cb, law, n = problem.stiffness, problem.contact, problem.law, problem.n_dofs
    zero, lam = newton.zero, point.lam
    bound, frictional, slip, stick, changes = sets
    base, slope, e = disk_slip_step(point.q[slip], lam[slip], newton.gamma[slip])
    slip_base = np.zeros_like(lam)
    slip_base[slip] = base
    e_full = np.zeros_like(lam)
    e_full[slip] = e
    direction = cb.tangent * e_full[:, :1] + cb.tangent2 * e_full[:, 1:]  # e in space, (n_c, 3)
    coefficient = np.zeros(cb.size)
    coefficient[slip] = cb.weight[slip] * bound[slip] * slope
    shift = stick_shift(cb, stick, point.slip, n)
    friction_now = cb.scatter(zero, cb.times(cb.weight * bound, lam), n)
    slip_force = cb.scatter(zero, cb.times(cb.weight * bound, slip_base), n)
    Z = stick_basis(cb, np.flatnonzero(stick), n) if np.any(stick) else None

    def penalty():  # for a rebuilt AMG hierarchy: stick tangents nearly clamped
        weight = np.where(stick, STICK_PENALTY * newton.kd_tau, 0.0)
        return rank_one_blocks(cb, weight, cb.tangent, n) + rank_one_blocks(cb, weight, cb.tangent2, n)

    J = cb.normal_jacobian(point.u, law, newton.stiffness_cap) + rank_one_blocks(cb, coefficient, direction, n)
    if not law.reduced:  # the friction bound's derivative w p_tau'(t) (t1, t2) lambda_hat nu^T (unsymmetric)
        lam_hat = np.where(frictional[:, None], lam, 0.0)  # d(b lambda) = b d lambda + lambda b' dt: lambda now
        along = cb.tangent * lam_hat[:, :1] + cb.tangent2 * lam_hat[:, 1:]
        J = J + rank_one_blocks(cb, cb.weight * law.friction_bound_derivative(point.t), along, n, cb.normal)
    # direct: K + J formed as it always was; AMG: K x + J x, no copy of K's values
    A = newton.reduced.operator(K, J)
    rhs = -(point.R - friction_now) - A @ shift - slip_force
    correction, its = solve(newton, point, k, A, Z, rhs, penalty)
    du = shift + correction
    du_tau = cb.tangential_displacement(du)
    lam_new = lam.copy()
    lam_new[slip] = base + (slope * np.sum(e * du_tau[slip], axis=1))[:, None] * e
    lam_new[stick] = stick_multiplier(cb, stick, rhs - A @ correction, cb.weight * bound)
    slip_new = point.slip + du_tau
    moving = ~frictional & (cb.magnitude(slip_new) > 0.0)
    lam_new[moving] = cb.direction(slip_new[moving])
    return du, lam_new, its, changes


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
