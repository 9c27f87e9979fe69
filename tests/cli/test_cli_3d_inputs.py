"""3D scenes refuse what 2D refuses, for the true reason (issue 33), through the real command: every
scene key takes ``--set`` (list indices of any list, the box's corners too), the Poisson ratio's bound
names the model, a mesh size or an option the body cannot take is one line naming
``discretization.mesh`` (the rule of 2D), and a body beyond double precision says so."""

import subprocess
import sys
from pathlib import Path

import pytest
import xarray as xr
import yaml

ROOT = Path(__file__).resolve().parents[2]
BOX = {
    "name": "box",
    "model": "3d",
    "domain": {"box": [[0, 0, 0], [1, 1, 1]]},
    "material": {"E": 1.0, "nu": 0.3},
    "boundary": {"dirichlet": {"bottom": [0.0, 0.0, 0.0]}, "neumann": {"top": {"traction": [0.0, 0.0, -1.0]}}},
    "discretization": {"mesh": {"family": "hex", "n": 2}},
}
EXTRUDED = {
    **BOX,
    "name": "extruded",
    "domain": {
        "polygon": [[0, 0], [1, 0], [1, 1], [0, 1]],
        "sides": ["bottom", "right", "top", "left"],
        "extrude": {"depth": 0.5, "ends": ["front", "back"]},
    },
    "boundary": {"dirichlet": {"bottom": [0.0, 0.0, 0.0]}},
    "discretization": {"mesh": {"family": "square", "n": 2, "layers": 1}},
}
PLATE = {
    "name": "plate",
    "domain": {"polygon": [[0, 0], [1, 0], [1, 1], [0, 1]], "sides": ["bottom", "right", "top", "left"]},
    "material": {"E": 1.0, "nu": 0.3},
    "boundary": {"dirichlet": {"bottom": [0.0, 0.0]}},
    "discretization": {"mesh": {"family": "square", "n": 2}},
}


def solve(tmp_path, scene, *sets, name="s"):
    (tmp_path / f"{name}.yaml").write_text(yaml.safe_dump(scene))
    args = [a for s in sets for a in ("--set", s)]
    out = tmp_path / f"{name}.nc"
    run = subprocess.run(
        [sys.executable, "-m", "vemkit.cli", "solve", tmp_path / f"{name}.yaml", "-o", out, "-q", *args],
        capture_output=True,
        text=True,
        timeout=300,
    )
    return run, out


def refused(run, out, *says):
    """Exit 2, one line naming the key, no traceback, no file."""
    assert run.returncode == 2, (run.returncode, run.stderr)
    assert run.stderr.count("\n") == 1 and "Traceback" not in run.stderr, run.stderr
    for text in says:
        assert text in run.stderr, run.stderr
    assert not out.exists()


# -- --set reaches every key ----------------------------------------------------------------------
@pytest.mark.parametrize(
    "scene, override",
    [
        (BOX, "domain.box[1][2]=2"),
        (BOX, "domain.sides[5]=top"),
        (BOX, "body_force[2]=-1"),
        (BOX, "boundary.neumann.top.traction[2]=-2"),
        (EXTRUDED, "domain.extrude.ends[1]=lid"),
        (EXTRUDED, "domain.polygon[2][1]=1.5"),
        (PLATE, "domain.polygon[2][1]=1.5"),
    ],
)
def test_set_reaches_an_entry_of_any_list(tmp_path, scene, override):
    run, out = solve(tmp_path, scene, override)
    assert run.returncode == 0, run.stderr
    key, value = override.split("=")
    with xr.open_dataset(out) as ds:
        stored = yaml.safe_load(ds.attrs["scene"])
    path = key.replace("]", "").replace("[", ".").split(".")
    for part in path:
        stored = stored[int(part)] if part.isdigit() else stored[part]
    assert stored == yaml.safe_load(value)


def test_set_names_a_key_of_another_form_of_the_entry(tmp_path):
    run, out = solve(tmp_path, PLATE, "domain.box=[[0, 0, 0], [1, 1, 1]]")
    refused(run, out, "domain.box belongs to another form of domain (a mapping with box)", "--set 'domain={box: ...}'")
    run, out = solve(tmp_path, BOX, "domain.foo=1")
    refused(run, out, "unknown key 'domain.foo'; allowed here: box, sides")


# -- the Poisson ratio's bound names the model ----------------------------------------------------
@pytest.mark.parametrize(
    "scene, sets, model",
    [
        (BOX, (), "Poisson ratio of the 3D model (model: 3d), below 0.5 where lambda = E nu/((1+nu)(1-2nu))"),
        (PLATE, ("model=plane_strain",), "Poisson ratio of plane strain, below 0.5 where lambda"),
        (PLATE, (), "(Poisson ratio of plane stress); fix the scene or --set material.nu=..."),
    ],
)
def test_the_poisson_ratio_bound_names_the_model(tmp_path, scene, sets, model):
    run, out = solve(tmp_path, scene, "material.nu=0.5", *sets)
    refused(run, out, "material.nu = 0.5: must be < 0.5", model)
    if scene is BOX:
        assert "plane stress" not in run.stderr


# -- a mesh size or option the body cannot take: the rules of 2D ----------------------------------
LAME = ROOT / "config" / "scenes" / "3d" / "lame.yaml"


@pytest.mark.parametrize("family", ["hex", "voronoi", "tet", "octree"])
def test_a_cell_size_beyond_any_memory_is_refused_on_a_box(tmp_path, family):
    run, out = solve(tmp_path, BOX, f"discretization.mesh={{family: {family}, h: 1.0e-300}}")
    refused(run, out, "discretization.mesh (h = 1e-300): about 1e+300 cells", "across a body of 1 x 1 x 1")


