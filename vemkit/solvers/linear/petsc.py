"""The PETSc backend (``solver.linear: petsc``): CG preconditioned by PETSc's algebraic multigrid
GAMG through petsc4py, in one process.

The stiffness is a PETSc AIJ matrix of block size d: the free dofs are numbered node by node, d
components each (``vemkit.vem.dofs``; a held component keeps its row, with only its diagonal), so
d always fits. The rigid motions, orthonormalized, are its near-nullspace (``MatNullSpace``), which
GAMG's smoothed aggregation reproduces on every level. The scene's ``solver.petsc_options``
override the defaults (``ksp_type: cg``, ``pc_type: gamg``) under an options prefix of their own,
so no global PETSc option is ever read from a scene; tolerances and iteration limits stay
``solver.tol``'s. A solve with another matrix keeps K's preconditioner.

The semismooth Newton systems (:class:`PETScNewtonSystems`) are solved by CG (GMRES when
unsymmetric) on Z^T (K + D) Z, preconditioned by Z^T M Z with M a GAMG hierarchy set up again for
K + D + the stick penalty at every step (the AMG backend's design, ``vemkit.solvers.linear.amg``,
with a full rebuild: the simplest correct choice). When they stall the direct backend takes over.

petsc4py is imported on first use; without it :func:`require_petsc4py` says how to install it.
"""

from __future__ import annotations

import itertools
from contextlib import contextmanager

import numpy as np

from vemkit.exceptions import LinearSolveError, SceneError
from vemkit.solvers.linear.base import LinearSolver, NewtonSystems, reduced_right_hand_side
from vemkit.solvers.linear.direct import IterativeNewtonSystems
from vemkit.solvers.sparse_ops import as_matrix
from vemkit.vem.distributed_matrix import owned_rows, petsc_rows
from vemkit.vem.parallel import require_petsc4py

#: near-nullspace columns (the rigid motions) -> components per node, the matrix's block size
BLOCK_SIZE_OF_MODES = {3: 2, 6: 3}
NEWTON_MAXITER = 5000  # Krylov iterations of one Newton step (as the AMG backend's)
GMRES_RESTART = 50
_prefixes = itertools.count()  # every solver's options live under a prefix of its own


def block_size(near_nullspace, n: int) -> int:
    """d for a body's rigid motions (3 columns: 2, 6: 3) when it divides n, else 1."""
    bs = BLOCK_SIZE_OF_MODES.get(0 if near_nullspace is None else np.shape(near_nullspace)[1], 1)
    return bs if n % bs == 0 else 1


class OneProcess:
    """The layout of a matrix in one process: PETSc's vectors hold the whole vectors
    (``vemkit.vem.distributed_assembly.DofLayout`` is the layout across MPI ranks)."""

    def __init__(self, n: int):
        self.size = self.n_owned = n
        self.comm = require_petsc4py().COMM_SELF

    def local(self, x) -> np.ndarray:
        return np.ascontiguousarray(x, dtype=float)

    def gather(self, local) -> np.ndarray:
        return np.array(local, dtype=float)


def layout_of(A):
    """How A's rows are split: its :class:`DofLayout` across ranks, or :class:`OneProcess`."""
    layout = getattr(A, "layout", None)
    return OneProcess(A.shape[0]) if layout is None else layout


def petsc_matrix(A, bs: int = 1, near_nullspace=None):
    """A as a PETSc matrix: a distributed stiffness's own MPIAIJ matrix, or a scipy matrix as an AIJ
    matrix of block size ``bs`` in this process; the orthonormalized columns of ``near_nullspace``
    (whole vectors) its near-nullspace."""
    PETSc = require_petsc4py()
    A = as_matrix(A)
    if getattr(A, "distributed", False):
        M = A.petsc
    else:
        A = A.tocsr()
        if not A.has_sorted_indices:
            A = A.sorted_indices()
        csr = (A.indptr.astype(PETSc.IntType), A.indices.astype(PETSc.IntType), A.data.astype(PETSc.ScalarType))
        M = PETSc.Mat().createAIJ(size=A.shape, bsize=bs, csr=csr, comm=PETSc.COMM_SELF)
        M.assemble()
    if near_nullspace is not None:
        layout = layout_of(A)
        orthonormal, _ = np.linalg.qr(np.asarray(near_nullspace, dtype=float))
        vectors = []
        for column in orthonormal.T:
            v = M.createVecRight()
            v.setArray(layout.local(column))
            vectors.append(v)
        M.setNearNullSpace(PETSc.NullSpace().create(constant=False, vectors=vectors, comm=layout.comm))
    return M


