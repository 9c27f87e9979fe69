"""The extruded paper body with u3 = 0 on both end faces against the 2D plane-strain contact solve
(docs/reference/files.md, issue 21 item 5): equal u1, u2 at every vertex to 1e-10, both solvers, friction on.

The end faces' contact vertices have u3 prescribed (a symmetry roller meeting Gamma_C): they stay
contact points with u1, u2 in the law (vemkit.contact.boundary). On prisms over triangles, squares
and Voronoi polygons the 3D element on each prism and the 2D element on its base give the same
plane-strain stiffness (the 3D stabilization length of a right prism is half its height,
``vemkit.vem.elements.k1_3d.stabilization_lengths``; with the diameter the elasticity alone differed
by 12 % on squares, n = 4), so the contact solves agree too; and the 3D contact solve is a
plane-strain state (u3 = 0, u1 and u2 the same on every layer), both solvers.
"""

import copy
from pathlib import Path

import numpy as np
import pytest
import yaml
from conftest import AGREEMENT_SOLVERS

from vemkit.config.scene import scene_from_dict
from vemkit.contact.problem import scene_problem
from vemkit.solvers.dispatch import solve
from vemkit.solvers.solution import SEPARATED, SLIP, STICK, contact_state

PAPER = Path(__file__).resolve().parents[2] / "config" / "scenes" / "paper.yaml"
BASE = {"polygon": [[0, 0], [1, 0], [1, 1], [0, 1]], "sides": ["bottom", "right", "top", "left"]}
OPTIONS = AGREEMENT_SOLVERS


def scenes(family: str, n: int, layers: int, friction: float):
    """The paper scene on the square as a polygon (plane strain) and extruded by 0.25 (3D)."""
    flat = yaml.safe_load(PAPER.read_text())
    flat.update(model="plane_strain", domain=BASE)
    flat["contact"]["friction"]["k"] = friction
    flat["discretization"]["mesh"] = {"family": family, "n": n}
    body = copy.deepcopy(flat)
    body.update(model="3d", domain=dict(BASE, extrude={"depth": 0.25}), body_force=[0, 0, 0])
    body["discretization"]["mesh"] = {"family": family, "n": n, "layers": layers}
    body["boundary"]["dirichlet"] = {"right": [0, 0, 0], "front": [None, None, 0], "back": [None, None, 0]}
    body["boundary"]["neumann"] = {"left": {"traction": ["200*(5-y)", -200, 0]}, "top": {"traction": [0, 0, 0]}}
    return scene_from_dict(flat), scene_from_dict(body)


def compare(family, n, layers, friction, method):
    flat, body = (scene_problem(s) for s in scenes(family, n, layers, friction))
    s2, s3 = solve(flat, OPTIONS[method]), solve(body, OPTIONS[method])
    u2, u3 = flat.vertex_displacement(s2.u), body.vertex_displacement(s3.u)
    base = {tuple(np.round(x, 12)): i for i, x in enumerate(flat.mesh.vertices)}
    below = np.array([base[tuple(np.round(x[:2], 12))] for x in body.mesh.vertices])
    difference = np.max(np.abs(u3[:, :2] - u2[below])) / np.max(np.abs(u2))
    return difference, np.max(np.abs(u3[:, 2])), body, s3


@pytest.mark.parametrize("method", ["ssn", "uzawa"])
@pytest.mark.parametrize("friction, layers", [(450.0, 2), (700.0, 2), (700.0, 1)])
def test_the_extruded_paper_body_is_the_plane_strain_solve(method, friction, layers):
    difference, u3, body, solution = compare("triangle", 6, layers, friction, method)
    assert difference < 1e-10 and u3 < 1e-14, (difference, u3)
    cb = body.contact
    assert cb.fixed is not None and cb.fixed[:, 2].sum() == 2 * cb.size // (layers + 1)  # both end faces
    states = contact_state(body, solution.u, solution.multiplier).state
    assert np.sum(states == SLIP) > 0 and np.sum(states == SEPARATED) > 0
    if friction == 700.0:
        assert np.sum(states == STICK) > 0


