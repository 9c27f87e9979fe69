"""Contact solvers: Uzawa (the paper's Steps 1-3) and semismooth Newton solve the same discrete problem."""

from __future__ import annotations

import functools
import itertools

import numpy as np
import pytest
import scipy.sparse.linalg as spla
from conftest import FAMILY_CASES, family_mesh, paper_problem

from vemkit.contact.laws import ContactLaw
from vemkit.contact.problem import discrete_problem
from vemkit.exceptions import ConvergenceError
from vemkit.mesh.families.square import square
from vemkit.mesh.mesh import Mesh
from vemkit.solvers.solution import (
    SEPARATED,
    SLIP,
    STICK,
    contact_residual,
    contact_state,
)
from vemkit.solvers.ssn import solve_ssn
from vemkit.solvers.uzawa import solve_uzawa

PAPER_LAW = ContactLaw(10.0, 1.0, 450.0, 0.0)
TIGHT_UZAWA = dict(stop="both", eps_u=1e-13, eps_lambda=1e-13)


def _paper_tractions(scale):
    return {
        "left": lambda x, y: (scale * 200 * (5 - y), -scale * 200 + 0 * y),
        "top": lambda x, y: (0 * x, 0 * x),
    }


@functools.cache
def scene(n, law=PAPER_LAW, gap=0.1, E=2000.0, traction_scale=1.0):
    """The paper's scene (docs/reference/mathematics.md) on square(n), with optional changes of law, gap and E."""
    return discrete_problem(
        square(n),
        E,
        0.4,
        dirichlet=("right",),
        neumann=_paper_tractions(traction_scale),
        contact=("bottom",),
        gap=lambda x, y: gap + 0 * x,
        law=law,
        stabilization="dofi-2mu",
    )


@functools.cache
def contact_elsewhere(part):
    """Contact on the top edge (pushed up) or on the left edge (pushed left), right edge clamped."""
    if part == "top":
        neumann = {"left": lambda x, y: (200 * (5 - y), 400 + 0 * y), "bottom": lambda x, y: (0 * x, 0 * x)}
    else:
        neumann = {"top": lambda x, y: (-2000 + 0 * x, -200 + 0 * x), "bottom": lambda x, y: (0 * x, 0 * x)}
    return discrete_problem(
        square(16),
        2000.0,
        0.4,
        dirichlet=("right",),
        neumann=neumann,
        contact=(part,),
        gap=lambda x, y: 0.1 + 0 * x,
        law=PAPER_LAW,
        stabilization="dofi-2mu",
    )


_SSN_RESULTS = {}


def ssn(problem, linear="direct", tol=1e-12):
    """solve_ssn, remembered per (cached) problem and options."""
    key = (id(problem), linear, tol)
    if key not in _SSN_RESULTS:
        _SSN_RESULTS[key] = solve_ssn(problem, linear=linear, tol=tol)
    return _SSN_RESULTS[key]


def relative_difference(a, b):
    return np.max(np.abs(a.u - b.u)) / np.max(np.abs(b.u))


def assert_coulomb(problem, solution, slip_tol=1e-8):
    """(2.6)-(2.9) vertexwise, from the derived quantities of contact_state."""
    state = contact_state(problem, solution.u, solution.multiplier, tol=slip_tol)
    # tangential quantities are (n_c, d - 1): the one component of a plane body
    bound, stress, slip = state.friction_bound, state.tangential_stress[:, 0], state.slip[:, 0]
    scale = np.max(np.abs(solution.u))
    assert np.all(state.normal_pressure >= 0.0)
    assert np.allclose(state.normal_pressure, problem.law.normal_pressure(state.penetration))
    assert np.all(np.abs(stress) <= bound * (1 + 1e-12))  # |sigma_tau| <= p_tau (2.7)
    moving = np.abs(slip) > slip_tol * scale
    # slip opposes the tangential stress at the bound (2.8)
    assert np.allclose(stress[moving], -bound[moving] * np.sign(slip[moving]), rtol=1e-8, atol=0)
    # below the bound the vertex sticks (2.9)
    below = np.abs(stress) < bound * (1 - 1e-6)
    assert np.all(np.abs(slip[below]) <= slip_tol * scale)
    assert np.all((state.state == SEPARATED) == (state.penetration <= 0))
    assert np.all(state.state[state.penetration > 0] == np.where(moving, SLIP, STICK)[state.penetration > 0])
    return state


