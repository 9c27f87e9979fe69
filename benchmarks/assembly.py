"""Assembly and linear-solve benchmark (issue 2, item 7). Writes benchmarks/out/assembly.{json,md}.

    .venv/bin/python benchmarks/assembly.py [--quick]

(a) stiffness assembly to CSR (after JIT warm-up, sparsity pattern included) on 256^2, 512^2,
    1024^2 squares and a 512^2 structured triangle mesh, beside scikit-fem's P1 elasticity
    assembly on the same triangle mesh;
(b) the linear elastic paper scene (contact boundary traction-free) solved by pyamg-CG at
    h = 2^-8 and 2^-10, each in a fresh process so that its peak memory (ru_maxrss) is its own.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time

import numpy as np

from _common import MACHINE, OUT, best_of


def assembly_case(kind: str, n: int, repeat: int) -> dict:
    from vemkit.mesh.families.square import square, structured_triangle
    from vemkit.vem.elasticity import lame_parameters
    from vemkit.vem.space import VirtualElementSpace

    lam, mu = lame_parameters(2000.0, 0.4)
    mesh = (square if kind == "square" else structured_triangle)(n)
    VirtualElementSpace(square(2)).stiffness_matrix(lam, mu, "dofi-2mu")  # JIT warm-up (cached kernels load)
    seconds, A = best_of(lambda: VirtualElementSpace(mesh).stiffness_matrix(lam, mu, "dofi-2mu"), repeat)
    return {
        "case": f"vemkit {kind} {n}x{n}",
        "cells": mesh.n_cells,
        "dofs": A.shape[0],
        "nnz": int(A.nnz),
        "seconds": seconds,
        "cells_per_second": mesh.n_cells / seconds,
    }


def skfem_case(n: int, repeat: int) -> dict:
    import skfem
    from skfem.models.elasticity import linear_elasticity

    from vemkit.mesh.families.square import structured_triangle
    from vemkit.vem.elasticity import lame_parameters

    lam, mu = lame_parameters(2000.0, 0.4)
    mesh = structured_triangle(n)
    m = skfem.MeshTri(mesh.vertices.T.copy(), mesh.cell_vertices.reshape(-1, 3).T.copy())
    form = linear_elasticity(lam, mu)

    def run():
        basis = skfem.Basis(m, skfem.ElementVector(skfem.ElementTriP1()))
        return skfem.asm(form, basis).tocsr()

    seconds, A = best_of(run, repeat)
    return {
        "case": f"scikit-fem P1 triangle {n}x{n}",
        "cells": mesh.n_cells,
        "dofs": A.shape[0],
        "nnz": int(A.nnz),
        "seconds": seconds,
        "cells_per_second": mesh.n_cells / seconds,
    }


def linear_solve_case(n: int) -> dict:
    """Runs in its own process (see main): the paper scene without contact, AMG-CG."""
    from vemkit.contact.problem import discrete_problem
    from vemkit.mesh.families.square import square
    from vemkit.solvers.dispatch import single_threaded_blas
    from vemkit.solvers.linear import linear_solver

    discrete_problem(square(2), 2000.0, 0.4, neumann={"left": lambda x, y: (x, y)})  # JIT warm-up
    t0 = time.perf_counter()
    mesh = square(n)
    t1 = time.perf_counter()
    pb = discrete_problem(
        mesh,
        2000.0,
        0.4,
        dirichlet=("right",),
        neumann={"left": lambda x, y: (200 * (5 - y), -200 + 0 * y), "top": lambda x, y: (0 * x, 0 * x)},
    )
    t2 = time.perf_counter()
    with single_threaded_blas():  # as every vemkit solve (vemkit.solvers.dispatch)
        solver = linear_solver(pb.stiffness, "amg", pb.near_nullspace, tol=1e-8)
        t3 = time.perf_counter()
        u = solver.solve(pb.load)
    t4 = time.perf_counter()
    assert np.all(np.isfinite(u))
    return {
        "case": f"paper scene, no contact, h = 1/{n}",
        "dofs": pb.n_dofs,
        "mesh_s": t1 - t0,
        "assembly_s": t2 - t1,
        "amg_setup_s": t3 - t2,
        "cg_solve_s": t4 - t3,
        "cg_iterations": solver.iterations,
        "relative_residual": solver.residual,
        "total_s": t4 - t1,
        "total_with_mesh_s": t4 - t0,
        "peak_memory_gib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20,
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="smaller meshes (a smoke test, not the targets)")
    parser.add_argument("--linear-case", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.linear_case:
        print(json.dumps(linear_solve_case(args.linear_case)))
        return
    sizes = [64, 128, 256] if args.quick else [256, 512, 1024]
    tri = 128 if args.quick else 512
    solve_sizes = [64, 128] if args.quick else [256, 1024]
    assembly = [assembly_case("square", n, 3) for n in sizes]
    assembly.append(assembly_case("triangle", tri, 3))
    assembly.append(skfem_case(tri, 1))
    speedup = assembly[-2]["cells_per_second"] / assembly[-1]["cells_per_second"]
    solves = []
    for n in solve_sizes:
        out = subprocess.run(
            [sys.executable, __file__, "--linear-case", str(n)], capture_output=True, text=True, check=True
        )
        solves.append(json.loads(out.stdout.strip().splitlines()[-1]))
    record = {
        "command": "python benchmarks/assembly.py" + (" --quick" if args.quick else ""),
        "machine": MACHINE,
        "assembly": assembly,
        "speedup_vs_scikit_fem": speedup,
        "linear_solves": solves,
        "targets": {
            "speedup >= 10": speedup >= 10,
            "1024^2 squares <= 2 s": (not args.quick) and assembly[2]["seconds"] <= 2.0,
            "h = 2^-8 solve <= 2 s": (not args.quick) and solves[0]["total_s"] <= 2.0,
            "h = 2^-10 solve <= 30 s": (not args.quick) and solves[1]["total_s"] <= 30.0,
            "h = 2^-10 peak memory <= 3 GiB": (not args.quick) and solves[1]["peak_memory_gib"] <= 3.0,
        },
    }
    OUT.mkdir(exist_ok=True)
    (OUT / "assembly.json").write_text(json.dumps(record, indent=2))
    lines = [
        "# Assembly and linear solve benchmark",
        "",
        f"`{record['command']}` on {record['machine']}",
        "",
        "| case | cells | dofs | nnz | seconds | cells/s |",
        "|---|---|---|---|---|---|",
    ]
    for r in assembly:
        lines.append(
            f"| {r['case']} | {r['cells']} | {r['dofs']} | {r['nnz']} | {r['seconds']:.3f} | {r['cells_per_second']:.3g} |"
        )
    lines += [
        "",
        f"vemkit / scikit-fem elements per second on the same triangle mesh: **{speedup:.1f}x**",
        "",
        "| case | dofs | assembly s | AMG setup s | CG s | CG its | total s (no mesh) | peak GiB |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in solves:
        lines.append(
            f"| {r['case']} | {r['dofs']} | {r['assembly_s']:.2f} | {r['amg_setup_s']:.2f} | {r['cg_solve_s']:.2f} | "
            f"{r['cg_iterations']} | {r['total_s']:.2f} | {r['peak_memory_gib']:.2f} |"
        )
    lines += ["", "Targets: " + ", ".join(f"{k}: {'met' if v else 'NOT met'}" for k, v in record["targets"].items())]
    (OUT / "assembly.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
