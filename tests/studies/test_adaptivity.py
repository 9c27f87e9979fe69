"""The adaptive loop (vemkit.studies.adaptivity): stops as asked; the estimator tracks the true error."""

from pathlib import Path

import numpy as np
import pytest
from manufactured import elasticity_solution

from vemkit.config.scene import load_scene, scene_from_dict
from vemkit.mesh.checks import validate_mesh
from vemkit.studies.adaptivity import AdaptivitySettings, adapt
from vemkit.vem.elements.k1_fields import projected_solution
from vemkit.vem.norms import exact_errors

PAPER = Path(__file__).resolve().parents[2] / "config" / "scenes" / "paper.yaml"
SMOOTH = "x*(1-x)*y*(1-y)*(1-x)**4*(1-y)**4"  # steep near the corner (0, 0): adaptivity has work to do


def _manufactured_scene():
    solution = elasticity_solution(SMOOTH, "0.5*" + SMOOTH, 1.0, 0.3)
    scene = scene_from_dict(
        {
            "name": "manufactured",
            "material": {"E": 1.0, "nu": 0.3},
            "body_force": solution["body_force"],
            "boundary": {"dirichlet": ["left", "right", "bottom", "top"], "neumann": {}, "contact": []},
            "discretization": {"mesh": {"family": "square", "n": 4}},
            "solver": {"method": "ssn", "tol": 1e-10},
        }
    )
    return scene, solution


def test_the_estimator_tracks_the_exact_error_within_a_factor_3_over_the_steps():
    scene, exact = _manufactured_scene()

    def true_error(problem, u_free):
        mesh, u = problem.mesh, problem.vertex_displacement(u_free)
        absolute = exact_errors(mesh, projected_solution(mesh, u), exact["u"], exact["grad"])
        norm = exact_errors(mesh, projected_solution(mesh, 0 * u), exact["u"], exact["grad"])
        semi = absolute["h1_semi"] / norm["h1_semi"]
        return {
            "error_h1_semi": semi,
            "error_h1": np.hypot(absolute["h1_semi"], absolute["l2"]) / np.hypot(norm["h1_semi"], norm["l2"]),
        }

    run = adapt(scene, AdaptivitySettings(theta=0.5, target=1e-3, max_steps=9), true_error=true_error)
    errors = np.array([r["true_error"] for r in run.history])
    effectivity = np.array([r["effectivity"] for r in run.history])
    dofs = np.array([r["n_dofs"] for r in run.history])
    assert run.reason == "max_steps" and len(run.history) == 9
    assert np.all(np.diff(dofs) > 0) and errors[-1] < 0.25 * errors[0]
    assert effectivity.max() / effectivity.min() < 3.0 and effectivity.min() > 1.0
    validate_mesh(run.problem.mesh)


def test_the_loop_stops_at_the_target_and_at_max_dofs():
    scene = load_scene(PAPER, ["discretization.mesh.n=4"])
    reached = adapt(scene, AdaptivitySettings(target=0.5))
    assert reached.reason == "target" and len(reached.history) == 1
    capped = adapt(scene, AdaptivitySettings(target=1e-6, max_dofs=200, max_steps=30))
    assert capped.reason == "max_dofs"
    assert capped.history[-1]["n_dofs"] <= 200 and len(capped.history) >= 2


def test_the_paper_scene_is_refined_where_the_indicators_are_large():
    scene = load_scene(PAPER, ["discretization.mesh.n=4"])
    run = adapt(scene, AdaptivitySettings(theta=0.3, target=1e-6, max_steps=5))
    mesh = run.problem.mesh
    estimates = [r["estimate"] for r in run.history]
    assert estimates[-1] < estimates[0]
    # the corners are stress singularities (the ends of the clamped side, the jumps of the left
    # traction to the top and the contact side): the finest cells sit there, the middle stays coarse
    centres = np.array([mesh.vertices[mesh.cell(k)].mean(axis=0) for k in range(mesh.n_cells)])
    to_corner = np.min(np.linalg.norm(centres[:, None] - np.array([[0, 0], [1, 0], [1, 1], [0, 1]]), axis=2), axis=1)
    assert np.all(to_corner[np.argsort(mesh.cell_areas)[:8]] < 0.2)
    middle = np.all(np.abs(centres - 0.5) < 0.25, axis=1)
    assert mesh.cell_areas[middle].min() >= 1 / 64


@pytest.mark.parametrize("theta, target", [(0.0, 0.01), (1.5, 0.01), (0.5, 0.0)])
def test_bad_settings_are_refused(theta, target):
    from vemkit.exceptions import InputError

    with pytest.raises(InputError):
        AdaptivitySettings(theta=theta, target=target)


