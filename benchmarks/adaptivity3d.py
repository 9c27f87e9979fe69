"""Adaptive refinement in 3D, speed (issue 36 item 6). Writes benchmarks/out/adaptivity3d.{json,md}.

    .venv/bin/python benchmarks/adaptivity3d.py [--quick]

Each case is one whole ``vemkit adapt`` process (start-up, every solve, estimate, marking and
refinement, the file), from the scene's coarse mesh until the next mesh would pass
``adaptivity.max_dofs`` = 1.2 x 10⁵ unknowns (so that they end at about 10⁵). Reported per case: the process's wall time, the loop's own
time (``adapt_wall_time``: what the steps cost without measuring the true error, which a scene with
``exact:`` adds per step as ``adapt_error_time``), and per step the DOFs, the step's wall time and its
parts (``adapt_solve_time``: assembly, contact solve and independent check; the rest: estimate,
marking, refinement and its checks). The cost per step should grow about linearly in the DOFs: the
slope of log(step time) against log(DOFs) over the steps above 10⁴ DOFs is fitted.

Targets: every run ends at about 10⁵ DOFs in at most 120 s of loop time, and the per-step slope is
at most 1.3 (roughly linear; the contact solve grows fastest, its AMG updates with Γ_C).
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import xarray as xr

from _common import MACHINE, quick_parser, targets_line, write_report

ROOT = Path(__file__).resolve().parents[1]
VEMKIT = [sys.executable, "-m", "vemkit.cli"]
#: label -> (scene, overrides): an edge singularity, frictional contact (ssn), a vertex singularity
CASES = {
    "lshape_edge": ("config/scenes/3d/lshape_edge.yaml", ["discretization.mesh.n=4", "solver.linear=amg"]),
    "sheared_box": ("config/scenes/3d/sheared_box.yaml", ["discretization.mesh.n=4"]),
    "fichera": ("config/scenes/3d/fichera.yaml", ["solver.linear=amg"]),
}
MAX_DOFS = 120_000  # the runs end at about 10⁵ (the next mesh would pass this)
LOOP_TARGET = 120.0  # s
SLOPE_TARGET = 1.3  # "roughly linear": N^1.3 at most


def run_case(label: str, max_dofs: int) -> dict:
    scene, overrides = CASES[label]
    settings = [f"adaptivity.max_dofs={max_dofs}", "adaptivity.marking.dorfler=0.3", "adaptivity.target=1e-4"]
    settings.append("adaptivity.max_steps=80")
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "a.nc"
        args = [*VEMKIT, "adapt", ROOT / scene, "-o", out, "-q"]
        for item in overrides + settings:
            args += ["--set", item]
        start = time.perf_counter()
        done = subprocess.run(list(map(str, args)), capture_output=True, text=True, cwd=ROOT)
        process = time.perf_counter() - start
        if done.returncode != 0:
            raise SystemExit(f"{label}: vemkit adapt failed: {done.stderr.strip()}")
        with xr.open_dataset(out) as ds:
            steps = {name: ds[f"adapt_{name}"].values.tolist() for name in ("n_dofs", "wall_time", "solve_time")}
            errors = (
                ds["adapt_error_time"].values.tolist() if "adapt_error_time" in ds else [0.0] * len(steps["n_dofs"])
            )
            record = {"reason": ds.attrs["adapt_stop_reason"], "loop_time": float(ds.attrs["adapt_wall_time"])}
    dofs, wall = np.array(steps["n_dofs"], float), np.array(steps["wall_time"])
    large = dofs >= 1e4
    slope = float(np.polyfit(np.log(dofs[large]), np.log(wall[large]), 1)[0]) if large.sum() >= 3 else float("nan")
    return {
        **record,
        "process_time": process,
        "error_time": float(sum(errors)),
        "steps": steps,
        "final_dofs": int(dofs[-1]),
        "slope": slope,
        "microseconds_per_dof_last_step": 1e6 * float(wall[-1] / dofs[-1]),
    }


def _lines(results: dict, targets: dict, quick: bool) -> list:
    lines = [
        f"# Adaptive refinement in 3D: speed ({MACHINE}){' (--quick: not the targets)' if quick else ''}",
        "",
        "Command: `.venv/bin/python benchmarks/adaptivity3d.py` (each case one `vemkit adapt` process, Dörfler θ = 0.3,",
        f"until the next mesh would pass {MAX_DOFS if not quick else 'the quick limit of'} unknowns).",
        "",
        "| case | steps | final DOFs | loop time (s) | process time (s) | of which true error (s) | slope of step time in DOFs | µs per DOF, last step |",
        "|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for label, r in results.items():
        lines.append(
            f"| {label} | {len(r['steps']['n_dofs'])} | {r['final_dofs']} | {r['loop_time']:.1f} | "
            f"{r['process_time']:.1f} | {r['error_time']:.1f} | {r['slope']:.2f} | {r['microseconds_per_dof_last_step']:.0f} |"
        )
    for label, r in results.items():
        lines += [
            "",
            f"## {label}: per step",
            "",
            "| DOFs | step (s) | solve (s) | estimate + refine (s) |",
            "|---:|---:|---:|---:|",
        ]
        for n, w, s in zip(r["steps"]["n_dofs"], r["steps"]["wall_time"], r["steps"]["solve_time"], strict=True):
            lines.append(f"| {n} | {w:.2f} | {s:.2f} | {w - s:.2f} |")
    return lines + ["", targets_line(targets)]


def main() -> None:
    args = quick_parser(__doc__, "runs to 5000 DOFs").parse_args()
    max_dofs = 5000 if args.quick else MAX_DOFS
    results = {label: run_case(label, max_dofs) for label in CASES}
    targets = {
        f"loop time <= {LOOP_TARGET:.0f} s to ~1e5 DOFs": all(r["loop_time"] <= LOOP_TARGET for r in results.values()),
        f"step time about linear in DOFs (slope <= {SLOPE_TARGET})": all(
            not r["slope"] > SLOPE_TARGET for r in results.values()
        ),
    }
    write_report("adaptivity3d", {"machine": MACHINE, "quick": args.quick, "results": results, "targets": targets},
                 _lines(results, targets, args.quick))  # fmt: skip


if __name__ == "__main__":
    main()
