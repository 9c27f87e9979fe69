"""Stability at the extremes (vemkit.studies.robustness): classification, the independent check, the matrix."""

from pathlib import Path

import numpy as np
import pytest
from conftest import assert_no_nan_stored

from vemkit.config.scene import load_scene
from vemkit.contact.problem import scene_problem
from vemkit.exceptions import ConvergenceError, LinearSolveError, SceneError, TimeBudgetExceeded
from vemkit.report.study_figures import stability_figure
from vemkit.solvers.verification import (
    FAILURE_CLASSES,
    STATUS_MEANINGS,
    failed,
    failure_class,
    guarded_solve,
    verify_solution,
)
from vemkit.studies.robustness import (
    CASE_FAMILIES,
    CASES,
    case_base_scene,
    case_overrides,
    load_case_scenes,
    nodal_average_ratio,
    run_matrix,
    select_cases,
    stability_dataset,
    stability_markdown,
)
from vemkit.studies.sweeps import write_dataset

ROOT = Path(__file__).resolve().parents[2]
SOLVERS = {"ssn": {"max_iterations": 100}, "uzawa": {"max_iterations": 3000, "stop": "both"}}
# one case of each kind of extreme; the whole matrix is the workflow's results/stability
REPRESENTATIVE = [
    "paper",
    "k_nu=1e+08",
    "k_tau=0",
    "k_tau=1e+06",
    "m_nu=3,k_nu=10000",
    "m_tau=1,k_tau=10000",
    "kappa=0.4999",
    "E=0.002",
    "E=2e+09",
    "g_a=10",
    "voronoi,tiny edges,anisotropy=10",
    "hanging,levels=3",
]


@pytest.fixture(scope="module")
def scene():
    return load_scene(ROOT / "config/scenes/paper.yaml")


@pytest.fixture(scope="module")
def matrix(scene):
    return run_matrix(scene, select_cases(REPRESENTATIVE), SOLVERS, 8, time_budget=30)


def test_the_matrix_has_at_least_fifty_valid_cases(scene):
    names = [c["name"] for c in CASES]
    assert len(names) >= 50 and len(set(names)) == len(names)
    k_nu = {c["set"].get("contact.normal.k") for c in CASES}
    assert {1e-3, 1e8} <= k_nu
    assert {0.0, 1e6} <= {c["set"].get("contact.friction.k") for c in CASES}
    assert {2.0, 3.0} <= {c["set"].get("contact.normal.m") for c in CASES}
    assert 1.0 in {c["set"].get("contact.friction.m") for c in CASES}
    assert 0.4999 in {c["set"].get("material.nu") for c in CASES}
    assert {2e-3, 2e9} <= {c["set"].get("material.E") for c in CASES}
    assert {0.0, 10.0} <= {c["set"].get("contact.gap") for c in CASES}
    scenes = load_case_scenes(root=ROOT)
    for case in CASES:  # every case is a valid scene, on its own base scene where it names one
        base = case_base_scene(scene, case, scenes)
        base.with_overrides(case_overrides(case, 8, CASE_FAMILIES[base.dimension] or "hex"))
    with pytest.raises(ValueError, match="box3d"):
        case_base_scene(scene, next(c for c in CASES if c.get("scene") == "box3d"), {})
    with pytest.raises(ValueError, match="unknown"):
        select_cases(["no such case"])


def test_every_case_converges_checked_or_fails_classified(matrix):
    for result in matrix:
        name = result["case"]["name"]
        for method, outcome in result["outcomes"].items():
            assert outcome.status == "converged" or outcome.status in FAILURE_CLASSES, (name, method)
            if outcome.converged:
                checks = outcome.checks
                assert checks["passed"] and checks["worst"] <= 1e-6, (name, method, checks)
                assert all(np.isfinite(outcome.solution.u))
            else:
                assert outcome.message and outcome.solution is None, (name, method)
    ssn = {r["case"]["name"]: r["outcomes"]["ssn"].status for r in matrix}
    assert all(status == "converged" for status in ssn.values()), ssn


def test_uzawa_fails_for_a_stiff_foundation_naming_the_culprit(matrix):
    stiff = next(r for r in matrix if r["case"]["name"] == "k_nu=1e+08")["outcomes"]["uzawa"]
    assert stiff.status in ("diverged", "stagnated", "max_iterations")
    assert "contact.normal.k" in stiff.message and stiff.iterations > 0


