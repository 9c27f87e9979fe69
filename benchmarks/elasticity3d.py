"""3D elasticity at about 10^6 DOFs (docs/reference/files.md, issue 20). Writes benchmarks/out/elasticity3d.{json,md}.

    .venv/bin/python benchmarks/elasticity3d.py [--quick] [--n N]

The unit cube in n^3 hexahedra (n = 69: 70^3 vertices, 1 014 300 free DOFs), the bottom face
clamped, a uniform traction (0, 0, -1) on the top face, E = 1, nu = 0.3, dofi-2mu stabilization:
the times of the mesh build, the stiffness assembly (3.9), the traction load, the AMG set-up and
the CG solve (six rigid modes as near-nullspace, relative residual 1e-8), and the wall time of all of
it; the peak resident memory (ru_maxrss) against ``vemkit.config.limits.estimate_resources3d``.
Every Numba kernel is compiled (or loaded from its cache) on a 4^3 mesh first, outside the timing.
Targets: assembly <= 10 s, all <= 60 s wall, peak <= 6 GiB, prediction >= peak (within 1.5x).
"""

from __future__ import annotations

import os
import resource
import time

import numpy as np

from _common import MACHINE, quick_parser, targets_line, write_report

CUBE = {"box": [[0, 0, 0], [1, 1, 1]]}
E, NU = 1.0, 0.3
LAM, MU = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
TOL = 1e-8


def run(n: int) -> dict:
    """One solve on n^3 hexahedra; the seconds of every step."""
    from vemkit.mesh.families3d import build_mesh3d
    from vemkit.solvers.linear import AMGSolver
    from vemkit.vem.elasticity import rigid_body_modes
    from vemkit.vem.space import VirtualElementSpace

    seconds, cpu = {}, {}
    start, start_cpu = time.perf_counter(), time.process_time()

    def step(name, thunk):
        t, c = time.perf_counter(), time.process_time()
        value = thunk()
        seconds[name], cpu[name] = time.perf_counter() - t, time.process_time() - c
        return value

    mesh = step("mesh", lambda: build_mesh3d("hex", CUBE, n=n))
    space = VirtualElementSpace(mesh, 1)
    clamped = np.zeros(space.n_nodes, dtype=bool)
    clamped[mesh.boundary_vertices("bottom")] = True
    dofs = space.numbering(clamped)
    K = step("assembly", lambda: space.stiffness_matrix(LAM, MU, "dofi-2mu", dofs))
    top = mesh.boundary["top"]
    load = step("load", lambda: dofs.restrict(space.traction_load(top, lambda x, y, z: (0 * x, 0 * x, -1 + 0 * x))))
    modes = rigid_body_modes(space.node_coordinates[dofs.free_nodes])
    amg = step("amg_setup", lambda: AMGSolver(K, near_nullspace=modes, tol=TOL))
    u = step("solve", lambda: amg.solve(load))
    seconds["wall"], cpu["wall"] = time.perf_counter() - start, time.process_time() - start_cpu
    return {
        "n": n,
        "cells": mesh.n_cells,
        "vertices": mesh.n_vertices,
        "faces": mesh.n_faces,
        "dofs": int(K.shape[0]),
        "nnz": int(K.nnz),
        "seconds": seconds,
        "cpu_seconds": cpu,
        "iterations": amg.iterations,
        "residual": amg.residual,
        "levels": len(amg.hierarchy.levels),
        "top_deflection": float(-u[2::3].min()),
    }


def main():
    parser = quick_parser(__doc__, "n = 16")
    parser.add_argument("--n", type=int, default=None, help="hexahedra per edge (default 69)")
    args = parser.parse_args()
    n = args.n or (16 if args.quick else 69)
    from vemkit.config.limits import estimate_resources3d

    run(4)  # compile or load every kernel
    record = run(n)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    predicted = estimate_resources3d(record["cells"], record["vertices"], record["faces"])
    s, c = record["seconds"], record["cpu_seconds"]
    record.update(
        command="python benchmarks/elasticity3d.py"
        + (" --quick" if args.quick else "")
        + (f" --n {args.n}" if args.n else ""),
        machine=MACHINE,
        peak_bytes=peak,
        predicted_bytes=predicted.peak_bytes,
        load_average=[round(x, 2) for x in os.getloadavg()],
    )
    full = n >= 69
    record["targets"] = {
        "assembly <= 10 s": full and s["assembly"] <= 10.0,
        "all <= 60 s wall": full and s["wall"] <= 60.0,
        "peak <= 6 GiB": full and peak <= 6 * 2**30,
        "peak <= predicted <= 1.5 peak": peak <= predicted.peak_bytes <= 1.5 * peak,
    }
    gib = 2.0**30
    lines = [
        "# 3D elasticity benchmark (k = 1, hexahedra)",
        "",
        f"`{record['command']}` on {record['machine']}",
        "",
        f"{record['cells']:,} cells, {record['vertices']:,} vertices, {record['dofs']:,} DOFs, "
        f"{record['nnz']:,} nonzeros; AMG {record['levels']} levels, {record['iterations']} CG iterations "
        f"to {record['residual']:.1e}",
        "",
        "| seconds | mesh | assembly | load | AMG set-up | CG | all |",
        "|---|---|---|---|---|---|---|",
        *(
            f"| {label} | "
            + " | ".join(f"{t[k]:.2f}" for k in ("mesh", "assembly", "load", "amg_setup", "solve", "wall"))
            + " |"
            for label, t in (("wall", s), ("CPU (process, all threads)", c))
        ),
        "",
        f"Peak memory (ru_maxrss) {peak / gib:.2f} GiB, predicted (``estimate_resources3d``) "
        f"{predicted.peak_bytes / gib:.2f} GiB.",
        "",
        f"Load average at the end (1, 5, 15 min): {record['load_average']} (2 cores, shared: the wall times "
        "include waiting for a core).",
        "",
        targets_line(record["targets"]),
    ]
    write_report("elasticity3d", record, lines)


if __name__ == "__main__":
    main()
