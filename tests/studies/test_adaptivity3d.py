"""`vemkit adapt` on 3D bodies (issue 36, item 3): the loop of 2D with the 3D estimator and refinement.

Checked here: the estimate and the true error (the manufactured box's exact solution) fall together
with a bounded effectivity, every refined mesh passes the 3D mesh check, contact with friction works
with either solver and the warm start saves Newton steps, new vertices of an extruded body's curved
sides lie on the arcs, the stop reasons, and the CLI's file and its refusals.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from vemkit.config.scene import load_scene
from vemkit.io.solution_file import read_solution
from vemkit.mesh.checks3d import validate_mesh3d
from vemkit.studies.adaptivity import AdaptivitySettings, adapt
from vemkit.studies.adaptivity_errors import scene_true_error

SCENES = "config/scenes/3d"


def _run(name, overrides, settings, **kwargs):
    scene = load_scene(f"{SCENES}/{name}.yaml", overrides)
    meshes = []
    run = adapt(scene, settings, observe=lambda step, so_far: meshes.append(so_far.problem.mesh), **kwargs)
    return scene, run, meshes


@pytest.mark.parametrize("family", ["hex", "tet"])
def test_the_estimate_and_the_exact_error_fall_together_on_the_manufactured_box(family):
    scene = load_scene(
        f"{SCENES}/box_manufactured.yaml", [f"discretization.mesh.family={family}", "discretization.mesh.n=2"]
    )
    meshes = []
    run = adapt(
        scene,
        AdaptivitySettings(theta=0.5, max_steps=4),
        true_error=scene_true_error(scene),
        observe=lambda step, so_far: meshes.append(so_far.problem.mesh),
    )
    estimates = np.array([r["estimate"] for r in run.history])
    errors = np.array([r["true_error"] for r in run.history])
    effectivity = estimates / errors
    assert run.reason == "max_steps" and np.all(np.diff(estimates) < 0) and np.all(np.diff(errors) < 0)
    assert 1.0 < effectivity.min() and effectivity.max() / effectivity.min() < 2.0, effectivity
    assert all(r["marked"] > 0 for r in run.history[:-1])
    for mesh in meshes:
        validate_mesh3d(mesh)
    assert meshes[-1].meta["refined_3d"] == 3


@pytest.mark.parametrize("method", ["ssn", "uzawa"])
def test_frictional_contact_adapts_with_either_solver_and_the_warm_start_saves_steps(method):
    overrides = ["discretization.mesh.n=3", f"solver.method={method}"]
    settings = AdaptivitySettings(theta=0.5, max_steps=4)
    _, warm, meshes = _run("sheared_box", overrides, settings)
    _, cold, _ = _run("sheared_box", overrides, settings, warm_start=False)
    assert [r["n_dofs"] for r in warm.history] == [r["n_dofs"] for r in cold.history]
    assert [r["warm_start"] for r in warm.history] == [0, 1, 1, 1]
    assert sum(r["iterations"] for r in warm.history[1:]) < sum(r["iterations"] for r in cold.history[1:])
    assert np.allclose([r["estimate"] for r in warm.history], [r["estimate"] for r in cold.history], rtol=1e-6)
    assert warm.checks["check_worst"] < 1e-8
    # the contact side is where the estimate is: its cells are refined first
    bottom = meshes[-1].boundary_facets("bottom")
    assert meshes[-1].facet_areas[bottom].min() < 0.3 * meshes[0].facet_areas[meshes[0].boundary_facets("bottom")].min()


def test_new_vertices_of_curved_sides_lie_on_the_arcs_of_the_extruded_body():
    overrides = ["discretization.mesh.family=triangle", "discretization.mesh.h=0.25"]
    _, run, meshes = _run("lame", overrides, AdaptivitySettings(theta=0.5, max_steps=3))
    mesh = meshes[-1]
    assert mesh.n_vertices > meshes[0].n_vertices
    for side, radius in (("bore", 1.0), ("outer", 2.0)):
        xy = mesh.vertices[mesh.boundary_vertices(side), :2]
        assert np.abs(np.hypot(*xy.T) - radius).max() < 1e-12, side
    assert len(mesh.boundary_vertices("bore")) > len(meshes[0].boundary_vertices("bore"))  # σ peaks at the bore


def test_the_loop_stops_before_a_mesh_over_max_dofs_is_solved():
    _, run, _ = _run("sheared_box", ["discretization.mesh.n=3"], AdaptivitySettings(theta=0.5, max_dofs=500))
    assert run.reason == "max_dofs" and all(r["n_dofs"] <= 500 for r in run.history)
    _, run, _ = _run("sheared_box", ["discretization.mesh.n=3"], AdaptivitySettings(target=0.9))
    assert run.reason == "target" and len(run.history) == 1


def vemkit(*args):
    return subprocess.run([sys.executable, "-m", "vemkit.cli", *map(str, args)], capture_output=True, text=True)


def test_the_cli_writes_the_3d_adaptive_file_and_its_vtu(tmp_path):
    run = vemkit(
        "adapt", f"{SCENES}/sheared_box.yaml", "-o", tmp_path / "a.nc", "--vtu", tmp_path / "a.vtu",
        "--set", "discretization.mesh.n=2", "--set", "adaptivity.max_steps=3", "-q",
    )  # fmt: skip
    assert run.returncode == 0, run.stderr
    mesh, ds = read_solution(tmp_path / "a.nc")
    assert ds["error_indicator"].dims == ("mesh3d_nVolumes",) and ds["error_indicator"].size == mesh.n_cells
    assert ds.attrs["adapt_steps"] == 3 and ds["adapt_n_dofs"].values[-1] == 3 * mesh.n_vertices
    assert np.all(np.isfinite(ds["error_indicator"].values)) and (tmp_path / "a.vtu").stat().st_size > 0


@pytest.mark.parametrize(
    "override, message",
    [
        ("adaptivity.max_hanging=1", "adaptivity.max_hanging = 1: the refinement of 3D bodies"),
        ("discretization.mesh.family=voronoi", "vemkit adapt: cell "),
        ("adaptivity.reference=any.nc", "adaptivity.reference: the true error against a reference solution"),
    ],
)
def test_what_3d_refinement_cannot_do_is_refused_in_one_line_before_solving(tmp_path, override, message):
    run = vemkit("adapt", f"{SCENES}/sheared_box.yaml", "-o", tmp_path / "a.nc", "--set", override)
    assert run.returncode == 2 and message in run.stderr and len(run.stderr.strip().splitlines()) == 1, run.stderr
    assert "adapt: step" not in run.stderr and not (tmp_path / "a.nc").exists()
