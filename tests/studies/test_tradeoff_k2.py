"""k = 2 in the speed-accuracy study (vemkit.studies.tradeoff, issue 14 item 5): errors of Pi_2 u_h,
DOFs of the whole k = 2 space, k = 2 in the Pareto answer and in the k = 1 / k = 2 comparison."""

from pathlib import Path

import pytest

from vemkit.config.scene import load_scene
from vemkit.exceptions import InputError
from vemkit.io.solution_file import write_netcdf
from vemkit.mesh.families import build_mesh
from vemkit.studies.error_records import ReferenceSolution
from vemkit.studies.scene_solve import solve_scene
from vemkit.studies.tradeoff import family_order, run_family
from vemkit.studies.tradeoff_answers import tradeoff_dataset, tradeoff_markdown
from vemkit.vem.elements.k1_fields import projected_solution
from vemkit.vem.norms import projection_error
from vemkit.vem.quadrature import reference_quadrature

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "config/scenes/paper.yaml"
RUN = {"solvers": ["ssn"], "tolerances": [1e-10], "stabilizations": ["dofi-2mu"]}


def _reference(tmp_path_factory, n, order):
    scene = load_scene(PAPER, [f"discretization.mesh.n={n}", f"discretization.order={order}"])
    _, _, ds = solve_scene(scene, mesh=build_mesh("square", n))
    return load_scene(PAPER), ReferenceSolution(write_netcdf(ds, tmp_path_factory.mktemp("ref") / f"k{order}.nc"))


@pytest.fixture(scope="module")
def k2_reference(tmp_path_factory):
    return _reference(tmp_path_factory, 8, 2)


def test_a_k2_run_is_measured_with_pi2_on_its_own_reference(k2_reference):
    """The same problem on the same mesh as a k = 2 reference: Pi_2 on both sides gives zero error
    (to the solver tolerance); Pi_1 of the k = 2 vertex values would not (an O(h) error)."""
    scene, ref = k2_reference
    assert ref.order == 2
    (record,) = run_family(scene, "square-k2", {"family": "square", "order": 2}, ref, levels=[8], reference_n=8, **RUN)
    assert record["status"] == 0 and record["order"] == 2
    assert record["error_h1"] < 1e-8 and record["error_l2"] < 1e-8
    assert record["n_dofs"] == record["n_unknowns"] + 2 * record["n_cells"]  # the condensed cell means count
    vertex = ref.displacement  # the wrong measure: Pi_1 of the k = 2 solution's vertex values
    wrong = projection_error(
        ref.mesh,
        projected_solution(ref.mesh, vertex),
        ref.mesh,
        ref.projected,
        reference_quadrature(ref.mesh, degree=5),
    )
    assert wrong["h1"] > 1e-2
    (k1,) = run_family(scene, "square", {"family": "square"}, ref, levels=[8], reference_n=8, **RUN)
    assert k1["order"] == 1 and k1["error_h1"] > 1e-2


@pytest.fixture(scope="module")
def k1_reference(tmp_path_factory):
    return _reference(tmp_path_factory, 32, 1)


def test_k2_beats_k1_at_equal_mesh_against_the_k1_reference(k1_reference):
    scene, ref = k1_reference
    k2 = run_family(scene, "square-k2", {"family": "square", "order": 2}, ref, levels=[4, 8], reference_n=32, **RUN)
    k1 = run_family(scene, "square", {"family": "square"}, ref, levels=[4, 8], reference_n=32, **RUN)
    assert all(r["status"] == 0 for r in k1 + k2)
    assert k2[0]["error_h1"] > k2[1]["error_h1"]
    for one, two in zip(k1, k2, strict=True):
        assert two["error_h1"] < 0.6 * one["error_h1"], (one["error_h1"], two["error_h1"])
    tri = run_family(
        scene,
        "tri-k2",
        {"family": "triangle", "options": {"kind": "structured"}, "order": 2},
        ref,
        levels=[4],
        solvers=["ssn"],
        tolerances=[1e-10],
        stabilizations=["dofi-2mu", "trace"],
        reference_n=32,
    )
    assert len(tri) == 2  # k = 2 on triangles is not P2: every stabilization counts


def _record(family, order, n, error, time):
    dofs = 2 * n * (n + 1) * order**2
    return {
        "family": family,
        "family_name": "square",
        "solver": "ssn",
        "tol": 1e-10,
        "stabilization": "dofi-2mu",
        "n": n,
        "order": order,
        "n_dofs": dofs,
        "n_unknowns": dofs,
        "n_cells": n * n,
        "h_min": 1.0 / n,
        "iterations": 2,
        "status": 0,
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


def test_the_pareto_answer_includes_k2():
    """Synthetic runs where k = 2 reaches 1 % fastest: the answer, the front and the comparison name it."""
    records = [_record("square", 1, n, 1.0 / n, 1e-4 * n * n) for n in (4, 8, 16, 32, 64, 128)]
    records += [_record("square-k2", 2, n, 0.3 / n, 3e-4 * n * n) for n in (4, 8, 16, 32)]
    adaptive = {k: v for k, v in _record("adaptive", 1, 8, 0.2, 0.5).items() if k not in ("order", "n_unknowns")}
    ds = tradeoff_dataset(records + [adaptive], targets=(0.05, 0.01))
    assert ds["order"].values[-1] == 1 and ds["n_unknowns"].values[-1] == ds["n_dofs"].values[-1]
    text = tradeoff_markdown(ds)
    assert "**For 1% error the cheapest configuration is** square-k2 (k = 2), ssn" in text
    assert "## First against second order" in text
    k2_front = (ds["order"].values == 2) & (ds["pareto_time"].values == 1)
    assert k2_front.any()
    line = next(x for x in text.splitlines() if x.startswith("| 1% | square, ssn"))
    assert "square-k2 (k = 2)" in line and line.rstrip(" |").endswith("0.19")  # 0.3072 s / 1.6384 s


def test_an_unknown_order_is_refused():
    with pytest.raises(InputError, match="order 1 or 2"):
        family_order({"family": "square", "order": 3})
    assert family_order({"family": "square"}) == 1
