"""The adaptive loop (vemkit.studies.adaptivity): stops as asked; the estimator tracks the true error."""

import numpy as np
import pytest

from manufactured import elasticity_solution
from vemkit.config.scene import load_scene, scene_from_dict
from vemkit.mesh.checks import validate_mesh
from vemkit.studies.adaptivity import AdaptivitySettings, adapt
from vemkit.vem.norms import exact_errors
from vemkit.vem.projection import projected_solution
from pathlib import Path

PAPER = Path(__file__).resolve().parents[2] / "config" / "scenes" / "paper.yaml"
SMOOTH = "x*(1-x)*y*(1-y)*(1-x)**4*(1-y)**4"  # steep near the corner (0, 0): adaptivity has work to do


def _manufactured_scene():
    solution = elasticity_solution(SMOOTH, "0.5*" + SMOOTH, 1.0, 0.3)
    scene = scene_from_dict({
        "name": "manufactured", "material": {"E": 1.0, "nu": 0.3}, "body_force": solution["body_force"],
        "boundary": {"dirichlet": ["left", "right", "bottom", "top"], "neumann": {}, "contact": []},
        "discretization": {"mesh": {"family": "square", "n": 4}}, "solver": {"method": "ssn", "tol": 1e-10}})
    return scene, solution


def test_the_estimator_tracks_the_exact_error_within_a_factor_3_over_the_steps():
    scene, exact = _manufactured_scene()

    def true_error(problem, solution):
        u = problem.dofs.expand(solution.u)
        absolute = exact_errors(problem.mesh, projected_solution(problem.mesh, u), exact["u"], exact["grad"])
        norm = exact_errors(problem.mesh, projected_solution(problem.mesh, 0 * u), exact["u"], exact["grad"])
        return absolute["h1_semi"] / norm["h1_semi"]

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
