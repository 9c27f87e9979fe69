"""3D contact through the real CLI (docs/reference/files.md, issue 21 items 1-2): a box pressed on a foundation plane
gives the solution file's contact node variables (the per-vertex basis, tangential quantities with a
``contact_tangent`` dimension of size 2), and bad 3D contact keys are refused in one line (exit 2,
nothing written)."""

import subprocess
import sys

import netCDF4
import numpy as np
import pytest

from vemkit.io.solution_file import read_solution

DELTA, K, E, H = 0.01, 200.0, 1000.0, 0.5
SCENE = f"""name: pressed3d
model: 3d
domain: {{box: [[0, 0, 0], [1, 1, {H}]]}}
material: {{E: {E}, nu: 0.3}}
boundary:
  dirichlet: {{top: [0.003, 0.001, {-DELTA}]}}
  contact: [bottom]
contact:
  foundation: {{point: [0, 0, 0], normal: [0, 0, 1]}}
  normal: {{k: {K}, m: 1.0}}
  friction: {{k: 3.0, m: 0.0}}
discretization: {{mesh: {{family: hex, n: 3}}}}
solver: {{method: ssn, tol: 1.0e-12}}
"""


def vemkit(*args):
    return subprocess.run([sys.executable, "-m", "vemkit.cli", *map(str, args)], capture_output=True, text=True)


def test_a_3d_contact_solve_writes_the_contact_node_variables(tmp_path):
    (tmp_path / "s.yaml").write_text(SCENE)
    run = vemkit("solve", tmp_path / "s.yaml", "-o", tmp_path / "s.nc", "-q")
    assert run.returncode == 0, run.stderr
    mesh, ds = read_solution(tmp_path / "s.nc")
    n_c = 16  # the 4 x 4 vertices of the bottom
    assert ds.sizes["contact_node"] == n_c and ds.sizes["contact_tangent"] == 2
    for name in (
        "contact_x",
        "contact_y",
        "contact_z",
        "contact_vertex",
        "contact_weight",
        "normal_pressure",
        "penetration",
        "friction_bound",
        "contact_state",
        *(f"contact_{v}_{a}" for v in ("normal", "tangent1", "tangent2") for a in "xyz"),
    ):
        assert ds[name].dims == ("contact_node",), name
    for name in ("tangential_stress", "friction_multiplier", "slip"):
        assert ds[name].dims == ("contact_node", "contact_tangent"), name
    assert "contact_tangent1" in ds.attrs["contact_tangent_basis"]
    assert np.isclose(ds["contact_weight"].sum(), 1.0) and np.allclose(ds["contact_z"], 0.0)
    vertex = ds["contact_vertex"].values
    for k, axis in enumerate("xyz"):
        assert np.allclose(mesh.vertices[vertex, k], ds[f"contact_{axis}"])
    basis = np.stack(
        [np.stack([ds[f"contact_{v}_{a}"].values for a in "xyz"], axis=1) for v in ("tangent1", "tangent2", "normal")],
        axis=1,
    )
    assert np.allclose(basis @ basis.transpose(0, 2, 1), np.eye(3))
    # the slip in the basis is the displacement of the vertex projected on t1, t2
    u = np.stack([ds[f"u{c}"].values[vertex] for c in (1, 2, 3)], axis=1)
    assert np.allclose(ds["slip"].values, np.einsum("cti,ci->ct", basis[:, :2], u), rtol=0, atol=1e-15)
    lam = ds["friction_multiplier"].values
    assert np.all(np.linalg.norm(lam, axis=1) <= 1 + 1e-12)
    assert np.allclose(ds["tangential_stress"].values, -ds["friction_bound"].values[:, None] * lam)
    assert np.allclose(ds["normal_pressure"], K * np.maximum(ds["penetration"], 0))
    with netCDF4.Dataset(tmp_path / "s.nc") as nc:
        assert nc["slip"].dimensions == ("contact_node", "contact_tangent")


BAD = {
    "contact.foundation.normal=[0, 0, 0]": "contact.foundation.normal = [0, 0, 0]",
    "contact.foundation.normal=[0, 1]": "give 3",
    "contact.foundation.point=[0, 0, 0.1]": "beyond the foundation plane",
    "contact.foundation={point: [0, 0, -0.1], normal: [0, 0, -1]}": "beyond the foundation plane",
    "discretization.contact_quadrature=simpson": "contact_quadrature",
    "contact.normal.k=1e15": "must be at most",
}


@pytest.mark.parametrize("override", list(BAD))
def test_bad_3d_contact_keys_are_refused_in_one_line(tmp_path, override):
    (tmp_path / "s.yaml").write_text(SCENE)
    run = vemkit("solve", tmp_path / "s.yaml", "-o", tmp_path / "s.nc", "--set", override)
    assert run.returncode == 2, run.stderr
    assert len(run.stderr.strip().splitlines()) == 1 and BAD[override] in run.stderr, run.stderr
    assert not (tmp_path / "s.nc").exists()


@pytest.mark.parametrize("gap, message", [("'-0.01 + z'", "< 0 at x="), ("'1/(x - 0.5)'", "finite"), ("'0.01*w'", "w")])
def test_a_bad_3d_gap_expression_is_refused_in_one_line(tmp_path, gap, message):
    text = SCENE.replace("  foundation: {point: [0, 0, 0], normal: [0, 0, 1]}", f"  gap: {gap}")
    (tmp_path / "s.yaml").write_text(text)
    run = vemkit("solve", tmp_path / "s.yaml", "-o", tmp_path / "s.nc")
    assert run.returncode == 2 and len(run.stderr.strip().splitlines()) == 1 and message in run.stderr, run.stderr
    assert not (tmp_path / "s.nc").exists()


def test_a_2d_scene_refuses_a_3d_foundation_in_one_line(tmp_path):
    text = (
        "domain: unit_square\nmaterial: {E: 1000.0, nu: 0.3}\nboundary: {dirichlet: [top], contact: [bottom]}\n"
        "contact:\n  foundation: {point: [0, 0, 0], normal: [0, 0, 1]}\n  normal: {k: 1.0, m: 1.0}\n"
        "  friction: {k: 0.0, m: 0.0}\ndiscretization: {mesh: {family: square, n: 2}}\n"
    )
    (tmp_path / "s.yaml").write_text(text)
    run = vemkit("solve", tmp_path / "s.yaml", "-o", tmp_path / "s.nc")
    assert run.returncode == 2 and len(run.stderr.strip().splitlines()) == 1, run.stderr
    assert "a 2D scene's foundation is a line: give 2" in run.stderr
    assert not (tmp_path / "s.nc").exists()
