"""k = 2 against k = 1 stiffness assembly, time per degree of freedom (issue 14, item 6 first half).
Writes benchmarks/out/assembly_k2.{json,md}.

    .venv/bin/python benchmarks/assembly_k2.py [--quick] [--repeat R]

Both assemblies start from the mesh and end with the CSR matrix (sparsity pattern and dof
numbering included: each builds its space's DofMap inside the timed call), all dofs free, `dofi-2mu`.
The best of R runs after a JIT warm-up is kept; wall time and process CPU time (all threads) are
both recorded, because the machine may be shared: CPU time per dof is the steadier comparison.
"""

from __future__ import annotations

import time

from _common import MACHINE, quick_parser, targets_line, write_report


def timed(fn, repeat):
    """(best wall s, best CPU s, result) over ``repeat`` runs."""
    walls, cpus = [], []
    for _ in range(repeat):
        w, c = time.perf_counter(), time.process_time()
        result = fn()
        walls.append(time.perf_counter() - w)
        cpus.append(time.process_time() - c)
    return min(walls), min(cpus), result


def case(n: int, repeat: int) -> dict:
    from vemkit.mesh.families.square import square
    from vemkit.vem.elasticity import lame_parameters
    from vemkit.vem.space import VirtualElementSpace

    lam, mu = lame_parameters(2000.0, 0.4)
    warm = square(2)
    for order in (1, 2):
        VirtualElementSpace(warm, order).stiffness_matrix(lam, mu, "dofi-2mu")
    mesh = square(n)
    t = time.perf_counter()
    mesh.edges  # noqa: B018  (mesh topology, cached on the mesh: not part of either assembly)
    row = {"mesh": f"{n}x{n} squares", "cells": mesh.n_cells, "mesh_edges_s": time.perf_counter() - t}
    runs = {
        "k1": lambda: VirtualElementSpace(mesh, 1).stiffness_matrix(lam, mu, "dofi-2mu"),
        "k2": lambda: VirtualElementSpace(mesh, 2).stiffness_matrix(lam, mu, "dofi-2mu"),
    }
    for k, fn in runs.items():
        wall, cpu, A = timed(fn, repeat)
        row[k] = {
            "dofs": A.shape[0],
            "nnz": int(A.nnz),
            "wall_s": wall,
            "cpu_s": cpu,
            "wall_us_per_dof": 1e6 * wall / A.shape[0],
            "cpu_us_per_dof": 1e6 * cpu / A.shape[0],
        }
    row["wall_ratio_per_dof"] = row["k2"]["wall_us_per_dof"] / row["k1"]["wall_us_per_dof"]
    row["cpu_ratio_per_dof"] = row["k2"]["cpu_us_per_dof"] / row["k1"]["cpu_us_per_dof"]
    return row


def main():
    args = quick_parser(__doc__, "64^2 and 128^2", repeat=5).parse_args()
    sizes = [64, 128] if args.quick else [256, 512]
    rows = [case(n, args.repeat) for n in sizes]
    command = "python benchmarks/assembly_k2.py" + (" --quick" if args.quick else "") + f" --repeat {args.repeat}"
    met = {f"{r['mesh']}: k2/k1 wall time per dof <= 2": r["wall_ratio_per_dof"] <= 2.0 for r in rows}
    met.update({f"{r['mesh']}: k2/k1 CPU time per dof <= 2": r["cpu_ratio_per_dof"] <= 2.0 for r in rows})
    record = {"command": command, "machine": MACHINE, "cases": rows, "targets": met}
    lines = [
        "# k = 2 against k = 1 assembly (time per dof)",
        "",
        f"`{command}` on {record['machine']}",
        "",
        "| mesh | k | dofs | nnz | wall s | CPU s | wall us/dof | CPU us/dof |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        for k in ("k1", "k2"):
            x = r[k]
            lines.append(
                f"| {r['mesh']} | {k[1]} | {x['dofs']} | {x['nnz']} | {x['wall_s']:.3f} | {x['cpu_s']:.3f} | "
                f"{x['wall_us_per_dof']:.3f} | {x['cpu_us_per_dof']:.3f} |"
            )
    lines += ["", "| mesh | k2/k1 wall per dof | k2/k1 CPU per dof |", "|---|---|---|"]
    lines += [f"| {r['mesh']} | {r['wall_ratio_per_dof']:.2f} | {r['cpu_ratio_per_dof']:.2f} |" for r in rows]
    lines += ["", targets_line(met)]
    write_report("assembly_k2", record, lines)


if __name__ == "__main__":
    main()
