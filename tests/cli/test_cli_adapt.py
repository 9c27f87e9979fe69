"""`vemkit adapt` (docs/reference/files.md) through the real command: the final solution file with the indicator and
the history, a progress line per step, a note when the limits stop the loop, and bad input refused
in one line with exit status 2 and nothing written."""

import contextlib
import io
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml
from conftest import assert_no_nan_stored

from vemkit.cli import main

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "config" / "scenes" / "paper.yaml"
N4 = ("--set", "discretization.mesh.n=4")


def vemkit(*args, cwd=None, timeout=120):
    return subprocess.run(
        [sys.executable, "-m", "vemkit.cli", *map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=timeout
    )


def test_a_small_adaptive_run_writes_the_final_solution_with_indicator_and_history(tmp_path):
    out = tmp_path / "adapted.nc"
    run = vemkit("adapt", PAPER, "-o", out, *N4, "--set", "adaptivity.max_steps=3", "--vtu", tmp_path / "adapted.vtu")
    assert run.returncode == 0, run.stderr
    lines = run.stderr.splitlines()
    assert [line.split(":")[1].strip() for line in lines[:3]] == ["step 1", "step 2", "step 3"]
    assert len(lines) == 4 and lines[3].startswith("vemkit: note: adaptivity.target = 0.01 not reached")
    assert "max_steps" in lines[3] and run.stdout.startswith(f"{out}: 3 adaptive steps (max_steps)")
    assert_no_nan_stored(out)
    with xr.open_dataset(out) as ds:
        assert ds.sizes["adapt_step"] == 3
        dofs, cells, estimate = ds["adapt_n_dofs"].values, ds["adapt_n_cells"].values, ds["adapt_estimate"].values
        assert np.all(np.diff(dofs) > 0) and np.all(np.diff(estimate) < 0)
        assert dofs[-1] == ds.attrs["n_dofs"] and cells[-1] == ds.sizes["mesh2d_nFaces"]
        assert np.all(ds["adapt_wall_time"].values > 0) and list(ds["adapt_warm_start"].values[:1]) == [0]
        assert ds["error_indicator"].dims == ("mesh2d_nFaces",) and np.all(ds["error_indicator"].values >= 0)
        assert ds.attrs["adapt_stop_reason"] == "max_steps" and ds.attrs["check_worst"] < 1e-6
        assert "adapt_true_error" not in ds  # no exact solution, no reference
        for name in ("u1", "u2", "mesh2d_face_nodes", "normal_pressure"):
            assert name in ds.variables
        assert yaml.safe_load(ds.attrs["scene"])["adaptivity"]["max_steps"] == 3
    assert (tmp_path / "adapted.vtu").stat().st_size > 0


def test_the_target_ends_the_loop_without_a_note_and_quiet_is_silent(tmp_path):
    run = vemkit("adapt", PAPER, "-o", tmp_path / "a.nc", *N4, "--set", "adaptivity.target=0.5", "-q")
    assert run.returncode == 0 and run.stdout == "" and run.stderr == "", run.stderr
    with xr.open_dataset(tmp_path / "a.nc") as ds:
        assert ds.sizes["adapt_step"] == 1 and ds.attrs["adapt_stop_reason"] == "target"
        assert ds["adapt_estimate"].values[0] <= 0.5


def test_a_reference_file_gives_the_true_error_of_every_step(tmp_path, monkeypatch, capsys):
    """adaptivity.reference (relative to the scene file): a finer solve of the same scene."""
    scene = tmp_path / "scene.yaml"
    scene.write_text(PAPER.read_text())
    assert main(["solve", str(scene), "-o", str(tmp_path / "ref.nc"), "--set", "discretization.mesh.n=32", "-q"]) == 0
    monkeypatch.chdir(ROOT)  # not the scene's directory: the reference is found next to the scene
    assert (
        main(
            [
                "adapt",
                str(scene),
                "-o",
                str(tmp_path / "a.nc"),
                *N4,
                "--set",
                "adaptivity.reference=ref.nc",
                "--set",
                "adaptivity.max_steps=3",
                "-q",
            ]
        )
        == 0
    )
    with xr.open_dataset(tmp_path / "a.nc") as ds:
        true = ds["adapt_true_error"].values
        assert true.size == 3 and np.all(np.diff(true) < 0) and 0.01 < true[0] < 0.5
        assert np.all(ds["adapt_true_error_h1"].values <= true)  # the L2 part is smaller than the seminorm's
        assert np.allclose(ds["adapt_effectivity"].values, ds["adapt_estimate"].values / true)
    capsys.readouterr()
    assert main(["adapt", str(scene), "-o", str(tmp_path / "ref.nc"), *N4, "--set", "adaptivity.reference=ref.nc"]) == 2
    assert "input file" in capsys.readouterr().err
    # a reference of another problem (a softer material) is refused, naming the section that differs
    assert (
        main(
            [
                "solve",
                str(scene),
                "-o",
                str(tmp_path / "other.nc"),
                "--set",
                "discretization.mesh.n=8",
                "--set",
                "material.E=1000",
                "-q",
            ]
        )
        == 0
    )
    assert main(["adapt", str(scene), "-o", str(tmp_path / "b.nc"), *N4, "--set", "adaptivity.reference=other.nc"]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "adaptivity.reference" in err and "'material'" in err
    assert not (tmp_path / "b.nc").exists()


# (arguments after SCENE -o out.nc, text the one error line must contain)
BAD = {
    "dorfler 0": (["--set", "adaptivity.marking.dorfler=0"], "adaptivity.marking.dorfler"),
    "dorfler 1.5": (["--set", "adaptivity.marking.dorfler=1.5"], "adaptivity.marking.dorfler"),
    "target 0": (["--set", "adaptivity.target=0"], "adaptivity.target"),
    "target text": (["--set", "adaptivity.target=small"], "adaptivity.target"),
    "max_steps 0": (["--set", "adaptivity.max_steps=0"], "adaptivity.max_steps"),
    "max_dofs 2.5": (["--set", "adaptivity.max_dofs=2.5"], "adaptivity.max_dofs"),
    "max_hanging 0": (["--set", "adaptivity.max_hanging=0"], "adaptivity.max_hanging"),
    "estimator": (["--set", "adaptivity.estimator=hierarchical"], "adaptivity.estimator"),
    "unknown key": (["--set", "adaptivity.theta=0.5"], "adaptivity.theta"),
    "missing reference": (["--set", "adaptivity.reference=nothere.nc"], "adaptivity.reference"),
    "reference not a solution": (["--set", "adaptivity.reference=SCENE"], "adaptivity.reference"),
    "first mesh above max_dofs": (["--set", "adaptivity.max_dofs=10"], "adaptivity.max_dofs"),
    "first mesh above --max-dofs": (["--max-dofs", "10"], "DOFs"),
}


@pytest.fixture(scope="module")
def bad_runs(tmp_path_factory):
    """Every case through the command's entry point (in this process: a Python start-up costs seconds)."""
    path = tmp_path_factory.mktemp("adapt")
    (path / "SCENE").write_text(PAPER.read_text())
    runs = {}
    with pytest.MonkeyPatch.context() as patch:
        patch.chdir(path)
        for case, (extra, _) in BAD.items():
            err, out = io.StringIO(), io.StringIO()
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
                status = main(["adapt", "SCENE", "-o", "out.nc", *N4, *extra])
            runs[case] = (status, err.getvalue(), out.getvalue())
    return runs, sorted(p.name for p in path.iterdir())


@pytest.mark.parametrize("case", BAD)
def test_bad_adaptivity_input_is_one_line_exit_2(bad_runs, case):
    status, stderr, stdout = bad_runs[0][case]
    lines = stderr.splitlines()
    assert status == 2, (status, stderr)
    assert len(lines) == 1 and lines[0].startswith("vemkit: error: ") and BAD[case][1] in lines[0], stderr
    assert not stdout


def test_bad_adaptivity_input_through_the_console_script(tmp_path):
    run = vemkit("adapt", PAPER, "-o", tmp_path / "out.nc", "--set", "adaptivity.marking.dorfler=0")
    assert run.returncode == 2 and len(run.stderr.splitlines()) == 1 and "adaptivity.marking.dorfler" in run.stderr
    assert not any(tmp_path.iterdir())


def test_bad_adaptivity_input_writes_nothing(bad_runs):
    assert bad_runs[1] == ["SCENE"]


def test_an_exact_solution_gives_the_true_error_of_every_step(tmp_path):
    """Kirsch's plate (config/scenes/kirsch.yaml, exact: the Kirsch field): the estimate tracks the error."""
    out = tmp_path / "kirsch.nc"
    assert (
        main(
            [
                "adapt",
                str(ROOT / "config" / "scenes" / "kirsch.yaml"),
                "-o",
                str(out),
                "--set",
                "discretization.mesh.h=1",
                "--set",
                "adaptivity.max_steps=3",
                "-q",
            ]
        )
        == 0
    )
    with xr.open_dataset(out) as ds:
        true, effectivity = ds["adapt_true_error"].values, ds["adapt_effectivity"].values
        assert true.size == 3 and np.all(np.diff(true) < 0) and 0.05 < true[0] < 0.5
        assert np.all((effectivity > 1.0) & (effectivity < 3.0))
