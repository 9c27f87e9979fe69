"""PETSc's plumbing for the PETSc backend (``vemkit.solvers.linear.petsc``): matrices, vectors and
Krylov solvers in one process or across MPI ranks.

- Layouts: :class:`OneProcess` (PETSc's vectors hold the whole vectors) or a stiffness split across
  ranks (``vemkit.vem.distributed_assembly.DofLayout``), :func:`layout_of`; each rank gives PETSc
  its entries of a whole vector and gathers the whole result (:func:`krylov`).
- Matrices: :func:`petsc_matrix` (scipy or the distributed stiffness's own; the rigid motions as
  near-nullspace), :func:`stick_basis_matrix` (Z, its columns owned with their vertex),
  :class:`ReducedOperator` (Z^T A Z as three products, never formed), :class:`ProjectedPreconditioner`
  (Z^T M Z).
- Options: :func:`scene_options` (the scene's ``solver.petsc_options`` under a prefix of their own,
  a refused one a SceneError naming them) and :func:`configured_ksp`.
"""

from __future__ import annotations

from contextlib import contextmanager

import numpy as np

from vemkit.exceptions import SceneError
from vemkit.solvers.sparse_ops import as_matrix
from vemkit.vem.distributed_matrix import owned_rows, petsc_rows
from vemkit.vem.parallel import require_petsc4py

#: near-nullspace columns (the rigid motions) -> components per node, the matrix's block size
BLOCK_SIZE_OF_MODES = {3: 2, 6: 3}
GMRES_RESTART = 50


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
    return with_near_nullspace(M, layout_of(A), near_nullspace)


def with_near_nullspace(M, layout, near_nullspace):
    """M with the orthonormalized columns of ``near_nullspace`` (whole vectors; None: M as it is)
    as its near-nullspace (``MatNullSpace``)."""
    if near_nullspace is None:
        return M
    PETSc = require_petsc4py()
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


def configured_ksp(matrix, prefix, options, *, krylov="cg", operator=None, preconditioner=None, defaults=None):
    """A KSP of ``operator`` (default ``matrix``) with GAMG on ``matrix`` (or the python-context
    ``preconditioner``), the scene's options applied over ``defaults``, set up; residuals in the
    unpreconditioned norm."""
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
    with scene_options(prefix, {**(defaults or {}), **options}):
        ksp.setFromOptions()
        if preconditioner is not None:
            ksp.getPC().setType("python")
            ksp.getPC().setPythonContext(preconditioner)
        ksp.setUp()
    return ksp


def krylov_solve(ksp, b, x0, rtol, atol, maxiter, layout):
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


class ProjectedPreconditioner:
    """petsc4py's python-context PC applying y = Z^T M (Z x), M one application of the PC ``inner``
    (Z None: y = M x)."""

    def __init__(self, Z, inner):
        self.Z, self.inner = Z, inner
        if Z is not None:
            self.full_in, self.full_out = Z.createVecLeft(), Z.createVecLeft()

    def apply(self, pc, x, y):
        if self.Z is None:
            self.inner.apply(x, y)
            return
        self.Z.mult(x, self.full_in)
        self.inner.apply(self.full_in, self.full_out)
        self.Z.multTranspose(self.full_out, y)


class ReducedOperator:
    """petsc4py's python-context matrix y = Z^T A Z x: three products, Z^T A Z never formed."""

    def __init__(self, A, Z):
        self.A, self.Z = A, Z
        self.full_in, self.full_out = Z.createVecLeft(), Z.createVecLeft()

    def mult(self, mat, x, y):
        self.Z.mult(x, self.full_in)
        self.A.mult(self.full_in, self.full_out)
        self.Z.multTranspose(self.full_out, y)

    @staticmethod
    def of(A, Z):
        """The shell matrix of Z^T A Z (A, Z PETSc matrices), laid out as Z's columns."""
        PETSc = require_petsc4py()
        columns = Z.getSizes()[1]
        return PETSc.Mat().createPython((columns, columns), ReducedOperator(A, Z), comm=Z.getComm())


def renewed_matrix(previous, A, term, bs: int, near_nullspace):
    """A + term (A scipy or distributed, term scipy) as a PETSc matrix: ``previous`` holding its
    values when it has their nonzero pattern (one object over the Newton steps: the GAMG set up
    for it then keeps its prolongators), else a new matrix with the rigid motions as near-nullspace."""
    PETSc = require_petsc4py()
    A = as_matrix(A)
    if getattr(A, "distributed", False):  # split: K's values copied and the terms' rows added in place
        if previous is not None and A.copy_into(previous, term):
            return previous
        return with_near_nullspace(A.formed(term).petsc, A.layout, near_nullspace)
    matrix = petsc_matrix(A + term, bs)
    if previous is not None and _same_pattern(previous, matrix):
        matrix.copy(previous, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        return previous
    return with_near_nullspace(matrix, layout_of(A), near_nullspace)


def _same_pattern(a, b) -> bool:
    """Whether two PETSc matrices of one process have the same nonzero pattern."""
    return all(np.array_equal(x, y) for x, y in zip(a.getValuesCSR()[:2], b.getValuesCSR()[:2]))


def collect_garbage(layout) -> None:
    """Free the PETSc objects Python dropped. Across ranks petsc4py never destroys them while
    collecting garbage (a destruction is collective: it could wait forever); it keeps them for
    this call, which every rank makes at the same point (measured: one K + D, 80 MB, per Newton
    step otherwise). Nothing to do in one process."""
    if not isinstance(layout, OneProcess):
        require_petsc4py().garbage_cleanup(layout.comm)


def failure_advice(layout) -> str:
    """What to try when a PETSc solve stalls: another backend in one process; across ranks a
    stronger preconditioner (the other backends hold the whole matrix)."""
    if isinstance(layout, OneProcess):
        return "try solver.linear=amg or direct"
    return "try stronger GAMG options in solver.petsc_options, or one process with solver.linear=direct"