@pytest.mark.parametrize("method", ["ssn", "uzawa"])
@pytest.mark.parametrize("family", ["square", "voronoi"])
def test_on_polygonal_prisms_too_the_extruded_body_is_the_plane_strain_solve(family, method):
    difference, u3, _, _ = compare(family, 4, 2, 700.0, method)
    assert difference < 1e-10 and u3 < 1e-14, (difference, u3)


@pytest.mark.parametrize("family", ["square", "voronoi"])
def test_on_polygonal_prisms_the_contact_solve_is_a_plane_strain_state(family):
    """What holds there: u3 = 0 and u1, u2 the same on every layer of vertices (the end faces'
    contact vertices, with u3 held, slide as the inner ones), and both solvers agree to 1e-10."""
    _, body = scenes(family, 4, 2, 700.0)
    problem = scene_problem(body)
    solutions = [solve(problem, OPTIONS[m]) for m in ("ssn", "uzawa")]
    u = [problem.vertex_displacement(s.u) for s in solutions]
    assert np.max(np.abs(u[0] - u[1])) / np.max(np.abs(u[0])) < 1e-10
    z = problem.mesh.vertices[:, 2]
    plane = {tuple(np.round(x[:2], 12)): k for k, x in enumerate(problem.mesh.vertices) if z[k] == 0.0}
    bottom_twin = np.array([plane[tuple(np.round(x[:2], 12))] for x in problem.mesh.vertices])
    assert np.max(np.abs(u[0][:, :2] - u[0][bottom_twin, :2])) / np.max(np.abs(u[0])) < 1e-12
    assert np.max(np.abs(u[0][:, 2])) < 1e-14
    states = contact_state(problem, solutions[0].u, solutions[0].multiplier).state
    assert np.sum(states == SLIP) > 0 and np.sum(states == STICK) + np.sum(states == SEPARATED) > 0


def test_a_curved_contact_side_on_a_foundation_plane_is_the_plane_strain_solve():
    """The Hertz half disk (config/scenes/hertz.yaml: curved Gamma_C, rollers, foundation line)
    extruded by 0.1 on the foundation plane y = -1: vertex normals averaged over the curved faces and
    the gap along them give the 2D plane-strain solve and its total force per depth, to 1e-12."""
    flat = yaml.safe_load((PAPER.parent / "hertz.yaml").read_text())
    flat.update(model="plane_strain")
    flat["discretization"]["mesh"] = {"family": "triangle", "h": 0.04}
    body = copy.deepcopy(flat)
    body.update(model="3d", body_force=[0, 0, 0])
    body["domain"]["extrude"] = {"depth": 0.1}
    body["discretization"]["mesh"]["layers"] = 1
    body["boundary"]["dirichlet"] = {
        "top": [None, -0.01, None],
        "pin": [0.0, -0.01, None],
        "front": [None, None, 0],
        "back": [None, None, 0],
    }
    body["contact"]["foundation"] = {"point": [0, -1, 0], "normal": [0, 1, 0]}
    p2, p3 = scene_problem(scene_from_dict(flat)), scene_problem(scene_from_dict(body))
    s2, s3 = solve(p2, OPTIONS["ssn"]), solve(p3, OPTIONS["ssn"])
    u2, u3 = p2.vertex_displacement(s2.u), p3.vertex_displacement(s3.u)
    base = {tuple(np.round(x, 10)): i for i, x in enumerate(p2.mesh.vertices)}
    below = np.array([base[tuple(np.round(x[:2], 10))] for x in p3.mesh.vertices])
    assert np.max(np.abs(u3[:, :2] - u2[below])) / np.max(np.abs(u2)) < 1e-12
    forces = [
        np.sum(p.contact.weight * p.law.normal_pressure(p.contact.normal_displacement(s.u) - p.contact.gap))
        for p, s in ((p2, s2), (p3, s3))
    ]
    assert forces[0] > 0 and abs(forces[1] / 0.1 / forces[0] - 1) < 1e-12
    assert np.allclose(p3.contact.normal[:, 2], 0.0) and not np.allclose(p3.contact.normal[:, 0], 0.0)
