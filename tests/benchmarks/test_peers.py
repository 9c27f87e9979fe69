"""vemkit k = 1 on triangles is the P1 finite element method: the same discrete problem as
scikit-fem and GetFEM (benchmarks/peers.py, issue 22), pinned on small meshes.

GetFEM runs under the system /usr/bin/python3 (Debian python3-getfem; `make peers` and .ci/run
install it when root); without it those cases are skipped with the reason.
"""

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

import vemkit

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
sys.path.append(str(BENCHMARKS))  # appended: the benchmark scripts' names shadow nothing
peers = pytest.importorskip("peers", reason="benchmarks/peers.py")

STICKING_K = 4000.0
MESHES = {"structured": dict(kind="structured"), "delaunay": dict(kind="delaunay", seed=1)}


def _module(path: Path, name: str):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def vemkit_displacement(problem, mesh, mesh_entry, tmp_path, friction_k=peers.FRICTION_K):
    scene_path = tmp_path / f"{problem}.yaml"
    scene_path.write_text(yaml.safe_dump(peers.vemkit_scene(problem, mesh_entry, friction_k)))
    scene = vemkit.load_scene(scene_path)
    discrete = vemkit.scene_problem(scene, mesh)
    ds = vemkit.solution_dataset(discrete, vemkit.solve(discrete, scene.solver_options))
    return np.stack([ds.u1.values, ds.u2.values], axis=1)


def small_case(kind: str, n: int = 8):
    mesh = vemkit.build_mesh("triangle", n, **MESHES[kind])
    return mesh, {"family": "triangle", "n": n, **MESHES[kind]}, peers.case_from_mesh(mesh)


@pytest.mark.parametrize("kind", sorted(MESHES))
def test_elasticity_equals_scikit_fem_p1(kind, tmp_path):
    pytest.importorskip("skfem")
    mesh, entry, case = small_case(kind)
    u_vem = vemkit_displacement("elasticity", mesh, entry, tmp_path)
    skfem_solve = _module(BENCHMARKS / "peers" / "skfem_solve.py", "skfem_solve")
    np.savez(tmp_path / "case.npz", params=peers.json.dumps(peers.peer_params("elasticity", 100)), **case)
    skfem_solve.main(tmp_path / "case.npz", tmp_path / "out.npz")
    u_skfem = np.load(tmp_path / "out.npz")["u"]
    assert np.abs(u_vem).max() > 1e-3
    assert peers.relative_difference(u_skfem, u_vem) <= 1e-10


@pytest.mark.parametrize("problem", peers.PROBLEMS)
@pytest.mark.parametrize("kind", sorted(MESHES))
def test_getfem_solves_the_same_discrete_problem(kind, problem, tmp_path):
    reason = peers.getfem_missing()
    if reason:
        pytest.skip(reason)
    mesh, entry, case = small_case(kind)
    u_vem = vemkit_displacement(problem, mesh, entry, tmp_path)
    u_getfem, record = peers.run_peer("getfem", problem, case, tmp_path)
    assert peers.relative_difference(u_getfem, u_vem) <= 1e-8, record


def test_getfem_friction_with_sticking_vertices(tmp_path):
    """A friction bound large enough that part of Gamma_C sticks: both branches of the law."""
    reason = peers.getfem_missing()
    if reason:
        pytest.skip(reason)
    mesh, entry, case = small_case("structured")
    u_vem = vemkit_displacement("friction", mesh, entry, tmp_path, friction_k=STICKING_K)
    params = peers.peer_params("friction", 100, friction_k=STICKING_K)
    u_getfem, record = peers.run_peer("getfem", "friction", case, tmp_path, params)
    bottom = np.unique(case["side_bottom"])
    assert np.sum(np.abs(u_vem[bottom, 0]) < 1e-12) >= 3  # sticking vertices besides the clamped one
    assert peers.relative_difference(u_getfem, u_vem) <= 1e-8, record


