"""The gauss rule of the normal-compliance term on 3D Gamma_C faces (vemkit.contact.rules, issue 21
item 1): the patch test on hex, tet and Voronoi meshes, exactness on triangles to the stated degree,
the exact Newton linearization, gauss -> nodal under refinement, and both solvers agreeing."""

import dataclasses
from math import factorial

import numpy as np
import pytest
from test_contact3d_boundary import DELTA, NU, E, H, K, pressed_box

from vemkit.config.scene import scene_from_dict
from vemkit.contact.gauss_rules import triangle_rule
from vemkit.contact.laws import ContactLaw
from vemkit.contact.problem import scene_problem
from vemkit.solvers.dispatch import solve
from vemkit.solvers.verification import verify_solution


def gauss_problem(family, n=3, points=3, friction=None):
    data = pressed_box(family, n=n)
    data["discretization"].update(contact_quadrature="gauss", contact_gauss_points=points)
    if friction is not None:  # and the top pulled sideways: part of Gamma_C slides
        data["contact"]["friction"] = friction
        data["boundary"]["dirichlet"]["top"] = [0.004, 0.002, -DELTA]
    return scene_problem(scene_from_dict(data))


def free_rows(cb, vector):
    """(n_c, 3) a free-dof vector at the contact points, 0 in their prescribed components."""
    out = vector[cb.dofs]
    return out if cb.fixed is None else np.where(cb.fixed, 0.0, out)


@pytest.mark.parametrize("family", ["hex", "tet", "voronoi"])
@pytest.mark.parametrize("method", ["ssn", "uzawa"])
def test_a_uniformly_pressed_box_gets_the_exact_force_and_the_nodal_vertex_forces(family, method):
    """Rollers meet Gamma_C (they stay contact points with their normal component free)."""
    problem = gauss_problem(family)
    cb = problem.contact
    assert cb.fixed is not None and cb.fixed.any() and np.all(cb.facet_vertex >= 0)
    solution = solve(problem, {"method": method, "tol": 1e-12, "linear": "direct"})
    t = cb.normal_displacement(solution.u) - cb.gap
    exact = DELTA / (1 + K * H / E)
    assert np.allclose(t, exact, rtol=1e-9 if method == "uzawa" else 1e-12, atol=0)
    force = -free_rows(cb, cb.normal_force(solution.u, problem.law))[:, 2]
    assert force.sum() == pytest.approx(K * exact, rel=1e-9 if method == "uzawa" else 1e-13)
    # the patch test: every vertex gets K t w_i, the nodal rule's force (the fan's apex values)
    assert np.allclose(force, K * t * cb.weight, rtol=1e-9, atol=0)
    assert verify_solution(problem, solution.u, solution.multiplier)["worst"] < 1e-9


def _monomial_integral(exponents):
    """int_T lambda^alpha / |T| = 2 alpha! / (|alpha| + 2)!."""
    return 2.0 * np.prod([factorial(a) for a in exponents]) / factorial(sum(exponents) + 2)


def exact_triangle_force(t_corners, power, k):
    """int_T k t^power lambda_a / |T| for t = sum_i t_i lambda_i, by the multinomial expansion."""
    out = np.zeros(3)
    for i in range(power + 1):
        for j in range(power + 1 - i):
            c = power - i - j
            coefficient = factorial(power) / (factorial(i) * factorial(j) * factorial(c))
            term = coefficient * t_corners[0] ** i * t_corners[1] ** j * t_corners[2] ** c
            for a in range(3):
                exponents = [i, j, c]
                exponents[a] += 1
                out[a] += term * _monomial_integral(exponents)
    return k * out