# (a) the two solvers give the same discrete solution ----------------------------------------------
@pytest.mark.parametrize("n", [4, 8, 16, 32, 64])
def test_uzawa_and_ssn_agree_on_paper_scene(n):
    pb = scene(n)
    newton = ssn(pb)
    uzawa = solve_uzawa(pb, linear="direct", **TIGHT_UZAWA)
    assert relative_difference(uzawa, newton) <= 1e-8
    assert np.max(np.abs(uzawa.multiplier - newton.multiplier)) <= 1e-8
    default = solve_uzawa(pb, linear="direct")  # the paper's stopping rule ("either")
    assert default.converged and default.iterations < uzawa.iterations + 1
    assert relative_difference(default, newton) <= 1e-4  # stopped on |Δλ| = 0: one lagged step short


def test_uzawa_default_rho_is_mesh_independent():
    rhos = [solve_uzawa(scene(n), linear="direct").info["rho"] for n in (8, 32, 64)]
    assert max(rhos) / min(rhos) < 1.05


def test_uzawa_with_amg_matches_direct():
    pb = scene(32)
    amg = solve_uzawa(pb, linear="amg", **TIGHT_UZAWA)
    assert amg.info["linear"] == "amg"
    assert relative_difference(amg, ssn(pb)) <= 1e-8


# (b) the discrete conditions and Coulomb's law hold at the solution --------------------------------
@pytest.mark.parametrize("k_friction", [450.0, 700.0])  # all slip / stick and slip
def test_contact_conditions_hold(k_friction):
    pb = scene(32, law=ContactLaw(10.0, 1.0, k_friction, 0.0))
    for solution in (ssn(pb), solve_uzawa(pb, linear="direct", **TIGHT_UZAWA)):
        assert contact_residual(pb, solution.u, solution.multiplier)["worst"] <= 1e-9
        state = assert_coulomb(pb, solution)
        counts = state.count()
        assert counts["slip"] > 0 and (counts["stick"] > 0) == (k_friction == 700.0)


def test_contact_residual_flags_violations():
    pb = scene(16)
    good = ssn(pb)
    assert contact_residual(pb, good.u, good.multiplier)["worst"] <= 1e-10
    assert contact_residual(pb, good.u, 1.5 * good.multiplier)["multiplier_bound"] == pytest.approx(0.5)
    assert contact_residual(pb, good.u, -good.multiplier)["complementarity"] > 0.1
    assert contact_residual(pb, 1.01 * good.u, good.multiplier)["equilibrium"] > 1e-3
    assert contact_residual(pb, np.full_like(good.u, np.nan), good.multiplier)["worst"] == np.inf


# (c) no contact force at the plain linear solution: nothing to iterate ----------------------------
@pytest.mark.parametrize(
    "law, gap",
    [
        (ContactLaw(10.0, 1.0, 0.0, 0.0), 10.0),  # frictionless, never closing
        (ContactLaw(10.0, 1.0, 450.0, 1.0), 10.0),  # friction bound p_tau(u_nu - g) = 0 without contact
        (ContactLaw(0.0, 1.0, 0.0, 0.0), 0.1),  # no foundation at all
    ],
)
def test_no_contact_force_gives_plain_linear_solution(law, gap):
    pb = scene(16, law=law, gap=gap)
    plain = spla.spsolve(pb.stiffness.tocsc(), pb.load)
    for solution in (solve_ssn(pb, linear="direct"), solve_uzawa(pb, linear="direct")):
        assert solution.iterations == 0
        assert np.max(np.abs(solution.u - plain)) <= 1e-12 * np.max(np.abs(plain))
        assert contact_residual(pb, solution.u, solution.multiplier)["worst"] <= 1e-12


def test_reduced_law_rubs_without_contact():
    """m_tau = 0: the friction bound k_tau acts even across an open gap, so this is no linear solve."""
    pb = scene(16, gap=10.0)
    newton = ssn(pb)
    assert newton.iterations > 0
    assert relative_difference(solve_uzawa(pb, linear="direct", **TIGHT_UZAWA), newton) <= 1e-8
    assert np.all(contact_state(pb, newton.u, newton.multiplier).state == SEPARATED)


# (d) a stiff foundation: the lagged normal compliance of Uzawa fails, Newton does not --------------
def test_uzawa_fails_on_stiff_foundation_and_ssn_solves_it():
    pb = scene(16, law=ContactLaw(1e6, 1.0, 450.0, 0.0))
    with pytest.raises(ConvergenceError) as failure:
        solve_uzawa(pb, linear="direct")
    message = str(failure.value)
    assert "\n" not in message and "contact.normal.k" in message and "ssn" in message
    newton = ssn(pb)
    assert contact_residual(pb, newton.u, newton.multiplier)["worst"] <= 1e-9
    assert_coulomb(pb, newton)


