"""Gauss quadrature of the normal-compliance term on Gamma_C (vemkit.contact.boundary) against the nodal rule."""

import numpy as np
import pytest
from conftest import PAPER

from vemkit.contact.laws import ContactLaw
from vemkit.contact.problem import discrete_problem
from vemkit.exceptions import SceneError
from vemkit.mesh.families.square import square
from vemkit.solvers.solution import contact_force_vector
from vemkit.solvers.ssn import solve_ssn
from vemkit.solvers.uzawa import solve_uzawa
from vemkit.solvers.verification import verify_solution
from vemkit.vem.elements.k1_fields import projected_solution
from vemkit.vem.norms import projection_error

TRACTIONS = {"left": lambda x, y: (200 * (5 - y), -200 + 0 * y), "top": lambda x, y: (0 * x, 0 * x)}


def problem(n, quadrature, law=PAPER["law"], points=3, dirichlet=("right",), neumann=None):
    return discrete_problem(
        square(n),
        PAPER["E"],
        PAPER["nu"],
        dirichlet=dirichlet,
        neumann=TRACTIONS if neumann is None else neumann,
        contact=("bottom",),
        gap=lambda x, y: 0.1 + 0 * x,
        law=law,
        contact_quadrature=quadrature,
        contact_gauss_points=points,
    )


def pushed_down(pb, penetration):
    """Free-dof u pushing every free vertex down so that u_nu - g = penetration(x) on the bottom."""
    xy = pb.mesh.vertices[pb.dofs.free_nodes]
    u = np.zeros((xy.shape[0], 2))
    u[:, 1] = -(0.1 + penetration(xy[:, 0]))
    return u.ravel()


