"""The contact boundary of a 3D body (docs/reference/files.md, issue 21 item 1) and the partial-Dirichlet rule in 2D.

The nodal weights are int_F Pi^F phi_i over the Gamma_C faces: they sum to the area, and on the
bottom of a prism over a 2D mesh they are the 2D trapezoid weight times the trapezoid across the
layer. Normals and the (t1, t2) basis follow the documented rule. A vertex with some components
prescribed (a roller meeting Gamma_C) stays a contact point: a box pressed on a plane through
rollers gives the exact total force k t |Gamma_C| with the closed-form penetration, in 2D and 3D.
"""

from __future__ import annotations

import numpy as np
import pytest

from vemkit.config.scene import scene_from_dict
from vemkit.contact.problem import scene_problem
from vemkit.contact.rules import tangent_basis
from vemkit.solvers.dispatch import solve
from vemkit.solvers.verification import verify_solution

E, NU, H, K, DELTA = 1000.0, 0.3, 0.5, 200.0, 0.01


def pressed_box(family: str, n: int = 3, dimension: int = 3, foundation: bool = True) -> dict:
    """A box (square) on the plane z = 0 (y = 0), its top moved down by DELTA, rollers on x = 0
    (and y = 0): uniaxial compression, penetration t = DELTA / (1 + K H / E) (3D; 2D plane stress
    the same), total contact force K t |Gamma_C|."""
    if dimension == 3:
        contact = {"foundation": {"point": [0, 0, 0], "normal": [0, 0, 1]}} if foundation else {"gap": "0*x*y*z"}
        return {
            "model": "3d",
            "domain": {"box": [[0, 0, 0], [1, 1, H]]},
            "material": {"E": E, "nu": NU},
            "boundary": {
                "dirichlet": {"top": [None, None, -DELTA], "left": [0.0, None, None], "front": [None, 0.0, None]},
                "contact": ["bottom"],
            },
            "contact": dict(contact, normal={"k": K, "m": 1.0}, friction={"k": 0.0, "m": 0.0}),
            "discretization": {"mesh": {"family": family, "n": n}},
        }
    return {
        "domain": {"polygon": [[0, 0], [1, 0], [1, H], [0, H]], "sides": ["bottom", "right", "top", "left"]},
        "material": {"E": E, "nu": NU},
        "boundary": {"dirichlet": {"top": [None, -DELTA], "left": [0.0, None]}, "contact": ["bottom"]},
        "contact": {
            "foundation": {"point": [0, 0], "normal": [0, 1]},
            "normal": {"k": K, "m": 1.0},
            "friction": {"k": 0.0, "m": 0.0},
        },
        "discretization": {"mesh": {"family": family, "n": 2 * n}},
    }


@pytest.mark.parametrize("family", ["hex", "voronoi"])
def test_nodal_weights_normals_and_tangent_basis_on_a_box(family):
    cb = scene_problem(scene_from_dict(pressed_box(family))).contact
    assert np.isclose(cb.weight.sum(), 1.0, rtol=1e-13, atol=0) and np.all(cb.weight > 0)
    assert np.allclose(cb.normal, [0.0, 0.0, -1.0]) and np.allclose(cb.coords[:, 2], 0.0)
    frame = np.stack([cb.tangent, cb.tangent2, cb.normal], axis=1)  # (n_c, 3, 3) rows t1, t2, nu
    assert np.allclose(frame @ frame.transpose(0, 2, 1), np.eye(3), atol=1e-14)
    assert np.allclose(np.linalg.det(frame), 1.0)  # (t1, t2, nu) right-handed
    assert np.allclose(cb.tangent, [0.0, 1.0, 0.0]) and np.allclose(cb.tangent2, [1.0, 0.0, 0.0])
    assert cb.fixed is not None and cb.fixed.sum() > 0  # the rollers' vertices stayed on Gamma_C


def test_the_tangent_rule_on_a_slanted_normal():
    nu = np.array([[0.3, -0.8, 0.52]]) / np.linalg.norm([0.3, -0.8, 0.52])
    t1, t2 = tangent_basis(nu)
    e = np.array([1.0, 0.0, 0.0])  # |nu_x| is the smallest
    assert np.allclose(t1[0], np.cross(e, nu[0]) / np.linalg.norm(np.cross(e, nu[0])))
    assert np.allclose(t2[0], np.cross(nu[0], t1[0]))


