"""The interface every linear-solver backend implements (``vemkit.solvers.linear.amg``, ``.direct``).

A backend is a :class:`LinearSolver` subclass in a module of this package that names it
``BACKEND``; its ``method`` is the value of the scene key ``solver.linear`` that chooses it. The
contact solvers (ssn, uzawa) only call the members below, never a backend's name:

- set-up: ``Backend(A, near_nullspace=B, tol=..., maxiter=...)`` (a hierarchy, a factorization;
  a backend with scene options, e.g. petsc, also takes ``options=``, from a :class:`BackendChoice`);
- ``solve(b, x0=None, tol=None, A=None)``: the solution of A x = b from the start x0 to the
  relative tolerance tol (``A``: another matrix or operator of the same size, e.g. K + D, with the
  set-up of the first kept as it is or renewed); ``iterations`` and ``residual`` of the last solve;
- ``iterative``: whether a solve stops at a tolerance (a looser one is cheaper: the relaxed plain
  solve, inexact Newton steps, the Uzawa inner solves) or is exact whatever tol asks;
- ``newton_systems(problem, baseline)``: the :class:`NewtonSystems` that solve the semismooth
  Newton steps Z^T (K + D) Z y = Z^T r of ``problem`` (the AMG backend's update its hierarchy for
  K + D; the direct one forms and factorizes the reduced matrix).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


class LinearSolver:
    """One solver of A x = b, set up once for A and reused for every right-hand side."""

    method: str = ""  # the value of solver.linear that chooses this backend
    iterative: bool = False  # solves stop at a tolerance (True) or are exact (False)
    distributed: bool = False  # solves a matrix split across MPI ranks (vemkit.vem.distributed_matrix)

    A: object
    iterations: int = 0
    residual: float = 0.0

    def __init__(self, A, near_nullspace=None, tol=1e-10, maxiter=2000):  # pragma: no cover - the interface
        raise NotImplementedError

    def solve(self, b, x0=None, tol=None, A=None):  # pragma: no cover - the interface
        raise NotImplementedError

    @classmethod
    def check_available(cls) -> None:
        """Raise SceneError with the fix when the backend's packages are missing (before any work)."""

    def made_for(self, A) -> bool:
        """Whether this solver was set up for a matrix of A's size and pattern (a prebuilt one reused)."""
        return self.A.shape == A.shape and self.A.nnz == A.nnz

    def newton_systems(self, problem, baseline) -> NewtonSystems:  # pragma: no cover - the interface
        """The solver of the Newton steps of ``problem`` (``baseline``: iterations per decade of the
        plain solve with K)."""
        raise NotImplementedError


class NewtonSystems:
    """Solves the Newton systems Z^T A Z y = Z^T r of the semismooth Newton method (A = K + D, D the
    contact Jacobian; Z the basis that eliminates the stick constraints, None without any)."""

    method: str = ""  # the backend's solver.linear value (what info["fallback"] records)
    rebuilds: int = 0  # set-ups renewed for K + D

    def operator(self, K, *terms):  # pragma: no cover - the interface
        """A = K + the terms, as the solve wants it (a matrix, or an operator that never copies K)."""
        raise NotImplementedError

    def solve(self, A, Z, rhs, eta, penalty, symmetric=True, atol=0.0):  # pragma: no cover - the interface
        """(Z y, iterations) with Z^T A Z y = Z^T rhs: relative residual eta or absolute ``atol`` when
        iterative; ``penalty()``: the stick-tangent penalty a renewed preconditioner adds to A."""
        raise NotImplementedError

    def fallback(self) -> NewtonSystems | None:
        """The Newton systems to switch to when these stall (an iterative backend: direct), or None."""
        return None


@dataclass(frozen=True)
class BackendChoice:
    """A backend's solver.linear value with its scene options (``solver.petsc_options``), which
    ``linear_solver`` hands to the backend as ``options``."""

    method: str
    options: dict


def reduced_right_hand_side(Z, rhs):
    """(Z^T rhs, y -> Z y); Z None: (rhs, the identity)."""
    b = rhs if Z is None else Z.T @ rhs
    lift = (lambda y: y) if Z is None else (lambda y: Z @ y)
    return b, lift


RIGID_MODES_3D = 6  # columns of a 3D body's near-nullspace (three translations, three rotations)


def three_d(near_nullspace) -> bool:
    """Whether the near-nullspace is a 3D body's (the six rigid motions)."""
    return near_nullspace is not None and np.shape(near_nullspace)[1] == RIGID_MODES_3D
