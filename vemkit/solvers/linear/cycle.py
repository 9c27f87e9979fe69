"""The AMG V-cycle as a preconditioner: one symmetric V-cycle of a pyamg hierarchy, in single precision.

Used by the AMG backend (``vemkit.solvers.linear.amg``) and by the boundary update of its hierarchy
(``vemkit.solvers.amg_update``).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse.linalg as spla

from vemkit.solvers.sparse_ops import matvec


def v_cycle(levels, coarse_solver, level, b):
    """One V-cycle from x = 0 on ``level`` (the smoothers and transfers of the hierarchy)."""
    here = levels[level]
    x = np.zeros_like(b)
    here.presmoother(here.A, x, b)
    residual = b - matvec(here.A, x) if here.residual is None else here.residual(here.A, x, b)
    coarse_b = here.R @ residual
    if level == len(levels) - 2:
        coarse_x = coarse_solver(levels[-1].A, coarse_b)
    else:
        coarse_x = v_cycle(levels, coarse_solver, level + 1, coarse_b)
    x += here.P @ coarse_x
    here.postsmoother(here.A, x, b)
    return x


#: the floating type of every V-cycle (2D and 3D: its operators, transfers, smoothers and coarse solve);
#: CG stays in float64 and so reaches any tolerance. float32 halves the memory traffic of the sweeps and
#: products for the same CG iterations (benchmarks/cycle.py; tests/solvers/test_amg_preconditioner.py).
CYCLE_PRECISION = np.float32


class CycleLevel:
    """What :func:`v_cycle` reads of a level: A, the transfers P and R, the two smoothers (and the
    residual's own kernel, if any)."""

    def __init__(self, A, P=None, R=None, presmoother=None, postsmoother=None):
        self.A, self.P, self.R = A, P, R
        self.presmoother, self.postsmoother = presmoother, postsmoother
        self.residual = None  # b - A x by A's product, or residual(A, x, b)


def in_precision(M, precision):
    """The CSR (or CSC) matrix M with its values in ``precision`` on M's own index arrays (M itself
    when it already is)."""
    if M.dtype == precision:
        return M
    return type(M)((M.data.astype(precision), M.indices, M.indptr), shape=M.shape)


def transfers_in_precision(here, precision):
    """(P, R) of a level in ``precision``; R = P^T as a view of the new P when it was one of P."""
    P = in_precision(here.P, precision)
    if here.R.format == "csc" and np.shares_memory(here.R.data, here.P.data):
        return P, P.T
    return P, in_precision(here.R, precision)


def v_cycle_preconditioner(hierarchy, precision=CYCLE_PRECISION, release=False):
    """The V-cycle of a pyamg hierarchy as a LinearOperator (symmetric: forward Gauss-Seidel before,
    backward after), the operations of ``hierarchy.aspreconditioner("V")`` without the two residual
    norms pyamg's ``solve`` adds to every application (one a product with x = 0): ~17 % of each
    CG iteration at 10^6 DOFs. The coarse levels (pyamg makes them 3 x 3 block BSR for the three
    rigid modes) are smoothed in scalar CSR: pyamg's block Gauss-Seidel costs 3-4 times as much
    per nonzero, for the same CG iteration counts (measured: Cook at 10^6 DOFs, squares and
    triangles; the paper scene, ssn and uzawa, n = 128 ... 512). Both: CG time -32 %. The
    transfers P, R are CSR as well: a V-cycle at 2.1 M DOFs (paper scene, 1024^2) 0.246 -> 0.191 s
    CPU, the same vector to the last bit.

    The cycle runs in ``precision`` (:data:`CYCLE_PRECISION`): copies of the levels' values on
    their index arrays, b cast down, the correction cast up, the coarsest LU in float64. The
    hierarchy's levels keep their float64 operators; ``release``: their transfers become the cycle's
    (the float64 P of the finest level, 27 M entries at 2.1 M DOFs, is freed: nothing but the cycle
    reads it once the set-up is done, except vemkit.solvers.amg_update's products, 3D).
    """
    levels = hierarchy.levels
    for here in levels[1:-1]:
        here.A = here.A.tocsr()
    for here in levels[:-1]:  # the transfers too: BSR (1 x 3, 3 x 3) products cost 1.5 x CSR's, same sums
        here.P = here.P.tocsr()
        here.R = here.R if here.R.format == "csc" else here.R.tocsr()  # csc: P^T as a view of P
    if len(levels) == 1:
        return spla.aslinearoperator(hierarchy.aspreconditioner(cycle="V"))
    cycle = []
    for here in levels[:-1]:
        P, R = transfers_in_precision(here, precision)
        if release:
            here.P, here.R = P, R
        cycle.append(CycleLevel(in_precision(here.A, precision), P, R, here.presmoother, here.postsmoother))
    cycle.append(CycleLevel(levels[-1].A))
    coarse_solver = hierarchy.coarse_solver

    def coarse(A, b):  # the coarsest LU in float64 (a few thousand unknowns)
        return coarse_solver(A, b.astype(float)).astype(precision)

    def one_cycle(b):
        return v_cycle(cycle, coarse, 0, np.ravel(b).astype(precision)).astype(float)

    return spla.LinearOperator(levels[0].A.shape, dtype=float, matvec=one_cycle)
