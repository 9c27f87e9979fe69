"""Exit status 0 only on a valid mesh of the right body (issue 18, item 3), through the real command:
``vemkit solve`` and ``vemkit mesh`` refuse the same meshes (one path), refinement keeps every new
boundary vertex on the curve of its own boundary piece, whatever the side names, and the ``hanging``
family follows curved sides as it refines."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from vemkit.mesh.checks import validate_mesh
from vemkit.mesh.files import read_ugrid

ROOT = Path(__file__).resolve().parents[2]
SOLID = {"material": {"E": 1.0, "nu": 0.3}, "body_force": [0.0, -1.0], "solver": {"method": "ssn"}}


def vemkit(*args, cwd: Path):
    return subprocess.run(
        [sys.executable, "-m", "vemkit.cli", *map(str, args)], cwd=cwd, capture_output=True, text=True, timeout=300
    )


def _scene(folder: Path, name: str, domain: dict, dirichlet, mesh: dict, **extra) -> Path:
    data = {
        "name": name,
        "domain": domain,
        **SOLID,
        "boundary": {"dirichlet": dirichlet, "neumann": {}, "contact": []},
        "discretization": {"mesh": mesh},
        **extra,
    }
    (folder / f"{name}.yaml").write_text(json.dumps(data))
    return folder / f"{name}.yaml"


def test_solve_refuses_the_mesh_that_mesh_refuses(tmp_path):
    """A square mesh cut around a small hole with a pinched cell (one cell touching itself at a
    vertex): refused by both commands with the same line, nothing written."""
    domain = {
        "polygon": [[0, 0], [1, 0], [1, 1], [0, 1]],
        "sides": ["bottom", "right", "top", "left"],
        "holes": [{"circle": [0.59, 0.2982, 0.01], "side": "hole"}],
    }
    _scene(tmp_path, "pinched", domain, ["bottom"], {"family": "square", "h": 0.1})
    meshed = vemkit("mesh", "--scene", "pinched.yaml", "-o", "m.nc", cwd=tmp_path)
    solved = vemkit("solve", "pinched.yaml", "-o", "s.nc", cwd=tmp_path)
    for run in (meshed, solved):
        assert run.returncode == 2 and len(run.stderr.splitlines()) == 1, run.stderr
        assert "the square mesh (h = 0.1) is broken: cell" in run.stderr
    assert meshed.stderr == solved.stderr
    assert not (tmp_path / "m.nc").exists() and not (tmp_path / "s.nc").exists()


HALF_DISK = {
    "polygon": [[-1, 0], [-0.6, -0.8], [0.6, -0.8], [1, 0]],
    "sides": ["rim", "rim", "rim", "top"],
    "arcs": [[0, 0], [0, 0], [0, 0], None],
}
SLOT = [[-0.3, -0.5], [0.3, -0.5], [0.3, -0.3], [-0.3, -0.3]]
PIECES = {
    # an arc and a polygonal hole named alike: the hole's new vertices stay on its straight edges
    "arc and slot": (
        {**HALF_DISK, "holes": [{"polygon": SLOT, "sides": ["rim"] * 4}]},
        ["top"],
        [("circle", (0.0, 0.0, 1.0)), ("box", (-0.3, -0.5, 0.3, -0.3))],
    ),
    # two circular holes named alike: each hole's new vertices on its own circle
    "two bores": (
        {
            "polygon": [[0, 0], [3, 0], [3, 1], [0, 1]],
            "sides": ["bottom", "right", "top", "left"],
            "holes": [{"circle": [0.8, 0.5, 0.25], "side": "bore"}, {"circle": [2.2, 0.5, 0.2], "side": "bore"}],
        },
        ["left"],
        [("circle", (0.8, 0.5, 0.25)), ("circle", (2.2, 0.5, 0.2))],
    ),
}


def _on_piece(points, kind, shape, exact: bool = False) -> np.ndarray:
    """On the piece: a circle's vertices on it or (a cell left no kernel by the circle keeps its new
    vertices on its chords, vemkit.mesh.refine) on a chord of it; a box's on its edges."""
    if kind == "circle":
        cx, cy, r = shape
        d = np.hypot(points[:, 0] - cx, points[:, 1] - cy) - r
        return (np.abs(d) <= 1e-12) if exact else (d <= 1e-12) & (d >= -r * (1 - np.cos(np.pi / 8)))
    x0, y0, x1, y1 = shape
    inside = (
        (points[:, 0] >= x0 - 1e-12)
        & (points[:, 0] <= x1 + 1e-12)
        & (points[:, 1] >= y0 - 1e-12)
        & (points[:, 1] <= y1 + 1e-12)
    )
    edge = (
        np.isclose(points[:, 0], x0)
        | np.isclose(points[:, 0], x1)
        | np.isclose(points[:, 1], y0)
        | np.isclose(points[:, 1], y1)
    )
    return inside & edge


