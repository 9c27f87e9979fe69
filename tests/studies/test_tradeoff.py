"""The speed-accuracy study (vemkit.studies.tradeoff): Pareto front, cheapest configuration, Gamma_C gain."""

from pathlib import Path

import numpy as np
import pytest

from vemkit.config.scene import load_scene
from vemkit.io.solution_file import write_netcdf
from vemkit.report.study_figures import pareto_figure
from vemkit.studies.error_records import ReferenceSolution
from vemkit.studies.scene_solve import solve_scene
from vemkit.studies.tradeoff import check_reference_scene, run_family
from vemkit.studies.tradeoff_answers import (
    cheapest_for_targets,
    pareto_front,
    refinement_gain,
    tradeoff_dataset,
    tradeoff_markdown,
)

ROOT = Path(__file__).resolve().parents[2]


def test_pareto_front_of_synthetic_points():
    cost = [1.0, 2.0, 3.0, 2.0, 4.0, 5.0, np.nan, 0.5]
    error = [0.5, 0.3, 0.31, 0.4, 0.1, 0.1, 0.01, np.inf]
    np.testing.assert_array_equal(pareto_front(cost, error), [True, True, False, False, True, False, False, False])
    # equal points: the first counts; a single point is its own front
    np.testing.assert_array_equal(pareto_front([1.0, 1.0], [0.2, 0.2]), [True, False])
    np.testing.assert_array_equal(pareto_front([3.0], [0.1]), [True])


def _record(family, n, error, time, solver="ssn", tol=1e-10, stab="dofi-2mu", status=0):
    dofs = 2 * n * (n + 1) * (2 if family == "refined" else 1)
    return {
        "family": family,
        "family_name": "square",
        "solver": solver,
        "tol": tol,
        "stabilization": stab,
        "n": n,
        "n_dofs": dofs,
        "n_cells": n * n,
        "h_min": 1.0 / n,
        "iterations": 2,
        "status": status,
        "message": "",
        "wall_time": time,
        "assembly_time": 0.0,
        "mesh_time": 0.0,
        "cost_time": time,
        "residual": 0.0,
        "error_h1": error,
        "error_h1_semi": error,
        "error_l2": error / 10,
    }


def _synthetic():
    """Uniform: e = d^-1/2; refined: e = 0.8 d^-1/2 (so 1.25 times more accurate at equal DOFs)."""
    records = []
    for n in (4, 8, 16, 32, 64):
        d = 2 * n * (n + 1)
        records.append(_record("uniform", n, d**-0.5, 1e-3 * d))
        records.append(_record("refined", n, 0.8 * (2 * d) ** -0.5, 1.5e-3 * d))
        records.append(_record("uniform", n, d**-0.5 + 0.05, 0.5e-3 * d, solver="uzawa", tol=1e-4))
    records.append(_record("uniform", 128, np.nan, 99.0, status=3))
    return records


def test_refinement_gain_at_equal_dofs():
    ds = tradeoff_dataset(_synthetic())
    gain = refinement_gain(ds, "uniform", "refined", solver="ssn", tol=1e-10, stabilization="dofi-2mu")
    assert gain["error_ratio"]  # refined DOFs inside the uniform range
    np.testing.assert_allclose([r["ratio"] for r in gain["error_ratio"]], 1.25, rtol=1e-12)
    np.testing.assert_allclose(gain["error_ratio_geometric_mean"], 1.25, rtol=1e-12)
    np.testing.assert_allclose(gain["dofs_ratio_geometric_mean"], 1.25**2, rtol=1e-12)


def test_cheapest_configuration_and_markdown():
    ds = tradeoff_dataset(
        _synthetic(),
        targets=(0.1, 0.01, 1e-4),
        gains=[
            {"uniform": "uniform", "refined": "refined", "solver": "ssn", "tol": 1e-10, "stabilization": "dofi-2mu"}
        ],
    )
    ok = ds["status"].values == 0
    assert not np.any(ds["pareto_time"].values[~ok])
    answers = cheapest_for_targets(ds, (0.1, 0.01, 1e-4))
    for row in answers[:2]:
        reach = ok & (ds["error_h1"].values <= row["target"])
        assert row["reached"]
        assert row["cost_time"]["cost_time"] == pytest.approx(ds["cost_time"].values[reach].min())
        assert row["n_dofs"]["n_dofs"] == ds["n_dofs"].values[reach].min()
        assert row["cost_time"]["error"] <= row["target"]
    assert not answers[2]["reached"] and "closest" in answers[2]
    text = tradeoff_markdown(ds)
    assert f"**For 1% error the cheapest configuration is** {answers[1]['cost_time']['configuration']}" in text
    assert "not reached" in text and "| refined | uniform |" in text and "1.250" in text
    assert "Runs that did not converge" in text
    pareto_figure(ds, "error_h1", (0.01,))


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    scene = load_scene(ROOT / "config/scenes/paper.yaml", ["discretization.mesh.n=32"])
    _, _, ds = solve_scene(scene)
    path = write_netcdf(ds, tmp_path_factory.mktemp("reference") / "n32.nc")
    return scene, ReferenceSolution(path)


def test_run_family_against_a_reference(reference):
    scene, ref = reference
    check_reference_scene(scene, ref.dataset.attrs["scene"])
    with pytest.raises(ValueError, match="material"):
        check_reference_scene(scene.with_overrides(["material.E=1000"]), ref.dataset.attrs["scene"])
    records = run_family(
        scene,
        "square",
        {"family": "square"},
        ref,
        levels=[4, 8, 16],
        solvers=["ssn", "uzawa"],
        tolerances=[1e-10],
        stabilizations=["dofi-2mu"],
        reference_n=32,
        max_iterations={"uzawa": 3000},
    )
    assert len(records) == 6 and all(r["status"] == 0 for r in records)
    ssn = [r["error_h1"] for r in records if r["solver"] == "ssn"]
    assert ssn[0] > ssn[1] > ssn[2] > 0
    hanging = run_family(
        scene,
        "hanging",
        {"family": "hanging", "options": {"levels": 2, "rule": "contact"}},
        ref,
        levels=[4, 8, 16],
        solvers=["ssn"],
        tolerances=[1e-10],
        stabilizations=["dofi-2mu"],
        reference_n=32,
    )
    assert [r["n"] for r in hanging] == [4, 8]  # n = 16 with two levels is finer than the reference
    triangles = run_family(
        scene,
        "tri",
        {"family": "triangle", "options": {"kind": "structured"}},
        ref,
        levels=[4],
        solvers=["ssn"],
        tolerances=[1e-10],
        stabilizations=["dofi-2mu", "trace"],
        reference_n=32,
    )
    assert len(triangles) == 1  # the stabilization vanishes on triangles: solved once
    ds = tradeoff_dataset(records + hanging, targets=(0.5, 0.2))
    assert ds.sizes["run"] == 8 and int(ds["pareto_dofs"].sum()) >= 1
