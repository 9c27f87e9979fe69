"""The PETSc backend (``solver.linear: petsc``): CG preconditioned by PETSc's algebraic multigrid
GAMG through petsc4py, in one process or across the ranks of an MPI job.

The stiffness is a PETSc AIJ matrix of block size d: the free dofs are numbered node by node, d
components each (``vemkit.vem.dofs``; a held component keeps its row, with only its diagonal), so
d always fits. Across MPI ranks it is the distributed stiffness's own MPIAIJ matrix
(``vemkit.vem.distributed_matrix``), each rank owning its rows; the contact solvers still hand over
and get back whole vectors (each rank gives PETSc its entries, ``petsc_setup.krylov_solve``). The
rigid motions, orthonormalized, are its near-nullspace (``MatNullSpace``), which GAMG's smoothed
aggregation reproduces on every level. The scene's ``solver.petsc_options`` override the defaults
(``ksp_type: cg``, ``pc_type: gamg``) under an options prefix of their own, so no global PETSc
option is ever read from a scene; tolerances and iteration limits stay ``solver.tol``'s. A solve
with another matrix keeps K's preconditioner.

The semismooth Newton systems (:class:`PETScNewtonSystems`) are solved by CG (GMRES when
unsymmetric) on Z^T (K + D) Z, applied as three products, preconditioned by Z^T M Z with M a GAMG
hierarchy of K + D + the stick penalty (the AMG backend's design, ``vemkit.solvers.linear.amg``):
one matrix and one hierarchy over the steps, its prolongators kept and its Galerkin products
renewed at every step. In one process, when they stall the direct backend takes over; across
ranks there is no fallback (SuperLU holds the whole matrix).

petsc4py is imported on first use; without it ``vemkit.vem.parallel.require_petsc4py`` says how
to install it.
"""

from __future__ import annotations

import itertools

import numpy as np

from vemkit.exceptions import LinearSolveError
from vemkit.solvers.linear.base import LinearSolver, NewtonSystems, reduced_right_hand_side
from vemkit.solvers.linear.direct import IterativeNewtonSystems
from vemkit.solvers.linear.petsc_setup import (
    OneProcess,
    ProjectedPreconditioner,
    ReducedOperator,
    block_size,
    collect_garbage,
    configured_ksp,
    failure_advice,
    krylov_solve,
    layout_of,
    petsc_matrix,
    renewed_matrix,
    scene_options,
    stick_basis_matrix,
)
from vemkit.vem.distributed_matrix import DistributedSum
from vemkit.vem.parallel import require_petsc4py

NEWTON_MAXITER = 5000  # Krylov iterations of one Newton step (as the AMG backend's)
#: GAMG for elasticity: drop the weak couplings (below 0.01 of the diagonal's) from the aggregation
#: graph, Chebyshev's eigenvalue estimate from the prolongator smoothing (measured on the sheared box,
#: 180 075 DOFs on 2 ranks: set-up 2.9 -> 1.6 s, CG 2.3 -> 0.8 s, 12 iterations either way)
GAMG_DEFAULTS = {"pc_gamg_threshold": 0.01, "pc_gamg_use_sa_esteig": True}
#: ... and for the Newton steps, the prolongators kept when K + D changes (the Galerkin products renewed)
NEWTON_DEFAULTS = {**GAMG_DEFAULTS, "pc_gamg_reuse_interpolation": True}
_prefixes = itertools.count()  # every solver's options live under a prefix of its own


class PETScSolver(LinearSolver):
    """CG with PETSc's GAMG (block size d, the rigid motions as near-nullspace)."""

    method = "petsc"
    iterative = True
    distributed = True

    def __init__(self, A, near_nullspace=None, tol=1e-10, maxiter=2000, options=None):
        self.A = A if getattr(A, "distributed", False) else A.tocsr()
        self.layout = layout_of(A)
        self.tol, self.maxiter = tol, maxiter
        self.near_nullspace = near_nullspace
        self.options = dict(options or {})
        self.prefix = f"vemkit{next(_prefixes)}_"
        self.bs = block_size(near_nullspace, self.A.shape[0])
        self.matrix = petsc_matrix(self.A, self.bs, near_nullspace)
        self.ksp = None
        self._multigrid()  # K's KSP and GAMG, set up now
        self.iterations = 0
        self.residual = 0.0

    @classmethod
    def check_available(cls) -> None:
        """SceneError with the fix when petsc4py cannot be imported."""
        require_petsc4py()

    def _multigrid(self):
        """The KSP of K with its GAMG, set up again if :meth:`release` dropped it."""
        if self.ksp is None:
            self.ksp = configured_ksp(self.matrix, self.prefix, self.options, defaults=GAMG_DEFAULTS)
        return self.ksp

    def release(self) -> None:
        """Drop K's GAMG hierarchy until the next solve (the Newton steps build their own)."""
        if self.ksp is not None:
            self.ksp.destroy()
            self.ksp = None

    def solve(self, b, x0=None, tol=None, A=None):
        tol = self.tol if tol is None else tol
        bnorm = np.linalg.norm(b)
        if bnorm == 0.0:
            self.iterations, self.residual = 0, 0.0
            return np.zeros_like(b)
        collect_garbage(self.layout)  # the matrices of earlier solves
        operator = self.matrix if A is None or A is self.A else petsc_matrix(A, self.bs)
        self._multigrid().setOperators(operator, self.matrix)  # K's preconditioner kept for another matrix
        x, self.iterations, converged = krylov_solve(self.ksp, b, x0, tol, 0.0, self.maxiter, self.layout)
        used = self.A if A is None else A
        self.residual = float(np.linalg.norm(b - used @ x) / bnorm)
        if not converged:
            raise LinearSolveError(
                f"PETSc {self.ksp.getType()} stopped after {self.iterations} iterations at relative residual "
                f"{self.residual:.2e} (asked {tol:.1e}, reason {self.ksp.getConvergedReason()}); "
                f"{failure_advice(self.layout)}",
                solver=self.method,
                iterations=self.iterations,
            )
        return x

    def newton_systems(self, problem, baseline) -> NewtonSystems:
        return PETScNewtonSystems(self)


