"""Sweep benchmark (issue 5, item 5): >= 100 solves at h = 2^-5 within 3 minutes with `snakemake -j2`.

    .venv/bin/python benchmarks/sweep.py [--sweep friction-compliance] [--skip-inprocess]

(a) in one process: the sweep of config/sweeps.yaml solved with the problem (mesh, K, load and,
    when the contact solver takes one, the linear solver) reused across the contact parameters,
    and again built afresh for every point;
(b) the workflow: `snakemake -j2 --forceall results/sweeps/<sweep>.nc` timed from the command
    line (Python start-ups, DAG, the parts in parallel, the gathering). The repository's Snakefile
    is used when it includes workflow/rules/sweeps.smk, else a scratch Snakefile including it.
Writes benchmarks/out/sweep.{json,md}.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = Path(__file__).resolve().parent / "out"
LIMIT = 180.0  # seconds


def sweep_config(name: str) -> dict:
    import yaml

    data = yaml.safe_load((ROOT / os.environ.get("VEMKIT_SWEEPS_CONFIG", "config/sweeps.yaml")).read_text())
    spec = dict(data["sweeps"][name])
    solver = {**data.get("sweep_defaults", {}).get("solver", {"method": "ssn", "tol": 1e-10}), **spec.get("solver", {})}
    spec["all_overrides"] = (
        data.get("overrides", []) + spec.get("overrides", []) + [f"solver.{k}={v}" for k, v in solver.items()]
    )
    spec["scene"] = data.get("scene", "config/scenes/paper.yaml")
    return spec


def in_process(name: str) -> dict:
    import numpy as np

    from vemkit.config.scene import load_scene
    from vemkit.solvers.verification import prebuilt_linear_supported
    from vemkit.studies.sweeps import run_sweep

    spec = sweep_config(name)
    scene = load_scene(ROOT / spec["scene"], spec["all_overrides"])
    out = {
        "sweep": name,
        "n": scene.mesh_options["n"],
        "solver": scene.solver_options["method"],
        "linear_solver_reuse_supported": prebuilt_linear_supported(),
    }
    for reuse in (True, False):
        t0 = time.perf_counter()
        ds = run_sweep(scene, spec["grid"], reuse=reuse)
        seconds = time.perf_counter() - t0
        out["reused" if reuse else "fresh"] = {
            "seconds": seconds,
            "points": int(ds.attrs["points"]),
            "converged": int(ds.attrs["converged_points"]),
            "solve_seconds": float(ds["wall_time"].sum()),
            "setup_seconds": float(ds["setup_time"].sum()),
            "mean_solve_seconds": float(ds["wall_time"].mean()),
            "n_dofs": int(np.max(ds["n_dofs"].values)),
        }
    return out


def snakemake_run(name: str) -> dict:
    target = f"results/sweeps/{name}.nc"
    snakefile = ROOT / "Snakefile"
    scratch = None
    if "workflow/rules/sweeps.smk" not in snakefile.read_text(encoding="utf-8"):
        scratch = tempfile.NamedTemporaryFile("w", suffix=".smk", delete=False)  # noqa: SIM115
        scratch.write(f'include: "{ROOT / "workflow/rules/sweeps.smk"}"\n')
        scratch.close()
        snakefile = Path(scratch.name)
    command = [
        str(Path(sys.executable).with_name("snakemake")),
        "-s",
        str(snakefile),
        "-d",
        str(ROOT),
        "-j2",
        "--forceall",
        "--quiet",
        "rules",
        "--",
        target,
    ]
    t0 = time.perf_counter()
    run = subprocess.run(command, cwd=ROOT, capture_output=True, text=True)
    seconds = time.perf_counter() - t0
    if scratch is not None:
        Path(scratch.name).unlink()
    if run.returncode != 0:
        raise RuntimeError(f"snakemake failed ({run.returncode}):\n{run.stdout[-3000:]}\n{run.stderr[-3000:]}")
    benchmarks = {}
    for tsv in sorted((ROOT / "results/benchmarks/sweeps" / name).glob("*.tsv")):
        fields = tsv.read_text().splitlines()
        row = dict(zip(fields[0].split("\t"), fields[-1].split("\t")))
        benchmarks[tsv.stem] = {"seconds": float(row["s"]), "max_rss_mb": float(row["max_rss"])}
    import xarray as xr

    with xr.open_dataset(ROOT / target) as ds:
        points, converged = int(ds.attrs["points"]), int(ds.attrs["converged_points"])
    shown = (
        ["snakemake", "-j2", "--forceall", target]
        if scratch is None
        else ["snakemake", "-s", "<scratch Snakefile including workflow/rules/sweeps.smk>", "-j2", "--forceall", target]
    )
    return {
        "command": " ".join(shown),
        "seconds": seconds,
        "points": points,
        "converged": converged,
        "jobs": benchmarks,
        "within_limit": seconds <= LIMIT,
        "limit_seconds": LIMIT,
    }


def markdown(result: dict) -> str:
    lines = ["# Sweep benchmark", "", f"{result['machine']}", ""]
    proc = result.get("in_process")
    if proc:
        lines += [
            f"Sweep `{proc['sweep']}`: h = 1/{proc['n']}, {proc['reused']['n_dofs']} unknowns, solver "
            f"{proc['solver']}; linear solver reuse supported by the contact solver: "
            f"{proc['linear_solver_reuse_supported']}.",
            "",
            "| in one process | points | converged | total [s] | set-up [s] | solves [s] | mean solve [s] |",
            "|---|---:|---:|---:|---:|---:|---:|",
        ]
        for key, label in (("reused", "problem reused"), ("fresh", "built per point")):
            r = proc[key]
            lines.append(
                f"| {label} | {r['points']} | {r['converged']} | {r['seconds']:.2f} | {r['setup_seconds']:.2f} | "
                f"{r['solve_seconds']:.2f} | {r['mean_solve_seconds']:.3f} |"
            )
    snake = result.get("snakemake")
    if snake:
        lines += [
            "",
            f"Workflow: `{snake['command']}`: **{snake['seconds']:.1f} s** for {snake['points']} solves "
            f"({snake['converged']} converged); limit {snake['limit_seconds']:.0f} s: "
            f"{'met' if snake['within_limit'] else 'NOT met'}.",
            "",
            "| job | seconds | max RSS [MB] |",
            "|---|---:|---:|",
        ]
        lines += [f"| {job} | {b['seconds']:.2f} | {b['max_rss_mb']:.0f} |" for job, b in snake["jobs"].items()]
    return "\n".join(lines) + "\n"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sweep", default="friction-compliance")
    parser.add_argument("--skip-inprocess", action="store_true")
    args = parser.parse_args(argv)
    result = {"machine": f"{platform.platform()}, {os.cpu_count()} CPUs, Python {platform.python_version()}"}
    if not args.skip_inprocess:
        result["in_process"] = in_process(args.sweep)
    result["snakemake"] = snakemake_run(args.sweep)
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "sweep.json").write_text(json.dumps(result, indent=1) + "\n", encoding="utf-8")
    text = markdown(result)
    (OUT / "sweep.md").write_text(text, encoding="utf-8")
    print(text)
    return 0 if result["snakemake"]["within_limit"] else 1


if __name__ == "__main__":
    sys.exit(main())
