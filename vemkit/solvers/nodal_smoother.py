"""Nodal (d x d block) Gauss-Seidel on a scalar CSR matrix: the finest-level smoother of the 3D contact steps.

The semismooth Newton steps on a 3D body (vemkit.solvers.ssn_friction) add to K, at every sliding vertex,
the tangent stiffness of the slip direction w b slope (e1 t1 + e2 t2)(e1 t1 + e2 t2)^T, slope =
gamma / (|q| - 1) = 1 / |u_tau| at the solution: ~1e6 gamma where the slip is small, a rank-one
3 x 3 block that mixes the x and y dofs of the vertex. Scalar Gauss-Seidel relaxes the rows of a
vertex one after the other and crawls along that block's null direction: on the sheared box
(config/scenes/3d/sheared_box.yaml, n = 40) the last Newton steps needed 11 and 38 CG iterations for
eta = 1e-3, and 35 and 57 at 10^6 DOFs. Relaxing the d unknowns of a vertex together (solving its
diagonal block) removes that: 1 and 11 at n = 40.

Here the block sweep reads the rows of a vertex once, CSR (the same memory traffic as the scalar
sweep; pyamg's BSR block smoother costs 3-4 times as much per nonzero) or 3 x 3 BSR (x_j read once
per block: the 3D Newton steps' finest level, vemkit.solvers.amg_update, ~8 times faster than CSR),
and applies the inverse of the vertex's diagonal block (:class:`NodalBlocks`: K's once, the contact
vertices' at each step); :func:`block_residual` is the cycle's b - A x on the BSR form. The
dofs of vertex i are rows 3 i, 3 i + 1, 3 i + 2 (vemkit's interleaved numbering). ``nodal_gauss_seidel`` equals
pyamg's ``block_gauss_seidel`` on the BSR form of the matrix (tests/solvers/test_nodal_smoother.py);
a forward sweep before and a backward sweep after keep the V-cycle symmetric.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def _diagonal_blocks(indptr, indices, data, nodes, blocks):
    for k in range(nodes.shape[0]):
        node = nodes[k]
        for local in range(3):
            row = 3 * node + local
            for p in range(indptr[row], indptr[row + 1]):
                offset = indices[p] - 3 * node
                if 0 <= offset < 3:
                    blocks[k, local, offset] += data[p]


def diagonal_blocks(A, nodes=None) -> np.ndarray:
    """(n / 3, 3, 3): the 3 x 3 diagonal blocks of the CSR matrix A (duplicates summed); only those of
    ``nodes`` (len(nodes), 3, 3) when given."""
    nodes = np.arange(A.shape[0] // 3) if nodes is None else np.asarray(nodes, dtype=np.int64)
    blocks = np.zeros((nodes.size, 3, 3))
    _diagonal_blocks(A.indptr, A.indices, A.data, nodes, blocks)
    return blocks


class NodalBlocks:
    """The inverses of the diagonal blocks of K + D for the D of each Newton step: K's are inverted
    once, only the vertices D touches again (D lives on the contact vertices)."""

    def __init__(self, K):
        self.blocks = diagonal_blocks(K)
        self.inverses = np.linalg.inv(self.blocks)

    def with_term(self, D) -> np.ndarray:
        """The inverses for K + D (D CSR, the same size, duplicates summed)."""
        touched = np.unique(np.flatnonzero(np.diff(D.indptr)) // 3)
        inverses = self.inverses.copy()
        if touched.size:
            inverses[touched] = np.linalg.inv(self.blocks[touched] + diagonal_blocks(D, touched))
        return inverses


# fastmath: the row sums may be reassociated (vectorized); 19.7 against 34.4 ms per sweep at 1.8e5
# DOFs, pyamg's scalar Gauss-Seidel 16.1 ms (hexahedra, 81 entries per row)
@numba.njit(cache=True, fastmath=True)
def _sweep(indptr, indices, data, x, b, inverses, forward):
    nodes = inverses.shape[0]
    for k in range(nodes):
        node = k if forward else nodes - 1 - k
        row = 3 * node
        r0 = b[row]  # r = b - A x on the vertex's three rows, with the current x
        for p in range(indptr[row], indptr[row + 1]):
            r0 -= data[p] * x[indices[p]]
        r1 = b[row + 1]
        for p in range(indptr[row + 1], indptr[row + 2]):
            r1 -= data[p] * x[indices[p]]
        r2 = b[row + 2]
        for p in range(indptr[row + 2], indptr[row + 3]):
            r2 -= data[p] * x[indices[p]]
        block = inverses[node]  # x_i += D_i^-1 r_i
        x[row] += block[0, 0] * r0 + block[0, 1] * r1 + block[0, 2] * r2
        x[row + 1] += block[1, 0] * r0 + block[1, 1] * r1 + block[1, 2] * r2
        x[row + 2] += block[2, 0] * r0 + block[2, 1] * r1 + block[2, 2] * r2


# 3 x 3 BSR: x_j read once per block (not once per entry) and a contiguous block of values; the backward
# sweep walks each block row backwards too (the memory stream then only descends). Not fastmath: its
# vectorized gathers cost 4 times the plain loop (hexahedra at 2.2e5 DOFs, float32: 4.4 ms per forward
# sweep against 17.5 with fastmath and 33 for the CSR sweep; scipy's BSR product 10.7 ms)
@numba.njit(cache=True)
def _block_sweep(indptr, indices, data, x, b, inverses, forward):
    nodes = indptr.shape[0] - 1
    for k in range(nodes):
        node = k if forward else nodes - 1 - k
        row = 3 * node
        r0, r1, r2 = b[row], b[row + 1], b[row + 2]  # r = b - A x on the vertex's rows, the current x
        first, last = indptr[node], indptr[node + 1]
        for t in range(last - first):
            p = first + t if forward else last - 1 - t
            j = 3 * indices[p]
            x0, x1, x2 = x[j], x[j + 1], x[j + 2]
            q = 9 * p  # block p, row-major, in the flat values
            r0 -= data[q] * x0 + data[q + 1] * x1 + data[q + 2] * x2
            r1 -= data[q + 3] * x0 + data[q + 4] * x1 + data[q + 5] * x2
            r2 -= data[q + 6] * x0 + data[q + 7] * x1 + data[q + 8] * x2
        block = inverses[node]  # x_i += D_i^-1 r_i
        x[row] += block[0, 0] * r0 + block[0, 1] * r1 + block[0, 2] * r2
        x[row + 1] += block[1, 0] * r0 + block[1, 1] * r1 + block[1, 2] * r2
        x[row + 2] += block[2, 0] * r0 + block[2, 1] * r1 + block[2, 2] * r2


# the vertices split over the Numba threads: each row's sum in the serial order, the same bits
@numba.njit(cache=True, parallel=True)
def _block_residual(indptr, indices, data, x, b, r):
    for node in numba.prange(indptr.shape[0] - 1):
        row = 3 * node
        r0, r1, r2 = b[row], b[row + 1], b[row + 2]
        for p in range(indptr[node], indptr[node + 1]):
            j = 3 * indices[p]
            x0, x1, x2 = x[j], x[j + 1], x[j + 2]
            q = 9 * p
            r0 -= data[q] * x0 + data[q + 1] * x1 + data[q + 2] * x2
            r1 -= data[q + 3] * x0 + data[q + 4] * x1 + data[q + 5] * x2
            r2 -= data[q + 6] * x0 + data[q + 7] * x1 + data[q + 8] * x2
        r[row], r[row + 1], r[row + 2] = r0, r1, r2


def block_residual(A, x, b):
    """b - A x for A BSR with 3 x 3 blocks (the finest level's residual in the V-cycle: ~3 times
    faster than scipy's BSR product in float32)."""
    r = np.empty_like(b)
    _block_residual(A.indptr, A.indices, A.data.reshape(-1), x, b, r)
    return r


def nodal_gauss_seidel(A, x, b, inverses, forward: bool = True) -> None:
    """One block Gauss-Seidel sweep on ``x`` in place (A CSR, or BSR with 3 x 3 blocks, with 3 dofs
    per vertex; ``inverses`` of its diagonal blocks)."""
    if A.format == "bsr":
        _block_sweep(A.indptr, A.indices, A.data.reshape(-1), x, b, inverses, forward)
    else:
        _sweep(A.indptr, A.indices, A.data, x, b, inverses, forward)


def nodal_smoothers(inverses):
    """(presmoother, postsmoother) with the signature of pyamg's, ``smoother(A, x, b)``: a forward and
    a backward nodal sweep with the given inverses of A's diagonal blocks."""

    def presmoother(A, x, b):
        nodal_gauss_seidel(A, x, b, inverses, forward=True)

    def postsmoother(A, x, b):
        nodal_gauss_seidel(A, x, b, inverses, forward=False)

    return presmoother, postsmoother
