"""Linear solves for the symmetric positive definite systems of vemkit, behind one interface.

``linear_solver(A, method, near_nullspace=B)`` sets up the backend the scene key ``solver.linear``
names once (a pyamg smoothed aggregation hierarchy with the rigid-body modes as near-nullspace, or a
sparse LU factorization) and ``.solve(b, x0=..., tol=...)`` reuses it for every right-hand side. The
contact solvers also pass a modified matrix (K + contact Jacobian) to ``.solve``: the AMG solver
keeps its hierarchy as a preconditioner for it, the direct solver refactorizes. The interface
(``base.LinearSolver``, ``base.NewtonSystems``) is all ssn and uzawa see; what differs between the
backends (an iterative solve's relaxed tolerances, the hierarchy update on K + D, the direct
fallback, the explicitly formed reduced matrix) is a member of the backend, never a test of its name.

A new backend is one module of this package with a ``LinearSolver`` subclass named ``BACKEND``
(its ``method`` the new value) plus that value in ``solver.linear``'s enum of the scene schema:
:func:`backends` finds it.

Modules: ``base`` (the interface), ``amg``, ``direct`` and ``petsc`` (the backends; petsc4py is
imported only when petsc is chosen), ``cycle`` (the V-cycle),
``reduced`` (the Newton-step solver on any backend).
"""

from __future__ import annotations

import importlib
import pkgutil
from functools import cache

from vemkit.exceptions import InputError, SceneError
from vemkit.solvers.linear.amg import (
    AMG_OPTIONS,
    BLOCK_MAX_COARSE,
    COARSE_STRENGTH_2D,
    FINEST_OWN,
    AMGSolver,
    smoothed_aggregation,
)
from vemkit.solvers.linear.base import RIGID_MODES_3D, BackendChoice, LinearSolver, NewtonSystems, three_d
from vemkit.solvers.linear.cycle import (
    CYCLE_PRECISION,
    CycleLevel,
    in_precision,
    transfers_in_precision,
    v_cycle,
    v_cycle_preconditioner,
)
from vemkit.solvers.linear.direct import DirectSolver
from vemkit.solvers.linear.reduced import ReducedSolver

# No __all__: the names the one module linear.py had are re-exported for its importers (ruff's F401
# is off for this file in pyproject.toml), but this package is not one of the documented API packages.

DIRECT_LIMIT = 20_000  # "auto" picks the direct solver up to this many unknowns (measured crossover, 2D)
#: the same in 3D, where LU's fill grows much faster: the sheared box (config/scenes/3d/sheared_box.yaml),
#: ssn solve seconds direct / AMG: 1 254 DOFs 0.06 / 0.11, 3 198: 0.33 / 0.18, 13 629: 12.5 / 0.60
DIRECT_LIMIT_3D = 2_000
DISTRIBUTED_BACKEND = "petsc"  # the backend that solves across MPI ranks (and what auto picks there)


@cache
def backends() -> dict[str, type[LinearSolver]]:
    """{solver.linear value: backend class}: the ``BACKEND`` of every module of this package."""
    found = {}
    for module_info in pkgutil.iter_modules(__path__):
        backend = getattr(importlib.import_module(f"{__name__}.{module_info.name}"), "BACKEND", None)
        if backend is not None:
            found[backend.method] = backend
    return found


def direct_limit(near_nullspace) -> int:
    """The most unknowns ``auto`` solves directly: :data:`DIRECT_LIMIT_3D` for a 3D body (its
    near-nullspace holds the six rigid motions), :data:`DIRECT_LIMIT` otherwise."""
    return DIRECT_LIMIT_3D if three_d(near_nullspace) else DIRECT_LIMIT


def takes_split_problem(method: str) -> bool:
    """Whether the backend ``method`` (a solver.linear value) solves a problem split across MPI
    ranks (its matrix then PETSc's from the assembly on, also in one process)."""
    backend = backends().get(method)
    return backend is not None and backend.distributed


def check_distributed(method: str) -> None:
    """SceneError unless the backend ``method`` (or auto) solves a matrix split across MPI ranks."""
    backend = backends().get(DISTRIBUTED_BACKEND if method == "auto" else method)
    if backend is not None and not backend.distributed:
        raise SceneError(
            f"solver.linear = {method} solves in one process, but this job runs on several MPI ranks; "
            f"use --set solver.linear={DISTRIBUTED_BACKEND}, or run without mpiexec",
            key="solver.linear",
        )


def linear_solver(A, method="auto", near_nullspace=None, tol=1e-10, maxiter=2000) -> LinearSolver:
    """One solver object for repeated solves with A: ``method`` is a backend's name (amg, direct) or auto.

    ``method`` may also be a solver built earlier for the same matrix (a sweep over contact
    parameters keeps the stiffness matrix): it is returned as it is, set-up reused; or a
    :class:`BackendChoice`, a backend's name with its scene options (``solver.petsc_options``).
    """
    if isinstance(method, LinearSolver):
        if not method.made_for(A):
            raise InputError("the prebuilt linear solver was made for another stiffness matrix", key="linear")
        return method
    options = {}
    if isinstance(method, BackendChoice):
        method, options = method.method, {"options": method.options}
    distributed = getattr(A, "distributed", False)  # split across MPI ranks: only a backend that takes that
    if method == "auto":
        small = A.shape[0] <= direct_limit(near_nullspace)
        method = DISTRIBUTED_BACKEND if distributed else DirectSolver.method if small else AMGSolver.method
    backend = backends().get(method) if isinstance(method, str) else None
    if backend is None:
        names = ", ".join(sorted(backends()))
        raise SceneError(f"solver.linear = {method!r} is unknown; use {names} or auto", key="solver.linear")
    if distributed:
        check_distributed(method)
    return backend(A, near_nullspace=near_nullspace, tol=tol, maxiter=maxiter, **options)
