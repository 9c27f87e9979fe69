"""Contact with k = 2 virtual elements (vemkit.contact.problem, order = 2), pinned by exact solutions.

- A uniform penetration (a uniaxial strain state pressed onto the foundation) is reproduced to
  round-off on every family, and the total normal force is k_nu t |Gamma_C| (Simpson's weights sum
  to |Gamma_C|), with ssn and with uzawa.
- The change of variables (Gamma_C edge means -> midpoint values) changes nothing but the variables.
- ssn and uzawa agree on the paper scene; the independent check passes.
- Manufactured contact solutions (non-polynomial u; sliding everywhere, sticking everywhere, a
  separation point inside Gamma_C) converge at H1 order 2 for k = 2 against 1 for k = 1.
- Scenes: discretization.order: 2 with rollers and prescribed quadratic displacements through
  the scene, and the k = 2 solution file.
"""

from pathlib import Path

import numpy as np
import pytest
import scipy.sparse.linalg as spla
import sympy
from manufactured import X, elasticity_solution

from vemkit.config.scene import load_scene, scene_from_dict
from vemkit.contact.laws import ContactLaw
from vemkit.contact.problem import discrete_problem, scene_problem
from vemkit.exceptions import SceneError
from vemkit.mesh.families import build_mesh
from vemkit.solvers.dispatch import solve
from vemkit.solvers.verification import verify_solution
from vemkit.studies.scene_solve import solve_scene
from vemkit.vem.elasticity import lame_parameters
from vemkit.vem.elements.k1_fields import projected_solution
from vemkit.vem.elements.k2_fields import traction_load_k2
from vemkit.vem.norms import exact_errors
from vemkit.vem.space import VirtualElementSpace

E, NU = 2000.0, 0.4
LAM, MU = lame_parameters(E, NU)
PAPER = str(Path(__file__).resolve().parents[2] / "config" / "scenes" / "paper.yaml")


def _uniform_penetration(family, k_nu=50.0, depth=0.3, gap=0.1):
    """Top moved down by ``depth`` (u = (0, -depth)), sides loaded with the lateral stress of eps11 = 0:
    u = (0, eps22 (y - 1) - depth) with -(lam + 2 mu) eps22 = k_nu t, t = depth + eps22 - gap."""
    eps22 = -k_nu * (depth - gap) / (LAM + 2 * MU + k_nu)
    s11 = LAM * eps22
    mesh = build_mesh(family, 4)
    problem = discrete_problem(
        mesh,
        E,
        NU,
        order=2,
        dirichlet={"top": (0.0, -depth)},
        neumann={"left": lambda x, y: (-s11 + 0 * x, 0 * x), "right": lambda x, y: (s11 + 0 * x, 0 * x)},
        contact=["bottom"],
        gap=lambda x, y: np.full_like(x, gap),
        law=ContactLaw(k_nu, 1.0, 450.0, 0.0),
    )
    y = VirtualElementSpace(mesh, 2).node_coordinates[:, 1]
    exact = np.stack([0 * y, eps22 * (y - 1) - depth], axis=1)
    return problem, exact, depth + eps22 - gap


@pytest.mark.parametrize("family", ["square", "triangle", "voronoi", "hanging"])
@pytest.mark.parametrize("method", ["ssn", "uzawa"])
def test_uniform_penetration_is_exact_and_its_force_is_k_nu_t_length(family, method):
    problem, exact, t = _uniform_penetration(family)
    solution = solve(problem, {"method": method, "tol": 1e-12})
    atol = 1e-13 if method == "ssn" else 1e-10  # uzawa stops at its tolerance
    np.testing.assert_allclose(problem.node_values(solution.u), exact, atol=atol)
    cb = problem.contact
    assert cb.weight.sum() == pytest.approx(1.0, abs=1e-14)  # |Gamma_C| = 1: Simpson's weights
    force = cb.contact_force(solution.u, problem.law, solution.multiplier)
    assert -force[cb.dofs[:, 1]].sum() == pytest.approx(problem.law.k_normal * t, rel=1e-9)
    assert verify_solution(problem, solution.u, solution.multiplier)["passed"]


def test_the_contact_points_are_the_vertices_and_edge_midpoints_with_simpson_weights():
    problem, _, _ = _uniform_penetration("hanging")
    cb, nv = problem.contact, problem.mesh.n_vertices
    edges = problem.mesh.boundary["bottom"]
    lengths = np.linalg.norm(np.diff(problem.mesh.vertices[edges], axis=1)[:, 0], axis=1)
    mid = cb.vertices >= nv
    assert mid.sum() == edges.shape[0] and (~mid).sum() == edges.shape[0] + 1
    np.testing.assert_allclose(np.sort(cb.weight[mid]), np.sort(4 * lengths / 6), rtol=1e-14)
    np.testing.assert_allclose(cb.coords[mid, 1], 0.0, atol=1e-15)