class PETScNewtonSystems(IterativeNewtonSystems):
    """Krylov on Z^T (K + D) Z (three products a step, never formed) preconditioned by Z^T M Z, M
    GAMG on K + D + penalty: one PETSc matrix and one GAMG over the steps, their values renewed,
    GAMG keeping its prolongators (:data:`NEWTON_DEFAULTS`; the scene's options override)."""

    method = PETScSolver.method

    def __init__(self, base: PETScSolver):
        self.base = base
        self.rebuilds = 0
        self.full = None  # K + D + penalty as PETSc's matrix, one object over the steps
        self.inner = None  # the KSP whose PC (GAMG on self.full) preconditions the steps

    def operator(self, K, *terms):
        """K + the terms: split across ranks, the two kept apart (products K x + D x, no copy of K);
        in one scipy matrix, formed."""
        split = getattr(K, "distributed", False)
        A = K
        for term in terms:
            A = DistributedSum(K, term) if split and A is K else A + term
        return A if split else A.tocsr()

    def fallback(self) -> NewtonSystems | None:
        """Direct solves in one process; none across ranks (SuperLU holds the whole matrix)."""
        return super().fallback() if isinstance(self.base.layout, OneProcess) else None

    def _multigrid(self, A, penalty):
        """GAMG on K + D + penalty, set up again for the new values (its prolongators kept)."""
        base = self.base
        base.release()  # K's hierarchy is not used by the steps: its memory for theirs
        full = renewed_matrix(self.full, A, penalty(), base.bs, base.near_nullspace)
        if self.inner is None or full is not self.full:
            self.full = full
            self.inner = configured_ksp(full, base.prefix, base.options, defaults=NEWTON_DEFAULTS)
        else:
            with scene_options(base.prefix, {**NEWTON_DEFAULTS, **base.options}):
                self.inner.setOperators(full, full)
                self.inner.setUp()
        self.rebuilds += 1
        return self.inner.getPC()

    def solve(self, A, Z, rhs, eta, penalty, symmetric=True, atol=0.0):
        b, lift = reduced_right_hand_side(Z, rhs)
        if np.linalg.norm(b) == 0.0:
            return np.zeros(A.shape[0]), 0
        base = self.base
        collect_garbage(base.layout)  # the last step's K + D
        multigrid = self._multigrid(A, penalty)
        operator, layout, Zp = petsc_matrix(A, base.bs), base.layout, None
        if Z is not None:
            Zp, layout = stick_basis_matrix(Z, base.layout)
            operator = ReducedOperator.of(operator, Zp)
        preconditioner = ProjectedPreconditioner(Zp, multigrid)
        method = "cg" if symmetric else "gmres"
        ksp = configured_ksp(operator, base.prefix, base.options, krylov=method, preconditioner=preconditioner)
        try:
            y, its, converged = krylov_solve(ksp, b, None, eta, atol, NEWTON_MAXITER, layout)
            reason = ksp.getConvergedReason()
        finally:  # the python contexts hold PETSc objects, which hold them back: freed by hand
            for petsc_object in (ksp, operator if Zp is not None else None, Zp):
                if petsc_object is not None:
                    petsc_object.destroy()
        if not converged:
            raise LinearSolveError(
                f"PETSc {method.upper()} of the Newton step stopped after {its} iterations "
                f"(reason {reason}); {failure_advice(base.layout)}",
                solver=self.method,
                iterations=its,
            )
        return lift(y), its


BACKEND = PETScSolver
