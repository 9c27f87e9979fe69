"""The file ``adaptivity.reference`` names is an input (issue 18, item 1), through the real command:
its mesh validated like a mesh file, its scene attribute read by the safe YAML loader, an order-2
reference refused, and only the variables it needs read. Every refusal is one line, exit status 2,
nothing written; a reference with a large extra variable costs nothing more."""

import shutil
import sys
import time
from pathlib import Path

import netCDF4
import pytest

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "config" / "scenes" / "paper.yaml"
sys.path.insert(0, str(ROOT / "tests"))
from measured_process import run_vemkit  # noqa: E402


def vemkit(*args, cwd: Path):
    """(exit status, stdout, stderr, peak resident bytes) of one vemkit process (tests/measured_process.py)."""
    status, out, err, _, peak = run_vemkit(args, cwd)
    return status, out, err, peak


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """The paper scene, its k = 1 reference (n = 8) and a k = 2 reference (n = 4)."""
    path = tmp_path_factory.mktemp("reference")
    shutil.copy(PAPER, path / "scene.yaml")
    for name, extra in (
        ("ref.nc", ["--set", "discretization.mesh.n=8"]),
        ("ref2.nc", ["--set", "discretization.mesh.n=4", "--set", "discretization.order=2"]),
    ):
        status, _, err, _ = vemkit("solve", "scene.yaml", "-o", name, *extra, "-q", cwd=path)
        assert status == 0, err
    return path


def _adapt(folder: Path, reference: str, *extra):
    return vemkit(
        "adapt",
        "scene.yaml",
        "-o",
        "adapted.nc",
        "--set",
        "discretization.mesh.n=4",
        "--set",
        f"adaptivity.reference={reference}",
        "--set",
        "adaptivity.max_steps=1",
        *extra,
        "-q",
        cwd=folder,
    )


def _broken(folder: Path, name: str, edit) -> str:
    shutil.copy(folder / "ref.nc", folder / name)
    with netCDF4.Dataset(folder / name, "r+") as nc:
        edit(nc)
    return name


def _set_scene(text):
    return lambda nc: nc.setncattr("scene", text)


def _bad_vertex(nc):
    faces = nc.variables["mesh2d_face_nodes"]
    faces.set_auto_mask(False)
    faces[0, 0] = 10**6  # far beyond the node count


def _k2_scene(nc):
    nc.setncattr("scene", nc.getncattr("scene").replace("  order: 1\n", "  order: 2\n", 1))  # the attribute says 1


def _nan_in_u2(nc):
    values = nc.variables["u2"]
    values.set_auto_mask(False)
    values[3] = float("nan")


CASES = {
    "a NaN in u2": (_nan_in_u2, "variable u2 holds 1 NaN or inf value (the first at node 3: nan)"),
    "a vertex index out of range": (_bad_vertex, "vertex"),
    "a python tag in the scene attribute": (_set_scene("name: !!python/object/apply:os.system [echo]"), "tags"),
    "an alias in the scene attribute": (_set_scene("a: &x [1]\nb: *x"), "aliases"),
    "a YAML syntax error in the scene attribute": (_set_scene("name: [unclosed"), "YAML syntax error"),
    "a scene attribute that is a list": (_set_scene("- 1\n- 2"), "not a scene"),
    "an order-2 scene attribute": (_k2_scene, "order-2"),
}


@pytest.mark.parametrize("case", CASES)
def test_a_broken_reference_is_refused_in_one_line(folder, case):
    edit, words = CASES[case]
    name = _broken(folder, case.replace(" ", "_") + ".nc", edit)
    status, _, err, _ = _adapt(folder, name)
    assert status == 2 and len(err.splitlines()) == 1, (status, err)
    assert err.startswith("vemkit: error: adaptivity.reference") and name in err and words in err, err
    assert not (folder / "adapted.nc").exists()


def test_an_order_2_solution_file_is_refused_as_a_reference(folder):
    status, _, err, _ = _adapt(folder, "ref2.nc")
    assert status == 2 and len(err.splitlines()) == 1 and "order-2" in err, err
    assert not (folder / "adapted.nc").exists()


def test_only_the_variables_a_reference_needs_are_read(folder):
    """A reference with one extra variable of 1 GiB (never written: the file stays small, reading it
    would allocate it) costs no more memory than the plain reference."""

    def huge(nc):
        nc.createDimension("big", 2**27)
        nc.createVariable("extra", "f8", ("big",), fill_value=0.0)

    name = _broken(folder, "extra.nc", huge)
    assert (folder / name).stat().st_size < 2**20
    start = time.perf_counter()
    plain = _adapt(folder, "ref.nc")
    assert plain[0] == 0, plain[2]
    (folder / "adapted.nc").unlink()
    status, _, err, peak = _adapt(folder, name)
    assert status == 0, err
    assert peak < plain[3] + 200 * 2**20, (peak / 2**20, plain[3] / 2**20)
    assert time.perf_counter() - start < 120
    (folder / "adapted.nc").unlink()
