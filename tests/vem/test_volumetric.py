"""The averaged nodal volumetric strain (``vemkit.vem.volumetric``, ``discretization.volumetric_strain``):
its divergence rows are the element's projection, it passes the patch test, has no spurious modes,
keeps the convergence order at nu = 0.3 and removes the locking of triangles on Cook's membrane."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from manufactured import elasticity_solution
from volumetric_checks import LAM, MU, kernel_size, linear_field, patch_test

from vemkit.config.scene import scene_from_dict
from vemkit.contact.problem import scene_problem
from vemkit.mesh.families import build_mesh
from vemkit.solvers.dispatch import solve
from vemkit.studies.scene_solve import solve_scene
from vemkit.vem.projection import stress
from vemkit.vem.space import VirtualElementSpace
from vemkit.vem.volumetric import NodalAverage, cell_stress, stiffness_matrix

COOK_SCENE = Path(__file__).resolve().parents[2] / "config" / "scenes" / "cook.yaml"
FAMILIES_2D = {
    "triangle": dict(family="triangle", kind="delaunay", seed=1),
    "square": dict(family="square"),
    "voronoi": dict(family="voronoi", seed=2),
}


def mesh_2d(case: str, n: int = 5):
    options = dict(FAMILIES_2D[case])
    return build_mesh(options.pop("family"), n, **options)


@pytest.mark.parametrize("case", list(FAMILIES_2D))
def test_the_divergence_rows_are_the_trace_of_the_elements_projected_strain(case):
    space = VirtualElementSpace(mesh_2d(case), 1)
    u = np.random.default_rng(1).normal(size=(space.n_nodes, 2))
    strain = space.project(u, LAM, MU).cell_mean_strain()
    assert np.allclose(NodalAverage.of(space).cell_divergence(u), strain[:, 0] + strain[:, 1], rtol=0, atol=1e-12)


@pytest.mark.parametrize("stabilization", ["dofi-2mu", "dofi", "trace"])
@pytest.mark.parametrize("case", list(FAMILIES_2D))
def test_a_linear_displacement_is_reproduced_exactly(case, stabilization):
    space = VirtualElementSpace(mesh_2d(case), 1)
    assert patch_test(space, stabilization) < 1e-10


@pytest.mark.parametrize("case", list(FAMILIES_2D))
def test_the_stress_of_a_linear_field_is_c_eps(case):
    """theta_a is exact for a linear field: the nodal stress is C eps, as the cell one."""
    space = VirtualElementSpace(mesh_2d(case), 1)
    u = space.interpolate(linear_field(2, seed=3))
    strain = space.project(u, LAM, MU).cell_mean_strain()
    expected = stress(strain, LAM, MU)
    found = cell_stress(space, u, strain, LAM, MU, "nodal_average")
    assert np.allclose(found, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())


@pytest.mark.parametrize("case", ["triangle", "voronoi"])
def test_no_spurious_modes_the_kernel_is_the_rigid_motions(case):
    space = VirtualElementSpace(mesh_2d(case, n=4), 1)
    K = stiffness_matrix(space, LAM, MU, "dofi-2mu", space.numbering(natural=True), "nodal_average")
    assert kernel_size(K) == 3


def test_the_trace_stabilization_keeps_its_lambda_scaled_alpha():
    """trace: the element stiffness keeps its alpha_K (with lambda); only the lambda consistency
    term moves from the cells to the nodes. On triangles S_K = 0, so K is the dofi-2mu one."""
    space = VirtualElementSpace(mesh_2d("triangle", n=4), 1)
    dofs = space.numbering(natural=True)
    trace = stiffness_matrix(space, LAM, MU, "trace", dofs, "nodal_average")
    plain = stiffness_matrix(space, LAM, MU, "dofi-2mu", dofs, "nodal_average")
    assert abs(trace - plain).max() < 1e-12 * abs(plain).max()


def test_the_cell_treatment_is_the_elements_stiffness_bit_for_bit():
    space = VirtualElementSpace(mesh_2d("voronoi"), 1)
    dofs = space.numbering()
    K = stiffness_matrix(space, LAM, MU, "dofi-2mu", dofs, "cell")
    reference = space.stiffness_matrix(LAM, MU, "dofi-2mu", dofs)
    assert (K != reference).nnz == 0


def test_the_energy_order_is_kept_at_nu_0_3_on_triangles():
    """u = (sin x sin y, x y^2 / 4) with its body force, nu = 0.3 in plane strain: relative H1
    error O(h) with nodal_average, as with the cell form."""
    field = ["sin(x)*sin(y)", "x*y**2/4"]
    E, nu = 1.0, 0.3
    # the body force of the plane-strain C: the plane-stress formula at the equivalent E', nu'
    force = elasticity_solution(*field, E / (1 - nu**2), nu / (1 - nu))["body_force"]
    errors = []
    for n in (8, 16):
        scene = scene_from_dict(
            {
                "name": "manufactured",
                "model": "plane_strain",
                "domain": "unit_square",
                "material": {"E": E, "nu": nu},
                "body_force": force,
                "boundary": {"dirichlet": {side: field for side in ("bottom", "right", "top", "left")}},
                "exact": {"displacement": field},
                "discretization": {
                    "mesh": {"family": "triangle", "kind": "structured", "n": n},
                    "volumetric_strain": "nodal_average",
                },
            }
        )
        errors.append(solve_scene(scene)[2].attrs)
    assert errors[0]["volumetric_strain"] == "nodal_average"
    h1 = np.log2(errors[0]["error_h1"] / errors[1]["error_h1"])
    l2 = np.log2(errors[0]["error_l2"] / errors[1]["error_l2"])
    assert 0.9 < h1 < 1.2 and 1.8 < l2 < 2.3, (h1, l2)


# -- Cook's membrane in plane strain at nu = 0.4999 (issue 35) -----------------------------------
COOK_REFERENCE = 7.7695  # u2 at (48, 60): Taylor-Hood P2/P1, Richardson-extrapolated
COOK = {
    "name": "cook_plane_strain",
    "model": "plane_strain",
    "domain": {"polygon": [[0, 0], [48, 44], [48, 60], [0, 44]], "sides": ["bottom", "load", "top", "clamped"]},
    "material": {"E": 250.0, "nu": 0.4999},
    "boundary": {"dirichlet": ["clamped"], "neumann": {"load": {"traction": [0.0, 6.25]}}},
}


def cook_tip(h: float, volumetric: str) -> float:
    """u2(48, 60) / reference on the triangles of size h."""
    scene = scene_from_dict(
        dict(COOK, discretization={"mesh": {"family": "triangle", "h": h}, "volumetric_strain": volumetric})
    )
    problem = scene_problem(scene)
    u = problem.dofs.expand(solve(problem, {**scene.solver_options, "linear": "direct"}).u)
    corner = np.flatnonzero(np.all(np.isclose(problem.mesh.vertices, [48.0, 60.0]), axis=1))
    return float(u[corner[0], 1]) / COOK_REFERENCE


def test_cook_triangles_lock_with_the_cell_form_and_not_with_nodal_averaging():
    """Measured: cell 0.797 (h = 2) and 0.881 (h = 1) of the reference; nodal_average 0.966 and
    0.986 (the issue's target: within 2 % at h = 1)."""
    assert cook_tip(2.0, "cell") < 0.81
    assert cook_tip(2.0, "nodal_average") > 0.955
    assert abs(cook_tip(1.0, "nodal_average") - 1.0) < 0.02
    # auto: nodal_average for k = 1 in plane strain above nu = 0.45
    assert cook_tip(1.0, "auto") == cook_tip(1.0, "nodal_average")


@pytest.mark.parametrize("stabilization", ["dofi-2mu", "trace"])
def test_the_estimators_energy_is_the_formulations(stabilization):
    """error_indicators with nodal_average: sum_K a_h^K(u, u) = u^T K u of the nodal stiffness, and the
    stabilization term is the element's (the same as with the cell form)."""
    from vemkit.vem.estimator import error_indicators

    space = VirtualElementSpace(mesh_2d("voronoi", n=4), 1)
    u = np.random.default_rng(4).normal(size=(space.n_nodes, 2))
    K = stiffness_matrix(space, LAM, MU, stabilization, space.numbering(natural=True), "nodal_average")
    nodal = error_indicators(space, u, LAM, MU, stabilization, volumetric_strain="nodal_average")
    cell = error_indicators(space, u, LAM, MU, stabilization)
    assert np.isclose(nodal["energy"], u.ravel() @ (K @ u.ravel()), rtol=1e-10)
    assert np.allclose(
        nodal["stabilization"], cell["stabilization"], rtol=1e-8, atol=1e-9 * cell["stabilization"].max()
    )


def divergence_weights_numpy(mesh):
    """The numpy twin of ``k1_divergence.divergence_table_2d``: q_i = (y_{i+1} - y_{i-1}, x_{i-1} -
    x_{i+1}) / (2 |K|) (the k = 1 kernel's docstring), cell after cell, interleaved (q_i1, q_i2)."""
    offsets, ids = mesh.cell_offsets, mesh.cell_vertices
    weights, areas = [], []
    for c in range(mesh.n_cells):
        p = mesh.vertices[ids[offsets[c] : offsets[c + 1]]]
        nxt, prv = np.roll(p, -1, axis=0), np.roll(p, 1, axis=0)
        area = 0.5 * np.sum(p[:, 0] * nxt[:, 1] - nxt[:, 0] * p[:, 1])
        q = np.stack([nxt[:, 1] - prv[:, 1], prv[:, 0] - nxt[:, 0]], axis=1) / (2.0 * area)
        weights.append(q.ravel())
        areas.append(area)
    return np.concatenate(weights), np.array(areas)


@pytest.mark.parametrize("case", list(FAMILIES_2D))
def test_the_divergence_kernel_matches_its_numpy_twin(case):
    from vemkit.vem.elements.k1_divergence import divergence_2d

    mesh = mesh_2d(case)
    weights, areas = divergence_2d(mesh)
    twin_weights, twin_areas = divergence_weights_numpy(mesh)
    assert np.allclose(weights, twin_weights, rtol=1e-13, atol=1e-13 * np.abs(twin_weights).max())
    assert np.allclose(areas, twin_areas, rtol=1e-13)


def test_plane_stress_takes_the_effective_lambda_and_stays_valid():
    """nodal_average named in plane stress (it does not lock there: auto keeps cell) uses lambda* and
    gives the cell form's answer to the discretization error: Cook, E = 1, nu = 1/3, triangles h = 2."""
    from vemkit.config.scene import load_scene

    tips = {}
    for treatment in ("cell", "nodal_average"):
        scene = load_scene(
            COOK_SCENE,
            [
                "discretization.mesh.family=triangle",
                "discretization.mesh.h=2",
                f"discretization.volumetric_strain={treatment}",
            ],
        )
        problem = scene_problem(scene)
        assert problem.volumetric_strain == treatment and problem.model == "plane_stress"
        u = problem.dofs.expand(solve(problem, {**scene.solver_options, "linear": "direct"}).u)
        corner = np.flatnonzero(np.all(np.isclose(problem.mesh.vertices, [48.0, 60.0]), axis=1))
        tips[treatment] = float(u[corner[0], 1])
    assert abs(tips["nodal_average"] / tips["cell"] - 1.0) < 0.02


def test_the_api_refuses_nodal_average_at_order_2_and_unknown_treatments():
    from vemkit.exceptions import InputError

    space = VirtualElementSpace(mesh_2d("square", n=2), 2)
    with pytest.raises(InputError, match="does not lock") as caught:
        stiffness_matrix(space, LAM, MU, "dofi-2mu", space.numbering(), "nodal_average")
    assert caught.value.key == "discretization.volumetric_strain"
    with pytest.raises(InputError, match="unknown"):
        stiffness_matrix(space, LAM, MU, "dofi-2mu", space.numbering(), "nodal")
