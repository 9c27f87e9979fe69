"""Adaptive against uniform (vemkit.studies.adaptivity_compare) on histories with known answers."""

import numpy as np
import pytest

from vemkit.studies.adaptivity_compare import compare, dofs_at_error, fitted_rate, summary_markdown


def _history(dofs, error, seconds_per_dof=1e-5):
    dofs = np.asarray(dofs, float)
    error = np.asarray(error, float)
    return {
        "n_dofs": dofs,
        "true_error_h1": error,
        "estimate": 2.0 * error,
        "effectivity": np.full(dofs.size, 2.0),
        "wall_time": seconds_per_dof * dofs,
        "solve_time": 0.5 * seconds_per_dof * dofs,
    }


def test_the_fitted_rate_of_a_power_law_is_its_exponent_after_the_coarse_steps():
    dofs = 40.0 * 1.6 ** np.arange(14)
    error = 3.0 * dofs**-0.5
    error[:3] *= 1.7  # pre-asymptotic: left out (fewer than 8 x the first step's DOFs)
    fit = fitted_rate(dofs, error)
    assert fit["rate"] == pytest.approx(-0.5, abs=1e-12) and fit["constant"] == pytest.approx(3.0, rel=1e-10)
    assert fit["from_dofs"] >= 8 * 40


def test_dofs_at_error_interpolates_log_log_and_knows_when_a_run_never_gets_there():
    dofs, error = [100.0, 400.0, 1600.0], [0.1, 0.05, 0.025]  # error = N^-1/2
    assert dofs_at_error(dofs, error, 0.05) == pytest.approx(400.0)
    assert dofs_at_error(dofs, error, 0.1 / np.sqrt(2.0)) == pytest.approx(200.0)
    assert dofs_at_error(dofs, error, 0.2) == 100.0 and dofs_at_error(dofs, error, 0.01) is None


def test_compare_finds_the_dofs_ratio_at_the_finest_uniform_error():
    """Uniform: e = N^-1/4 (a corner singularity); adaptive: e = N^-1/2. At the finest uniform step
    e_u = 4096^-1/4 = 1/8, reached adaptively at N = 64: 64 times fewer DOFs."""
    uniform = _history(4.0 ** np.arange(1, 7), (4.0 ** np.arange(1, 7)) ** -0.25)
    steps = 2.0 ** np.arange(2, 13)
    adaptive = _history(steps, steps**-0.5)
    out = compare(adaptive, uniform, targets=(0.2,))
    assert out["rates"]["adaptive"]["rate"] == pytest.approx(-0.5) and out["rates"]["uniform"]["rate"] == pytest.approx(
        -0.25
    )
    finest = out["finest_uniform"]
    assert finest["adaptive_dofs"] == pytest.approx(64.0) and finest["dofs_ratio"] == pytest.approx(64.0)
    assert finest["adaptive_time"] == pytest.approx(1e-5 * sum(2.0 ** np.arange(2, 7)))  # every step up to N = 64
    assert finest["uniform_time"] == pytest.approx(0.5e-5 * 4096)  # the one uniform solve
    target = out["targets"][0]  # 0.2: adaptive N = 25, uniform N = 5^4 = 625
    assert target["adaptive_dofs"] == pytest.approx(25.0) and target["uniform_dofs"] == pytest.approx(625.0)
    assert out["effectivity_adaptive"] == [2.0, 2.0]
    text = summary_markdown({"corner": out})
    assert "| corner | true_error_h1 | -0.500 | -0.250 |" in text and "| 64.00 |" in text


def test_the_adaptive_loop_enters_the_speed_accuracy_study_as_a_configuration():
    from pathlib import Path

    from vemkit.config.scene import load_scene
    from vemkit.studies.adaptivity_compare import tradeoff_records
    from vemkit.studies.error_records import ReferenceSolution
    from vemkit.studies.scene_solve import solve_scene
    from vemkit.studies.tradeoff_answers import (
        RECORD_FLOATS,
        RECORD_INTS,
        RECORD_STRINGS,
        cheapest_for_targets,
        tradeoff_dataset,
    )

    paper = Path(__file__).resolve().parents[2] / "config" / "scenes" / "paper.yaml"
    problem, _, ds = solve_scene(load_scene(paper, ["discretization.mesh.n=32"]))
    reference = ReferenceSolution("<n = 32>", solution=(problem.mesh, ds))
    scene = load_scene(paper, ["discretization.mesh.n=4"])
    records = tradeoff_records(
        scene, reference, theta=0.5, max_dofs=1500, solvers=["ssn"], tolerances=[1e-8], stabilization="dofi-2mu"
    )
    assert all(set(RECORD_FLOATS + RECORD_INTS + RECORD_STRINGS) <= set(r) for r in records)
    dofs, cost, error = (np.array([r[k] for r in records]) for k in ("n_dofs", "cost_time", "error_h1"))
    assert len(records) >= 4 and np.all(np.diff(dofs) > 0) and np.all(np.diff(cost) > 0)
    assert np.all(np.diff(error) < 0) and error[0] == pytest.approx(0.19, abs=0.02)  # n = 4 against n = 32
    study = tradeoff_dataset(records, targets=(0.05,))
    answer = cheapest_for_targets(study, (0.05,))[0]
    assert answer["reached"] and answer["n_dofs"]["configuration"].startswith("adaptive, ssn")
