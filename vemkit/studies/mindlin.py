"""Cattaneo-Mindlin in steps (issue 21 item 4): a body pressed, then pushed sideways, the slip of
each step counted from the previous one (the incremental friction law, ``slip_reference``).

K. L. Johnson, Contact Mechanics (1985), section 7.1: a sphere pressed by P (Hertz: contact radius
a, p0 = 3P/(2 pi a^2)), then loaded by a tangential force Q < mu P, slips in the annulus c <= r <= a
with c = a (1 - Q/(mu P))^(1/3), and carries the shear traction

    q(r) = mu p0 / a [sqrt(a^2 - r^2) - sqrt(c^2 - r^2) (r < c)].

``loading_in_steps`` runs the steps on problems made by a callable (the platen's tangential
displacement of each step -> DiscreteProblem, the mesh and the law fixed), ``mindlin_measures`` reads
P, Q, a, c and the shear traction off a step on a half body (the plane x = 0 a symmetry plane: the
forces doubled).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from vemkit.contact.boundary3d import tangent_basis
from vemkit.contact.laws import ContactLaw
from vemkit.solvers.dispatch import solve
from vemkit.solvers.solution import contact_state
from vemkit.solvers.verification import verify_solution

STICK_LEVEL = 1.0 - 1e-6  # |lambda| below this: a stick vertex


def loading_in_steps(problem_at, shifts, solver: dict, *, frictionless_normal_step: bool = False):
    """[(shift, problem, solution, slip_reference, check)] of the normal step (shift 0) and the
    tangential steps ``shifts`` (increasing), each from the previous step's u_tau
    (``problem_at(shift)``: the problem with the platen moved sideways by ``shift``).
    ``frictionless_normal_step``: the normal step without friction (Hertz's frictionless contact;
    Mindlin's theory assumes the normal loading leaves no shear traction)."""
    steps = []
    problem = problem_at(0.0)
    first = problem
    if frictionless_normal_step:
        law = problem.law
        first = dataclasses.replace(problem, law=ContactLaw(law.k_normal, law.m_normal, 0.0, 0.0))
    solution = solve(first, dict(solver))
    steps.append((0.0, first, solution, None, verify_solution(first, solution.u, solution.multiplier, solver["tol"])))
    for shift in shifts:
        reference = problem.contact.tangential_displacement(solution.u)
        problem = problem_at(shift)
        solution = solve(problem, dict(solver), slip_reference=reference, initial=(solution.u, solution.multiplier))
        check = verify_solution(problem, solution.u, solution.multiplier, 10 * solver["tol"], slip_reference=reference)
        steps.append((shift, problem, solution, reference, check))
    return steps


def roller_normals(problem, gap):
    """The problem with the vertex normals of Gamma_C in the symmetry planes where a roller meets it:
    nu's prescribed components set to zero, renormalized, the tangent basis and the gap (``gap``:
    the scene's gap or FoundationLine) rebuilt. The area-weighted normal of a vertex on x = 0 sees
    the faces on one side only and tilts out of the plane; with the roller u1 = 0 a stick vertex is
    then pinned and a sliding one cannot follow its slip direction (the held component's friction
    force is the constraint's), so ssn's slip-direction test stalls there (measured: 4e-4 on the
    Hertz half sphere). The symmetric body's normal lies in the plane. (Its home should be
    vemkit.contact.boundary3d; here until that module is free to edit.)"""
    cb = problem.contact
    if cb.fixed is None:
        return problem
    normal = np.where(cb.fixed, 0.0, cb.normal)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    t1, t2 = tangent_basis(normal)
    contact = dataclasses.replace(cb, normal=normal, tangent=t1, tangent2=t2).with_gap(gap)
    return dataclasses.replace(problem, contact=contact)


def mindlin_shear(r, a: float, c: float, mu: float, P: float):
    """Johnson's q(r) (module docstring)."""
    r = np.asarray(r, dtype=float)
    p0 = 3.0 * P / (2.0 * math.pi * a**2)
    outer = np.sqrt(np.maximum(a**2 - r**2, 0.0))
    inner = np.sqrt(np.maximum(c**2 - r**2, 0.0))
    return mu * p0 / a * (outer - inner)


def mindlin_measures(problem, solution, reference, mu: float, axis: int = 2, symmetry: float = 2.0) -> dict:
    """P, Q (along ``axis``), a and c (sqrt(symmetry A / pi) from the nodal weights of the contact and
    stick vertices), Mindlin's c at the measured Q/(mu P), and the shear traction against q(r)
    (its RMS misfit over the contact vertices relative to mu p0)."""
    cb = problem.contact
    state = contact_state(problem, solution.u, solution.multiplier, slip_reference=reference)
    p = state.normal_pressure
    on = p > 0
    traction = state.tangential_stress[:, :1] * cb.tangent + state.tangential_stress[:, 1:] * cb.tangent2
    P = symmetry * float(np.sum(cb.weight * p))
    Q = symmetry * float(np.sum(cb.weight * traction[:, axis]))
    stick = on & (np.linalg.norm(solution.multiplier, axis=1) < STICK_LEVEL)
    a = math.sqrt(symmetry * float(np.sum(cb.weight[on])) / math.pi)
    c = math.sqrt(symmetry * float(np.sum(cb.weight[stick])) / math.pi)
    ratio = abs(Q) / (mu * P) if P > 0 else float("nan")
    c_mindlin = a * (1.0 - ratio) ** (1.0 / 3.0) if ratio < 1 else 0.0
    r = np.hypot(cb.coords[:, 0], cb.coords[:, axis])
    q = np.abs(traction[:, axis])
    q_mindlin = mindlin_shear(r, a, c_mindlin, mu, P)
    p0 = 3.0 * P / (2.0 * math.pi * a**2)
    return {
        "P": P,
        "Q": Q,
        "Q_over_muP": ratio,
        "a": a,
        "c": c,
        "c_max": float(r[stick].max()) if stick.any() else 0.0,
        "c_mindlin": c_mindlin,
        "err_c": c / c_mindlin - 1.0 if c_mindlin > 0 else float("nan"),
        "q_rms_misfit": float(np.sqrt(np.mean((q[on] - q_mindlin[on]) ** 2)) / (mu * p0)),
        "stick_vertices": int(stick.sum()),
        "slip_vertices": int((on & ~stick).sum()),
        "r": r,
        "q": q,
        "on": on,
        "stick": stick,
    }
