"""Contact solver benchmark (issue 3, item 7). Writes benchmarks/out/contact.{json,md}.

    .venv/bin/python benchmarks/contact.py [--quick] [--max-level 10] [--uzawa-max-level 8]

The paper scene on square meshes h = 2^-2 ... 2^-10: iterations and wall time of `ssn` and
`uzawa` (linear solver "auto": SuperLU below 60 000 unknowns, AMG-CG above). Every case runs in
a fresh process (JIT caches warm) so that its peak memory (ru_maxrss) is its own. Wall time is
the contact solver's (preconditioner or factorization set-up included); assembly is listed apart.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time

from _common import MACHINE, OUT, PAPER_SCENE


def run_case(method: str, level: int) -> dict:
    from vemkit.config.scene import load_scene
    from vemkit.contact.problem import scene_problem
    from vemkit.solvers.dispatch import solve as solve_problem

    scene = load_scene(PAPER_SCENE, [f"discretization.mesh.n={2**level}", f"solver.method={method}"])
    warm = load_scene(PAPER_SCENE, ["discretization.mesh.n=4", f"solver.method={method}"])
    solve_problem(scene_problem(warm), warm.solver_options)  # JIT warm-up
    t0 = time.perf_counter()
    problem = scene_problem(scene)
    t1 = time.perf_counter()
    solution = solve_problem(problem, scene.solver_options)
    t2 = time.perf_counter()
    return {
        "method": method,
        "h": f"2^-{level}",
        "n": 2**level,
        "dofs": problem.n_dofs,
        "iterations": int(solution.iterations),
        "linear_iterations": int(solution.linear_iterations),
        "assembly_s": t1 - t0,
        "solve_s": t2 - t1,
        "peak_memory_gib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20,
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="levels 2..6 only (a smoke test)")
    parser.add_argument("--max-level", type=int, default=10)
    parser.add_argument("--uzawa-max-level", type=int, default=8, help="uzawa is only run up to this level")
    parser.add_argument("--case", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.case:
        print(json.dumps(run_case(args.case[0], int(args.case[1]))))
        return
    top = 6 if args.quick else args.max_level
    rows = []
    for level in range(2, top + 1):
        for method in ("ssn", "uzawa"):
            if method == "uzawa" and level > args.uzawa_max_level:
                continue
            out = subprocess.run(
                [sys.executable, __file__, "--case", method, str(level)], capture_output=True, text=True
            )
            if out.returncode != 0:
                rows.append({"method": method, "h": f"2^-{level}", "error": out.stderr.strip().splitlines()[-1]})
            else:
                rows.append(json.loads(out.stdout.strip().splitlines()[-1]))
            print(rows[-1], flush=True)

    def find(method, level):
        return next((r for r in rows if r["method"] == method and r["h"] == f"2^-{level}" and "solve_s" in r), None)

    ssn = [r for r in rows if r["method"] == "ssn" and "iterations" in r]
    targets = {}
    if not args.quick:
        s8, u8, s10 = find("ssn", 8), find("uzawa", 8), find("ssn", 10)
        targets = {
            "ssn <= 15 iterations at every h": bool(ssn) and max(r["iterations"] for r in ssn) <= 15,
            "ssn <= 2 s at 2^-8": bool(s8) and s8["solve_s"] <= 2.0,
            "uzawa <= 30 s at 2^-8": bool(u8) and u8["solve_s"] <= 30.0,
            "ssn <= 40 s at 2^-10": bool(s10) and s10["solve_s"] <= 40.0,
            "ssn peak memory <= 4 GiB at 2^-10": bool(s10) and s10["peak_memory_gib"] <= 4.0,
        }
    record = {
        "command": "python benchmarks/contact.py" + (" --quick" if args.quick else ""),
        "machine": MACHINE,
        "rows": rows,
        "targets": targets,
    }
    OUT.mkdir(exist_ok=True)
    (OUT / "contact.json").write_text(json.dumps(record, indent=2))
    lines = [
        "# Contact solvers on the paper scene",
        "",
        f"`{record['command']}` on {record['machine']}",
        "",
        "| h | dofs | method | iterations | linear its | assembly s | solve s | peak GiB |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        if "error" in r:
            lines.append(f"| {r['h']} | | {r['method']} | failed: {r['error']} | | | | |")
        else:
            lines.append(
                f"| {r['h']} | {r['dofs']} | {r['method']} | {r['iterations']} | {r['linear_iterations']} | "
                f"{r['assembly_s']:.2f} | {r['solve_s']:.2f} | {r['peak_memory_gib']:.2f} |"
            )
    if targets:
        lines += ["", "Targets: " + ", ".join(f"{k}: {'met' if v else 'NOT met'}" for k, v in targets.items())]
    (OUT / "contact.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
