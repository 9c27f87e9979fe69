"""The stiffness matrix split by rows across MPI ranks, seen by the contact solvers as a matrix.

:class:`DistributedStiffness` holds a PETSc MPIAIJ matrix of block size d (each rank its own rows,
:class:`vemkit.vem.distributed_assembly.DofLayout`) and answers what the contact solvers ask of a
stiffness matrix with whole vectors in the serial numbering, which every rank holds: K x (PETSc's
parallel product, then an allgather), |K| |x| (the rounding floor), K's entries at the contact
vertices, its diagonal, and K + D for a Newton step (D, the contact terms, whole on every rank:
each rank adds the rows it owns). The PETSc backend (``vemkit.solvers.linear.petsc``) solves with
:attr:`DistributedStiffness.petsc` itself.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from vemkit.vem.parallel import require_petsc4py


def owned_rows(layout, A, column_position=None) -> sp.csr_matrix:
    """The rows of A (scipy, serial numbering, whole on every rank) that this rank owns, in PETSc's
    order, columns renumbered by ``column_position`` (default: PETSc's numbering of the unknowns)."""
    position = layout.position if column_position is None else column_position
    rows = A.tocsr()[layout.order[layout.owned]]
    rows = sp.csr_matrix((rows.data, position[rows.indices], rows.indptr), shape=(rows.shape[0], A.shape[1]))
    rows.sum_duplicates()
    rows.sort_indices()
    return rows


def petsc_rows(layout, rows: sp.csr_matrix, columns=None, bs: int = 1):
    """A PETSc MPIAIJ matrix of this rank's ``rows`` (``owned_rows``); ``columns``: (local, global)
    column sizes (default: the unknowns' layout)."""
    PETSc = require_petsc4py()
    columns = (layout.n_owned, layout.size) if columns is None else columns
    csr = (rows.indptr.astype(PETSc.IntType), rows.indices.astype(PETSc.IntType), rows.data.astype(PETSc.ScalarType))
    M = PETSc.Mat().create(comm=layout.comm)
    M.setSizes(((rows.shape[0], layout.size), columns), bsize=bs)
    M.setType(PETSc.Mat.Type.MPIAIJ)
    M.setPreallocationCSR(csr)
    M.assemble()
    return M


class DistributedStiffness:
    """K split by rows across the ranks (module docstring); vectors whole, serial numbering."""

    distributed = True
    dtype = np.dtype(float)

    def __init__(self, layout, petsc_matrix, on_pattern: bool = True):
        self.layout = layout
        self.petsc = petsc_matrix
        self.on_pattern = on_pattern  # its nonzero pattern is the stiffness's (terms added within it)

    @classmethod
    def from_rows(cls, layout, rows: sp.csr_matrix):
        """K of each rank's own rows (scipy CSR, global columns in PETSc's numbering), block size d."""
        return cls(layout, petsc_rows(layout, rows, bs=layout.dimension))

    @property
    def shape(self) -> tuple[int, int]:
        return (self.layout.size, self.layout.size)

    @property
    def nnz(self) -> int:
        return int(self.petsc.getInfo()["nz_used"])

    @property
    def T(self):  # noqa: N802 - scipy's name; K is symmetric
        return self

    def local_rows(self) -> sp.csr_matrix:
        """This rank's rows as scipy CSR (PETSc's column numbering): a copy made for the call, not kept
        (it would be a second stiffness on every rank)."""
        indptr, indices, data = self.petsc.getValuesCSR()
        return sp.csr_matrix((data, indices, indptr), shape=(self.layout.n_owned, self.layout.size))

    def vector(self, x):
        """A PETSc vector of this rank's entries of x (whole, serial numbering)."""
        v = self.petsc.createVecRight()
        v.setArray(self.layout.local(x))
        return v

    def whole(self, v) -> np.ndarray:
        """The whole vector (serial numbering) of a PETSc vector of this layout."""
        return self.layout.gather(v.getArray())

    def __matmul__(self, x):
        y = self.petsc.createVecLeft()
        self.petsc.mult(self.vector(x), y)
        return self.whole(y)

    dot = __matmul__

    def abs_matvec(self, x) -> np.ndarray:
        """|K| x, entrywise absolute values."""
        local = self.local_rows()
        absolute = sp.csr_matrix((np.abs(local.data), local.indices, local.indptr), shape=local.shape)
        return self.layout.gather(absolute @ np.asarray(x, dtype=float)[self.layout.order])

    def diagonal(self) -> np.ndarray:
        return self.whole(self.petsc.getDiagonal())

    def __getitem__(self, index):
        """K[i, j] for equally long arrays of unknowns i, j (serial numbering): the entries, whole."""
        i, j = (np.asarray(a, dtype=np.int64).ravel() for a in index)
        rows, cols = self.layout.position[i], self.layout.position[j]
        mine = (rows >= self.layout.owned.start) & (rows < self.layout.owned.stop)
        values = np.zeros(i.size)
        if np.any(mine):
            values[mine] = np.asarray(self.local_rows()[rows[mine] - self.layout.owned.start, cols[mine]]).ravel()
        return self.layout.sum(values)

    def __add__(self, other):
        """K + D (D scipy, whole on every rank, on K's pattern): each rank adds its rows of D."""
        M = self.petsc.duplicate(copy=True)
        if self.on_pattern and _added_within(M, self.layout, other):
            return DistributedStiffness(self.layout, M)
        M.destroy()  # D reaches beyond K's pattern
        M = self.petsc.duplicate(copy=True)
        PETSc = require_petsc4py()
        M.axpy(
            1.0, petsc_rows(self.layout, owned_rows(self.layout, other)), PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN
        )
        return DistributedStiffness(self.layout, M, on_pattern=False)

    __radd__ = __add__

    def formed(self, other):
        """This matrix + ``other`` (scipy, whole) as one PETSc matrix."""
        return self + other

    def copy_into(self, target, other) -> bool:
        """target = this matrix + ``other`` (scipy, whole), in place of a PETSc matrix whose pattern
        holds this one's (no new matrix); False, target undefined, when either reaches beyond it."""
        PETSc = require_petsc4py()
        if target.getInfo()["nz_used"] == self.petsc.getInfo()["nz_used"]:  # the same pattern
            self.petsc.copy(target, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        else:  # a wider one (a term beyond K's pattern made it)
            target.zeroEntries()
            try:
                target.axpy(1.0, self.petsc, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
            except PETSc.Error:
                return False
        return _added_within(target, self.layout, other)


def _added_within(M, layout, other) -> bool:
    """M += other's rows owned here, within M's pattern (True), or False when other reaches beyond it."""
    PETSc = require_petsc4py()
    term = petsc_rows(layout, owned_rows(layout, other))
    try:
        M.axpy(1.0, term, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
    except PETSc.Error:
        return False
    finally:
        term.destroy()
    return True


class DistributedSum:
    """K + D kept as its two terms (D scipy, whole on every rank: a few rows per contact vertex), as
    a Newton step's matrix: products K x + D x, PETSc's view a shell of the two, no copy of K."""

    distributed = True
    dtype = np.dtype(float)

    def __init__(self, stiffness: DistributedStiffness, term):
        self.stiffness, self.term = stiffness, term.tocsr()
        self.layout = stiffness.layout
        self._petsc = None

    @property
    def shape(self) -> tuple[int, int]:
        return self.stiffness.shape

    def __matmul__(self, x):
        return self.stiffness @ x + self.term @ np.asarray(x, dtype=float)

    dot = __matmul__

    def __add__(self, other):
        return DistributedSum(self.stiffness, self.term + other)

    def copy_into(self, target, other) -> bool:
        """target = K + D + other in place (:meth:`DistributedStiffness.copy_into`)."""
        return self.stiffness.copy_into(target, self.term + other)

    def formed(self, other):
        """K + D + other as one PETSc matrix (a :class:`DistributedStiffness`)."""
        return self.stiffness.formed(self.term + other)

    @property
    def petsc(self):
        """PETSc's shell matrix y = K x + D x (D's rows owned here, a small matrix)."""
        if self._petsc is None:
            PETSc = require_petsc4py()
            rows = petsc_rows(self.layout, owned_rows(self.layout, self.term))
            size = (self.layout.n_owned, self.layout.size)
            context = _SumOfMatrices(self.stiffness.petsc, rows)
            self._petsc = PETSc.Mat().createPython((size, size), context, comm=self.layout.comm)
            self._petsc.setUp()
        return self._petsc


class _SumOfMatrices:
    """petsc4py's python-context matrix y = A x + B x."""

    def __init__(self, A, B):
        self.A, self.B = A, B

    def mult(self, mat, x, y):
        self.A.mult(x, y)
        self.B.multAdd(x, y, y)