def stick_basis_matrix(Z, layout):
    """(Z as a PETSc matrix, the layout of its columns): in one process the scipy Z; across ranks
    each column (one vertex's) owned with the rows it touches (``vemkit.vem.distributed_assembly.column_layout``)."""
    if isinstance(layout, OneProcess):
        return petsc_matrix(Z), OneProcess(Z.shape[1])
    from vemkit.vem.distributed_assembly import column_layout

    columns = column_layout(layout, Z)
    rows = owned_rows(layout, Z, columns.position)
    return petsc_rows(layout, rows, (columns.n_owned, columns.size)), columns


def _option_text(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


@contextmanager
def scene_options(prefix: str, options: dict):
    """The scene's PETSc options in PETSc's database under ``prefix`` while the block runs (set-ups
    read some, e.g. the GAMG levels' smoothers); a PETSc error inside is a SceneError naming them."""
    PETSc = require_petsc4py()
    database = PETSc.Options()
    for name, value in options.items():
        database.setValue(prefix + name, _option_text(value))
    try:
        yield
    except PETSc.Error as error:
        shown = ", ".join(f"{name}: {_option_text(value)}" for name, value in options.items()) or "none"
        said = str(error).strip().splitlines()[-1].split("] ", 1)[-1]  # PETSc's last line: the reason
        raise SceneError(
            f"solver.petsc_options ({shown}): PETSc refused the set-up ({said}); fix or remove the option",
            key="solver.petsc_options",
        ) from None
    finally:
        for name in options:
            database.delValue(prefix + name)


def _configured_ksp(matrix, prefix, options, *, krylov="cg", operator=None, preconditioner=None):
    """A KSP of ``operator`` (default ``matrix``) with GAMG on ``matrix`` (or the python-context
    ``preconditioner``), the scene's options applied, set up; residuals in the unpreconditioned norm."""
    PETSc = require_petsc4py()
    ksp = PETSc.KSP().create(comm=matrix.getComm())
    ksp.setOperators(matrix if operator is None else operator, matrix)
    ksp.setType(krylov)
    if krylov == "gmres":
        ksp.setGMRESRestart(GMRES_RESTART)
        ksp.setPCSide(PETSc.PC.Side.RIGHT)
    ksp.setNormType(PETSc.KSP.NormType.UNPRECONDITIONED)
    ksp.getPC().setType("gamg")
    ksp.setOptionsPrefix(prefix)
    with scene_options(prefix, options):
        ksp.setFromOptions()
        if preconditioner is not None:
            ksp.getPC().setType("python")
            ksp.getPC().setPythonContext(preconditioner)
        ksp.setUp()
    return ksp


def _krylov(ksp, b, x0, rtol, atol, maxiter, layout):
    """(x, iterations, converged) of ksp on b from x0 (None: zero); b, x0 and x whole vectors, each
    rank giving PETSc its entries (``layout``)."""
    x = ksp.getOperators()[0].createVecRight()
    if x0 is None:
        x.set(0.0)
    else:
        x.setArray(layout.local(x0))
    rhs = x.duplicate()
    rhs.setArray(layout.local(b))
    ksp.setInitialGuessNonzero(x0 is not None)
    ksp.setTolerances(rtol=rtol, atol=atol, max_it=maxiter)
    ksp.solve(rhs, x)
    solution = layout.gather(x.getArray())
    return solution, ksp.getIterationNumber(), ksp.getConvergedReason() > 0 and np.all(np.isfinite(solution))


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
        self.ksp = _configured_ksp(self.matrix, self.prefix, self.options)
        self.iterations = 0
        self.residual = 0.0

    @classmethod
    def check_available(cls) -> None:
        """SceneError with the fix when petsc4py cannot be imported."""
        require_petsc4py()

    def solve(self, b, x0=None, tol=None, A=None):
        tol = self.tol if tol is None else tol
        bnorm = np.linalg.norm(b)
        if bnorm == 0.0:
            self.iterations, self.residual = 0, 0.0
            return np.zeros_like(b)
        operator = self.matrix if A is None or A is self.A else petsc_matrix(A, self.bs)
        self.ksp.setOperators(operator, self.matrix)  # K's preconditioner kept for another matrix
        x, self.iterations, converged = _krylov(self.ksp, b, x0, tol, 0.0, self.maxiter, self.layout)
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


class ProjectedPreconditioner:
    """petsc4py's python-context PC applying y = Z^T M (Z x), M one application of ``inner``."""

    def __init__(self, Z, inner):
        self.Z, self.inner = Z, inner
        self.full_in, self.full_out = Z.createVecLeft(), Z.createVecLeft()

    def apply(self, pc, x, y):
        self.Z.mult(x, self.full_in)
        self.inner.apply(self.full_in, self.full_out)
        self.Z.multTranspose(self.full_out, y)


class PETScNewtonSystems(IterativeNewtonSystems):
    """Krylov on Z^T (K + D) Z with Z^T M Z, M GAMG set up for K + D + penalty at every step."""

    method = PETScSolver.method

    def __init__(self, base: PETScSolver):
        self.base = base
        self.rebuilds = 0

    def operator(self, K, *terms):
        """K + the terms, formed (PETSc takes a matrix; across ranks each adds its rows)."""
        A = K
        for term in terms:
            A = A + term
        return A if getattr(A, "distributed", False) else A.tocsr()

    def fallback(self) -> NewtonSystems | None:
        """Direct solves in one process; none across ranks (SuperLU holds the whole matrix)."""
        return super().fallback() if isinstance(self.base.layout, OneProcess) else None

    def solve(self, A, Z, rhs, eta, penalty, symmetric=True, atol=0.0):
        b, lift = reduced_right_hand_side(Z, rhs)
        if np.linalg.norm(b) == 0.0:
            return np.zeros(A.shape[0]), 0
        base = self.base
        full = petsc_matrix(as_matrix(A) + penalty(), base.bs, base.near_nullspace)
        krylov = "cg" if symmetric else "gmres"
        layout = base.layout
        if Z is None:
            ksp = _configured_ksp(full, base.prefix, base.options, krylov=krylov, operator=petsc_matrix(A, base.bs))
        else:
            inner = _configured_ksp(full, base.prefix, base.options).getPC()
            Zp, layout = stick_basis_matrix(Z, base.layout)
            reduced = _reduced_matrix(A, Z, Zp, base.bs)
            projected = ProjectedPreconditioner(Zp, inner)
            ksp = _configured_ksp(reduced, base.prefix, base.options, krylov=krylov, preconditioner=projected)
        self.rebuilds += 1
        y, its, converged = _krylov(ksp, b, None, eta, atol, NEWTON_MAXITER, layout)
        if not converged:
            raise LinearSolveError(
                f"PETSc {ksp.getType()} of the Newton step stopped after {its} iterations "
                f"(reason {ksp.getConvergedReason()}); {failure_advice(base.layout)}",
                solver=self.method,
                iterations=its,
            )
        return lift(y), its


def _reduced_matrix(A, Z, Zp, bs):
    """Z^T A Z as a PETSc matrix: scipy's product in one process, PETSc's PtAP across ranks."""
    if getattr(A, "distributed", False):
        return A.petsc.ptap(Zp)
    return petsc_matrix((Z.T @ as_matrix(A) @ Z).tocsr())


def failure_advice(layout) -> str:
    """What to try when a PETSc solve stalls: another backend in one process; across ranks a
    stronger preconditioner (the other backends hold the whole matrix)."""
    if isinstance(layout, OneProcess):
        return "try solver.linear=amg or direct"
    return "try stronger GAMG options in solver.petsc_options, or one process with solver.linear=direct"


BACKEND = PETScSolver
