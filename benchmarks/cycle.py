"""The AMG-CG pieces on one stiffness matrix, A/B in one process (issue 22): set-up, the plain CG
solve K u = f with the V-cycle in float64 and in float32 (vemkit.solvers.linear.CYCLE_PRECISION)
and one V-cycle in each.

    .venv/bin/python benchmarks/cycle.py --n 1024 [--family square|triangle] [--repeat 3] [--tol 1e-10]

Every time is the best of ``--repeat`` runs (wall seconds). Prints one JSON line.
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from _common import best_of, paper_problem


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, default=256)
    parser.add_argument("--family", default="square")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--tol", type=float, default=1e-10)
    parser.add_argument("--setup-repeat", type=int, default=1)
    args = parser.parse_args()
    from vemkit.solvers import linear

    problem, record = paper_problem(args.n, args.family)
    K, f = problem.stiffness.tocsr(), problem.load
    record["setup_s"], amg = best_of(
        lambda: linear.AMGSolver(K, problem.near_nullspace, tol=args.tol), args.setup_repeat
    )
    x = np.random.default_rng(0).standard_normal(K.shape[0])
    for precision in (np.float64, np.float32):
        name = np.dtype(precision).name
        amg.preconditioner = linear.v_cycle_preconditioner(amg.hierarchy, precision)
        record[f"cycle_{name}_s"], _ = best_of(lambda: amg.preconditioner @ x, args.repeat)
        record[f"cg_{name}_s"], u = best_of(lambda: amg.solve(f), args.repeat)
        record[f"cg_{name}_iterations"], record[f"cg_{name}_residual"] = amg.iterations, amg.residual
    print(json.dumps(record))


if __name__ == "__main__":
    main()
