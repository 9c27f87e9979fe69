"""Cook's membrane solve benchmark (issue 11, item 8). Writes benchmarks/out/cook.{json,md}.

    .venv/bin/python benchmarks/cook.py [--quick] [--families square triangle] [--n 4 8 19]

config/scenes/cook.yaml (plane stress E = 1, nu = 1/3, total shear 1 on side ``load``, clamped
left side, no contact) at about 10^6 DOFs (``discretization.mesh.n`` cells per unit length; the
panel's area is 1440, so n = 19 gives about 1.05 million unknowns on either family), solved with
the scene's solver (``ssn``, tol 1e-10; without contact it is one AMG-CG solve). Every case runs
in a fresh process, after a warm-up on a coarse mesh (Numba compiled, imports done), so that its
peak memory (ru_maxrss) is its own. Timed apart, wall and CPU time (the machine may be shared;
CPU time counts every thread): the mesh, the assembly (``scene_problem`` on the given mesh), the
``ssn`` solve, and the independent check (``verify_solution`` at the scene's check tolerance,
which must pass). Also reported: v at (48, 52), the middle of the loaded edge (published 23.96),
on every size (the coarser ones show its convergence and how the times scale).
Targets (on the cases with at least 900 000 DOFs): ssn solve <= 30 s, peak memory <= 4 GiB.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from _common import MACHINE, quick_parser, targets_line, write_report

COOK_SCENE = Path(__file__).resolve().parents[1] / "config" / "scenes" / "cook.yaml"
TIP = (48.0, 52.0)  # the middle of the loaded edge
PUBLISHED_TIP = 23.96  # Belytschko et al. 2014, Table 8.1
FAMILIES = ("square", "triangle")
SIZES = (4, 8, 19)  # cells per unit length; 19: about 1.04e6 DOFs on either family
TARGET_DOFS = 900_000  # "about 10^6"


def edge_value(problem, u_free, side: str, point) -> float:
    """v at ``point`` on a straight vertical side: linear along the side's edges (exact for k = 1)."""
    mesh = problem.mesh
    u = problem.dofs.expand(u_free)
    edges = mesh.boundary[side]
    y = mesh.vertices[edges, 1]
    lo, hi = np.minimum(y[:, 0], y[:, 1]), np.maximum(y[:, 0], y[:, 1])
    e = int(np.flatnonzero((lo <= point[1]) & (point[1] <= hi))[0])
    a, b = edges[e]
    ya, yb = mesh.vertices[a, 1], mesh.vertices[b, 1]
    s = 0.0 if yb == ya else (point[1] - ya) / (yb - ya)
    return float((1.0 - s) * u[a, 1] + s * u[b, 1])


def _timed(call):
    t, c = time.perf_counter(), time.process_time()
    out = call()
    return out, time.perf_counter() - t, time.process_time() - c


def run_case(family: str, n: int) -> dict:
    from vemkit.config.scene import load_scene
    from vemkit.contact.problem import scene_problem
    from vemkit.mesh import scene_mesh
    from vemkit.solvers.dispatch import solve
    from vemkit.solvers.verification import verify_solution
    from vemkit.studies.scene_solve import check_tolerance

    def scene_at(size):
        return load_scene(COOK_SCENE, [f"discretization.mesh.family={family}", f"discretization.mesh.n={size}"])

    warm = scene_at(1)
    warm_problem = scene_problem(warm)
    warm_solution = solve(warm_problem, {**warm.solver_options, "linear": "amg"})  # AMG imported and run once
    verify_solution(warm_problem, warm_solution.u, warm_solution.multiplier)
    scene = scene_at(n)
    mesh, mesh_s, mesh_cpu = _timed(lambda: scene_mesh(scene))
    problem, assembly_s, assembly_cpu = _timed(lambda: scene_problem(scene, mesh))
    solution, solve_s, solve_cpu = _timed(lambda: solve(problem, scene.solver_options))
    tol = check_tolerance(scene.solver_options)
    checks, check_s, check_cpu = _timed(lambda: verify_solution(problem, solution.u, solution.multiplier, tol))
    return {
        "family": family,
        "n": n,
        "cells": mesh.n_cells,
        "vertices": mesh.n_vertices,
        "dofs": problem.n_dofs,
        "nnz": int(problem.stiffness.nnz),
        "method": solution.method,
        "linear": solution.info.get("linear"),
        "tol": scene.solver_options["tol"],
        "linear_iterations": int(solution.linear_iterations),  # 1 if direct
        "mesh_s": mesh_s,
        "mesh_cpu_s": mesh_cpu,
        "assembly_s": assembly_s,
        "assembly_cpu_s": assembly_cpu,
        "solve_s": solve_s,
        "solve_cpu_s": solve_cpu,
        "check_s": check_s,
        "check_cpu_s": check_cpu,
        "check_worst": checks["worst"],
        "check_tolerance": tol,
        "check_passed": checks["passed"],
        "tip_v": edge_value(problem, solution.u, "load", TIP),
        "peak_memory_gib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20,
    }


