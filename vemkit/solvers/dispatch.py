"""Run the contact solver a scene names (``solver.method``) on an assembled problem.

BLAS threads: vemkit's work is sparse (CSR products, AMG cycles, Numba kernels with their own
threads), and multi-threaded dense BLAS only spins and competes with them (CG was 4x slower on 2
cores). So :func:`solve` runs the solver with BLAS limited to one thread (threadpoolctl), unless
the user has set ``OPENBLAS_NUM_THREADS`` or ``MKL_NUM_THREADS``; nothing is changed at import.

Floating-point failures (overflow, 0/0, division by zero) inside the solve raise instead of
producing inf/NaN with a RuntimeWarning; :func:`solve` reports them as a ConvergenceError.
"""

from __future__ import annotations

import os
import time
import warnings
from collections.abc import Callable
from contextlib import contextmanager, nullcontext

import numpy as np

from vemkit.exceptions import ConvergenceError, SceneError, TimeBudgetExceeded
from vemkit.solvers.linear.base import BackendChoice
from vemkit.solvers.solution import ContactSolution
from vemkit.solvers.ssn import solve_ssn
from vemkit.solvers.uzawa import solve_uzawa

USER_BLAS_VARIABLES = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def single_threaded_blas():
    """A context in which BLAS runs on one thread (no-op when the user chose a thread count)."""
    if any(name in os.environ for name in USER_BLAS_VARIABLES):
        return nullcontext()
    from threadpoolctl import threadpool_limits

    return threadpool_limits(limits=1, user_api="blas")


def _budgeted(progress, budget, method: str):
    """``progress`` that raises TimeBudgetExceeded once ``budget`` seconds have passed."""
    if budget is None:
        return progress
    start = time.perf_counter()

    def watched(iteration, record=None):
        if progress is not None:
            progress(iteration, record)
        elapsed = time.perf_counter() - start
        if elapsed > budget:
            raise TimeBudgetExceeded(
                f"{method} ran past solver.time_budget = {budget:g} s ({elapsed:.1f} s after "
                f"{iteration} iterations); raise solver.time_budget or use a coarser mesh",
                solver=method,
                iterations=iteration,
            )

    return watched


@contextmanager
def floating_point_errors_raise():
    """Overflow, invalid operations and division by zero raise (numpy), and so do RuntimeWarnings:
    a solve never ends with warnings on stderr next to a result."""
    with np.errstate(over="raise", invalid="raise", divide="raise"), warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        yield


def solve(problem, solver_options: dict, progress=None, initial=None, slip_reference=None):
    """Run the configured contact solver; raises ConvergenceError on failure.

    Parameters
    ----------
    problem : DiscreteProblem
        The assembled problem (``vemkit.scene_problem`` or ``vemkit.discrete_problem``).
    solver_options : dict
        The scene's ``solver`` block (``Scene.solver_options``): ``method`` (``ssn`` or ``uzawa``),
        ``tol`` and the method's own keys.
    progress : callable, optional
        Called after every iteration (a progress display).
    initial : tuple, optional
        None (each solver's own start) or (u0 free-dof vector, multiplier per contact vertex), a
        warm start (e.g. a coarser solution prolongated to this mesh).
    slip_reference : array, optional
        u_tau^ref per contact vertex (the previous load step's ``cb.tangential_displacement(u)``):
        the slip is counted from it (the incremental friction law of a loading in steps); None:
        from the unloaded shape.

    Returns
    -------
    ContactSolution
        The displacement, the friction multiplier, the iterations and the history.

    Raises
    ------
    ConvergenceError
        When the solver does not converge. ``solver_options["time_budget"]`` (seconds, optional):
        TimeBudgetExceeded once the solve has run longer (checked after every iteration). A
        floating-point overflow, invalid operation or division by zero inside the solve is a
        ConvergenceError (reason ``diverged``), never a result.

    Examples
    --------
    >>> import vemkit
    >>> scene = vemkit.load_scene("config/scenes/paper.yaml", ["discretization.mesh.n=4"])
    >>> solution = vemkit.solve(vemkit.scene_problem(scene), scene.solver_options)
    >>> solution.method, solution.iterations > 0
    ('ssn', True)
    """
    opts = dict(solver_options)
    method = opts.pop("method")
    progress = _budgeted(progress, opts.pop("time_budget", None), method)
    linear = opts.pop("linear", "auto")
    backend_options = opts.get(f"{linear}_options") if isinstance(linear, str) else None
    if backend_options:  # the chosen backend's own scene options (solver.petsc_options)
        linear = BackendChoice(linear, dict(backend_options))
    common = dict(linear=linear, tol=opts.pop("tol"), progress=progress)
    if method == "uzawa":
        uzawa_keys = ("rho", "eps_u", "eps_lambda", "stop", "max_iterations")
        kwargs = {k: opts[k] for k in uzawa_keys if opts.get(k) is not None}
        run: Callable[..., ContactSolution] = solve_uzawa
    elif method == "ssn":
        kwargs = {"max_iterations": opts["max_iterations"]} if opts.get("max_iterations") else {}
        run = solve_ssn
    else:
        raise SceneError(f"solver.method = {method!r} is unknown; use ssn or uzawa", key="solver.method")
    if initial is not None:
        kwargs["initial"] = initial
    if slip_reference is not None:
        kwargs["slip_reference"] = slip_reference
    try:
        with single_threaded_blas(), floating_point_errors_raise():
            return run(problem, **common, **kwargs)
    except (FloatingPointError, RuntimeWarning, ZeroDivisionError, OverflowError) as error:
        raise ConvergenceError(
            f"{method}: floating-point failure during the solve ({error}); the scene's numbers are "
            "too large or too small for double precision: rescale the units (E, k, tractions)",
            solver=method,
            reason="diverged",
        ) from error
