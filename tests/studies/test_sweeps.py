"""Parameter sweeps (vemkit.studies.sweeps): dimensions, physical consistency, reuse, the file's fill scheme."""

from pathlib import Path

import netCDF4
import numpy as np
import pytest
from conftest import assert_no_nan_stored

from vemkit.config.scene import load_scene
from vemkit.solvers.verification import STATUS_MEANINGS
from vemkit.studies.sweeps import (
    FLOAT_FILL,
    combine_parts,
    dimension_name,
    normalize_grid,
    read_dataset,
    run_sweep,
    split_grid,
    write_dataset,
)

ROOT = Path(__file__).resolve().parents[2]
QUANTITIES = ("max_penetration", "contact_length", "stick_length", "slip_length", "normal_force", "tangential_force")


@pytest.fixture(scope="module")
def scene():
    return load_scene(ROOT / "config/scenes/paper.yaml", ["discretization.mesh.n=8"])


@pytest.fixture(scope="module")
def friction_grid(scene):
    grid = {"contact.friction.k": [0.0, 450.0], "contact.normal.k": [1.0, 10.0, 100.0]}
    return grid, run_sweep(scene, grid)


def test_dimensions_coordinates_and_attributes(friction_grid, scene):
    grid, ds = friction_grid
    assert ds["status"].dims == ("k_tau", "k_nu")
    assert ds["profile_pressure"].dims == ("k_tau", "k_nu", "contact_node")
    np.testing.assert_array_equal(ds["k_tau"].values, grid["contact.friction.k"])
    np.testing.assert_array_equal(ds["k_nu"].values, grid["contact.normal.k"])
    assert ds["k_nu"].attrs["scene_key"] == "contact.normal.k"
    assert ds.sizes["contact_node"] == 8  # 9 bottom vertices, the clamped corner dropped
    assert np.all(np.diff(ds["contact_x"].values) > 0)
    assert ds["status"].attrs["flag_meanings"].split() == list(STATUS_MEANINGS)
    assert np.all(ds["status"].values == 0) and np.all(ds["valid"].values == 1)
    assert ds.attrs["scene"] == scene.to_yaml() and "vemkit_version" in ds.attrs and "solver_options" in ds.attrs
    for name in QUANTITIES:
        assert np.all(np.isfinite(ds[name].values)), name
    assert np.all(ds["iterations"].values >= 0) and np.all(ds["wall_time"].values > 0)


def test_quantities_are_consistent(friction_grid):
    _, ds = friction_grid
    w = ds["contact_weight"].values
    np.testing.assert_allclose(
        ds["normal_force"].values, (ds["profile_pressure"] * w).sum("contact_node").values, rtol=1e-12
    )
    np.testing.assert_allclose(
        ds["tangential_force"].values,
        (ds["profile_tangential_stress"] * w).sum("contact_node").values,
        rtol=1e-12,
        atol=1e-12,
    )
    in_contact = (ds["profile_penetration"] > 0).values
    np.testing.assert_allclose(ds["contact_length"].values, (in_contact * w).sum(-1), rtol=1e-12)
    np.testing.assert_allclose(ds["stick_length"] + ds["slip_length"], ds["contact_length"], rtol=1e-12)
    np.testing.assert_allclose(
        ds["max_penetration"].values, np.maximum(ds["profile_penetration"].max("contact_node").values, 0.0)
    )
    frictionless = ds.sel(k_tau=0.0)
    np.testing.assert_array_equal(frictionless["tangential_force"].values, 0.0)
    assert np.all(np.abs(ds.sel(k_tau=450.0)["tangential_force"].values) > 0)
    # a stiffer foundation is penetrated less
    assert np.all(np.diff(ds["max_penetration"].values, axis=1) < 0)


def test_normal_force_grows_with_the_load_and_falls_with_the_gap(scene):
    ds = run_sweep(
        scene, {"boundary.neumann.left.traction[1]": [-100.0, -200.0, -400.0], "contact.gap": [0.0, 0.05, 0.1, 0.2]}
    )
    assert ds["status"].dims == ("boundary_neumann_left_traction_1", "g_a")
    force = ds["normal_force"].values
    assert np.all(np.diff(force, axis=0) > 0)
    assert np.all(np.diff(force, axis=1) <= 0)  # 0 once the gap stays open
    assert np.all(np.diff(force, axis=1)[force[:, 1:] > 0] < 0)


def test_a_large_gap_means_no_contact(scene):
    ds = run_sweep(scene, {"contact.gap": [10.0], "contact.friction.k": [0.0, 450.0]})
    for name in ("max_penetration", "contact_length", "stick_length", "slip_length", "normal_force"):
        np.testing.assert_array_equal(ds[name].values, 0.0)
    assert np.all(ds["profile_state"].values == 0)  # separated everywhere


