"""discretization.order = 2 where a study would mis-measure it (Pi_1 of vertex values, docs/reference/mathematics.md) is refused
with a typed one-line error; the studies that measure k = 2 correctly (sweeps, robustness matrix: contact
quantities on the k = 2 contact boundary) accept it and agree with k = 1."""

from pathlib import Path

import pytest

from vemkit.config.scene import load_scene
from vemkit.exceptions import InputError, SceneError
from vemkit.io.solution_file import write_netcdf
from vemkit.mesh.families import build_mesh
from vemkit.studies.error_records import ReferenceSolution, solved_error_records
from vemkit.studies.robustness import run_case, select_cases
from vemkit.studies.scene_solve import solve_scene
from vemkit.studies.solution_order import require_order1
from vemkit.studies.sweeps import run_grid

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "config/scenes/paper.yaml"


@pytest.fixture(scope="module")
def solutions(tmp_path_factory):
    out = {}
    for order in (1, 2):
        scene = load_scene(PAPER, ["discretization.mesh.n=4", f"discretization.order={order}"])
        _, _, ds = solve_scene(scene, mesh=build_mesh("square", 4))
        out[order] = write_netcdf(ds, tmp_path_factory.mktemp("k") / f"k{order}.nc")
    return out


def test_the_convergence_measure_refuses_k2_solutions(solutions):
    k1, k2 = ReferenceSolution(solutions[1]), ReferenceSolution(solutions[2])
    with pytest.raises(InputError, match="discretization.order = 2") as caught:
        k1.errors(k2.mesh, k2.dataset)  # a k = 2 run against a k = 1 reference
    assert caught.value.key == "discretization.order" and "\n" not in str(caught.value)
    with pytest.raises(InputError, match="reference has discretization.order = 2"):
        k2.errors(k1.mesh, k1.dataset)
    assert set(k1.errors(k1.mesh, k1.dataset)) == {"h1", "h1_semi", "l2", "paper"}


def test_solved_error_records_refuse_order2_before_solving():
    meshes = [(4, build_mesh("square", 4))]
    with pytest.raises(SceneError, match="convergence study") as caught:
        solved_error_records(
            "square",
            {"family": "square"},
            "dofi-2mu",
            meshes,
            (8, build_mesh("square", 8)),
            PAPER,
            overrides=["discretization.order=2"],
        )
    assert caught.value.key == "discretization.order"
    require_order1(load_scene(PAPER), "anything")  # k = 1 passes


def test_sweeps_and_robustness_measure_k2_on_its_own_contact_boundary():
    """Contact quantities come from the k = 2 contact boundary (Simpson nodes): the normal force of
    k = 2 on 16^2 squares agrees with k = 1 on 32^2 to 0.5 % (measured 0.13 %), and k = 2 moves less
    between 8^2 and 16^2 than k = 1 does."""
    force = {}
    for order, n in ((1, 16), (1, 32), (2, 8), (2, 16)):
        scene = load_scene(PAPER, [f"discretization.mesh.n={n}", f"discretization.order={order}"])
        (point,) = run_grid(scene, {"contact.normal.k": [1000.0]}).values()
        assert point.outcome.converged
        force[order, n] = point.quantities["normal_force"]
    assert abs(force[2, 16] - force[1, 32]) < 5e-3 * abs(force[1, 32])
    assert abs(force[2, 8] - force[2, 16]) < abs(force[1, 16] - force[1, 32])
    result = run_case(load_scene(PAPER, ["discretization.order=2"]), select_cases()[0], {"ssn": {}}, 8)
    assert result["outcomes"]["ssn"].converged