# (e) the full quasi-variational law m_tau > 0, and other exponents --------------------------------------------------------
@pytest.mark.parametrize(
    "law",
    [
        ContactLaw(10.0, 1.0, 450.0, 1.0),
        ContactLaw(10.0, 2.0, 450.0, 2.0),
        ContactLaw(10.0, 1.0, 450.0, 0.5),
        ContactLaw(10.0, 1.0, 0.0, 0.0),  # frictionless, penetrating
        ContactLaw(10.0, 0.5, 450.0, 0.0),  # p_nu' unbounded at 0
    ],
)
def test_other_laws(law):
    pb = scene(16, law=law)
    newton = ssn(pb)
    uzawa = solve_uzawa(pb, linear="direct", **TIGHT_UZAWA)
    assert relative_difference(uzawa, newton) <= 1e-8
    assert newton.iterations <= 5  # joint Newton, friction-bound derivative included for m_tau > 0
    assert_coulomb(pb, newton)


# (f) contact on another part of the boundary ---------------------------------------------------------
@pytest.mark.parametrize("part, normal", [("top", (0.0, 1.0)), ("left", (-1.0, 0.0))])
def test_contact_on_other_parts(part, normal):
    pb = contact_elsewhere(part)
    cb = pb.contact
    assert np.allclose(cb.normal, normal) and np.allclose(cb.tangent, [-normal[1], normal[0]])
    newton = ssn(pb)
    uzawa = solve_uzawa(pb, linear="direct", **TIGHT_UZAWA)
    assert relative_difference(uzawa, newton) <= 1e-8
    state = assert_coulomb(pb, newton)
    assert state.count()["slip"] > 0  # the load pushes the body into the foundation


def test_rotated_scene_gives_rotated_solution():
    """Normals and tangents off the axes (stick elimination in a rotated basis): the solution rotates."""
    c, s = np.cos(0.5), np.sin(0.5)
    R = np.array([[c, -s], [s, c]])
    base = square(8)
    rotated_mesh = Mesh(base.vertices @ R.T, base.cell_offsets, base.cell_vertices, base.boundary, base.meta)

    def rotated(traction):
        def load(x, y):
            original = np.stack([x, y], axis=-1) @ R  # R^T (x, y)
            t1, t2 = traction(original[..., 0], original[..., 1])
            out = np.stack(np.broadcast_arrays(t1, t2), axis=-1) @ R.T
            return out[..., 0], out[..., 1]

        return load

    law = ContactLaw(10.0, 1.0, 700.0, 0.0)  # stick and slip vertices
    pb = discrete_problem(
        rotated_mesh,
        2000.0,
        0.4,
        dirichlet=("right",),
        neumann={name: rotated(t) for name, t in _paper_tractions(1.0).items()},
        contact=("bottom",),
        gap=lambda x, y: 0.1 + 0 * x,
        law=law,
        stabilization="dofi-2mu",
    )
    assert np.allclose(pb.contact.normal, [s, -c])
    reference = ssn(scene(8, law=law))
    for solution in (ssn(pb), solve_uzawa(pb, linear="direct", **TIGHT_UZAWA)):
        u = solution.u.reshape(-1, 2)
        expected = reference.u.reshape(-1, 2) @ R.T
        assert np.max(np.abs(u - expected)) <= 1e-8 * np.max(np.abs(expected))
        assert np.allclose(solution.multiplier, reference.multiplier, atol=1e-8)
    assert contact_state(pb, ssn(pb).u, ssn(pb).multiplier).count()["stick"] > 0


# (g) Newton iterations: few and mesh independent -------------------------------------------------------
@pytest.mark.parametrize("k_friction", [450.0, 700.0, 1000.0])  # all slip, stick and slip, all stick
def test_ssn_iterations_are_few_and_mesh_independent(k_friction):
    law = ContactLaw(10.0, 1.0, k_friction, 0.0)
    iterations = {n: ssn(scene(n, law=law), tol=1e-10).iterations for n in (4, 8, 16, 32, 64)}
    assert max(iterations.values()) <= 15
    assert iterations[64] <= iterations[4] + 5  # measured: 1 -> 2, 4 -> 8, 3 -> 3


def test_ssn_with_amg_at_h_2_6():
    amg = solve_ssn(scene(64), linear="amg")
    assert amg.info["linear"] == "amg" and amg.iterations <= 15
    assert relative_difference(amg, ssn(scene(64))) <= 1e-8
    assert len(amg.history["residual"]) == amg.iterations
    assert amg.linear_iterations > np.sum(amg.history["linear_iterations"])  # plus the first linear solve


# (h) extreme parameters, from u = 0 ---------------------------------------------------------------------
EXTREME_LAWS = [
    ContactLaw(k_normal, m_normal, k_friction, 0.0)
    for k_normal, k_friction, m_normal in itertools.product((1e-3, 1e8), (0.0, 1e6), (1.0, 2.0, 3.0))
]


