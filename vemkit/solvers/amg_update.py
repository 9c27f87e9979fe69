"""The AMG hierarchy of K made the preconditioner of K + D, D a boundary term, without a new set-up.

The semismooth Newton steps (vemkit.solvers.ssn) solve with K + D: D the contact Jacobian (rank-one
3 x 3 blocks per contact vertex, vemkit.contact.boundary.rank_one_blocks) plus a penalty on the tangents
of the stick vertices (which the step holds fixed, Z^T (K + D) Z). Rebuilding the hierarchy for K + D
(aggregation, smoothed prolongators, Galerkin products) costs the whole set-up each time the stick set
moves: on a 3D box at 1.8e5 DOFs, 10 rebuilds in 13 Newton steps and 1 651 CG iterations. Here the
aggregates and the prolongators of K are kept and only the operators follow D:

    A_0 = K + D,   A_{l+1} = A_{l+1}(K) + D_{l+1},   D_{l+1} = R_l D_l P_l

(the Galerkin coarse operators of K + D exactly, since R_l (A_l(K) + D_l) P_l = A_{l+1}(K) + D_{l+1});
D_l lives on the few rows the boundary's aggregates touch, so the update is a small sparse product
per level (:func:`coarse_term`, from the rows of P_l where D_l lives), the values of D added in the
patterns of the levels (no new index arrays: D's blocks lie in K's pattern, the Galerkin products keep
them inside), and a new LU of the coarsest level. The finest level is smoothed by vertices (``nodal``,
vemkit.solvers.nodal_smoother): D's slip-direction blocks are rank one and up to ~1e6 times K's
diagonal, which scalar Gauss-Seidel relaxes poorly; it is then held as 3 x 3 BSR in the cycle's
precision (:class:`_NodalLevelOperator`), the only copy of K's values besides K.

What it cost and costs at 10^6 DOFs (the sheared box, benchmarks/contact3d_speed.py): the finest level
in scalar CSR on a widened float64 copy of K and a float32 copy (1.3 GB) and its scalar-row sweep were
most of the solve (the hierarchy updates themselves: ~0.4 s per Newton step); in BSR 0.36 GB and the
block sweep reads each x_j once per block.
"""

from __future__ import annotations

import numba
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from vemkit.solvers.linear.cycle import transfers_in_precision, v_cycle
from vemkit.solvers.nodal_smoother import NodalBlocks, block_residual, nodal_smoothers
from vemkit.solvers.reversed_sweep import ReversedRows
from vemkit.solvers.sparse_ops import to_blocks


def _lookup(A, D):
    """For every entry of D (both CSR, column indices sorted): whether A's pattern holds it, and its
    position in ``A.data`` (where it is) or the position it would be inserted at (where it is not)."""
    counts = np.diff(D.indptr)
    touched = np.flatnonzero(counts)
    starts = A.indptr[touched].astype(np.int64)
    lengths = A.indptr[touched + 1] - starts
    # the touched rows of A side by side: (local row, column) keys, sorted since each row is sorted
    before = np.concatenate([[0], np.cumsum(lengths)[:-1]]).astype(np.int64)
    flat = np.arange(int(lengths.sum()), dtype=np.int64) + np.repeat(starts - before, lengths)  # in A.data
    keys = np.repeat(np.arange(touched.size, dtype=np.int64), lengths) * A.shape[1] + A.indices[flat]
    local = np.repeat(np.arange(touched.size, dtype=np.int64), counts[touched])
    wanted = local * A.shape[1] + D.indices
    at = np.searchsorted(keys, wanted)
    found = (at < keys.size) & (keys[np.minimum(at, keys.size - 1)] == wanted)
    return found, starts[local] + (at - before[local])


def pattern_positions(A, D):
    """Positions in ``A.data`` of the entries of D (both CSR, column indices sorted; D summed), or
    None when an entry of D is not in A's pattern."""
    if D.nnz == 0:
        return np.zeros(0, dtype=np.int64)
    found, positions = _lookup(A, D)
    return positions if np.all(found) else None