def test_the_adaptive_solution_file_holds_the_indicator_and_the_history(tmp_path):
    import xarray as xr

    from vemkit.io.solution_file import write_netcdf
    from vemkit.studies.adaptivity import adaptive_dataset

    scene = load_scene(PAPER, ["discretization.mesh.n=4"])
    run = adapt(scene, AdaptivitySettings(max_steps=3))
    write_netcdf(adaptive_dataset(scene, run), tmp_path / "adapted.nc")
    with xr.open_dataset(tmp_path / "adapted.nc") as ds:
        assert ds.sizes["adapt_step"] == 3 and ds.sizes["mesh2d_nFaces"] == run.problem.mesh.n_cells
        assert np.allclose(ds["error_indicator"], run.indicators["indicator"])
        assert list(ds["adapt_n_dofs"].values) == [r["n_dofs"] for r in run.history]
        assert "adapt_true_error" not in ds and ds.attrs["adapt_stop_reason"] == "max_steps"


def test_theta_1_refines_every_cell_uniform_refinement():
    scene = load_scene(PAPER, ["discretization.mesh.n=4"])
    run = adapt(scene, AdaptivitySettings(theta=1.0, target=1e-6, max_steps=3))
    assert [r["n_cells"] for r in run.history] == [16, 64, 256]
    assert np.allclose(run.problem.mesh.cell_areas, 1 / 256)  # the square mesh n = 16


def test_the_warm_start_finds_the_same_solutions_with_far_fewer_uzawa_iterations():
    """Each solve starts from the previous step's solution prolongated to the refined mesh: on the paper
    scene the friction multiplier is then already right, and Uzawa stops after a few iterations."""
    scene = load_scene(PAPER, ["discretization.mesh.n=4", "solver.method=uzawa"])
    settings = AdaptivitySettings(theta=0.5, target=1e-6, max_steps=5)
    cold = adapt(scene, settings, warm_start=False)
    warm = adapt(scene, settings)
    assert [r["n_cells"] for r in warm.history] == [r["n_cells"] for r in cold.history]
    assert np.abs(warm.solution.u - cold.solution.u).max() < 1e-7 * np.abs(cold.solution.u).max()
    assert [r["warm_start"] for r in warm.history] == [0, 1, 1, 1, 1]
    warm_its, cold_its = (sum(r["iterations"] for r in run.history[1:]) for run in (warm, cold))
    assert 5 * warm_its < cold_its


def test_a_circular_hole_is_refined_on_the_circle_and_every_mesh_is_valid():
    from vemkit.mesh import scene_mesh

    scene = scene_from_dict(
        {
            "name": "plate",
            "material": {"E": 1.0, "nu": 0.3},
            "domain": {
                "polygon": [[0, 0], [2, 0], [2, 1], [0, 1]],
                "sides": ["bottom", "right", "top", "left"],
                "holes": [{"circle": [1.0, 0.5, 0.25], "side": "hole"}],
            },
            "boundary": {"dirichlet": ["left"], "neumann": {"right": {"traction": [1.0, 0.0]}}},
            "discretization": {"mesh": {"family": "triangle", "n": 4}},
        }
    )
    meshes = []
    run = adapt(
        scene,
        AdaptivitySettings(theta=0.5, target=1e-6, max_steps=5),
        observe=lambda step, so_far: meshes.append(so_far.problem.mesh),
    )
    for mesh in meshes:
        validate_mesh(mesh)
    estimates = [r["estimate"] for r in run.history]
    assert np.all(np.diff(estimates) < 0) and estimates[-1] < 0.5 * estimates[0]
    mesh, first = run.problem.mesh, scene_mesh(scene)
    on_hole = np.unique(mesh.boundary["hole"])
    assert on_hole.size > 2 * np.unique(first.boundary["hole"]).size  # refined at the hole ...
    assert np.allclose(np.linalg.norm(mesh.vertices[on_hole] - [1.0, 0.5], axis=1), 0.25, atol=1e-13)  # ... on it
    assert sorted(mesh.boundary) == sorted(first.boundary)