def test_prism_weights_are_the_2d_trapezoid_times_the_layer_trapezoid():
    base = {"polygon": [[0, 0], [1, 0], [1, 1], [0, 1]], "sides": ["bottom", "right", "top", "left"]}
    common = {
        "material": {"E": E, "nu": NU},
        "contact": {"gap": 0.0, "normal": {"k": K, "m": 1.0}, "friction": {"k": 0.0, "m": 0.0}},
    }
    d2 = dict(
        common,
        domain=base,
        boundary={"dirichlet": ["top"], "contact": ["bottom"]},
        discretization={"mesh": {"family": "voronoi", "n": 5}},
    )
    d3 = dict(
        common,
        model="3d",
        domain=dict(base, extrude={"depth": 0.3}),
        boundary={"dirichlet": ["top"], "contact": ["bottom"]},
        discretization={"mesh": {"family": "voronoi", "n": 5, "layers": 2}},
    )
    c2, c3 = scene_problem(scene_from_dict(d2)).contact, scene_problem(scene_from_dict(d3)).contact
    w2 = dict(zip(np.round(c2.coords[:, 0], 12), c2.weight))
    across = np.where(np.isclose(c3.coords[:, 2], 0.15), 0.15, 0.075)  # two layers of 0.15
    expected = np.array([w2[x] for x in np.round(c3.coords[:, 0], 12)]) * across
    assert np.allclose(c3.weight, expected, rtol=1e-12, atol=0)
    assert np.allclose(c3.normal, [0.0, -1.0, 0.0])


@pytest.mark.parametrize("family", ["hex", "voronoi"])
@pytest.mark.parametrize("method", ["uzawa", "ssn"])
@pytest.mark.parametrize("foundation", [True, False])
def test_uniform_penetration_gives_the_exact_total_force_in_3d(family, method, foundation):
    problem = scene_problem(scene_from_dict(pressed_box(family, foundation=foundation)))
    solution = solve(problem, {"method": method, "tol": 1e-12, "linear": "direct"})
    cb = problem.contact
    t = cb.normal_displacement(solution.u) - cb.gap
    force = np.sum(cb.weight * problem.law.normal_pressure(t))
    exact = K * DELTA / (1 + K * H / E) * 1.0
    assert abs(force / exact - 1) < (1e-14 if method == "ssn" else 1e-10), (force, exact)
    assert np.ptp(t) < 1e-14
    assert verify_solution(problem, solution.u, solution.multiplier)["worst"] < 1e-10


def test_a_roller_vertex_stays_on_gamma_c_in_2d_and_holds_its_prescribed_value():
    problem = scene_problem(scene_from_dict(pressed_box("square", dimension=2)))
    cb = problem.contact
    corner = np.flatnonzero(np.isclose(cb.coords[:, 0], 0.0))
    assert corner.size == 1 and cb.fixed is not None and cb.fixed[corner[0]].tolist() == [True, False]
    solution = solve(problem, {"method": "ssn", "tol": 1e-12, "linear": "direct"})
    t = cb.normal_displacement(solution.u) - cb.gap
    exact = DELTA / (1 + K * H / E)  # plane stress, uniaxial: the same closed form
    assert np.allclose(t, exact, rtol=1e-12, atol=0)
    assert np.isclose(np.sum(cb.weight * K * t), K * exact, rtol=1e-12, atol=0)
    assert solution.u[cb.dofs[corner[0], 0]] == 0.0  # the prescribed component, no contact force in its row
    forces = cb.contact_force(solution.u, problem.law, solution.multiplier)
    assert forces[cb.dofs[corner[0], 0]] == 0.0 and forces[cb.dofs[corner[0], 1]] != 0.0


def test_a_nonzero_prescribed_component_is_what_the_law_reads():
    data = pressed_box("hex")
    data["boundary"]["dirichlet"]["left"] = [0.002, None, None]  # the roller pushes in x
    problem = scene_problem(scene_from_dict(data))
    solution = solve(problem, {"method": "ssn", "tol": 1e-12, "linear": "direct"})
    cb = problem.contact
    held = cb.fixed[:, 0]
    assert held.any() and np.allclose(solution.u[cb.dofs[held, 0]], 0.002, rtol=1e-14, atol=0)
    # a rigid shift in x changes nothing normal: the same penetration and force as without it
    t = cb.normal_displacement(solution.u) - cb.gap
    assert np.allclose(t, DELTA / (1 + K * H / E), rtol=1e-12, atol=0)