def test_the_change_of_variables_gives_the_plain_k2_solution():
    """No contact law: the transformed system's solution, mapped back to edge means, is the solution
    of the untransformed k = 2 system (clamped right side, traction on the left)."""
    mesh = build_mesh("voronoi", 5, seed=2)
    traction = lambda x, y: (200 * (5 - y), -200 + 0 * y)  # noqa: E731
    problem = discrete_problem(
        mesh,
        E,
        NU,
        order=2,
        dirichlet=("right",),
        neumann={"left": traction},
        contact=["bottom"],
        law=ContactLaw(0.0, 1.0, 0.0, 0.0),
    )
    assert problem.dofs.change.nnz > 0
    space = VirtualElementSpace(mesh, 2)
    nodes = space.numbering(space.clamped_on(mesh.boundary["right"]))
    K = space.stiffness_matrix(LAM, MU, "dofi-2mu", nodes)
    plain = nodes.node_values(
        spla.spsolve(K.tocsc(), nodes.restrict(traction_load_k2(mesh, mesh.boundary["left"], traction)))
    )
    solution = solve(problem, {"method": "ssn", "tol": 1e-12, "linear": "direct"})
    np.testing.assert_allclose(problem.node_values(solution.u), plain, atol=1e-12 * np.abs(plain).max())


@pytest.mark.parametrize("family", ["square", "voronoi"])
def test_ssn_and_uzawa_agree_on_the_paper_scene_at_order_2(family):
    solutions = {}
    for method in ("ssn", "uzawa"):
        scene = load_scene(
            PAPER,
            [
                "discretization.order=2",
                f"discretization.mesh.family={family}",
                "discretization.mesh.n=8",
                f"solver.method={method}",
            ],
        )
        problem = scene_problem(scene)
        solutions[method] = solve(problem, scene.solver_options)
        assert verify_solution(problem, solutions[method].u, solutions[method].multiplier, 1e-8)["passed"]
    u_ssn, u_uzawa = solutions["ssn"].u, solutions["uzawa"].u
    assert np.abs(u_ssn - u_uzawa).max() < 1e-8 * np.abs(u_ssn).max()
    np.testing.assert_allclose(solutions["ssn"].multiplier, solutions["uzawa"].multiplier, atol=1e-7)


# -- manufactured contact solutions -------------------------------------------------------------------
LAW = ContactLaw(1000.0, 1.0, 100.0, 0.0)
U2 = "-0.1 + 0.03*sin(2*x + y)"
#: name -> (u1, penetration t(x) = u_nu - g on Gamma_C, multiplier lambda(x) of the exact solution)
CASES = {
    "sliding": ("0.02*cos(x)*exp(y)", "0.02*(1 + x)", lambda x: np.ones_like(x)),  # u_tau = u1 > 0
    "sticking": ("0.02*y*cos(x)*exp(y)", "0.02*(1 + x)", lambda x: 0.5 * np.cos(x)),  # u_tau = 0
    "separation": ("0.02*cos(x)*exp(y)", "0.04*(0.5 - x)", lambda x: np.ones_like(x)),  # t < 0 for x > 1/2
}


def manufactured_problem(case, mesh, order):
    """The exact u solves the contact problem with the body force -div sigma(u), tractions sigma(u) n on
    left and top, u on the right, the gap g = u_nu - t and, on Gamma_C (the bottom, nu = (0, -1)), the
    extra traction h = sigma(u) nu + p_nu(t) nu + p_tau lambda tau that the contact terms leave over."""
    u1, penetration, multiplier = CASES[case]
    exact = elasticity_solution(u1, U2, E, NU)
    force = sympy.lambdify(sympy.symbols("x y"), [sympy.sympify(c) for c in exact["body_force"]], "numpy")
    t = sympy.lambdify(X, sympy.sympify(penetration), "numpy")
    u, stress = exact["u"], exact["stress"]

    def traction(normal):
        return lambda x, y: tuple(np.einsum("ij...,j->i...", stress(x, y), np.asarray(normal, float)))

    def extra(x, y):
        s, tt = stress(x, y), np.broadcast_to(t(x), np.shape(x))
        return (-s[0, 1] + LAW.friction_bound(tt) * multiplier(x), -s[1, 1] - LAW.normal_pressure(tt))

    kwargs = dict(
        dirichlet={"right": (lambda x, y: u(x, y)[0], lambda x, y: u(x, y)[1])},
        neumann={"left": traction((-1, 0)), "top": traction((0, 1)), "bottom": extra},
        contact=["bottom"],
        gap=lambda x, y: -u(x, 0 * x)[1] - np.broadcast_to(t(x), np.shape(x)),
        law=LAW,
        body_force=lambda x, y: tuple(np.broadcast_to(v, np.shape(x)) for v in force(x, y)),
    )
    problem = discrete_problem(mesh, E, NU, order=order, **kwargs)
    return problem, exact, multiplier