@pytest.mark.parametrize("case", PIECES)
def test_refinement_keeps_each_boundary_vertex_on_its_own_piece(tmp_path, case):
    domain, dirichlet, pieces = PIECES[case]
    side = "rim" if case == "arc and slot" else "bore"
    _scene(
        tmp_path,
        "pieces",
        domain,
        dirichlet,
        {"family": "square", "h": 0.2},
        adaptivity={"marking": {"dorfler": 1.0}, "max_steps": 3, "target": 1e-6},
    )
    run = vemkit("adapt", "pieces.yaml", "-o", "a.nc", "-q", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert vemkit("mesh", "--scene", "pieces.yaml", "-o", "first.nc", "-q", cwd=tmp_path).returncode == 0
    mesh, first = read_ugrid(tmp_path / "a.nc"), read_ugrid(tmp_path / "first.nc")
    validate_mesh(mesh)
    points = mesh.vertices[np.unique(mesh.boundary[side])]
    old = {tuple(p) for p in first.vertices[np.unique(first.boundary[side])].tolist()}
    points = points[[tuple(p) not in old for p in points.tolist()]]  # the vertices refinement added
    on = [_on_piece(points, kind, shape) for kind, shape in pieces]
    assert np.all(np.any(on, axis=0)), points[~np.any(on, axis=0)]
    exact = [_on_piece(points, kind, shape, exact=True) for kind, shape in pieces]
    assert all(hit.sum() >= 8 for hit in exact)  # each piece has gained vertices of its own
    assert np.any(exact, axis=0).mean() > 0.8  # most on the curves themselves


HERTZ = ROOT / "config" / "scenes" / "hertz.yaml"
HANGING = '{"family": "hanging", "h": 0.04, "levels": 3, "contact_side": "contact"}'


def test_the_hanging_family_follows_curved_sides_as_it_refines(tmp_path):
    """Hertz's half-disk (config/scenes/hertz.yaml) on squares h = 0.04 refined three times at the
    contact arc: the arcs are chords of the finest squares (h / 8), not of the coarse ones, and the peak
    pressure is Hertz's p0 = 2 P / (pi a), a = 2 sqrt(R P / (pi E)), to 6 % (it was +45 % on the coarse
    chords; triangles: -1.3 %, squares: +17 % at this h)."""
    mesh_run = vemkit(
        "mesh", "--scene", HERTZ, "-o", tmp_path / "m.nc", "--set", f"discretization.mesh={HANGING}", "-q", cwd=tmp_path
    )
    assert mesh_run.returncode == 0, mesh_run.stderr
    mesh = read_ugrid(tmp_path / "m.nc")
    for side in ("contact", "flank"):
        edges = mesh.boundary[side]
        ends = mesh.vertices[edges]
        lengths = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1)
        assert lengths.max() <= 0.04 / 8 * 1.01, (side, lengths.max())
        radius = np.hypot(*ends.reshape(-1, 2).T)
        assert np.all(radius <= 1.0 + 1e-12) and radius.min() > 1.0 - 1e-4  # on the arcs or their fine chords
    run = vemkit("solve", HERTZ, "-o", tmp_path / "s.nc", "--set", f"discretization.mesh={HANGING}", "-q", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    import xarray as xr

    with xr.open_dataset(tmp_path / "s.nc") as ds:
        x, y = ds["contact_x"].values, ds["contact_y"].values
        p, w = ds["normal_pressure"].values, ds["contact_weight"].values
    force = float(np.sum(w * p * (-y / np.hypot(x, y))))  # -nu . e2, nu the radial outer normal of the arc
    a = 2.0 * np.sqrt(force / np.pi)  # R = 1, E = 1
    p0 = 2.0 * force / (np.pi * a)
    assert abs(p.max() / p0 - 1.0) < 0.06, p.max() / p0 - 1.0