def test_getfem_dirichlet_with_multipliers_is_the_eliminated_problem(tmp_path):
    """The peer's two ways to impose u = 0 (multipliers, the default; dof elimination) solve the
    same discrete problem: the multiplier's boundary mass matrix is regular on the side's dofs."""
    reason = peers.getfem_missing()
    if reason:
        pytest.skip(reason)
    _, _, case = small_case("structured")
    params = peers.peer_params("compliance", 100)
    u_multipliers, record = peers.run_peer("getfem", "compliance", case, tmp_path, params)
    eliminated = params | {"getfem_dirichlet": "simplification"}
    u_eliminated, _ = peers.run_peer("getfem", "compliance", case, tmp_path, eliminated)
    right = np.unique(case["side_right"])
    assert np.abs(u_multipliers[right]).max() <= 1e-12 < np.abs(u_multipliers).max()
    assert peers.relative_difference(u_multipliers, u_eliminated) <= 1e-10, record


def test_vemkit_3d_on_tetrahedra_is_scikit_fem_p1_through_the_benchmark(tmp_path):
    """benchmarks/peers3d.py's case (issue 22 (d)): the whole path, both processes, one small mesh."""
    peers3d = pytest.importorskip("peers3d", reason="benchmarks/peers3d.py")
    vem, skfem_row = peers3d.run_case(3, tmp_path)
    assert vem["dofs"] == skfem_row["dofs"] == 3 * 4**3
    assert skfem_row["rel_diff_to_vemkit"] < 1e-10


@pytest.mark.parametrize("problem", ["elasticity", "compliance", "friction"])
def test_getfem_p1_tetrahedra_solve_the_same_3d_problem(problem, tmp_path):
    """benchmarks/peers3d.py against GetFEM (issue 22 (d)): 3D elasticity; the box pressed onto a
    curved foundation with the 7-point face rule on both sides (vemkit gauss, 3 points; GetFEM
    IM_TETRAHEDRON(5)), part of the bottom in contact; and the same box sheared, with Coulomb's law on
    the compliance pressure (nodal rule), sticking and sliding vertices."""
    reason = peers.getfem_missing()
    if reason:
        pytest.skip(reason)
    peers3d = pytest.importorskip("peers3d", reason="benchmarks/peers3d.py")
    u_vem, _, case = peers3d.run_vemkit(4, problem, tmp_path)
    u_getfem, record = peers3d.run_peer("getfem", problem, 4, case, tmp_path)
    if problem != "elasticity":
        bottom = np.unique(case["side_bottom"])
        t = -u_vem[bottom, 2] - peers3d.gap_at(case["vertices"][bottom])  # nu = -e_z
        assert 0 < np.sum(t > 0) < bottom.size - 3, t  # a contact zone and vertices out of contact
    if problem == "friction":
        with xr.open_dataset(tmp_path / "solve-friction-4.nc") as ds:
            lam = np.linalg.norm(ds.friction_multiplier.values, axis=1)[ds.penetration.values > 0]
        assert np.any(lam < 1 - 1e-6) and np.any(lam > 1 - 1e-12), lam  # sticking and sliding
    assert np.abs(u_vem).max() > 1e-3
    assert peers.relative_difference(u_getfem, u_vem) <= 1e-8, record


def test_getfem_3d_compliance_newton_converges_from_the_dirichlet_value(tmp_path):
    """n = 8 (2 187 DOFs): with the top's displacement imposed by multipliers, GetFEM's Newton from
    u = 0 stalled in its line search (100 steps); started from u = the value on the side it takes
    the steps of the eliminated problem and solves vemkit's discrete problem."""
    reason = peers.getfem_missing()
    if reason:
        pytest.skip(reason)
    peers3d = pytest.importorskip("peers3d", reason="benchmarks/peers3d.py")
    u_vem, _, case = peers3d.run_vemkit(8, "compliance", tmp_path)
    u_getfem, record = peers3d.run_peer("getfem", "compliance", 8, case, tmp_path)
    assert record["iterations"] <= 6, record
    assert peers.relative_difference(u_getfem, u_vem) <= 1e-8, record
