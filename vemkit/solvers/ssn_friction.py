"""The semismooth Newton step of vemkit.solvers.ssn: Coulomb friction on the unit ball of R^(d-1).

The complementarity function is C = lambda - P(q), q = lambda + gamma u_tau, with P the projection
onto the unit ball (``vemkit.contact.ball``: [-1, 1] in 2D, the unit disk of the tangent plane in
3D; lambda and u_tau (n_c, d - 1), their components in the vertex basis). Generalized Newton on
C = 0 with the derivative P'(q) = 0 (stick, |q| <= 1) or (I - n n^T)/|q| (slip, n = q/|q|):

- stick A = {|q| <= 1}: u_tau,new = 0 (every tangent; eliminated by Z, v_c = a nu_c), the stick
  multiplier from the tangential equilibrium;
- slip S = {|q| > 1}: lambda_new = base + slope sum_e e (e . du_tau) (``ball_slip_step``, e an
  orthonormal basis of the complement of n in R^(d-1): none in 2D, where lambda_new = n = sign(q);
  one vector in 3D), so the friction force w b (t1, t2) lambda_new adds the symmetric PSD rank-one
  Jacobian w b slope (e1 t1 + e2 t2)(e1 t1 + e2 t2)^T per slip vertex and e: the Newton system
  Z^T (K + J) Z stays SPD (CG with AMG, or direct). This is the semismooth Newton method of the
  primal-dual active set family for 3D Coulomb (Hueber, Stadler, Wohlmuth, SIAM J. Sci. Comput. 30,
  2008), here on the projection form of the complementarity function.

With m_tau > 0 the Jacobian also holds the friction bound's derivative w p_tau'(t) lambda_hat tau nu^T
(unsymmetric; ``_bound_slope``): 2D takes lambda_hat = the new multiplier at a slip vertex (sign(q),
independent of du: the exact derivative) and the current one at a stick vertex; 3D the current
lambda at every frictional vertex (d(b lambda) = b d lambda + lambda b' dt) -- the two measured
choices are kept as they were, bit for bit.

A stick vertex with a prescribed component (a symmetry roller meeting Gamma_C) keeps it exactly when
that component is orthogonal to nu (a symmetry plane crosses Gamma_C at right angles: the extruded
body's end faces, a quarter model's planes), since the column nu_c of Z has no entry there; otherwise
the step moves it and only the converged residual (which holds its row) restores it.
"""

from __future__ import annotations

import functools
import operator

import numpy as np

from vemkit.contact import ball
from vemkit.contact.boundary import rank_one_blocks
from vemkit.solvers.ssn_steps import stick_basis, stick_multiplier, stick_shift

STICK_PENALTY = 1e3  # penalty (times the stiffness diagonal) on stick tangents in a rebuilt hierarchy


def ball_slip_step(q, lam, gamma):
    """The Newton step of C = lambda - P(q) at the slip vertices (|q| > 1, q = lambda + gamma u_tau,
    P the projection on the unit ball): with n = q/|q|, P' = (I - n n^T)/|q|, solving the linearized
    C = 0 for the new multiplier gives

        lambda_new = n + (I - n n^T)(gamma du_tau - lambda) / (|q| - 1),

    so (returned) lambda_new = base + slope sum_e e (e . du_tau): base = n - sum_e (e . lambda) e / (|q| - 1),
    slope = gamma / (|q| - 1), e the orthonormal basis of the complement of n (``ball.perpendiculars``,
    I - n n^T = sum_e e e^T). In 2D there is no e: lambda_new = n = sign(q)."""
    size = ball.norm(q)
    unit = q / size[:, None]
    perpendiculars = ball.perpendiculars(unit)
    excess = size - 1.0
    base = unit
    for e in perpendiculars:
        base = base - (np.sum(e * lam, axis=1) / excess)[:, None] * e
    return base, gamma / excess, perpendiculars


