"""The sweeps and the stability matrix on a 3D studies scene (docs/reference/files.md, issue 21 item 5): areas and
forces instead of lengths and forces per depth, the resultant tangential force as a vector's magnitude,
tangential profiles in the per-vertex basis (dimension contact_tangent), the scene's own mesh family
in the matrix, and config/sweeps3d.yaml planned by the workflow."""

from pathlib import Path

import numpy as np
import pytest
from conftest import assert_no_nan_stored

from vemkit.config.scene import load_scene
from vemkit.contact.problem import scene_problem
from vemkit.solvers.dispatch import solve
from vemkit.solvers.solution import contact_state
from vemkit.studies import robustness
from vemkit.studies.sweeps import QUANTITIES_3D, read_dataset, run_sweep, write_dataset

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "config/scenes/3d/sheared_box.yaml"
SETTINGS = ["discretization.mesh.n=4", "solver.linear=direct"]


@pytest.fixture(scope="module")
def sweep():
    grid = {"contact.friction.k": [0.0, 3.0], "contact.normal.k": [50.0, 200.0]}
    return grid, run_sweep(load_scene(SCENE, SETTINGS), grid)


def test_the_3d_quantities_are_areas_and_forces_of_the_surface(sweep):
    grid, ds = sweep
    assert set(QUANTITIES_3D) <= set(ds.data_vars) and "contact_length" not in ds
    assert ds["contact_area"].attrs["units"] == "mm2" and ds["normal_force"].attrs["units"] == "daN"
    assert int(ds["valid"].sum()) == 4
    w = ds["contact_weight"].values
    np.testing.assert_allclose(w.sum(), 1.0, rtol=1e-12)  # the unit square bottom face
    touching = ds["profile_penetration"].values > 0
    np.testing.assert_allclose(ds["contact_area"].values, (touching * w).sum(-1), rtol=1e-12)
    np.testing.assert_allclose(ds["stick_area"] + ds["slip_area"], ds["contact_area"], rtol=1e-12)
    np.testing.assert_allclose(ds["normal_force"].values, (ds["profile_pressure"].values * w).sum(-1), rtol=1e-12)
    assert ds["profile_multiplier"].dims[-2:] == ("contact_node", "contact_tangent")
    assert np.all(ds["tangential_force"].sel(k_tau=0.0).values == 0.0)
    # the reduced law's bound k_tau on all of Gamma_C: |sum w sigma_tau| <= k_tau |Gamma_C|, here the
    # box slides over part of it
    friction = ds["tangential_force"].sel(k_tau=3.0).values
    assert np.all((0 < friction) & (friction <= 3.0 + 1e-12)) and np.all(ds["slip_area"].sel(k_tau=3.0) > 0)


def test_the_tangential_force_is_the_resultant_vector_of_the_solution(sweep):
    _, ds = sweep
    scene = load_scene(SCENE, SETTINGS + ["contact.friction.k=3.0", "contact.normal.k=200.0"])
    problem = scene_problem(scene)
    solution = solve(problem, scene.solver_options)
    state = contact_state(problem, solution.u, solution.multiplier)
    cb = problem.contact
    vectors = cb.tangent * state.tangential_stress[:, :1] + cb.tangent2 * state.tangential_stress[:, 1:]
    resultant = np.linalg.norm((cb.weight[:, None] * vectors).sum(axis=0))
    np.testing.assert_allclose(float(ds["tangential_force"].sel(k_tau=3.0, k_nu=200.0)), resultant, rtol=1e-8)


def test_the_3d_sweep_file_reads_back_without_nan(sweep, tmp_path):
    _, ds = sweep
    path = tmp_path / "box3d.nc"
    write_dataset(ds, path)
    assert_no_nan_stored(path)
    back = read_dataset(path)
    assert back.sizes["contact_tangent"] == 2 and "contact_z" in back.coords
    np.testing.assert_allclose(back["slip_area"].values, ds["slip_area"].values)


def test_the_stability_matrix_keeps_the_3d_scene_s_family_and_checks_the_disk():
    scene = load_scene(SCENE, ["solver.linear=direct"])
    cases = robustness.select_cases(["paper", "E=2e9,k_nu=1e8", "hanging,levels=3"])
    results = robustness.run_matrix(scene, cases, {"ssn": {}}, 3)
    paper, stiff, hanging = results
    assert paper["parameters"]["mesh"] == '{"family": "hex", "n": 3}' and paper["outcomes"]["ssn"].converged
    # |lambda| = 1 + 2.8e-4 after one step was accepted before: the disk is part of ssn's test now
    assert stiff["outcomes"]["ssn"].converged and stiff["outcomes"]["ssn"].checks["multiplier_bound"] <= 1e-10
    assert hanging["outcomes"]["ssn"].status == "invalid_input"  # a 2D family on a box: refused, classified