def test_the_reference_error_is_exact_on_meshes_finer_than_the_reference_in_places():
    """Two adapted meshes, each finer than the other somewhere: ‖Π(u_A − u_B)‖ is the same whichever
    is the reference (the common-refinement quadrature is exact on nested meshes), and on a uniform
    mesh coarser than the reference it is projection_error (docs/reference/mathematics.md)."""
    from vemkit.io.solution_file import solution_dataset
    from vemkit.mesh.families import build_mesh
    from vemkit.studies.adaptivity_errors import reference_errors
    from vemkit.studies.error_records import ReferenceSolution
    from vemkit.vem.norms import projection_error, seminorm_squared

    scene = load_scene(PAPER, ["discretization.mesh.n=4"])
    runs = [
        adapt(scene, AdaptivitySettings(theta=theta, target=1e-6, max_steps=steps))
        for theta, steps in ((0.3, 6), (1.0, 3))
    ]
    meshes = [run.problem.mesh for run in runs]
    fields = [run.problem.dofs.expand(run.solution.u) for run in runs]
    refs = [
        ReferenceSolution("<memory>", solution=(m, solution_dataset(r.problem, r.solution)))
        for m, r in zip(meshes, runs)
    ]
    norms = [np.sqrt(seminorm_squared(m.cell_areas, projected_solution(m, u).gradient)) for m, u in zip(meshes, fields)]
    assert (
        meshes[0].cell_areas.min() < meshes[1].cell_areas.min()
        and meshes[0].cell_areas.max() > meshes[1].cell_areas.max()
    )
    a_vs_b = reference_errors(meshes[0], fields[0], refs[1])["error_h1_semi"] * norms[1]
    b_vs_a = reference_errors(meshes[1], fields[1], refs[0])["error_h1_semi"] * norms[0]
    assert 1e-3 < a_vs_b / norms[1] < 0.2 and np.isclose(a_vs_b, b_vs_a, rtol=1e-10)
    coarse = load_scene(PAPER, ["discretization.mesh.n=8"])
    coarse_run = adapt(coarse, AdaptivitySettings(target=1e-6, max_steps=1))
    u = coarse_run.problem.dofs.expand(coarse_run.solution.u)
    mine = reference_errors(coarse_run.problem.mesh, u, refs[1])
    spec5 = projection_error(
        build_mesh("square", 8), projected_solution(coarse_run.problem.mesh, u), meshes[1], refs[1].projected
    )
    assert np.isclose(mine["error_h1"], spec5["h1"], rtol=1e-12) and np.isclose(
        mine["error_l2"], spec5["l2"], rtol=1e-12
    )


def test_the_reference_error_takes_the_slivers_at_a_circular_hole_finer_than_the_reference():
    """The L-bracket's bore: refined twice, its 32 vertices lie on the circle, outside the octagon of
    the scene's mesh; the octagon mesh's solution as the reference covers slivers the refined mesh
    leaves out. Measured both ways, ‖Π(u_A − u_B)‖ agrees (the slivers hold 0.1 % of the area)."""
    from vemkit.io.solution_file import solution_dataset
    from vemkit.studies.adaptivity_errors import reference_errors
    from vemkit.studies.error_records import ReferenceSolution
    from vemkit.vem.norms import seminorm_squared

    scene = load_scene(
        Path(__file__).resolve().parents[2] / "config" / "scenes" / "lbracket.yaml", ["discretization.mesh.h=2.5"]
    )
    runs = [adapt(scene, AdaptivitySettings(theta=1.0, target=1e-9, max_steps=steps)) for steps in (1, 3)]
    meshes = [run.problem.mesh for run in runs]
    fields = [run.problem.dofs.expand(run.solution.u) for run in runs]
    assert np.unique(meshes[1].boundary["bore"]).size == 32 and meshes[1].cell_areas.sum() < meshes[0].cell_areas.sum()
    refs = [
        ReferenceSolution("<memory>", solution=(m, solution_dataset(r.problem, r.solution)))
        for m, r in zip(meshes, runs)
    ]
    norms = [np.sqrt(seminorm_squared(m.cell_areas, projected_solution(m, u).gradient)) for m, u in zip(meshes, fields)]
    fine_vs_coarse = reference_errors(meshes[1], fields[1], refs[0])["error_h1_semi"] * norms[0]
    coarse_vs_fine = reference_errors(meshes[0], fields[0], refs[1])["error_h1_semi"] * norms[1]
    assert 0.05 < fine_vs_coarse / norms[0] < 0.5 and np.isclose(fine_vs_coarse, coarse_vs_fine, rtol=0.01)


def test_a_pressure_side_is_estimated_as_its_traction_minus_p_nu():
    """The L-bracket's shelf (outward normal +y) under traction (0, −5) and under pressure 5: one load,
    one estimate, the same adaptive meshes."""

    runs = []
    for load in ("{traction: [0.0, -5.0]}", "{pressure: 5.0}"):
        overrides = ["discretization.mesh.h=5", "adaptivity.max_steps=3", f"boundary.neumann.shelf={load}"]
        scene = load_scene("config/scenes/lbracket.yaml", overrides)
        runs.append(adapt(scene, AdaptivitySettings.from_scene(scene)).history)
    assert [r["n_dofs"] for r in runs[0]] == [r["n_dofs"] for r in runs[1]]
    assert np.allclose([r["estimate"] for r in runs[0]], [r["estimate"] for r in runs[1]], rtol=1e-9, atol=0)