def friction_direction(newton, point, k, sets, solve):
    """(du, lambda_new, linear iterations, active-set changes) of the Newton step at ``point``;
    ``sets``: ssn._active_sets at the point, ``solve``: ssn._solve_newton_system."""
    problem = newton.problem
    K, cb, law, n = problem.stiffness, problem.contact, problem.law, problem.n_dofs
    zero, lam = newton.zero, point.lam
    bound, frictional, slip, stick, changes = sets
    base, slope, perpendiculars = ball_slip_step(point.q[slip], lam[slip], newton.gamma[slip])
    slip_base = np.zeros_like(lam)
    slip_base[slip] = base
    shift = stick_shift(cb, stick, point.slip, n)
    friction_now = cb.scatter(zero, cb.times(cb.weight * bound, lam), n)
    slip_force = cb.scatter(zero, cb.times(cb.weight * bound, slip_base), n)
    Z = stick_basis(cb, np.flatnonzero(stick), n) if np.any(stick) else None

    def penalty():  # for a rebuilt AMG hierarchy: stick tangents nearly clamped
        weight = np.where(stick, STICK_PENALTY * newton.kd_tau, 0.0)
        return functools.reduce(operator.add, [rank_one_blocks(cb, weight, t, n) for t in cb.tangents])

    J = cb.normal_jacobian(point.u, law, newton.stiffness_cap)
    coefficient = np.zeros(cb.size)
    coefficient[slip] = cb.weight[slip] * bound[slip] * slope
    for e in perpendiculars:  # the slip vertices' rank-one blocks along e in space
        J = J + rank_one_blocks(cb, coefficient, _in_space(cb, _at(slip, e)), n)
    # direct: K + J formed as it always was; AMG: K x + J x, no copy of K's values
    A = _bound_slope(newton, point, sets, slip_base, J) if not law.reduced else newton.reduced.operator(K, J)
    rhs = -(point.R - friction_now) - A @ shift - slip_force
    correction, its = solve(newton, point, k, A, Z, rhs, penalty)
    du = shift + correction
    du_tau = cb.tangential_displacement(du)
    lam_new = lam.copy()
    lam_new[slip] = base
    for e in perpendiculars:
        lam_new[slip] += (slope * np.sum(e * du_tau[slip], axis=1))[:, None] * e
    lam_new[stick] = stick_multiplier(cb, stick, rhs - A @ correction, cb.weight * bound)
    slip_new = point.slip + du_tau
    moving = ~frictional & (cb.magnitude(slip_new) > 0.0)
    lam_new[moving] = cb.direction(slip_new[moving])
    return du, lam_new, its, changes


def _at(mask, values):
    """(n_c, k) zeros with ``values`` in the rows of ``mask``."""
    out = np.zeros((mask.size, values.shape[1]))
    out[mask] = values
    return out


def _in_space(cb, tangential):
    """sum_k x_k t_k: tangential components (n_c, d - 1) as vectors in space (n_c, d)."""
    tangents = cb.tangents
    out = tangents[0] * tangential[:, :1]
    for i in range(1, len(tangents)):
        out = out + tangents[i] * tangential[:, i : i + 1]
    return out


def _bound_slope(newton, point, sets, slip_base, J):
    """K + J + the friction bound's derivative w p_tau'(t) lambda_hat tau nu^T (m_tau > 0, module
    docstring), as the backend solves with it."""
    problem = newton.problem
    K, cb, law, n = problem.stiffness, problem.contact, problem.law, problem.n_dofs
    bound, frictional, slip, stick, _ = sets
    if cb.ball.direction_from_projection:  # lambda_hat = sign(q) at slip: the exact derivative; the term added last
        lam_hat = np.where(slip, slip_base[:, 0], np.where(stick, point.lam[:, 0], 0.0))
        bound_slope = cb.weight * law.friction_bound_derivative(point.t) * lam_hat
        return newton.reduced.operator(K, J, rank_one_blocks(cb, bound_slope, cb.tangent, n, cb.normal))
    lam_hat = np.where(frictional[:, None], point.lam, 0.0)  # d(b lambda) = b d lambda + lambda b' dt: lambda now
    along = _in_space(cb, lam_hat)
    J = J + rank_one_blocks(cb, cb.weight * law.friction_bound_derivative(point.t), along, n, cb.normal)
    return newton.reduced.operator(K, J)
