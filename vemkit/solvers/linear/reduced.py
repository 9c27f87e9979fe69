"""The solver of the semismooth Newton steps, Z^T (K + D) Z y = Z^T r, on any backend.

:class:`ReducedSolver` holds the backend's :class:`~vemkit.solvers.linear.base.NewtonSystems` (made
by the base solver of K, ``base.newton_systems``) and switches them to their fallback when the
Newton iteration asks (:meth:`ReducedSolver.fall_back`); it never looks at which backend it runs.
"""

from __future__ import annotations


class ReducedSolver:
    """Solves Z^T A Z y = Z^T r for the Newton steps with the Newton systems of the base solver's backend."""

    def __init__(self, problem, base, baseline):
        self.problem = problem
        self.systems = base.newton_systems(problem, baseline)
        self._earlier_rebuilds = 0  # set-ups renewed by Newton systems that were switched away from

    @property
    def method(self) -> str:
        """The solver.linear value of the backend now solving the Newton steps."""
        return self.systems.method

    @property
    def rebuilds(self) -> int:
        return self._earlier_rebuilds + self.systems.rebuilds

    def operator(self, K, *terms):
        """The Newton matrix K + the terms as the backend solves with it (formed, or an operator)."""
        return self.systems.operator(K, *terms)

    def fall_back(self) -> str | None:
        """Switch to the backend's fallback (AMG: direct solves); its solver.linear value, or None
        when there is none (already direct): nothing changes then."""
        fallback = self.systems.fallback()
        if fallback is None:
            return None
        self._earlier_rebuilds += self.systems.rebuilds
        self.systems = fallback
        return fallback.method

    def solve(self, A, Z, rhs, eta, penalty, symmetric=True, atol=0.0):
        """Z y with Z^T A Z y = Z^T rhs (Z None: no stick constraint, y solves A y = rhs). A: what
        :meth:`operator` made. Iterative backends: relative residual eta, or absolute ``atol``."""
        return self.systems.solve(A, Z, rhs, eta, penalty, symmetric=symmetric, atol=atol)
