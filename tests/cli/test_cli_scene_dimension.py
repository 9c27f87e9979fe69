"""The body says the dimension, ``model`` the constitution (docs/reference/files.md, issue 34 item 6),
through the real CLI: a 3D body without ``model`` solves to the very file of the same scene with
``model: 3d``; a model that does not fit the body (a 2D model on a box, an extruded polygon or a 3D
mesh file; ``3d`` on a polygon, the unit square or a plane mesh file) is one line, exit 2, nothing
written; a 2D scene without ``model`` is still plane stress."""

import subprocess
import sys

import netCDF4
import numpy as np
import pytest

#: attributes that measure the run, not what it computed
TIMINGS = {"wall_time", "assembly_time"}
BOX = "domain: {box: [[0, 0, 0], [1, 1, 0.5]]}\n"
EXTRUDE = "domain: {polygon: [[0, 0], [1, 0], [1, 1], [0, 1]], sides: [s, e, n, w], extrude: {depth: 0.5, ends: [bottom, top]}}\n"
BODY_3D = (
    "material: {E: 1000.0, nu: 0.3}\nboundary:\n  dirichlet: [bottom]\n"
    "  neumann: {top: {traction: [0, 0, -1]}}\ndiscretization: {mesh: {family: hex, n: 2}}\n"
)
BODY_2D = (
    "material: {E: 1000.0, nu: 0.3}\nboundary:\n  dirichlet: [bottom]\n"
    "  neumann: {top: {traction: [0, -1]}}\ndiscretization: {mesh: {family: square, n: 2}}\n"
)
POLYGON = "domain: {polygon: [[0, 0], [1, 0], [1, 1], [0, 1]], sides: [bottom, right, top, left]}\n"


def vemkit(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "vemkit.cli", *map(str, args)], capture_output=True, text=True, cwd=cwd
    )


def contents(path) -> tuple[dict, dict]:
    """The global attributes but the timings, and every variable's bytes and attributes."""
    with netCDF4.Dataset(path) as nc:
        nc.set_auto_mask(False)
        attrs = {k: str(nc.getncattr(k)) for k in nc.ncattrs() if k not in TIMINGS}
        variables = {
            name: (np.asarray(v[...]).tobytes(), {a: str(v.getncattr(a)) for a in v.ncattrs()})
            for name, v in nc.variables.items()
        }
    return attrs, variables


def solve(tmp_path, name, text, *extra):
    (tmp_path / f"{name}.yaml").write_text(text)
    return vemkit("solve", tmp_path / f"{name}.yaml", "-o", tmp_path / f"{name}.nc", "-q", *extra)


@pytest.mark.parametrize("domain", [BOX, EXTRUDE], ids=["box", "extrude"])
def test_a_3d_body_without_model_is_the_same_file_as_with_model_3d(tmp_path, domain):
    body = BODY_3D.replace("family: hex", "family: square") if domain == EXTRUDE else BODY_3D
    implicit = solve(tmp_path, "implicit", "name: block\n" + domain + body)
    explicit = solve(tmp_path, "explicit", "name: block\nmodel: 3d\n" + domain + body)
    assert implicit.returncode == 0 and explicit.returncode == 0, implicit.stderr + explicit.stderr
    attrs, variables = contents(tmp_path / "implicit.nc")
    assert attrs["model"] == "3d" and "model: 3d" in attrs["scene"] and "mesh3d" in variables
    assert (attrs, variables) == contents(tmp_path / "explicit.nc")


def test_a_3d_mesh_file_without_model_is_3d(tmp_path):
    (tmp_path / "box.yaml").write_text("name: block\n" + BOX + BODY_3D)
    assert vemkit("mesh", "--scene", tmp_path / "box.yaml", "-o", tmp_path / "m.nc", "-q").returncode == 0
    body = BODY_3D.replace("{family: hex, n: 2}", "{file: m.nc}")
    implicit = solve(tmp_path, "implicit", "name: block\n" + body)
    explicit = solve(tmp_path, "explicit", "name: block\nmodel: 3d\n" + body)
    assert implicit.returncode == 0 and explicit.returncode == 0, implicit.stderr + explicit.stderr
    assert contents(tmp_path / "implicit.nc") == contents(tmp_path / "explicit.nc")
    assert contents(tmp_path / "implicit.nc")[0]["model"] == "3d"