@pytest.mark.parametrize("scene, family", [(EXTRUDED, "square"), (EXTRUDED, "voronoi"), (EXTRUDED, "tet")])
def test_a_cell_size_beyond_any_memory_is_refused_on_an_extruded_body(tmp_path, scene, family):
    run, out = solve(tmp_path, scene, f"discretization.mesh={{family: {family}, h: 1.0e-300}}")
    refused(run, out, "discretization.mesh (h = 1e-300): about 1e+300 cells", "across a body of 1 x 1 x 0.5")


def test_cells_larger_than_the_body_are_refused_as_in_2d(tmp_path):
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "vemkit.cli",
            "solve",
            LAME,
            "-o",
            tmp_path / "l.nc",
            "--set",
            "discretization.mesh.h=100",
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    refused(run, tmp_path / "l.nc", "cells of size 100 on a body of 2 x 2 x 0.1; give h <= 2 (the body's larger side)")
    run, out = solve(tmp_path, PLATE, "discretization.mesh.h=100", name="plate")
    refused(run, out, "cells of size 100 on a body of 1 x 1; give h <= 1 (the body's larger side)")


def test_a_box_far_from_the_origin_says_to_move_it(tmp_path):
    run, out = solve(tmp_path, BOX, "domain.box=[[1.0e9, 0, 0], [1000000001, 1, 1]]")
    refused(run, out, "at |x|, |y|, |z| up to 1e+09", "too fine for double precision there", "(shift domain.box)")


@pytest.mark.parametrize(
    "scene, mesh, says",
    [
        (
            BOX,
            "{family: octree, n: 2, contact_side: lid}",
            "contact_side = 'lid': the octree family refines towards a side of the body; give one of left, right, "
            "front, back, bottom, top",
        ),
        (BOX, "{family: octree, cells: 100, contact_side: lid}", "contact_side = 'lid'"),
        (BOX, "{family: octree, n: 2, levels: 2}", "discretization.mesh.levels = 2: the octree family refines one"),
        (
            EXTRUDED,
            "{family: hanging, n: 2, contact_side: lid}",
            "contact_side = 'lid': the hanging family refines towards a side of the body; give one of bottom, right",
        ),
    ],
)
def test_a_refinement_option_the_body_cannot_take_names_the_key(tmp_path, scene, mesh, says):
    run, out = solve(tmp_path, scene, f"discretization.mesh={mesh}")
    refused(run, out, says)


# -- a body beyond double precision says so -------------------------------------------------------
@pytest.mark.parametrize(
    "scene, override, says",
    [
        (EXTRUDED, "domain.extrude.depth=1.0e12", "domain.extrude.depth = 1e+12: a body of 1 x 1 x 1e+12 is 1.0e+12"),
        (EXTRUDED, "domain.extrude.depth=1.0e-300", "domain.extrude.depth = 1e-300: a body of 1 x 1 x 1e-300"),
        (BOX, "domain.box[1][2]=1.0e-7", "domain.box: a box of 1 x 1 x 1e-07 is 1.0e+07 times longer than thick"),
    ],
)
def test_a_body_too_thin_for_double_precision_says_so(tmp_path, scene, override, says):
    run, out = solve(tmp_path, scene, override, "boundary.dirichlet.bottom=[0, 0, 0]")
    refused(run, out, says, "beyond what a mesh resolves in double precision")
    assert "rotation" not in run.stderr


def _cube_file(path, x0):
    """A gmsh 2.2 file of one hexahedron [x0, x0 + 1] x [0, 1]², its faces bottom, top and sides."""
    corners = [(x0 + i, j, k) for k in (0, 1) for j in (0, 1) for i in (0, 1)]
    faces = {10: [(1, 3, 4, 2)], 11: [(5, 6, 8, 7)], 12: [(1, 2, 6, 5), (3, 7, 8, 4), (1, 5, 7, 3), (2, 4, 8, 6)]}
    rows = [(3, tag, face) for tag, group in faces.items() for face in group] + [(5, 1, (1, 2, 4, 3, 5, 6, 8, 7))]
    lines = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$PhysicalNames", "4", '3 1 "body"', '2 10 "bottom"']
    lines += ['2 11 "top"', '2 12 "sides"', "$EndPhysicalNames", "$Nodes", "8"]
    lines += [f"{i + 1} {x!r} {float(y)!r} {float(z)!r}" for i, (x, y, z) in enumerate(corners)]
    lines += ["$EndNodes", "$Elements", str(len(rows))]
    lines += [f"{k + 1} {kind} 2 {tag} {tag} " + " ".join(map(str, nodes)) for k, (kind, tag, nodes) in enumerate(rows)]
    path.write_text("\n".join([*lines, "$EndElements", ""]))


def test_a_mesh_file_far_from_the_origin_says_so_as_in_2d(tmp_path):
    scene = {k: v for k, v in BOX.items() if k != "domain"}
    scene["discretization"] = {"mesh": {"file": "cube.msh"}}
    _cube_file(tmp_path / "cube.msh", 0.0)
    run, out = solve(tmp_path, scene)
    assert run.returncode == 0, run.stderr
    out.unlink()
    _cube_file(tmp_path / "cube.msh", 1.0e9)
    run, out = solve(tmp_path, scene)
    refused(run, out, "cube.msh: edge (", "at |x|, |y|, |z| = 1e+09", "shift the mesh near the origin")
    assert "not planar" not in run.stderr
