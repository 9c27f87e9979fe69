"""The pieces of one semismooth Newton step (vemkit.solvers.ssn, whose docstring has the maths).

Linear algebra: stiffness diagonals in a direction, rank-one contact blocks, the basis Z that
eliminates the stick constraints (the reduced systems Z^T A Z y = Z^T r are solved by the linear
solver's backend, vemkit.solvers.linear.ReducedSolver). Globalisation: the line search.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

ARMIJO = 1e-4
MIN_STEP = 2.0**-30
MAX_EXPANSION = 64.0  # largest step length tried when the energy still falls steeply after a full step
EXPAND_SLOPE = 0.1  # ... "steeply": the slope at the full step is still this fraction of the initial one


def direction_diagonal(K, cb, direction):
    """d_c^T K_cc d_c at each contact vertex (the stiffness diagonal in direction d)."""
    if cb.dimension == 3:
        return sum(
            direction[:, a] * direction[:, b] * np.asarray(K[cb.dofs[:, a], cb.dofs[:, b]]).ravel()
            for a in range(3)
            for b in range(3)
        )
    i, j = cb.dofs[:, 0], cb.dofs[:, 1]
    Kii = np.asarray(K[i, i]).ravel()
    Kjj = np.asarray(K[j, j]).ravel()
    Kij = np.asarray(K[i, j]).ravel()
    return direction[:, 0] ** 2 * Kii + 2 * direction[:, 0] * direction[:, 1] * Kij + direction[:, 1] ** 2 * Kjj


def tangential_diagonal(K, cb):
    """The stiffness diagonal in the tangent plane: along tau (2D), the mean over t1 and t2 (3D)."""
    return sum(direction_diagonal(K, cb, t) for t in cb.tangents) / len(cb.tangents)


def stick_basis(cb, stick, n):
    """Orthonormal Z (n x (n - (d - 1)|stick|)) spanning {v : t . v_c = 0 for every tangent t of the
    stick vertices c}: v_c = a nu_c there (the column of the vertex's first dof); a held stick vertex
    (``_held``) gets the null space of its constraints on its unprescribed components."""
    first, others = cb.dofs[stick, 0], cb.dofs[stick, 1:]
    held = np.isin(stick, _held(cb, np.isin(np.arange(cb.size), stick)))
    keep = np.ones(n, dtype=bool)
    keep[others.ravel()] = False
    keep[first[held]] = False  # a held stick vertex: its columns are those of held_stick_moves
    column = np.cumsum(keep) - 1
    rows = np.flatnonzero(keep)
    vals = np.ones(rows.size)
    free = ~held
    vals[column[first[free]]] = cb.normal[stick[free], 0]
    rows = np.concatenate([rows, others[free].ravel()])
    cols = np.concatenate([np.arange(vals.size), np.repeat(column[first[free]], others.shape[1])])
    vals = np.concatenate([vals, cb.normal[stick[free], 1:].ravel()])
    width = int(keep.sum())
    for c in stick[held]:  # the null space of the stick constraints on the unprescribed components
        for direction in held_stick_moves(cb, c)[1]:
            rows = np.concatenate([rows, cb.dofs[c]])
            cols = np.concatenate([cols, np.full(cb.dofs.shape[1], width)])
            vals = np.concatenate([vals, direction])
            width += 1
    return sp.csr_matrix((vals, (rows, cols)), shape=(n, width))


HELD_RANK_TOL = 1e-10  # singular values of the stick constraints below this (relative) are a held direction


def held_stick_moves(cb, c, slip=None):
    """A stick vertex ``c`` with prescribed components (a symmetry roller meeting Gamma_C): the stick
    constraints t1 . v = -s1, t2 . v = -s2 on its other components P. Returns (the min-norm move
    v (3,) that meets them, zeros on the prescribed ones, for s = ``slip`` (2,); the (k, 3) null
    space directions, k = |P| - rank). When nu has a component along a held axis (a vertex normal
    averaged over the faces on one side of the plane), the vertex is pinned: v is determined, k = 0."""
    free = ~cb.fixed[c]
    M = np.stack([cb.tangent[c][free], cb.tangent2[c][free]])  # (2, |P|)
    U, sigma, Vt = np.linalg.svd(M)
    rank = int(np.sum(sigma > HELD_RANK_TOL * max(sigma.max(), 1.0)))
    null = np.zeros((Vt.shape[0] - rank, 3))
    null[:, free] = Vt[rank:]
    move = np.zeros(3)
    if slip is not None:
        inverse = Vt[:rank].T @ ((U[:, :rank].T @ -np.asarray(slip, float)) / sigma[:rank])
        move[free] = inverse
    return move, null


def stick_shift(cb, stick_mask, slip, n):
    """The free-dof move that makes u_tau = u_tau^ref at the stick vertices (slip = u_tau - u_tau^ref
    there): -(s1 t1 + s2 t2) (-s tau in 2D), or held_stick_moves' v at a vertex with a prescribed
    component."""
    zero = np.zeros(cb.size)
    shift = cb.scatter(zero, np.where(stick_mask[:, None], -slip, 0.0), n)
    for c in _held(cb, stick_mask):
        shift[cb.dofs[c]] = held_stick_moves(cb, c, slip[c])[0]
    return shift


def stick_multiplier(cb, stick_mask, reaction, scale):
    """The 3D lambda at the stick vertices from ``reaction`` (the free-dof vector of the force left
    for friction; scale = w b): (t1, t2) . reaction / scale, or at a vertex with a prescribed
    component the least-squares lambda of scale (lambda_1 t1 + lambda_2 t2) = reaction on its
    unprescribed components (the held ones' force is the constraint's)."""
    force = cb.tangential_displacement(reaction)
    lam = force[stick_mask] / scale[stick_mask][:, None]
    index = np.flatnonzero(stick_mask)
    for c in _held(cb, stick_mask):
        free = ~cb.fixed[c]
        T = np.stack([cb.tangent[c], cb.tangent2[c]], axis=1)[free]  # (|P|, 2)
        lam[np.searchsorted(index, c)] = np.linalg.lstsq(T, reaction[cb.dofs[c]][free], rcond=None)[0] / scale[c]
    return lam


def _held(cb, stick_mask):
    """The stick vertices with a prescribed component whose stick constraints are solved on the
    unprescribed ones (``held_stick_moves``): in 3D only -- in 2D the one constraint tau . v = 0 is
    the column nu_c of ``stick_basis``, which leaves a roller's held component alone wherever
    tau is along it."""
    if cb.dimension == 2 or cb.fixed is None:
        return np.zeros(0, np.int64)
    return np.flatnonzero(stick_mask & cb.fixed.any(axis=1))


def line_search(point, trial, slope, d0, energy_merit):
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
