"""Any body through the real CLI (docs/reference/files.md): the shipped Cook's membrane scene against its reference."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

ROOT = Path(__file__).resolve().parents[2]
COOK = ROOT / "config" / "scenes" / "cook.yaml"
REFERENCE = 23.96  # vertical displacement at the middle of the loaded edge (config/scenes/cook.yaml)


@pytest.mark.parametrize("family", ["square", "triangle", "voronoi"])
def test_cooks_membrane_meets_the_published_displacement(tmp_path, family):
    out = tmp_path / "cook.nc"
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "vemkit.cli",
            "solve",
            str(COOK),
            "-o",
            str(out),
            "-q",
            "--set",
            f"discretization.mesh.family={family}",
            "--set",
            "discretization.mesh.n=1",
        ],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stderr
    with xr.open_dataset(out) as ds:
        x, y, v = ds["mesh2d_node_x"].values, ds["mesh2d_node_y"].values, ds["u2"].values
    on_edge = np.isclose(x, 48.0)
    mid = np.argmin(np.where(on_edge, np.abs(y - 52.0), np.inf))
    assert abs(y[mid] - 52.0) < 0.5
    assert abs(v[mid] - REFERENCE) < 0.02 * REFERENCE


def _vemkit(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "vemkit.cli", *map(str, args)], capture_output=True, text=True, cwd=cwd
    )


@pytest.mark.parametrize("family", ["square", "voronoi"])
def test_vemkit_mesh_scene_meshes_the_body_with_its_sides(tmp_path, family):
    from vemkit.mesh.files import read_ugrid

    out = tmp_path / "cook-mesh.nc"
    run = _vemkit("mesh", "--scene", COOK, "-o", out, "-q", "--set", f"discretization.mesh.family={family}")
    assert run.returncode == 0, run.stderr
    mesh = read_ugrid(out)
    assert set(mesh.boundary) == {"bottom", "load", "top", "clamped"}
    assert np.isclose(mesh.cell_areas.sum(), 1440.0)  # the shoelace area of Cook's panel
    loaded = mesh.vertices[np.unique(mesh.boundary["load"])]
    assert np.allclose(loaded[:, 0], 48.0) and np.isclose(np.ptp(loaded[:, 1]), 16.0)


@pytest.mark.parametrize(
    "args",
    [
        ["-o", "m.nc"],
        ["square", "4", "--scene", COOK, "-o", "m.nc"],
        ["square", "4", "--set", "discretization.mesh.n=3", "-o", "m.nc"],
    ],
)
def test_vemkit_mesh_wants_a_family_or_a_scene_not_both(tmp_path, args):
    run = _vemkit("mesh", *args, cwd=tmp_path)
    assert run.returncode == 2 and len(run.stderr.strip().splitlines()) == 1
    assert run.stderr.startswith("vemkit: error: vemkit mesh") and not (tmp_path / "m.nc").exists()


def test_a_scene_solves_on_a_mesh_file_named_relative_to_it(tmp_path):
    """docs/reference/files.md: `vemkit mesh --scene` writes Cook's mesh, a scene in another folder names it by a
    relative path and solves to the same displacement as meshing the scene itself."""
    folder = tmp_path / "study"
    folder.mkdir()
    assert _vemkit("mesh", "--scene", COOK, "-o", folder / "cook-mesh.nc", "-q").returncode == 0
    text = COOK.read_text().replace("mesh: {family: square, n: 1}", "mesh: {file: cook-mesh.nc}")
    (folder / "cook-file.yaml").write_text(text)
    solved = [
        _vemkit("solve", scene, "-o", tmp_path / f"{name}.nc", "-q", cwd=tmp_path)
        for name, scene in (("family", COOK), ("file", folder / "cook-file.yaml"))
    ]
    assert all(run.returncode == 0 for run in solved), [run.stderr for run in solved]
    with xr.open_dataset(tmp_path / "family.nc") as a, xr.open_dataset(tmp_path / "file.nc") as b:
        np.testing.assert_allclose(a["u2"].values, b["u2"].values, rtol=1e-12)
    missing = _vemkit("solve", COOK, "-o", tmp_path / "x.nc", "--set", "discretization.mesh={file: nowhere.msh}")
    assert missing.returncode == 2 and "nowhere.msh: no such mesh file" in missing.stderr
    assert len(missing.stderr.splitlines()) == 1 and not (tmp_path / "x.nc").exists()