def manufactured_errors(case, order, ns=(4, 8, 16)):
    """H1-seminorm errors of Pi_k u_h on square meshes, and the last problem and solution."""
    errors = []
    for n in ns:
        mesh = build_mesh("square", n)
        problem, exact, multiplier = manufactured_problem(case, mesh, order)
        solution = solve(problem, {"method": "ssn", "tol": 1e-12})
        proj = (
            problem.projected(solution.u) if order == 2 else projected_solution(mesh, problem.dofs.expand(solution.u))
        )
        errors.append(exact_errors(mesh, proj, exact["u"], exact["grad"])["h1_semi"])
    return np.array(errors), problem, solution, multiplier


@pytest.mark.parametrize("case", list(CASES))
def test_manufactured_contact_solutions_converge_at_second_order(case):
    errors2, problem, solution, multiplier = manufactured_errors(case, 2)
    errors1 = manufactured_errors(case, 1)[0]
    orders2, orders1 = np.log2(errors2[:-1] / errors2[1:]), np.log2(errors1[:-1] / errors1[1:])
    assert orders2[-1] >= 1.9 and 0.9 <= orders1[-1] <= 1.1, (orders2, orders1)
    assert errors2[-1] < 0.1 * errors1[-1]
    cb = problem.contact
    inside = cb.coords[:, 0] < 1.0 - 1e-12
    np.testing.assert_allclose(solution.multiplier[inside, 0], multiplier(cb.coords[inside, 0]), atol=0.02)


# -- scenes ------------------------------------------------------------------------------------------
def test_order_2_reproduces_a_prescribed_quadratic_field_through_the_scene():
    """A roller on the left (u1 given, u2 free: the field's shear stress vanishes there), nonzero
    quadratic Dirichlet data elsewhere (edge means on the new dofs) and the constant body force of u:
    the k = 2 solution is exact, and so are the errors the solution file reports."""
    field = ["0.01*x*x + 0.02*x*y", "-0.005*y*y + 0.03*x*x"]  # eps12 = 0.04 x: zero on x = 0
    data = {
        "name": "quadratic",
        "material": {"E": E, "nu": NU},
        "body_force": elasticity_solution(*field, E, NU)["body_force"],
        "boundary": {"dirichlet": {"left": [field[0], None], "bottom": field, "right": field, "top": field}},
        "discretization": {"mesh": {"family": "voronoi", "n": 4}, "order": 2},
        "exact": {"displacement": field},
    }
    problem, solution, ds = solve_scene(scene_from_dict(data))
    assert problem.dofs.fixed_dofs.size > 0
    assert ds.attrs["order"] == 2 and ds.attrs["error_h1"] < 1e-9 and ds.attrs["error_l2"] < 1e-9
    x, y = problem.mesh.vertices.T
    np.testing.assert_allclose(ds["u2"].values, -0.005 * y * y + 0.03 * x * x, atol=1e-12)


def test_the_order_2_solution_file_has_the_edge_means_and_the_contact_midpoints():
    scene = load_scene(PAPER, ["discretization.order=2", "discretization.mesh.n=4"])
    problem, solution, ds = solve_scene(scene, verify=True)
    assert ds.attrs["order"] == 2 and ds.attrs["n_dofs"] == problem.n_dofs
    edges = problem.mesh.edges
    means = problem.node_values(solution.u)[problem.mesh.n_vertices :][: edges.shape[0]]
    np.testing.assert_array_equal(ds["u1_edge_mean"].values, means[:, 0])
    assert ds["u1_edge_mean"].dims == ("mesh2d_nEdges",)
    vertex, edge = ds["contact_vertex"].values, ds["contact_edge"].values
    assert np.all((vertex >= 0) != (edge >= 0)) and (edge >= 0).sum() == 4 and (vertex >= 0).sum() == 4
    np.testing.assert_allclose(
        ds["contact_x"].values[edge >= 0], 0.5 * problem.mesh.vertices[edges[edge[edge >= 0]]].sum(axis=1)[:, 0]
    )
    k1 = solve_scene(load_scene(PAPER, ["discretization.mesh.n=4"]))[2]
    assert k1.attrs["order"] == 1 and "u1_edge_mean" not in k1


