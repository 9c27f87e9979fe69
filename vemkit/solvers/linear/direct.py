"""The direct backend (``solver.linear: direct``): sparse LU (SuperLU, symmetric mode).

A solve with another matrix refactorizes; the semismooth Newton systems Z^T (K + D) Z are formed
explicitly and factorized at every step (LU for the unsymmetric ones of Coulomb's coupled law).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse.linalg as spla

from vemkit.exceptions import LinearSolveError
from vemkit.solvers.linear.base import LinearSolver, NewtonSystems, reduced_right_hand_side
from vemkit.solvers.sparse_ops import as_matrix


class DirectSolver(LinearSolver):
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

    def newton_systems(self, problem, baseline) -> NewtonSystems:
        return DirectNewtonSystems()


class DirectNewtonSystems(NewtonSystems):
    """Z^T (K + D) Z formed and factorized at every Newton step."""

    method = DirectSolver.method

    def operator(self, K, *terms):
        """K + D formed as it always was (the terms added one by one): the same numbers to the last bit."""
        A = K
        for term in terms:
            A = A + term
        return A.tocsr()

    def solve(self, A, Z, rhs, eta, penalty, symmetric=True, atol=0.0):
        b, lift = reduced_right_hand_side(Z, rhs)
        A = as_matrix(A)
        A_red = A if Z is None else (Z.T @ A @ Z).tocsr()
        if symmetric:
            return lift(DirectSolver(A_red).solve(b)), 1
        y = spla.splu(A_red.tocsc()).solve(b)
        if not np.all(np.isfinite(y)):
            raise LinearSolveError(
                "the direct solve of the Newton step produced non-finite values", solver="direct", iterations=1
            )
        return lift(y), 1


BACKEND = DirectSolver


class IterativeNewtonSystems(NewtonSystems):
    """Newton systems solved to a tolerance (AMG, PETSc): when their inexact steps stall the line
    search, ssn switches to :class:`DirectNewtonSystems`."""

    def fallback(self) -> NewtonSystems:
        return DirectNewtonSystems()