def test_reused_problem_equals_fresh_solves(scene):
    grid = {"contact.normal.k": [1.0, 1000.0], "contact.friction.k": [100.0, 450.0], "solver.method": ["ssn", "uzawa"]}
    reused = run_sweep(scene, grid, reuse=True)
    fresh = run_sweep(scene, grid, reuse=False)
    np.testing.assert_array_equal(reused["status"].values, fresh["status"].values)
    for name in (*QUANTITIES, "profile_pressure", "profile_slip", "profile_multiplier"):
        np.testing.assert_allclose(reused[name].values, fresh[name].values, rtol=1e-12, atol=1e-14, equal_nan=True)
    np.testing.assert_array_equal(reused["iterations"].values, fresh["iterations"].values)
    assert reused["setup_time"].values.sum() < fresh["setup_time"].values.sum()


def test_reused_problem_equals_fresh_solves_with_gauss_quadrature(scene):
    """A changed gap reaches the Gauss points too (ContactBoundary.with_gap), and the resultant
    normal force is the Gauss integral, which differs from the nodal sum when p_nu is not linear."""
    gauss = scene.with_overrides(["discretization.contact_quadrature=gauss", "contact.normal.m=2.0"])
    grid = {"contact.gap": [0.0, 0.05], "contact.normal.k": [100.0]}
    reused = run_sweep(gauss, grid, reuse=True)
    fresh = run_sweep(gauss, grid, reuse=False)
    for name in ("normal_force", "max_penetration", "profile_pressure"):
        np.testing.assert_allclose(reused[name].values, fresh[name].values, rtol=1e-12, atol=1e-14)
    nodal = run_sweep(gauss.with_overrides(["discretization.contact_quadrature=nodal"]), grid)
    assert not np.allclose(nodal["normal_force"].values, reused["normal_force"].values, rtol=1e-6)


def test_failures_are_classified_and_the_file_holds_no_nan(scene, tmp_path):
    grid = {"solver.method": ["ssn", "uzawa"], "contact.normal.k": [10.0, 1e5, -1.0]}
    ds = run_sweep(scene.with_overrides(["solver.stop=both"]), grid)
    status = {
        (m, k): STATUS_MEANINGS[int(ds["status"].sel(solver=m, k_nu=k))]
        for m in ("ssn", "uzawa")
        for k in (10.0, 1e5, -1.0)
    }
    assert status[("ssn", 10.0)] == status[("ssn", 1e5)] == status[("uzawa", 10.0)] == "converged"
    assert status[("uzawa", 1e5)] in (
        "not_converged_diverged",
        "not_converged_stagnated",
        "not_converged_max_iterations",
    )
    assert "contact.normal.k" in str(ds["message"].sel(solver="uzawa", k_nu=1e5).values)
    assert status[("ssn", -1.0)] == status[("uzawa", -1.0)] == "error_invalid_input"
    assert np.isnan(float(ds["normal_force"].sel(solver="uzawa", k_nu=1e5)))
    path = write_dataset(ds, tmp_path / "sweep.nc")
    assert_no_nan_stored(path)
    with netCDF4.Dataset(path) as nc:
        nc.set_auto_mask(False)
        assert nc["normal_force"]._FillValue == FLOAT_FILL
        assert nc["profile_state"]._FillValue == -1
        assert np.sum(nc["normal_force"][:] == FLOAT_FILL) == 3
    back = read_dataset(path)
    np.testing.assert_array_equal(np.isnan(back["normal_force"].values), np.isnan(ds["normal_force"].values))
    np.testing.assert_allclose(back["normal_force"].values, ds["normal_force"].values, equal_nan=True)


def test_the_paper_stop_rule_is_held_to_tol(scene):
    """The paper's rule (stop on |du| OR |dlambda|) fires one lagged step early at h = 1/8 (residual ~3e-6);
    uzawa refuses that stop and iterates on until the residual is what solver.tol asks for."""
    ds = run_sweep(scene, {"solver.method": ["uzawa"], "solver.stop": ["either", "both"]}, check_tol=1e-6).squeeze(
        "solver"
    )
    for stop in ("either", "both"):
        assert int(ds["status"].sel(solver_stop=stop)) == 0, stop
        assert float(ds["residual"].sel(solver_stop=stop)) <= 1e-8, stop


def test_split_parts_combine_to_the_whole(scene):
    grid = {"contact.friction.k": [0.0, 100.0, 450.0], "contact.normal.k": [1.0, 10.0]}
    parts = split_grid(grid, 2)
    assert [p["contact.friction.k"] for p in parts] == [(0.0, 100.0), (450.0,)]
    whole = run_sweep(scene, grid)
    combined = combine_parts([run_sweep(scene, p) for p in parts])
    np.testing.assert_array_equal(combined["k_tau"].values, whole["k_tau"].values)
    for name in (*QUANTITIES, "profile_pressure", "status"):
        np.testing.assert_allclose(combined[name].values, whole[name].values, rtol=1e-12)
    assert combined.attrs["points"] == 6


def test_grid_checks():
    with pytest.raises(ValueError, match="listed twice"):
        normalize_grid({"contact.gap": [0.1, 0.1]})
    with pytest.raises(ValueError, match="at least one value"):
        normalize_grid({"contact.gap": []})
    assert dimension_name("material.nu") == "kappa"
    assert dimension_name("discretization.mesh.levels") == "discretization_mesh_levels"