def widened(A, D):
    """A (CSR, sorted) with the entries of D's pattern that it lacks inserted as explicit zeros (its
    own values untouched)."""
    found, positions = _lookup(A, D)
    missing = ~found
    rows = np.repeat(np.arange(D.shape[0]), np.diff(D.indptr))[missing]
    indices = np.insert(A.indices, positions[missing], D.indices[missing])
    data = np.insert(A.data, positions[missing], 0.0)
    indptr = A.indptr + np.concatenate([[0], np.cumsum(np.bincount(rows, minlength=A.shape[0]))])
    wide = sp.csr_matrix((data, indices, indptr), shape=A.shape)
    wide.has_sorted_indices = True
    return wide


def _summed(D):
    """D as CSR with duplicates summed (and so its column indices sorted), explicit zeros dropped."""
    D = D.tocsr()
    D.sum_duplicates()
    D.eliminate_zeros()
    return D


def coarse_term(P, D):
    """R D P (R = P^T, D CSR summed) from the rows of P where D lives: no product, copy or transpose of
    the whole P (at 10^6 DOFs its finest level has 2.6e7 entries, D's rows a few 10^4). The same sums
    in the same order as R @ D @ P with R the CSR P^T (the rows of P dropped meet only empty rows and
    columns of D)."""
    lives = np.union1d(np.flatnonzero(np.diff(D.indptr)), D.indices)
    rows = P[lives]  # CSR, its rows in D's order (ascending)
    return _summed(rows.T.tocsr() @ D[lives][:, lives] @ rows)


def _same_pattern(pattern, D) -> bool:
    indptr, indices = pattern
    return np.array_equal(indptr, D.indptr) and np.array_equal(indices, D.indices)


class _LevelOperator:
    """One level's A(K) and a copy of its values that holds A(K) + D_l (updated in place)."""

    def __init__(self, A, precision=np.float64):
        self.base = A.tocsr()
        self.base.sort_indices()
        self.precision = precision
        self.current = self._copy()
        self.touched = np.zeros(0, dtype=np.int64)
        self.pattern = None  # D's index arrays at the last update (its positions are ``touched``)

    def update(self, D):
        """A(K) + D as ``current``, D's values added in place (D summed, explicit zeros dropped)."""
        data = self.current.data
        data[self.touched] = self.base.data[self.touched]
        same = self.pattern is not None and _same_pattern(self.pattern, D)
        positions = self.touched if same else pattern_positions(self.base, D)
        self.pattern = (D.indptr.copy(), D.indices.copy())
        if positions is None:  # an entry of D off the pattern: widen it once, then in place again
            self.widen(D)
            data = self.current.data
            positions = pattern_positions(self.base, D)
        data[positions] += D.data  # one position per entry
        self.touched = positions
        return self.current

    def widen(self, D):
        """A(K) on the union of its pattern and D's (an entry of K that is exactly zero, e.g. the
        x-y coupling at a vertex of an axis-aligned hexahedral grid, is not stored)."""
        self.base = widened(self.base, D)
        self.current = self._copy()
        self.touched = np.zeros(0, dtype=np.int64)
        self.pattern = None

    def _copy(self):
        """A(K)'s values in ``precision`` on its own index arrays (shared, not copied)."""
        data = self.base.data.astype(self.precision, copy=True)
        return sp.csr_matrix((data, self.base.indices, self.base.indptr), shape=self.base.shape)


def block_positions(B, D):
    """Positions in ``B.data.ravel()`` (B BSR with 3 x 3 blocks, sorted) of the entries of D (CSR,
    summed), or None when an entry of D lies in no block of B."""
    rows = np.repeat(np.arange(D.shape[0]), np.diff(D.indptr))
    block_rows, block_columns = rows // 3, D.indices // 3
    touched = np.unique(block_rows)
    starts = B.indptr[touched].astype(np.int64)
    lengths = B.indptr[touched + 1] - starts
    before = np.concatenate([[0], np.cumsum(lengths)[:-1]]).astype(np.int64)
    flat = np.arange(int(lengths.sum()), dtype=np.int64) + np.repeat(starts - before, lengths)  # blocks of B
    width = B.shape[1] // 3
    keys = np.repeat(np.arange(touched.size, dtype=np.int64), lengths) * width + B.indices[flat]
    local = np.searchsorted(touched, block_rows)
    at = np.searchsorted(keys, local * width + block_columns)
    clipped = np.minimum(at, max(keys.size - 1, 0))
    if keys.size == 0 or not np.array_equal(keys[clipped], local * width + block_columns):
        return None if D.nnz else np.zeros(0, dtype=np.int64)
    return 9 * flat[clipped] + 3 * (rows % 3) + D.indices % 3


