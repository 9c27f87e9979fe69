"""`vemkit solve` and `vemkit mesh`: the docs/reference/files.md contract, end to end through the console script."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "config" / "scenes" / "paper.yaml"


def vemkit(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "vemkit.cli", *map(str, args)], capture_output=True, text=True, cwd=cwd
    )


def test_solve_writes_the_contract_file(tmp_path):
    out = tmp_path / "paper.nc"
    vtu = tmp_path / "paper.vtu"
    run = vemkit("solve", PAPER, "-o", out, "--set", "discretization.mesh.n=8", "--vtu", vtu)
    assert run.returncode == 0, run.stderr
    assert vtu.exists()
    with xr.open_dataset(out, mask_and_scale=False) as ds:
        assert ds["mesh2d"].attrs["cf_role"] == "mesh_topology"
        for name in ("mesh2d_node_x", "mesh2d_node_y", "mesh2d_face_nodes", "u1", "u2"):
            assert name in ds.variables
        assert ds["u1"].dims == ("mesh2d_nNodes",) and ds.sizes["mesh2d_nNodes"] == 81
        assert "_FillValue" in ds["mesh2d_face_nodes"].attrs
        for name in (
            "normal_pressure",
            "tangential_stress",
            "friction_multiplier",
            "slip",
            "penetration",
            "contact_state",
        ):
            assert ds[name].dims == ("contact_node",)
        scene = yaml.safe_load(ds.attrs["scene"])
        assert scene["discretization"]["mesh"]["n"] == 8 and scene["material"]["E"] == 2000.0
        assert ds.attrs["solver"] == "ssn" and ds.attrs["iterations"] >= 1
        assert ds.attrs["vemkit_version"] and ds.attrs["wall_time"] > 0
        assert np.all(np.isfinite(ds["u1"].values)) and ds["u2"].values.min() < -0.1  # pressed into the foundation


def test_uzawa_and_ssn_files_agree(tmp_path):
    """stop=both: agreement to solver tolerance. The paper's Step 3 (stop=either, the default)
    stops once lambda stops changing, at once when every contact vertex slips: close, not exact."""
    a, b, c = tmp_path / "ssn.nc", tmp_path / "uzawa.nc", tmp_path / "uzawa-paper-rule.nc"
    n4 = ("--set", "discretization.mesh.n=4", "-q")
    assert vemkit("solve", PAPER, "-o", a, *n4).returncode == 0
    run = vemkit("solve", PAPER, "-o", b, *n4, "--set", "solver.method=uzawa", "--set", "solver.stop=both")
    assert run.returncode == 0, run.stderr
    assert vemkit("solve", PAPER, "-o", c, *n4, "--set", "solver.method=uzawa").returncode == 0
    with xr.open_dataset(a) as da, xr.open_dataset(b) as db, xr.open_dataset(c) as dc:
        scale = np.abs(da["u2"].values).max()
        for name in ("u1", "u2"):
            assert np.abs(da[name].values - db[name].values).max() < 1e-8 * scale
            assert np.abs(da[name].values - dc[name].values).max() < 1e-4 * scale
        assert db.attrs["solver"] == "uzawa"


BAD_SETS = {
    "negative k": ("contact.normal.k=-1", "contact.normal.k"),
    "negative m": ("contact.friction.m=-0.5", "contact.friction.m"),
    "E zero": ("material.E=0", "material.E"),
    "nu too large": ("material.nu=0.5", "material.nu"),
    "nu too small": ("material.nu=-1", "material.nu"),
    "unknown key": ("solver.colour=red", "colour"),
    "unknown boundary": ("boundary.contact=[bottom, front]", "front"),
    "bad expression": ("contact.gap='0.1*(x+'", "contact.gap"),
    "not whitelisted": ("contact.gap='__import__(\"os\")'", "contact.gap"),
    "n < 1": ("discretization.mesh.n=0", "discretization.mesh.n"),
    "not a number": ("material.E=abc", "material.E"),
    "no dirichlet": ("boundary.dirichlet=[]", "dirichlet"),
}


@pytest.mark.parametrize("case", BAD_SETS)
def test_bad_scene_exits_nonzero_with_one_line_and_keeps_the_old_file(tmp_path, case):
    override, named = BAD_SETS[case]
    out = tmp_path / "out.nc"
    out.write_text("stale result from an earlier run")
    run = vemkit("solve", PAPER, "-o", out, "--set", override)
    assert run.returncode != 0
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("vemkit: error:"), run.stderr
    assert named in lines[0]
    assert out.read_text() == "stale result from an earlier run"  # what the user had is kept (issue 9)
    assert not list(tmp_path.glob(".out.nc*"))


def test_missing_scene_and_divergence_are_one_line_errors(tmp_path):
    out = tmp_path / "x.nc"
    run = vemkit("solve", tmp_path / "nope.yaml", "-o", out)
    assert run.returncode != 0 and "nope.yaml" in run.stderr and len(run.stderr.strip().splitlines()) == 1
    run = vemkit(
        "solve",
        PAPER,
        "-o",
        out,
        "--set",
        "solver.method=uzawa",
        "--set",
        "contact.normal.k=1e7",
        "--set",
        "discretization.mesh.n=4",
    )
    assert run.returncode != 0 and not out.exists()
    assert "ssn" in run.stderr and len(run.stderr.strip().splitlines()) == 1


def test_mesh_command(tmp_path):
    out = tmp_path / "mesh.nc"
    run = vemkit("mesh", "hanging", 4, "-o", out, "--option", "levels=2", "-q")
    assert run.returncode == 0, run.stderr
    from vemkit.mesh.files import read_ugrid

    mesh = read_ugrid(out)
    assert mesh.n_cells > 16 and mesh.cell_sizes.max() > 4
    run = vemkit("mesh", "square", 4, "-o", out, "--option", "seed=2")
    assert run.returncode != 0 and "seed" in run.stderr


def test_gauss_contact_quadrature_is_used_and_bad_point_counts_refused(tmp_path):
    from vemkit.config.scene import load_scene
    from vemkit.contact.problem import scene_problem
    from vemkit.solvers.ssn import solve_ssn

    out = tmp_path / "gauss.nc"
    run = vemkit(
        "solve",
        PAPER,
        "-o",
        out,
        "--set",
        "discretization.mesh.n=4",
        "--set",
        "discretization.contact_quadrature=gauss",
    )
    assert run.returncode == 0, run.stderr
    with xr.open_dataset(out) as ds:
        assert "contact_gauss_points: 3" in ds.attrs["scene"]
        u = np.stack([ds["u1"].values, ds["u2"].values], axis=1)
    for quadrature, differs in (("nodal", True), ("gauss", False)):
        scene = load_scene(PAPER).with_overrides(
            ["discretization.mesh.n=4", f"discretization.contact_quadrature={quadrature}"]
        )
        pb = scene_problem(scene)
        expected = pb.dofs.expand(solve_ssn(pb, tol=1e-10).u)
        assert (np.max(np.abs(u - expected)) > 1e-8 * np.max(np.abs(expected))) == differs, quadrature
    out = tmp_path / "g.nc"
    run = vemkit(
        "solve",
        PAPER,
        "-o",
        out,
        "--set",
        "discretization.contact_quadrature=gauss",
        "--set",
        "discretization.contact_gauss_points=0",
    )
    assert run.returncode != 0 and "contact_gauss_points" in run.stderr and not out.exists()
