"""Linear solves for the symmetric positive definite systems of vemkit.

``linear_solver(A, method, near_nullspace=B)`` builds a solver once (a pyamg smoothed
aggregation hierarchy with the rigid-body modes as near-nullspace, or a sparse LU
factorization) and ``.solve(b, x0=...)`` reuses it for every right-hand side. The contact
solvers also pass a modified matrix (``A + contact Jacobian``) to ``.solve``: the AMG solver keeps
its hierarchy as a preconditioner for it, the direct solver refactorizes.
"""

from __future__ import annotations

import numpy as np
import pyamg
import scipy.sparse.linalg as spla

from vemkit.exceptions import InputError, LinearSolveError, SceneError

DIRECT_LIMIT = 20_000  # "auto" picks the direct solver below this many unknowns (measured crossover)


def _v_cycle(levels, coarse_solver, level, b):
    """One V-cycle from x = 0 on ``level`` (the smoothers and transfers of the hierarchy)."""
    here = levels[level]
    x = np.zeros_like(b)
    here.presmoother(here.A, x, b)
    coarse_b = here.R @ (b - here.A @ x)
    if level == len(levels) - 2:
        coarse_x = coarse_solver(levels[-1].A, coarse_b)
    else:
        coarse_x = _v_cycle(levels, coarse_solver, level + 1, coarse_b)
    x += here.P @ coarse_x
    here.postsmoother(here.A, x, b)
    return x


def v_cycle_preconditioner(hierarchy):
    """The V-cycle of a pyamg hierarchy as a LinearOperator (symmetric: forward Gauss-Seidel before,
    backward after), the operations of ``hierarchy.aspreconditioner("V")`` without the two residual
    norms pyamg's ``solve`` adds to every application (one a product with x = 0): ~17 % of each
    CG iteration at 10^6 DOFs. The coarse levels (pyamg makes them 3 x 3 block BSR for the three
    rigid modes) are smoothed in scalar CSR: pyamg's block Gauss-Seidel costs 3-4 times as much
    per nonzero, for the same CG iteration counts (measured: Cook at 10^6 DOFs, squares and
    triangles; the paper scene, ssn and uzawa, n = 128 ... 512). Both: CG time -32 %.
    """
    levels = hierarchy.levels
    for here in levels[1:-1]:
        here.A = here.A.tocsr()
    if len(levels) == 1:
        return spla.aslinearoperator(hierarchy.aspreconditioner(cycle="V"))
    return spla.LinearOperator(
        levels[0].A.shape, dtype=float, matvec=lambda b: _v_cycle(levels, hierarchy.coarse_solver, 0, np.ravel(b))
    )