class _NodalLevelOperator:
    """The finest level's K + D as 3 x 3 BSR in ``precision``, what the nodal sweeps read (its values
    K's, and D's added in place at each update; K's own values where D was, kept for the next one).
    Replaces a float64 copy of K on a widened pattern and a CSR copy in ``precision``: at 10^6 DOFs
    1.3 GB -> 0.36 GB in float32."""

    def __init__(self, A, support, precision):
        self.A = A.tocsr()  # K, float64 (read again only if a D falls outside the blocks)
        self.precision = precision
        self._build(support)

    def _build(self, D=None):
        """``current`` = K in blocks (a block holds its entries that K does not store as zeros), widened
        when an entry of D lies in no block of K (never for contact blocks: K couples a vertex to itself)."""
        self.current = self._blocks(self.A)
        if D is not None and D.nnz and block_positions(self.current, D) is None:
            self.current = self._blocks(widened(self.A, D))
        self.touched, self.saved, self.pattern = np.zeros(0, dtype=np.int64), np.zeros(0, self.precision), None

    def _blocks(self, K):
        values = sp.csr_matrix((K.data.astype(self.precision), K.indices, K.indptr), shape=K.shape)
        blocks = to_blocks(values, 3, 3)
        blocks.sort_indices()
        return blocks

    def update(self, D):
        """K + D as ``current`` (D summed, explicit zeros dropped)."""
        data = self.current.data.reshape(-1)
        data[self.touched] = self.saved
        same = self.pattern is not None and _same_pattern(self.pattern, D)
        positions = self.touched if same else block_positions(self.current, D)
        if positions is None:  # an entry of D in no block of K: the blocks widened once
            self._build(D)
            data = self.current.data.reshape(-1)
            positions = block_positions(self.current, D)
        self.pattern = (D.indptr.copy(), D.indices.copy())
        self.saved = data[positions]
        data[positions] += D.data  # one position per entry
        self.touched = positions
        return self.current


class BoundaryUpdatedHierarchy:
    """The V-cycle of a hierarchy of K (vemkit.solvers.linear.AMGSolver's, levels already in CSR) as
    the preconditioner of K + D, for any boundary term D (see the module docstring)."""

    def __init__(self, hierarchy, support=None, nodal=False, precision=np.float64, reversed_backward=False):
        """``support``: a matrix whose pattern holds every D to come (e.g. the full d x d blocks of all
        contact vertices), so that the finest level's pattern is widened once, here. ``nodal``: smooth
        the finest level by vertices of three dofs (vemkit.solvers.nodal_smoother; else the
        hierarchy's own smoothers). ``precision``: the floating type of the cycle (its operators,
        transfers, smoothers and coarse LU; D's Galerkin products are formed in float64 either way).
        ``reversed_backward``: the hierarchy's postsmoothers below the finest level are pyamg's backward
        Gauss-Seidel, swept instead on a copy of the level's rows last first (the same x, read front to
        back: vemkit.solvers.reversed_sweep)."""
        self.levels = hierarchy.levels
        nodal = nodal and len(self.levels) > 1  # one level: its LU, no smoother
        self.precision = precision
        self.nodal_blocks = NodalBlocks(hierarchy.levels[0].A) if nodal else None
        self.presmoother = [level.presmoother for level in self.levels[:-1]]
        self.postsmoother = [level.postsmoother for level in self.levels[:-1]]
        self.transfers = [transfers_in_precision(level, precision) for level in self.levels[:-1]]  # on P's index arrays
        if nodal and self.levels[0].P.shape[1] % 6 == 0:  # six rigid modes: the finest P in 3 x 6 blocks
            finest = BlockTransfer(to_blocks(self.transfers[0][0], 3, 6))
            self.transfers[0] = (finest, finest.T)
        support = None if support is None else _summed(support)
        self.operators = [_LevelOperator(level.A, precision) for level in self.levels[1 if nodal else 0 :]]
        if nodal:  # the finest level in 3 x 3 blocks, for the nodal sweeps
            self.operators.insert(0, _NodalLevelOperator(self.levels[0].A, support, precision))
        elif support is not None and pattern_positions(self.operators[0].base, support) is None:
            self.operators[0].widen(support)
        first = 1 if nodal else 0
        self.reversed = [
            ReversedRows(self.operators[index].current) if reversed_backward and index >= first else None
            for index in range(len(self.levels) - 1)
        ]

    def preconditioner(self, D):
        """A LinearOperator: one V-cycle for K + D (D square CSR, supported near the boundary)."""
        D = _summed(D)
        levels = []
        for index, level in enumerate(self.levels):
            before = self.operators[index].touched  # the positions of the last D, restored by the update
            here = _Level(self.operators[index].update(D))
            if index < len(self.levels) - 1:
                here.P, here.R = self.transfers[index]
                here.presmoother, here.postsmoother = self.presmoother[index], self.postsmoother[index]
                if index == 0 and self.nodal_blocks is not None:
                    inverses = self.nodal_blocks.with_term(D).astype(self.precision)
                    here.presmoother, here.postsmoother = nodal_smoothers(inverses)
                    here.residual = block_residual
                elif self.reversed[index] is not None:
                    self.reversed[index].refresh(here.A, before, self.operators[index].touched)
                    here.postsmoother = self.reversed[index].backward_sweep
                D = coarse_term(level.P, D)
            levels.append(here)
        lu = spla.splu(levels[-1].A.tocsc())
        if len(levels) == 1:
            cycle = lu.solve
        else:

            def cycle(b):
                return v_cycle(levels, lambda _, coarse_b: lu.solve(coarse_b), 0, b)

        precision = self.precision
        return spla.LinearOperator(
            levels[0].A.shape, dtype=float, matvec=lambda b: cycle(np.ravel(b).astype(precision)).astype(float)
        )