def test_the_independent_check_catches_wrong_solutions(scene):
    problem = scene_problem(scene.with_overrides(["discretization.mesh.n=8"]))
    outcome = guarded_solve(problem, {"method": "ssn", "tol": 1e-10})
    u, lam = outcome.solution.u, outcome.solution.multiplier
    assert verify_solution(problem, u, lam)["passed"]
    assert verify_solution(problem, 1.001 * u, lam)["equilibrium"] > 1e-4
    wrong = verify_solution(problem, u, -lam)
    assert not wrong["passed"] and wrong["complementarity"] > 0.1
    assert not verify_solution(problem, np.full_like(u, np.nan), lam)["passed"]


def test_failure_classes_come_from_types_and_attributes_not_messages():
    def raised_from(exc, cause):
        try:
            try:
                raise cause
            except type(cause) as inner:
                raise exc from inner
        except type(exc) as raised:
            return raised

    # the messages say one thing, the attributes another: the attributes win
    misleading = "uzawa diverged after 5 iterations (non-finite values, |Δu| stagnated, max_iterations = 9 reached)"
    for reason in ("diverged", "stagnated", "max_iterations", "inaccurate_stop", "other"):
        error = ConvergenceError(misleading, solver="uzawa", reason=reason, iterations=7)
        assert failure_class(error) == reason
        outcome = failed("uzawa", error, "solve")
        assert (outcome.status, outcome.iterations) == (reason, 7)
    assert failure_class(ConvergenceError("ssn diverged after 3 iterations")) == "other"  # no reason given
    assert failed("ssn", ConvergenceError("ssn did not converge after 50 iterations"), "solve").iterations == -1
    assert failure_class(TimeBudgetExceeded("diverged")) == "time_budget"
    wrapped = ConvergenceError("ssn: diverged", solver="ssn", reason="linear_solver_failed", iterations=2)
    assert failure_class(wrapped) == "linear_solver_failed"
    assert (
        failure_class(raised_from(ConvergenceError("ssn: diverged"), LinearSolveError("cg"))) == "linear_solver_failed"
    )
    assert failure_class(LinearSolveError("diverged")) == "linear_solver_failed"
    assert failure_class(SceneError("contact.normal.k = -1: must be >= 0")) == "invalid_input"
    assert failure_class(ValueError("anything"), phase="setup") == "invalid_input"
    assert failure_class(ValueError("solver.rho = -1"), phase="solve") == "unexpected_exception"
    assert failure_class(KeyError("x")) == "unexpected_exception"
    with pytest.raises(ValueError, match="unknown solve failure reason"):
        ConvergenceError("x", reason="no such reason")


def test_real_solver_failures_carry_their_class():
    """Each solver failure raised by the solvers names its reason, solver and iteration."""
    from conftest import paper_problem

    from vemkit.contact.laws import ContactLaw
    from vemkit.mesh.families.square import square
    from vemkit.solvers.ssn import solve_ssn
    from vemkit.solvers.uzawa import solve_uzawa

    stick_slip = paper_problem(square(8), law=ContactLaw(10.0, 1.0, 700.0, 0.0))
    stiff = paper_problem(square(8), law=ContactLaw(1e6, 1.0, 450.0, 0.0))
    cases = [
        (lambda: solve_ssn(stick_slip, linear="direct", max_iterations=1), "ssn", ("max_iterations",)),
        (lambda: solve_uzawa(stick_slip, linear="direct", max_iterations=5), "uzawa", ("max_iterations",)),
        (lambda: solve_uzawa(stiff, linear="direct"), "uzawa", ("diverged", "stagnated")),
        (
            lambda: solve_uzawa(paper_problem(square(8)), linear="direct", rho=1.0, max_iterations=3),
            "uzawa",
            ("inaccurate_stop",),
        ),
    ]
    for run, solver, reasons in cases:
        with pytest.raises(ConvergenceError) as failure:
            run()
        error = failure.value
        assert error.solver == solver and error.reason in reasons and error.iterations > 0, (solver, str(error))
        assert failure_class(error) == error.reason