def run_in_subprocess(family: str, n: int) -> dict:
    """One case in a fresh process; adds its CPU time as the parent sees it (os.times of children)."""
    before = os.times()
    out = subprocess.run([sys.executable, __file__, "--case", family, str(n)], capture_output=True, text=True)
    after = os.times()
    if out.returncode != 0:
        return {"family": family, "n": n, "error": (out.stderr.strip().splitlines() or ["?"])[-1]}
    row = json.loads(out.stdout.strip().splitlines()[-1])
    row["process_cpu_s"] = (after.children_user - before.children_user) + (
        after.children_system - before.children_system
    )
    row["process_wall_s"] = after.elapsed - before.elapsed
    row["load_average_after"] = [round(x, 2) for x in os.getloadavg()]
    return row


def targets_of(rows: list, families: list) -> dict:
    """Per family, on its cases with at least TARGET_DOFS unknowns (not met if there is none)."""
    targets = {}
    for family in families:
        large = [r for r in rows if r["family"] == family and r.get("dofs", 0) >= TARGET_DOFS]
        failed = [r for r in rows if r["family"] == family and "error" in r]
        targets[f"{family}: ssn <= 30 s at >= {TARGET_DOFS} DOFs"] = (
            bool(large) and not failed and all(r["solve_s"] <= 30.0 for r in large)
        )
        targets[f"{family}: peak <= 4 GiB"] = bool(large) and all(r["peak_memory_gib"] <= 4.0 for r in large)
        targets[f"{family}: independent check passed at every size"] = not failed and all(
            r["check_passed"] for r in rows if r["family"] == family
        )
    return targets


def table(rows: list) -> list:
    lines = [
        "| family | n | cells | DOFs | mesh s (CPU) | assembly s (CPU) | ssn solve s (CPU) | linear solver (its) | "
        "check s (CPU) | check worst | v(48, 52) | peak GiB | process s (CPU) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        if "error" in r:
            lines.append(f"| {r['family']} | {r['n']} | failed: {r['error']} |" + " |" * 10)
            continue
        lines.append(
            f"| {r['family']} | {r['n']} | {r['cells']} | {r['dofs']} | {r['mesh_s']:.2f} ({r['mesh_cpu_s']:.2f}) | "
            f"{r['assembly_s']:.2f} ({r['assembly_cpu_s']:.2f}) | {r['solve_s']:.2f} ({r['solve_cpu_s']:.2f}) | "
            f"{r['linear']} ({r['linear_iterations']}) | {r['check_s']:.2f} ({r['check_cpu_s']:.2f}) | {r['check_worst']:.1e} | "
            f"{r['tip_v']:.4f} | {r['peak_memory_gib']:.2f} | {r['process_wall_s']:.1f} ({r['process_cpu_s']:.1f}) |"
        )
    return lines


def main():
    parser = quick_parser(__doc__, "n = 2, 4 only (at most 47 000 DOFs)")
    parser.add_argument("--families", nargs="+", default=list(FAMILIES))
    parser.add_argument(
        "--n", type=int, nargs="+", default=list(SIZES), help="cells per unit length (19: about 1.05e6 DOFs)"
    )
    parser.add_argument("--case", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.case:
        print(json.dumps(run_case(args.case[0], int(args.case[1]))))
        return
    sizes = [2, 4] if args.quick else args.n
    load_before = [round(x, 2) for x in os.getloadavg()]
    rows = []
    for family in args.families:
        for n in sizes:
            rows.append(run_in_subprocess(family, n))
            print(rows[-1], flush=True)
    command = (
        "python benchmarks/cook.py"
        + (" --quick" if args.quick else "")
        + ("" if args.n == list(SIZES) or args.quick else " --n " + " ".join(map(str, args.n)))
        + ("" if args.families == list(FAMILIES) else " --families " + " ".join(args.families))
    )
    targets = targets_of(rows, args.families)
    record = {
        "command": command,
        "machine": MACHINE,
        "cpu_count": os.cpu_count(),
        "scene": str(COOK_SCENE.name),
        "published_tip_v": PUBLISHED_TIP,
        "load_average_before": load_before,
        "load_average_after": [round(x, 2) for x in os.getloadavg()],
        "rows": rows,
        "targets": targets,
    }
    lines = [
        "# Cook's membrane: one ssn solve at about 10^6 DOFs",
        "",
        f"`{command}` on {MACHINE}, {os.cpu_count()} cores",
        "",
        *table(rows),
        "",
        "Seconds are wall time, CPU time (all threads of the process) in brackets; each case runs in its own "
        "process after a warm-up at n = 1 (process s: the whole subprocess, imports and warm-up included). "
        f"`check`: the independent verification (`verify_solution`) at the scene's check tolerance. "
        f"v(48, 52): mid loaded edge, published {PUBLISHED_TIP}.",
        f"Load average (1, 5, 15 min) before: {load_before}, after: {record['load_average_after']} "
        "(shared machine: wall time includes waiting for a core).",
        "",
        targets_line(targets, "Targets"),
    ]
    write_report("cook", record, lines)


if __name__ == "__main__":
    main()