def test_gauss_contact_quadrature_is_refused_at_order_2():
    scene = load_scene(
        PAPER, ["discretization.order=2", "discretization.contact_quadrature=gauss", "discretization.mesh.n=2"]
    )
    with pytest.raises(SceneError, match="contact_quadrature.*order = 2") as error:
        scene_problem(scene)
    assert error.value.key == "discretization.contact_quadrature"


def test_contact_on_a_slanted_side_at_order_2_has_the_edge_normals_at_the_midpoints():
    """Any side (docs/reference/files.md): vertices and midpoints of a slanted Gamma_C get the side's normal, and the
    ssn solution passes the independent check (uzawa stagnates on this deep indentation for k = 1
    and k = 2 alike: the lagged normal compliance oscillates)."""
    import yaml

    data = yaml.safe_load(open(PAPER, encoding="utf-8").read())
    data["domain"] = {"polygon": [[0, 0], [2, 0], [3, 1], [0, 1]], "sides": ["base", "slope", "top", "left"]}
    data["boundary"] = {
        "dirichlet": ["left"],
        "neumann": {"top": {"traction": [0.0, -200.0]}},
        "contact": ["base", "slope"],
    }
    data["discretization"] = {"mesh": {"family": "voronoi", "n": 4}, "order": 2}
    scene = scene_from_dict(data)
    problem = scene_problem(scene)
    cb = problem.contact
    x, y = cb.coords.T
    on_slope = np.isclose(y, x - 2.0) & (y > 1e-9)
    midpoints = cb.vertices >= problem.mesh.n_vertices
    assert (on_slope & midpoints).sum() >= 2 and (on_slope & ~midpoints).sum() >= 2
    np.testing.assert_allclose(cb.normal[on_slope], np.tile([2**-0.5, -(2**-0.5)], (on_slope.sum(), 1)), atol=1e-14)
    solution = solve(problem, scene.solver_options)
    assert verify_solution(problem, solution.u, solution.multiplier, 1e-9)["passed"]


# -- the command line ---------------------------------------------------------------------------------
def _cli(tmp_path, *args):
    import subprocess
    import sys

    return subprocess.run(
        [sys.executable, "-m", "vemkit.cli", *args], capture_output=True, text=True, cwd=tmp_path, timeout=300
    )


@pytest.mark.parametrize(
    "args, named",
    [
        (["solve", "--set", "discretization.order=3"], "discretization.order = 3"),
        (
            ["solve", "--set", "discretization.order=2", "--set", "discretization.contact_quadrature=gauss"],
            "discretization.contact_quadrature",
        ),
        (["solve", "--set", "discretization.body_force_projection=p1"], "discretization.body_force_projection"),
        (
            ["solve", "--set", "discretization.order=2", "--set", "discretization.body_force_projection=p2"],
            "discretization.body_force_projection",
        ),
    ],
)
def test_bad_order_2_requests_are_one_line_errors_through_the_cli(tmp_path, args, named):
    run = _cli(tmp_path, args[0], PAPER, "-o", "out.nc", *args[1:], "--set", "discretization.mesh.n=2")
    assert run.returncode == 2 and len(run.stderr.splitlines()) == 1 and named in run.stderr, run.stderr
    assert not (tmp_path / "out.nc").exists()


@pytest.mark.slow  # a fresh interpreter: ~10 s on the shared machine, mostly start-up
def test_order_2_through_the_cli_writes_a_k2_solution_file(tmp_path):
    from vemkit.io.solution_file import read_solution

    run = _cli(
        tmp_path, "solve", PAPER, "-o", "out.nc", "--set", "discretization.order=2", "--set", "discretization.mesh.n=4"
    )
    assert run.returncode == 0, run.stderr
    mesh, ds = read_solution(tmp_path / "out.nc")
    assert ds.attrs["order"] == 2 and ds["u2_edge_mean"].size == mesh.edges.shape[0]
    assert ds.attrs["n_space_dofs"] == ds.attrs["n_dofs"] + 2 * mesh.n_cells


def test_adapt_runs_at_order_2():
    """``vemkit adapt`` once refused order 2 (its estimator and warm start were k = 1 only); both now
    run through the space (tests/studies/test_adaptivity_k2.py measures the rates): a k = 2 scene
    adapts in the k = 2 space, every step's solution passing the independent check."""
    from vemkit.studies.adaptivity import AdaptivitySettings, adapt

    scene = load_scene(PAPER, ["discretization.order=2", "discretization.mesh.n=2"])
    run = adapt(scene, AdaptivitySettings(theta=0.5, target=1e-9, max_steps=2), verify=True)
    assert run.reason == "max_steps" and len(run.history) == 2 and run.problem.order == 2
    assert run.history[0]["n_dofs"] < run.history[1]["n_dofs"] == run.problem.n_dofs
    assert verify_solution(run.problem, run.solution.u, run.solution.multiplier)["passed"]
