"""Cattaneo-Mindlin in steps (issue 21 item 4): a body pressed, then pushed sideways, the slip of
each step counted from the previous one (the incremental friction law, ``slip_reference``).

K. L. Johnson, Contact Mechanics (1985), section 7.1: a sphere pressed by P (Hertz: contact radius
a, p0 = 3P/(2 pi a^2)), then loaded by a tangential force Q < mu P, slips in the annulus c <= r <= a
with c = a (1 - Q/(mu P))^(1/3), and carries the shear traction

    q(r) = mu p0 / a [sqrt(a^2 - r^2) - sqrt(c^2 - r^2) (r < c)].

``loading_in_steps`` runs the steps on problems made by a callable (the platen's tangential
displacement of each step -> DiscreteProblem, the mesh and the law fixed), ``mindlin_measures`` reads
P, Q, a, c and the shear traction off a step on a half body (the plane x = 0 a symmetry plane: the
forces doubled), ``mindlin_run`` the whole loading on the Hertz half sphere (``vemkit.studies.hertz``).
"""

from __future__ import annotations

import copy
import dataclasses
import math
import time
from pathlib import Path

import numpy as np

from vemkit.solvers.dispatch import solve
from vemkit.solvers.solution import contact_state
from vemkit.solvers.verification import verify_solution
from vemkit.studies.hertz import hertz_peak_pressure

STICK_LEVEL = 1.0 - 1e-6  # |lambda| below this: a stick vertex
C_TOLERANCE = 0.05  # issue 21 item 4: the stick radius c within 5 % of Mindlin's


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
        first = dataclasses.replace(problem, law=problem.law.without_friction())
    solution = solve(first, dict(solver))
    steps.append((0.0, first, solution, None, verify_solution(first, solution.u, solution.multiplier, solver["tol"])))
    for shift in shifts:
        reference = problem.contact.tangential_displacement(solution.u)
        problem = problem_at(shift)
        solution = solve(problem, dict(solver), slip_reference=reference, initial=(solution.u, solution.multiplier))
        check = verify_solution(problem, solution.u, solution.multiplier, 10 * solver["tol"], slip_reference=reference)
        steps.append((shift, problem, solution, reference, check))
    return steps


def mindlin_shear(r, a: float, c: float, mu: float, P: float):
    """Johnson's q(r) (module docstring)."""
    r = np.asarray(r, dtype=float)
    p0 = hertz_peak_pressure(P, a)
    outer = np.sqrt(np.maximum(a**2 - r**2, 0.0))
    inner = np.sqrt(np.maximum(c**2 - r**2, 0.0))
    return mu * p0 / a * (outer - inner)


def mindlin_measures(problem, solution, reference, mu: float, axis: int = 2, symmetry: float = 2.0) -> dict:
    """P, Q (along ``axis``), a and c (sqrt(symmetry A / pi) from the nodal weights of the contact and
    stick vertices), Mindlin's c at the measured Q/(mu P) (``c_within``: |c / c_Mindlin - 1| <=
    C_TOLERANCE), and the shear traction against q(r) (its RMS misfit over the contact vertices
    relative to mu p0)."""
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
    return {
        "P": P,
        "Q": Q,
        "Q_over_muP": ratio,
        "a": a,
        "c": c,
        "c_max": float(r[stick].max()) if stick.any() else 0.0,
        "c_mindlin": c_mindlin,
        "err_c": c / c_mindlin - 1.0 if c_mindlin > 0 else float("nan"),
        "c_within": bool(c_mindlin > 0 and abs(c / c_mindlin - 1.0) <= C_TOLERANCE),
        "q_rms_misfit": float(np.sqrt(np.mean((q[on] - q_mindlin[on]) ** 2)) / (mu * hertz_peak_pressure(P, a))),
        "stick_vertices": int(stick.sum()),
        "slip_vertices": int((on & ~stick).sum()),
        "r": r,
        "q": q,
        "on": on,
        "stick": stick,
    }


def mindlin_run(data: dict, h: float, H: float, k: float, mu: float, shifts, solver: dict, folder, **mesh):
    """Cattaneo-Mindlin on the half sphere x >= 0 of the Hertz scene ``data`` (its top pressed down by
    its prescribed u2): step 0 frictionless (Mindlin's setting), then the top moved sideways along z
    by ``shifts``, each step's slip counted from the previous step's u_tau; Coulomb m_tau = m_nu = 1,
    k_tau = mu k_nu. One row (``mindlin_measures`` + sizes, ssn iterations, the independent check at
    10 tol) per tangential step; its profile (r, q, on, stick, coordinates) under "profile"."""
    from vemkit.studies.hertz import R, sphere_msh, sphere_problem

    start = time.perf_counter()
    msh = Path(folder) / f"half_{h:g}_{H:g}.msh"
    if not msh.exists():
        sphere_msh(msh, h, H, half=True, **mesh)
    data = copy.deepcopy(data)
    down = data["boundary"]["dirichlet"]["top"][1]
    data["contact"]["normal"]["m"] = 1.0
    data["contact"]["friction"] = {"k": mu * k * data["material"]["E"] / R, "m": 1.0}

    def problem_at(shift):
        data["boundary"]["dirichlet"] = {"top": [None, down, shift], "sym_x": [0.0, None, None]}
        return sphere_problem(data, msh, k)

    steps = loading_in_steps(problem_at, shifts, solver, frictionless_normal_step=True)
    rows = []
    for shift, problem, solution, reference, check in steps[1:]:
        m = mindlin_measures(problem, solution, reference, mu)
        profile = {key: m.pop(key) for key in ("r", "q", "on", "stick")}
        profile.update(x=problem.contact.coords[:, 0], z=problem.contact.coords[:, 2])
        m.update(
            h=h,
            H=H,
            k=k,
            mu=mu,
            shift=shift,
            cells=int(problem.mesh.n_cells),
            dofs=int(problem.n_dofs),
            iterations=int(solution.iterations),
            normal_step_iterations=int(steps[0][2].iterations),
            check=float(check["worst"]),
            passed=bool(check["passed"]),
            wall=time.perf_counter() - start,
            profile=profile,
        )
        rows.append(m)
    return rows