@pytest.mark.parametrize("m_normal", [1.0, 2.0])
def test_uniform_penetration_gauss_equals_nodal(m_normal):
    law = ContactLaw(10.0, m_normal, 450.0, 0.0)
    gauss, nodal = (problem(8, q, law, dirichlet=("top",), neumann={}) for q in ("gauss", "nodal"))
    assert gauss.contact.size == 9  # every bottom vertex is free: the penetration is uniform on every edge
    u = pushed_down(gauss, lambda x: 0.05 + 0 * x)
    lam = np.linspace(-1.0, 1.0, gauss.contact.size)
    force = contact_force_vector(gauss, u, lam)
    assert np.max(np.abs(force - contact_force_vector(nodal, u, lam))) <= 1e-14 * np.max(np.abs(force))
    assert np.isclose(-force[1::2].sum(), 10.0 * 0.05**m_normal)  # p_nu |Gamma_C|, |Gamma_C| = 1
    # the Jacobians differ (Gauss couples the two ends of an edge) but agree on a uniform normal motion
    J_gauss = gauss.contact.normal_jacobian(u, law).toarray()
    J_nodal = nodal.contact.normal_jacobian(u, law).toarray()
    uniform = np.tile([0.0, -1.0], gauss.n_dofs // 2)
    assert np.count_nonzero(J_gauss) > np.count_nonzero(J_nodal)
    assert np.allclose(J_gauss @ uniform, J_nodal @ uniform, rtol=0, atol=1e-12 * np.abs(J_nodal).max())


def test_gauss_integrates_a_linear_penetration_exactly_and_differs_from_nodal():
    """m_nu = 2, t = a + b x along the bottom: the integral of k t^2 phi_i is a cubic, exact with 2 points."""
    law = ContactLaw(10.0, 2.0, 450.0, 0.0)
    n, a, b = 4, 0.02, 0.2
    pbs = {q: problem(n, q, law, points=p, dirichlet=("top",), neumann={}) for q, p in (("gauss", 2), ("nodal", 3))}
    u = pushed_down(pbs["gauss"], lambda x: a + b * x)
    force = {q: -contact_force_vector(pb, u, np.zeros(pb.contact.size))[1::2] for q, pb in pbs.items()}
    xy = pbs["gauss"].mesh.vertices[pbs["gauss"].dofs.free_nodes]
    exact = np.zeros(xy.shape[0])
    for i, (x, y) in enumerate(xy):
        if y != 0.0:
            continue
        for left in (x - 1.0 / n, x):  # the two edges at x; Simpson's rule is exact for the cubic k t^2 hat_i
            if 0.0 <= left <= 1.0 - 1.0 / n:
                s = left + np.array([0.0, 0.5, 1.0]) / n
                integrand = 10.0 * (a + b * s) ** 2 * np.maximum(1.0 - np.abs(s - x) * n, 0.0)
                exact[i] += (integrand @ [1.0, 4.0, 1.0]) / (6.0 * n)
    assert np.allclose(force["gauss"], exact, rtol=1e-13, atol=1e-15)
    on_contact = exact > 0
    assert np.max(np.abs(force["nodal"] - exact)[on_contact] / exact[on_contact]) > 1e-2


@pytest.mark.parametrize("law", [ContactLaw(10.0, 2.0, 450.0, 0.0), ContactLaw(1e3, 3.0, 450.0, 1.0)])
def test_gauss_jacobian_is_the_derivative_of_the_force(law, rng):
    pb = problem(6, "gauss", law)  # the bottom-right vertex is clamped: one edge has a fixed end
    cb = pb.contact
    assert np.any(cb.facet_vertex < 0)
    u = pushed_down(pb, lambda x: 0.05 * np.sin(7 * x)) + 0.01 * rng.normal(size=pb.n_dofs)
    v = rng.normal(size=pb.n_dofs)
    J = cb.normal_jacobian(u, law).toarray()
    step = 1e-6
    difference = (cb.normal_force(u + step * v, law) - cb.normal_force(u - step * v, law)) / (2 * step)
    assert np.linalg.norm(J @ v - difference) <= 1e-7 * np.linalg.norm(difference)
    assert np.allclose(J, J.T, atol=1e-12 * np.abs(J).max())
    energy = (cb.normal_energy(u + step * v, law) - cb.normal_energy(u - step * v, law)) / (2 * step)
    assert energy == pytest.approx(cb.normal_force(u, law) @ v, rel=1e-7)


@pytest.mark.parametrize("law", [PAPER["law"], ContactLaw(10.0, 2.0, 700.0, 0.0), ContactLaw(10.0, 1.0, 450.0, 1.0)])
def test_ssn_and_uzawa_agree_with_gauss(law):
    pb = problem(16, "gauss", law)
    newton = solve_ssn(pb, linear="direct", tol=1e-12)
    uzawa = solve_uzawa(pb, linear="direct", stop="both", eps_u=1e-13, eps_lambda=1e-13)
    assert np.linalg.norm(uzawa.u - newton.u) <= 1e-9 * np.linalg.norm(newton.u)
    for solution in (newton, uzawa):
        checks = verify_solution(pb, solution.u, solution.multiplier, tol=1e-8)
        assert checks["passed"], checks
    nodal = solve_ssn(problem(16, "nodal", law), linear="direct", tol=1e-12)
    assert newton.iterations <= nodal.iterations + 1  # the consistent linearization keeps Newton fast
    assert 1e-7 < np.linalg.norm(nodal.u - newton.u) / np.linalg.norm(newton.u) < 1e-3


def test_gauss_keeps_the_order_of_convergence():
    """H1 errors against a 2^-6 reference: ratios ~2 at n = 4, 8, 16, with either quadrature."""

    def vertex_solution(pb):
        return pb.dofs.expand(solve_ssn(pb, linear="direct", tol=1e-12).u)

    for quadrature in ("gauss", "nodal"):
        reference = problem(64, quadrature)
        ref = projected_solution(reference.mesh, vertex_solution(reference))
        errors = []
        for n in (4, 8, 16):
            pb = problem(n, quadrature)
            coarse = projected_solution(pb.mesh, vertex_solution(pb))
            errors.append(projection_error(pb.mesh, coarse, reference.mesh, ref)["h1"])
        ratios = np.array(errors[:-1]) / np.array(errors[1:])
        assert np.all((ratios > 1.8) & (ratios < 2.3)), (quadrature, errors)


def test_gauss_points_are_checked():
    with pytest.raises(SceneError, match="contact_gauss_points"):
        problem(4, "gauss", points=0)
    with pytest.raises(SceneError, match="contact_quadrature"):
        problem(4, "simpson")
    pb = problem(4, "gauss")
    moved = pb.contact.with_gap(lambda x, y: 0.2 + x)
    assert np.allclose(moved.gap, 0.2 + moved.coords[:, 0])
    assert np.allclose(moved.facet_gap, 0.2 + moved.facet_coords[:, :, 0])
    with pytest.raises(ValueError, match="with_gap"):
        import dataclasses

        dataclasses.replace(pb.contact, gap=pb.contact.gap + 1.0)


def test_gauss_keeps_a_roller_vertex_on_gamma_c_with_its_free_component():
    """A roller meets Gamma_C (u_x held at x = 0): its u_y stays in the law, the box is pressed
    uniformly, t = DELTA / (1 + K H / E) everywhere (the gauss rule once read u_y = 0 there)."""
    from test_contact3d_boundary import DELTA, E, H, K, pressed_box

    from vemkit.config.scene import scene_from_dict
    from vemkit.contact.problem import scene_problem
    from vemkit.solvers.dispatch import solve

    data = pressed_box("square", dimension=2)
    data["discretization"].update(contact_quadrature="gauss")
    pb = scene_problem(scene_from_dict(data))
    cb = pb.contact
    assert cb.fixed is not None and np.all(cb.facet_vertex >= 0)
    solution = solve(pb, {"method": "ssn", "tol": 1e-12, "linear": "direct"})
    t = cb.normal_displacement(solution.u) - cb.gap
    assert np.allclose(t, DELTA / (1 + K * H / E), rtol=1e-12, atol=0)
    force = cb.normal_force(solution.u, pb.law)
    assert force[cb.dofs[cb.fixed]].tolist() == [0.0] * int(cb.fixed.sum())  # the constraint takes it