@pytest.mark.parametrize("points, degree", [(1, 1), (2, 3), (3, 5), (4, 7)])
def test_the_rule_on_a_triangle_is_exact_to_its_degree(points, degree):
    rule = triangle_rule(points)
    assert np.all(rule[1] > 0) and np.isclose(rule[1].sum(), 1.0)
    for power in (degree - 1, degree):  # the integrand t^power lambda_a has degree power + 1
        t = np.array([0.3, 1.1, 0.7])
        value = rule[1] @ ((rule[0] @ t)[:, None] ** power * rule[0])
        error = np.max(np.abs(value - exact_triangle_force(t, power, 1.0)))
        assert (error < 1e-14) if power + 1 <= degree else (error > 1e-8), (points, power, error)


@pytest.mark.parametrize("points", [2, 3])
def test_gauss_integrates_a_polynomial_penetration_on_tetrahedra_exactly(points, rng):
    """t linear on Gamma_C (u_z random, every t > 0), p = k t^m with m = 2N - 2: int p phi_a is of
    degree 2N - 1, integrated exactly on every triangle; the nodal rule is not."""
    power = 2 * points - 2
    law = ContactLaw(K, float(power), 0.0, 0.0)
    problem = gauss_problem("tet", n=3, points=points)
    cb = problem.contact
    u = np.zeros(problem.n_dofs)
    u[cb.dofs[:, 2]] = -(0.01 + 0.02 * rng.random(cb.size))  # t = -u_z - 0 > 0 (nu = -e_z, g = 0)
    u[cb.dofs[cb.fixed[:, 0], 0]] = u[cb.dofs[cb.fixed[:, 1], 1]] = 0.0
    force = -free_rows(cb, cb.normal_force(u, law))[:, 2]
    t = cb.normal_displacement(u) - cb.gap
    area = np.einsum("fq->f", cb.gauss_weight)
    exact = np.zeros(cb.size)
    for f in range(cb.facet_vertex.shape[0]):
        corners = cb.facet_vertex[f]
        np.add.at(exact, corners, area[f] * exact_triangle_force(t[corners], power, K))
    assert np.allclose(force, exact, rtol=1e-13, atol=0)
    nodal = cb.weight * law.normal_pressure(t)
    assert np.max(np.abs(nodal - exact) / exact) > 1e-3


@pytest.mark.parametrize("family", ["hex", "tet", "voronoi"])
def test_the_gauss_jacobian_is_the_derivative_of_the_force(family, rng):
    law = ContactLaw(K, 1.5, 0.0, 0.0)
    problem = gauss_problem(family, points=2)
    cb = problem.contact
    u = 0.01 * rng.normal(size=problem.n_dofs)  # some Gauss points in contact, some not
    t = np.einsum("fq->", cb.gauss_weight * (cb._gauss_penetration(u) > 0))
    assert 0.1 < t / cb.gauss_weight.sum() < 0.9
    v = rng.normal(size=problem.n_dofs)
    J = cb.normal_jacobian(u, law).toarray()
    step = 1e-7
    difference = (cb.normal_force(u + step * v, law) - cb.normal_force(u - step * v, law)) / (2 * step)
    assert np.linalg.norm(J @ v - difference) <= 1e-6 * np.linalg.norm(difference)
    assert np.allclose(J, J.T, atol=1e-12 * np.abs(J).max())
    energy = (cb.normal_energy(u + step * v, law) - cb.normal_energy(u - step * v, law)) / (2 * step)
    assert energy == pytest.approx(cb.normal_force(u, law) @ v, rel=1e-6)


CURVED_GAP = {"gap": "0.004 + 0.05*((x - 0.4)**2 + (y - 0.6)**2)"}