@numba.njit(cache=True, parallel=True)
def _prolong(indptr, indices, data, coarse, fine):
    """fine = P coarse, P BSR with 3 x 6 blocks (``data`` flat), ``fine`` zeroed (its vertices split
    over the threads: the same sums)."""
    for node in numba.prange(indptr.shape[0] - 1):
        row = 3 * node
        y0, y1, y2 = fine[row], fine[row + 1], fine[row + 2]
        for p in range(indptr[node], indptr[node + 1]):
            j, q = 6 * indices[p], 18 * p
            for c in range(6):
                v = coarse[j + c]
                y0 += data[q + c] * v
                y1 += data[q + 6 + c] * v
                y2 += data[q + 12 + c] * v
        fine[row], fine[row + 1], fine[row + 2] = y0, y1, y2


@numba.njit(cache=True)
def _restrict(indptr, indices, data, fine, coarse):
    """coarse += P^T fine, P BSR with 3 x 6 blocks (``data`` flat)."""
    for node in range(indptr.shape[0] - 1):
        r0, r1, r2 = fine[3 * node], fine[3 * node + 1], fine[3 * node + 2]
        for p in range(indptr[node], indptr[node + 1]):
            j, q = 6 * indices[p], 18 * p
            for c in range(6):
                coarse[j + c] += data[q + c] * r0 + data[q + 6 + c] * r1 + data[q + 12 + c] * r2


class BlockTransfer:
    """P (or P^T, ``transpose``) of the finest level as 3 x 6 BSR, applied by Numba kernels: half the
    bytes of the CSR P and ~3 times faster than its scipy product (the V-cycle reads both once)."""

    def __init__(self, blocks, transpose=False):
        self.blocks, self.transpose = blocks, transpose
        rows, cols = blocks.shape
        self.shape = (cols, rows) if transpose else (rows, cols)

    @property
    def T(self):
        return BlockTransfer(self.blocks, not self.transpose)

    def __matmul__(self, vector):
        B = self.blocks
        out = np.zeros(self.shape[0], dtype=np.result_type(B.dtype, vector.dtype))
        kernel = _restrict if self.transpose else _prolong
        kernel(B.indptr, B.indices, B.data.reshape(-1), vector, out)
        return out


class _Level:
    """What ``vemkit.solvers.linear.v_cycle`` reads of a level."""

    def __init__(self, A):
        self.A = A
        self.P = self.R = self.presmoother = self.postsmoother = self.residual = None
