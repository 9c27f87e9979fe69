"""`snakemake adaptivity` (dry runs: nothing is solved): the jobs per scene of config/adaptivity.yaml,
scenes added by name and skipped when their file is missing, bad settings refused naming the key."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
import xarray as xr
import yaml
from snakemake_runs import dry_run as run_dry

ROOT = Path(__file__).resolve().parents[2]
STUDY = yaml.safe_load((ROOT / "config" / "adaptivity.yaml").read_text())["adaptivity_study"]


def dry_run(*args) -> subprocess.CompletedProcess:
    return run_dry(*args, cores=2)


def planned(*args) -> dict:
    run = dry_run(*args)
    assert run.returncode == 0, run.stdout + run.stderr
    stats = run.stdout[run.stdout.index("Job stats:") :]
    stats = stats[: stats.index("total")]
    return {m.group(1): int(m.group(2)) for m in re.finditer(r"^(\w+)\s+(\d+)\s*$", stats, re.M)}


def _config(tmp_path, scenes: dict) -> str:
    path = tmp_path / "mine.yaml"
    path.write_text(yaml.safe_dump({"adaptivity_study": {"scenes": scenes}}))
    return str(path)


def test_every_scene_gets_its_runs_figures_and_reference_and_scenes_are_added_by_name(tmp_path):
    """A --configfile merges its scenes with the shipped ones; a scene whose file is missing is skipped."""
    added = {
        "mine": {"scene": "config/scenes/paper.yaml", "overrides": ["discretization.mesh.n=2"]},
        "ghost": {"scene": "config/scenes/no-such-scene.yaml", "reference": {"uniform": 3}},
    }
    scenes = {label: case for label, case in {**STUDY["scenes"], **added}.items() if (ROOT / case["scene"]).is_file()}
    assert "mine" in scenes and "ghost" not in scenes
    jobs = planned("adaptivity", "--configfile", _config(tmp_path, added))
    assert jobs.pop("adaptivity") == 1 and jobs.pop("adaptivity_summary") == 1
    assert jobs == {
        "adaptivity_run": 2 * len(scenes),
        "adaptivity_figures": len(scenes),
        "adaptivity_reference": sum(case.get("reference") is not None for case in scenes.values()),
    }


@pytest.mark.parametrize(
    "entry, key",
    [
        ({"scene": "config/scenes/paper.yaml", "theta": 1.5}, "theta"),
        ({"scene": "config/scenes/paper.yaml", "reference": {"uniform": 3, "adaptive": 10}}, "reference"),
    ],
)
def test_bad_settings_are_refused_naming_the_key(tmp_path, entry, key):
    run = dry_run("adaptivity", "--configfile", _config(tmp_path, {"mine": entry}))
    message = run.stdout + run.stderr
    assert run.returncode != 0 and key in message and "adaptivity_study" in message and "Traceback" not in message


def test_every_output_is_written_under_results_adaptive():
    """Issue 12: the pipeline writes results/adaptive/*.nc (per scene: the runs, the reference, the
    mesh snapshots; the figures and the summary beside them)."""
    run = dry_run("adaptivity")
    assert run.returncode == 0, run.stdout + run.stderr
    outputs = [path.strip() for line in re.findall(r"^\s+output: (.+)$", run.stdout, re.M) for path in line.split(",")]
    assert outputs and all(path.startswith("results/adaptive/") for path in outputs), outputs
    scenes = [label for label, case in STUDY["scenes"].items() if (ROOT / case["scene"]).is_file()]
    for label in scenes:
        assert {f"results/adaptive/{label}/{mode}.nc" for mode in ("adaptive", "uniform")} <= set(outputs)


STUDY3D = yaml.safe_load((ROOT / "config" / "adaptivity3d.yaml").read_text())["adaptivity3d_study"]


def test_the_3d_study_runs_every_3d_scene_under_results_adaptive3d(tmp_path):
    """Issue 36 item 5: `snakemake adaptivity3d` plans per 3D scene an adaptive and a uniform run
    (no reference: exact solutions or the estimate), the figures (convergence, the cut), one summary."""
    run = dry_run("adaptivity3d")
    assert run.returncode == 0, run.stdout + run.stderr
    outputs = [path.strip() for line in re.findall(r"^\s+output: (.+)$", run.stdout, re.M) for path in line.split(",")]
    assert outputs and all(path.startswith("results/adaptive3d/") for path in outputs), outputs
    scenes = [label for label, case in STUDY3D["scenes"].items() if (ROOT / case["scene"]).is_file()]
    assert {"lshape_edge", "fichera"} <= set(scenes)
    for label in scenes:
        expected = {f"results/adaptive3d/{label}/{name}" for name in ("adaptive.nc", "uniform.nc", "meshes.png")}
        assert expected <= set(outputs)
    jobs = planned("adaptivity3d")
    assert jobs == {"adaptivity3d": 1, "adaptivity_summary": 1, "adaptivity3d_run": 2 * len(scenes),
                    "adaptivity_figures": len(scenes)}  # fmt: skip


@pytest.mark.parametrize(
    "entry, key",
    [
        ({"scene": "config/scenes/3d/sheared_box.yaml", "reference": {"uniform": 2}}, "reference"),
        ({"scene": "config/scenes/3d/sheared_box.yaml", "cut": {"axis": "w", "at": 0}}, "axis"),
        ({"scene": "config/scenes/3d/sheared_box.yaml", "overrides": ["discretization.mesh.n=0"]}, "overrides"),
    ],
)
def test_bad_3d_settings_are_refused_naming_the_key(tmp_path, entry, key):
    path = tmp_path / "mine3d.yaml"
    path.write_text(yaml.safe_dump({"adaptivity3d_study": {"scenes": {"mine": entry}}}))
    run = dry_run("adaptivity3d", "--configfile", str(path))
    message = run.stdout + run.stderr
    assert run.returncode != 0 and key in message and "adaptivity3d_study" in message, message
    assert "Traceback" not in message


def test_a_tiny_3d_study_runs_through_its_scripts(tmp_path):
    """The rules' scripts for a 3D scene, really run (a copy of the workflow in tmp_path): the adaptive and
    the uniform file, the snapshots on mesh3d, the convergence figure and the cut."""
    import shutil

    for name in ("Snakefile", "workflow", "config"):
        (shutil.copytree if (ROOT / name).is_dir() else shutil.copy)(ROOT / name, tmp_path / name)
    (tmp_path / "benchmarks").mkdir()
    for scene in ROOT.glob("benchmarks/*.yaml"):  # scenes the configuration's checks read
        shutil.copy(scene, tmp_path / "benchmarks" / scene.name)
    tiny = {"scene": "config/scenes/3d/sheared_box.yaml", "overrides": ["discretization.mesh.n=2"],
            "max_dofs": 2000, "uniform_steps": 2, "cut": {"axis": "y", "at": 0.5}}  # fmt: skip
    (tmp_path / "tiny.yaml").write_text(yaml.safe_dump({"adaptivity3d_study": {"scenes": {"tiny": tiny}}}))
    exe = Path(sys.executable).with_name("snakemake")
    targets = [f"results/adaptive3d/tiny/{name}.png" for name in ("convergence", "meshes")]
    run = subprocess.run(
        [str(exe), *targets, "--cores", "1", "--configfile", "tiny.yaml"],
        cwd=tmp_path, capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    with xr.open_dataset(tmp_path / "results/adaptive3d/tiny/adaptive-mesh1.nc") as ds:
        assert "mesh3d" in ds and ds["error_indicator"].dims == ("mesh3d_nVolumes",) and "u3" in ds
    with xr.open_dataset(tmp_path / "results/adaptive3d/tiny/uniform.nc") as ds:
        assert ds.attrs["adapt_steps"] == 2 and ds["adapt_n_cells"].values.tolist() == [
            4,
            32,
        ]  # 2 x 2 x 1 boxes, then 8 each
    assert all((tmp_path / target).stat().st_size > 10_000 for target in targets)