def test_gauss_tends_to_nodal_on_a_curved_gap():
    """A flat Gamma_C against a paraboloid gap: part of it in contact, the rules differ by O(h^2)
    (measured on hex 1.0e-2, 3.6e-3, 9.9e-4 at n = 2, 4, 8)."""

    def displacement(n, quadrature):
        data = pressed_box("hex", n=n)
        data["contact"] = dict({k: v for k, v in data["contact"].items() if k != "foundation"}, **CURVED_GAP)
        data["discretization"].update(contact_quadrature=quadrature)
        problem = scene_problem(scene_from_dict(data))
        return problem, solve(problem, {"method": "ssn", "tol": 1e-12, "linear": "direct"}).u

    differences = []
    for n in (2, 4, 8):
        problem, gauss = displacement(n, "gauss")
        _, nodal = displacement(n, "nodal")
        t = problem.contact.normal_displacement(gauss) - problem.contact.gap
        assert 0 < np.sum(t > 0) < t.size
        differences.append(np.linalg.norm(gauss - nodal) / np.linalg.norm(gauss))
    ratios = np.array(differences[:-1]) / np.array(differences[1:])
    assert np.all(ratios > 2.5), differences


def bent_box_problem(n: int, quadrature: str):
    """Tetrahedra of a box whose bottom is bent into the paraboloid z = 0.2 ((x - 0.5)^2 + (y - 0.45)^2) (its
    vertices moved, z -> z + (1 - z / H) 0.2 r^2), its top pushed down onto the plane z = 0."""
    data = {
        "model": "3d",
        "domain": {"box": [[0, 0, 0], [1, 1, H]]},
        "material": {"E": E, "nu": NU},
        "boundary": {"dirichlet": {"top": [0.0, 0.0, -DELTA]}, "contact": ["bottom"]},
        "contact": {
            "foundation": {"point": [0, 0, 0], "normal": [0, 0, 1]},
            "normal": {"k": 1000.0, "m": 1.0},
            "friction": {"k": 0.0, "m": 0.0},
        },
        "discretization": {"mesh": {"family": "tet", "n": n, "kind": "structured"}, "contact_quadrature": quadrature},
    }
    scene = scene_from_dict(data)
    mesh = scene_problem(scene).mesh
    x, y, z = mesh.vertices.T
    bent = np.stack([x, y, z + (1 - z / H) * 0.2 * ((x - 0.5) ** 2 + (y - 0.45) ** 2)], axis=1)
    return scene_problem(scene, dataclasses.replace(mesh, vertices=bent))


def test_gauss_tends_to_nodal_on_a_curved_gamma_c():
    """Tetrahedra, Gamma_C a faceted paraboloid (vertex normals are not face normals): the rules
    differ by about O(h^2) (measured 1.5e-2, 4.7e-3, 1.3e-3 at n = 4, 8, 16)."""
    differences = []
    for n in (4, 8, 16):
        gauss, nodal = (bent_box_problem(n, q) for q in ("gauss", "nodal"))
        u = [solve(pb, {"method": "ssn", "tol": 1e-12, "linear": "direct"}).u for pb in (gauss, nodal)]
        t = nodal.contact.normal_displacement(u[1]) - nodal.contact.gap
        assert 0 < np.sum(t > 0) < t.size / 4  # a contact patch
        differences.append(np.linalg.norm(u[0] - u[1]) / np.linalg.norm(u[1]))
    ratios = np.array(differences[:-1]) / np.array(differences[1:])
    assert np.all(ratios > 2.8), differences


@pytest.mark.parametrize("family", ["tet", "voronoi"])
def test_ssn_and_uzawa_agree_with_gauss_and_friction(family):
    problem = gauss_problem(family, friction={"k": 2.0, "m": 0.0})
    newton = solve(problem, {"method": "ssn", "tol": 1e-12, "linear": "direct"})
    uzawa = solve(problem, {"method": "uzawa", "tol": 1e-13, "linear": "direct"})
    lam = np.linalg.norm(newton.multiplier, axis=1)
    assert np.any(lam > 1 - 1e-12) and np.any(lam < 1 - 1e-3)  # sliding and sticking vertices
    assert np.linalg.norm(uzawa.u - newton.u) <= 1e-8 * np.linalg.norm(newton.u)
    for solution in (newton, uzawa):
        assert verify_solution(problem, solution.u, solution.multiplier)["worst"] < 1e-8