def test_time_budget_is_a_classified_failure(scene):
    problem = scene_problem(scene.with_overrides(["discretization.mesh.n=8"]))
    outcome = guarded_solve(problem, {"method": "uzawa", "tol": 1e-10}, time_budget=1e-9)
    assert outcome.status == "time_budget" and "time budget" in outcome.message


def test_dataset_table_and_plot(matrix, tmp_path):
    ds = stability_dataset(matrix, settings={"n": 8, "check_tol": 1e-6})
    assert ds["status"].dims == ("case", "solver") and list(ds["solver"].values) == ["ssn", "uzawa"]
    assert ds["status"].attrs["flag_meanings"].split() == list(STATUS_MEANINGS)
    assert float(ds["k_nu"].sel(case="k_nu=1e+08")) == 1e8 and float(ds["kappa"].sel(case="kappa=0.4999")) == 0.4999
    path = write_dataset(ds, tmp_path / "stability.nc")
    assert_no_nan_stored(path)
    text = stability_markdown(ds)
    assert "| k_nu=1e+08 |" in text and "## Failures" in text and "**ssn**: converged" in text
    fig = stability_figure(ds)
    fig.savefig(tmp_path / "stability.png")
    assert (tmp_path / "stability.png").stat().st_size > 10_000


def test_nu_to_one_half_on_every_family_with_and_without_the_nodal_average(scene):
    """Every 2D family in plane strain and every 3D family on the box, nu in (0.49, 0.499, 0.4999),
    volumetric_strain cell and nodal_average; the 3D foundations reach 1e7 E, the friction mu = 1e3."""
    scenes = load_case_scenes(root=ROOT)
    declared = {
        (case.get("scene"), case["set"]["discretization.mesh"]["family"], case["set"]["material.nu"], volumetric)
        for case in CASES
        if (volumetric := case["set"].get("discretization.volumetric_strain")) and case["group"].startswith("incompr")
    }
    families = {None: ("square", "triangle", "voronoi", "hanging"), "box3d": ("hex", "tet", "voronoi", "octree")}
    wanted = {
        (where, family, nu, volumetric)
        for where, names in families.items()
        for family in names
        for nu in (0.49, 0.499, 0.4999)
        for volumetric in ("cell", "nodal_average")
    }
    assert declared == wanted
    assert all(c["set"]["model"] == "plane_strain" for c in CASES if c["group"] == "incompressible 2D")
    box = [c for c in CASES if c.get("scene") == "box3d"]
    box_e = scenes["box3d"].data["material"]["E"]
    assert max(c["set"].get("contact.normal.k", 0.0) for c in box) == pytest.approx(1e7 * box_e)
    coupled = [c["set"] for c in box if c["set"].get("contact.friction.m") == 1.0]
    assert max(s["contact.friction.k"] / s.get("contact.normal.k", 10.0) for s in coupled) == pytest.approx(1e3)


def test_plane_strain_triangles_lock_with_the_cell_form_and_not_with_the_nodal_average(scene):
    """nu = 0.4999 on 16 x 16 triangles (the matrix's mesh): the recorded u_max of the cell form
    misses the squares' by > 3 % (5.5 %), the nodal average's is within 0.5 % (0.03 %)."""
    names = [f"plane strain,{f},kappa=0.4999,{v}" for f, v in (("triangle", "cell"), ("triangle", "nodal_average"))]
    names.append("plane strain,square,kappa=0.4999,nodal_average")
    results = run_matrix(scene, select_cases(names), {"ssn": {}}, 16)
    cell, nodal, square = (r["u_max"]["ssn"] for r in results)
    assert all(r["outcomes"]["ssn"].converged for r in results)
    assert abs(cell / square - 1) > 0.03 and abs(nodal / square - 1) < 0.005, (cell, nodal, square)
    ds = stability_dataset(results)
    assert ds["u_max"].dims == ("case", "solver") and "largest displacement" in ds["u_max"].attrs["long_name"]
    assert list(ds["volumetric_strain"].values) == ["cell", "nodal_average", "nodal_average"]
    assert set(ds["model"].values) == {"plane_strain"}
    ratio = nodal_average_ratio(ds)  # the table's (×r) and the figure's right panel
    assert ratio[0] == pytest.approx(cell / nodal) and ratio[1] == ratio[2] == 1.0
    text = stability_markdown(ds)
    assert "| max \\|u\\| |" in text and f"(×{cell / nodal:.4f})" in text
