"""Run the contact solver a scene names (``solver.method``) on an assembled problem.

BLAS threads: vemkit's work is sparse (CSR products, AMG cycles, Numba kernels with their own
threads), and multi-threaded dense BLAS only spins and competes with them (CG was 4x slower on 2
cores). So :func:`solve` runs the solver with BLAS limited to one thread (threadpoolctl), unless
the user has set ``OPENBLAS_NUM_THREADS`` or ``MKL_NUM_THREADS``; nothing is changed at import.
"""

from __future__ import annotations

import os
from contextlib import nullcontext

from vemkit.solvers.ssn import solve_ssn
from vemkit.solvers.uzawa import solve_uzawa

USER_BLAS_VARIABLES = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def single_threaded_blas():
    """A context in which BLAS runs on one thread (no-op when the user chose a thread count)."""
    if any(name in os.environ for name in USER_BLAS_VARIABLES):
        return nullcontext()
    from threadpoolctl import threadpool_limits

    return threadpool_limits(limits=1, user_api="blas")


def solve(problem, solver_options: dict, progress=None):
    """Run the configured contact solver; raises ConvergenceError on failure."""
    opts = dict(solver_options)
    method = opts.pop("method")
    common = dict(linear=opts.pop("linear", "auto"), tol=opts.pop("tol"), progress=progress)
    if method == "uzawa":
        uzawa_keys = ("rho", "eps_u", "eps_lambda", "stop", "max_iterations")
        kwargs = {k: opts[k] for k in uzawa_keys if opts.get(k) is not None}
        with single_threaded_blas():
            return solve_uzawa(problem, **common, **kwargs)
    if method == "ssn":
        kwargs = {"max_iterations": opts["max_iterations"]} if opts.get("max_iterations") else {}
        with single_threaded_blas():
            return solve_ssn(problem, **common, **kwargs)
    raise ValueError(f"solver.method = {method!r} is unknown; use ssn or uzawa")