@pytest.mark.parametrize("gap", [0.0, 10.0])
@pytest.mark.parametrize(
    "law", EXTREME_LAWS, ids=lambda law: f"kn{law.k_normal:g}-kt{law.k_friction:g}-mn{law.m_normal:g}"
)
def test_ssn_extreme_laws(law, gap):
    pb = scene(8, law=law, gap=gap)
    solution = ssn(pb, tol=1e-10)
    assert solution.iterations <= 50
    assert contact_residual(pb, solution.u, solution.multiplier)["worst"] <= 1e-8


@pytest.mark.parametrize("traction_scale", ["with E", 1.0])
@pytest.mark.parametrize("E_scale", [1e-6, 1e6])
@pytest.mark.parametrize("m_normal", [1.0, 2.0, 3.0])
def test_ssn_extreme_young_modulus(E_scale, traction_scale, m_normal):
    scale = E_scale if traction_scale == "with E" else 1.0
    law = ContactLaw(10.0, m_normal, 450.0, 0.0)
    pb = scene(8, law=law, E=2000.0 * E_scale, traction_scale=scale)
    solution = ssn(pb, tol=1e-10)
    assert contact_residual(pb, solution.u, solution.multiplier)["worst"] <= 1e-8


def test_ssn_with_amg_on_a_stiff_contact():
    pb = scene(32, law=ContactLaw(1e8, 1.0, 1e6, 0.0), gap=0.0)
    solution = solve_ssn(pb, linear="amg")
    assert contact_residual(pb, solution.u, solution.multiplier)["worst"] <= 1e-8


# (i) failures raise, never return NaN ---------------------------------------------------------------------
def test_failures_raise_one_line_errors():
    pb = scene(16, law=ContactLaw(10.0, 1.0, 700.0, 0.0))
    cases = [
        (lambda: solve_ssn(pb, linear="direct", max_iterations=2), "ssn"),
        (lambda: solve_uzawa(pb, linear="direct", max_iterations=5), "uzawa"),
        (lambda: solve_uzawa(pb, linear="direct", rho=1.0), "solver.rho"),
        (lambda: solve_uzawa(scene(8), linear="direct", rho=1.0, max_iterations=3), "solver.stop=both"),
    ]
    for run, expected in cases:
        with pytest.raises(ConvergenceError) as failure:
            run()
        assert expected in str(failure.value) and "\n" not in str(failure.value)


def test_history_is_finite():
    for solution in (ssn(scene(16)), solve_uzawa(scene(16), linear="direct")):
        assert solution.history and all(np.all(np.isfinite(v)) for v in solution.history.values())
        assert np.all(np.isfinite(solution.u)) and np.all(np.abs(solution.multiplier) <= 1.0)


def test_prebuilt_linear_solver_is_reused_with_identical_results():
    """A sweep over contact parameters shares K: one factorization serves every solve."""
    import dataclasses

    from vemkit.solvers.linear import linear_solver

    pb = scene(8)
    prebuilt = linear_solver(pb.stiffness, "direct", pb.near_nullspace)
    for law in (ContactLaw(10.0, 1.0, 450.0, 0.0), ContactLaw(100.0, 2.0, 50.0, 0.0)):
        other = dataclasses.replace(pb, law=law)
        fresh = solve_ssn(other, linear="direct")
        reused = solve_ssn(other, linear=prebuilt)
        assert np.array_equal(fresh.u, reused.u)
        uzawa = functools.partial(solve_uzawa, other, stop="both")
        assert np.array_equal(uzawa(linear="direct").u, uzawa(linear=prebuilt).u)
    with pytest.raises(ValueError, match="another stiffness"):
        solve_ssn(scene(4), linear=prebuilt)


# (j) tol means what it says: a stop rule that fires early is refused until the residual meets tol ---------
@pytest.mark.parametrize("family", list(FAMILY_CASES))
def test_uzawa_and_ssn_agree_at_tol_on_every_family(family):
    pb = paper_problem(family_mesh(family, 32))
    newton = solve_ssn(pb, linear="direct", tol=1e-12)
    uzawa = solve_uzawa(pb, linear="direct", tol=1e-12)  # the paper's "either" rule, default eps
    assert np.linalg.norm(uzawa.u - newton.u) <= 1e-10 * np.linalg.norm(newton.u)
    refused = uzawa.history["stop_refused"]
    # the |Δλ| test fires once every vertex slips, a lagged normal-compliance step before u settles
    assert refused.sum() >= 1 and refused[-1] == 0.0 and uzawa.info["first_stop_refused"] < uzawa.iterations
    assert uzawa.info["residual"]["worst"] <= 1e-10


def test_uzawa_with_amg_meets_tol_too():
    pb = scene(32)
    uzawa = solve_uzawa(pb, linear="amg", tol=1e-12)
    assert uzawa.info["linear"] == "amg" and uzawa.history["stop_refused"].sum() >= 1
    assert relative_difference(uzawa, ssn(pb)) <= 1e-10