class AMGSolver:
    """pyamg smoothed aggregation (rigid-body near-nullspace) as the preconditioner of CG."""

    method = "amg"

    def __init__(self, A, near_nullspace=None, tol=1e-10, maxiter=2000):
        self.A = A.tocsr()
        self.tol = tol
        self.maxiter = maxiter
        # Settings measured on the paper scene (benchmarks/assembly.py, contact.py): scalar CSR aggregation with
        # the rigid-body modes converges in as few CG iterations as 2 x 2 BSR blocks and its
        # Gauss-Seidel sweeps are cheaper; improving the candidates doubles the setup for nothing.
        self.hierarchy = pyamg.smoothed_aggregation_solver(
            self.A,
            B=near_nullspace,
            symmetry="hermitian",
            # theta = 0: every entry is strong. On the scalar finest level the strength matrix is then
            # A's own pattern (None: the same aggregates; 0.5 s less set-up and 0.2 GiB less peak
            # memory at 10^6 DOFs, benchmarks/cook.py); the
            # coarse levels are 3 x 3 blocks, amalgamated by "symmetric"
            strength=[None, ("symmetric", {"theta": 0.0})],
            # "local" weighting bounds rho(D^-1 A) by row sums: the default Lanczos estimate
            # was 70 % of the set-up at 512^2 squares, for 4 fewer CG iterations
            smooth=("jacobi", {"omega": 4.0 / 3.0, "degree": 1, "weighting": "local"}),
            presmoother=("gauss_seidel", {"sweep": "forward"}),
            postsmoother=("gauss_seidel", {"sweep": "backward"}),
            improve_candidates=None,
            max_coarse=2000,
            coarse_solver="splu",  # pinv (the default) costs seconds when coarsening stalls above max_coarse
            keep=False,
        )
        self.preconditioner = v_cycle_preconditioner(self.hierarchy)
        self.iterations = 0
        self.residual = 0.0

    def solve(self, b, x0=None, tol=None, A=None):
        A = self.A if A is None else A
        tol = self.tol if tol is None else tol
        bnorm = np.linalg.norm(b)
        if bnorm == 0.0:
            self.iterations, self.residual = 0, 0.0
            return np.zeros_like(b)
        count = [0]

        def callback(xk):
            count[0] += 1

        x, info = spla.cg(
            A, b, x0=x0, rtol=tol, atol=0.0, maxiter=self.maxiter, M=self.preconditioner, callback=callback
        )
        self.iterations = count[0]
        self.residual = float(np.linalg.norm(b - A @ x) / bnorm)
        if info != 0 or not np.all(np.isfinite(x)):
            raise LinearSolveError(
                f"AMG-CG stopped after {count[0]} iterations at relative residual {self.residual:.2e} "
                f"(asked {tol:.1e}); try solver.linear=direct",
                solver="amg",
                iterations=count[0],
            )
        return x


class DirectSolver:
    """Sparse LU (SuperLU, symmetric mode); refactorizes when given another matrix."""

    method = "direct"

    def __init__(self, A, near_nullspace=None, tol=None, maxiter=None):
        self.A = A.tocsc()
        self._lu = self._factor(self.A)
        self.iterations = 0
        self.residual = 0.0

    @staticmethod
    def _factor(A):
        try:
            return spla.splu(
                A.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True}
            )
        except RuntimeError as exc:  # exactly singular
            raise LinearSolveError(
                f"the stiffness matrix is singular ({exc}); is the body held (Dirichlet part)?",
                solver="direct",
                iterations=0,
            ) from None

    def solve(self, b, x0=None, tol=None, A=None):
        lu = self._lu if A is None or A is self.A else self._factor(A)
        x = lu.solve(np.asarray(b, dtype=float))
        Aused = self.A if A is None else A
        bnorm = np.linalg.norm(b)
        self.residual = float(np.linalg.norm(b - Aused @ x) / bnorm) if bnorm else 0.0
        self.iterations = 1
        if not np.all(np.isfinite(x)):
            raise LinearSolveError(
                "the direct solve produced non-finite values; the matrix is singular or badly scaled",
                solver="direct",
                iterations=1,
            )
        return x


def linear_solver(A, method="auto", near_nullspace=None, tol=1e-10, maxiter=2000):
    """One solver object for repeated solves with A: ``method`` is amg, direct or auto.

    ``method`` may also be a solver built earlier for the same matrix (a sweep over contact
    parameters keeps the stiffness matrix): it is returned as it is, set-up reused.
    """
    if isinstance(method, (AMGSolver, DirectSolver)):
        if method.A.shape != A.shape or method.A.nnz != A.nnz:
            raise InputError("the prebuilt linear solver was made for another stiffness matrix", key="linear")
        return method
    if method == "auto":
        method = "direct" if A.shape[0] <= DIRECT_LIMIT else "amg"
    if method == "amg":
        return AMGSolver(A, near_nullspace=near_nullspace, tol=tol, maxiter=maxiter)
    if method == "direct":
        return DirectSolver(A)
    raise SceneError(f"solver.linear = {method!r} is unknown; use amg, direct or auto", key="solver.linear")