def _plane_mesh(tmp_path):
    (tmp_path / "square.yaml").write_text("name: plate\n" + BODY_2D)
    assert vemkit("mesh", "--scene", tmp_path / "square.yaml", "-o", tmp_path / "plane.nc", "-q").returncode == 0


REFUSED = {
    "plane_strain on a box": (
        "model: plane_strain\n" + BOX + BODY_3D,
        "model = 'plane_strain' does not fit the body: domain.box is 3D; the models of a 3D body: 3d (the default)",
    ),
    "plane_stress on an extruded polygon": (
        "model: plane_stress\n" + EXTRUDE + BODY_3D.replace("family: hex", "family: square"),
        "model = 'plane_stress' does not fit the body: domain.extrude is 3D; the models of a 3D body: 3d",
    ),
    "3d on a polygon": (
        "model: 3d\n" + POLYGON + BODY_2D,
        "model = '3d' does not fit the body: domain.polygon is 2D; the models of a 2D body: "
        "plane_stress (the default), plane_strain",
    ),
    "3d on the unit square": (
        "model: 3d\n" + BODY_2D,
        "model = '3d' does not fit the body: domain unit_square is 2D; the models of a 2D body",
    ),
    "3d on a plane mesh file": (
        "model: 3d\n" + BODY_2D.replace("{family: square, n: 2}", "{file: plane.nc}"),
        "model = '3d' does not fit the body: the mesh file plane.nc is 2D; the models of a 2D body",
    ),
    "a box beside a plane mesh file": (
        BOX + BODY_3D.replace("{family: hex, n: 2}", "{file: plane.nc}"),
        "domain.box is a 3D body but the mesh file plane.nc is a plane (2D) mesh",
    ),
}


@pytest.mark.parametrize("case", REFUSED)
def test_a_model_that_does_not_fit_the_body_is_refused_in_one_line(tmp_path, case):
    _plane_mesh(tmp_path)
    text, message = REFUSED[case]
    run = solve(tmp_path, "s", "name: s\n" + text)
    assert run.returncode == 2 and len(run.stderr.strip().splitlines()) == 1, run.stderr
    assert message in run.stderr, run.stderr
    assert not (tmp_path / "s.nc").exists()


def test_a_2d_model_on_a_3d_mesh_file_is_refused_and_set_model_too(tmp_path):
    (tmp_path / "box.yaml").write_text("name: block\n" + BOX + BODY_3D)
    assert vemkit("mesh", "--scene", tmp_path / "box.yaml", "-o", tmp_path / "m.nc", "-q").returncode == 0
    run = solve(
        tmp_path,
        "f",
        "name: block\n" + BODY_3D.replace("{family: hex, n: 2}", "{file: m.nc}"),
        "--set",
        "model=plane_stress",
    )
    assert run.returncode == 2 and len(run.stderr.strip().splitlines()) == 1, run.stderr
    assert "model = 'plane_stress' does not fit the body: the mesh file m.nc is 3D" in run.stderr
    assert not (tmp_path / "f.nc").exists()


def test_a_2d_scene_without_model_is_still_plane_stress(tmp_path):
    implicit = solve(tmp_path, "implicit", "name: plate\n" + POLYGON + BODY_2D)
    explicit = solve(tmp_path, "explicit", "name: plate\nmodel: plane_stress\n" + POLYGON + BODY_2D)
    strain = solve(tmp_path, "strain", "name: plate\nmodel: plane_strain\n" + POLYGON + BODY_2D)
    assert implicit.returncode == explicit.returncode == strain.returncode == 0, implicit.stderr + strain.stderr
    attrs, variables = contents(tmp_path / "implicit.nc")
    assert attrs["model"] == "plane_stress" and "mesh2d" in variables
    assert (attrs, variables) == contents(tmp_path / "explicit.nc")
    assert contents(tmp_path / "strain.nc")[0]["model"] == "plane_strain"
