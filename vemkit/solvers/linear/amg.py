"""The AMG backend (``solver.linear: amg``): CG preconditioned by a pyamg smoothed aggregation hierarchy
with the rigid-body modes as near-nullspace (the V-cycle of ``vemkit.solvers.linear.cycle``).

A solve with another matrix (K + D inside a Newton iteration) keeps the hierarchy of K as its
preconditioner. The semismooth Newton systems (:class:`AMGNewtonSystems`) are solved by CG (GMRES
when unsymmetric) on Z^T (K + D) Z, never formed, preconditioned by Z^T M Z, M the V-cycle: in 3D the
hierarchy follows every step's K + D (``vemkit.solvers.amg_update``), in 2D it is rebuilt for K + D
when CG needs REBUILD_FACTOR times the iterations per decade of the plain solve. When they stall the
Newton solves fall back to the direct backend (:meth:`AMGNewtonSystems.fallback`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse.linalg as spla

from vemkit.contact.boundary import rank_one_blocks
from vemkit.exceptions import LinearSolveError
from vemkit.solvers.linear.base import LinearSolver, NewtonSystems, reduced_right_hand_side, three_d
from vemkit.solvers.linear.cycle import CYCLE_PRECISION, v_cycle_preconditioner
from vemkit.solvers.linear.direct import IterativeNewtonSystems
from vemkit.solvers.sparse_ops import SumOperator, as_matrix, reduced_operator

REBUILD_FACTOR = 3.0  # rebuild the AMG hierarchy when CG needs this many times the baseline iterations/decade
MIN_REBUILD_ITERATIONS = 20
MAX_REBUILDS = 10

#: pyamg's options, measured on the paper scene (benchmarks/assembly.py, contact.py): scalar CSR
#: aggregation with the rigid-body modes converges in as few CG iterations as 2 x 2 BSR blocks and
#: its Gauss-Seidel sweeps are cheaper; improving the candidates doubles the setup for nothing.
AMG_OPTIONS = dict(
    symmetry="hermitian",
    # the coarse levels are 3 x 3 blocks, amalgamated by "symmetric" with theta = 0: every entry is strong
    strength=("symmetric", {"theta": 0.0}),
    # "local" weighting bounds rho(D^-1 A) by row sums: the default Lanczos estimate
    # was 70 % of the set-up at 512^2 squares, for 4 fewer CG iterations
    smooth=("jacobi", {"omega": 4.0 / 3.0, "degree": 1, "weighting": "local"}),
    presmoother=("gauss_seidel", {"sweep": "forward"}),
    postsmoother=("gauss_seidel", {"sweep": "backward"}),
    improve_candidates=None,
    max_coarse=2000,
    coarse_solver="splu",  # pinv (the default) costs seconds when coarsening stalls above max_coarse
    keep=False,
)
#: 3D: pyamg counts max_coarse in 3 x 3 block rows; 600 of them keep the coarsest LU under ~2000 unknowns
#: (a box at 5.6e4 DOFs: 4 356 unknowns and a 0.3 s factorization with 2000; 192 with 600, the CG
#: solve 0.45 -> 0.20 s; the contact solver refactors it at every Newton step, vemkit.solvers.amg_update)
BLOCK_MAX_COARSE = 600
FINEST_OWN = 2000  # above this many unknowns the finest level is vemkit.solvers.amg_setup's
#: 3D: above this many unknowns the finest level is vemkit.solvers.amg_setup.block_finest_level (pyamg's
#: aggregates and P, R A P to rounding; at 10^6 DOFs the set-up's peak 3.3 -> ~2 GiB); below it pyamg's
#: own, bit for bit as before (tests/golden)
BLOCK_FINEST_OWN = 100_000
#: 2D: the strength on the levels below vemkit's finest (3 x 3 blocks). theta = 0 (every block strong)
#: made the second level's aggregates too coarse: CG to 1e-12 on structured triangles at 5.3e5 DOFs
#: took 64 iterations, with 0.08 38 (CG 7.7 -> 4.7 s CPU, set-up 1.3 -> 0.8 s; operator complexity
#: 1.43 -> 1.45); paper squares 5.3e5: 29 -> 24, Delaunay 1.3e5: 40 -> 32, Voronoi 6.5e4: 26 both;
#: 0.15: 27 iterations but a 4767-unknown coarsest LU; 0.25: 1198 iterations (benchmarks/peers.py meshes)
COARSE_STRENGTH_2D = ("symmetric", {"theta": 0.08})


def smoothed_aggregation(A, near_nullspace=None):
    """The smoothed aggregation hierarchy of A (CSR) with the rigid-body modes as near-nullspace.

    The finest level: theta = 0 makes every entry strong, so its strength matrix is A's own
    pattern (strength None: the same aggregates; 0.5 s less set-up and 0.2 GiB less peak memory at
    10^6 DOFs, benchmarks/cook.py). Its smoothed prolongator is built by
    ``vemkit.solvers.amg_setup`` (the same P as pyamg's "local" Jacobi smoother without its three
    copies of A: at 2.1 M DOFs the set-up 8.8 -> 4.5 s CPU); the coarser levels are pyamg's
    with the same options.
    """
    import pyamg
    from pyamg.multilevel import MultilevelSolver
    from pyamg.relaxation.smoothing import change_smoothers

    options = dict(AMG_OPTIONS)
    if near_nullspace is not None and np.shape(near_nullspace)[1] == 6 and A.shape[0] % 3 == 0:
        return _block_hierarchy(A, near_nullspace, options)
    if A.shape[0] <= max(FINEST_OWN, options["max_coarse"]) or near_nullspace is None:
        return pyamg.smoothed_aggregation_solver(
            A, B=near_nullspace, **dict(options, strength=[None, options["strength"]])
        )
    from vemkit.solvers.amg_setup import finest_level

    P, R, A_coarse, B_coarse = finest_level(A, near_nullspace, omega=options["smooth"][1]["omega"])
    presmoother, postsmoother = options.pop("presmoother"), options.pop("postsmoother")
    coarse_solver = options.pop("coarse_solver")
    options["strength"] = COARSE_STRENGTH_2D
    coarse = pyamg.smoothed_aggregation_solver(
        A_coarse, B=B_coarse, presmoother=presmoother, postsmoother=postsmoother, coarse_solver=coarse_solver, **options
    )
    finest = MultilevelSolver.Level()
    finest.A, finest.B, finest.P, finest.R = A, np.asarray(near_nullspace, dtype=float), P, R
    A.symmetry = "hermitian"
    hierarchy = MultilevelSolver([finest] + coarse.levels, coarse_solver=coarse_solver)
    change_smoothers(hierarchy, presmoother, postsmoother)
    return hierarchy


def _block_hierarchy(A, near_nullspace, options):
    """3D (six rigid modes, three dofs per node): the set-up on the 3 x 3 block form of A, so that every
    level's strength is by "symmetric" on blocks: the same aggregates and CG iterations as scalar CSR,
    set-up 2.2 times faster (hexahedra at 2e5 DOFs: 1.41 s instead of 3.08 s CPU, 24 iterations either
    way; theta = 0.02: 22 iterations, the same CG time; max_coarse 500 or 2000 the same levels, 8000
    stops at a 16 464-unknown LU: 18 iterations, 3.7 x the CG time). The cycle smooths the finest
    level in scalar CSR (``v_cycle_preconditioner``)."""
    import pyamg

    options = dict(options, max_coarse=BLOCK_MAX_COARSE)
    if A.shape[0] > BLOCK_FINEST_OWN:
        hierarchy = _own_finest_level(A, near_nullspace, options)
    else:
        hierarchy = pyamg.smoothed_aggregation_solver(A.tobsr(blocksize=(3, 3)), B=near_nullspace, **options)
        hierarchy.levels[0].A = A
    for level in hierarchy.levels[:-1]:  # R = P^T as a view of P (CSC): pyamg's R is a copy of P^T's values
        level.P = level.P.tocsr()
        level.R = level.P.T
    return hierarchy


def _own_finest_level(A, near_nullspace, options):
    """The block hierarchy with its finest level from ``vemkit.solvers.amg_setup.block_finest_level``
    (pyamg's aggregates and P, no BSR copies of A) and pyamg's coarser levels, the same options."""
    import pyamg
    from pyamg.multilevel import MultilevelSolver
    from pyamg.relaxation.smoothing import change_smoothers

    from vemkit.solvers.amg_setup import block_finest_level

    P, R, A_coarse, B_coarse = block_finest_level(A, near_nullspace, omega=options["smooth"][1]["omega"])
    coarse = pyamg.smoothed_aggregation_solver(A_coarse, B=B_coarse, **options)
    finest = MultilevelSolver.Level()
    finest.A, finest.B, finest.P, finest.R = A, np.asarray(near_nullspace, dtype=float), P, R
    A.symmetry = "hermitian"
    hierarchy = MultilevelSolver([finest] + coarse.levels, coarse_solver=options["coarse_solver"])
    change_smoothers(hierarchy, options["presmoother"], options["postsmoother"])
    return hierarchy


class AMGSolver(LinearSolver):
    """pyamg smoothed aggregation (rigid-body near-nullspace) as the preconditioner of CG."""

    method = "amg"
    iterative = True

    def __init__(self, A, near_nullspace=None, tol=1e-10, maxiter=2000):
        self.A = A.tocsr()
        self.tol = tol
        self.maxiter = maxiter
        self.hierarchy = smoothed_aggregation(self.A, near_nullspace)
        self.three_d = three_d(near_nullspace)  # 2D: only the cycle reads the transfers after the set-up
        self._preconditioner = v_cycle_preconditioner(self.hierarchy, release=not self.three_d)
        self.iterations = 0
        self.residual = 0.0

    @property
    def preconditioner(self):
        """The V-cycle of the hierarchy (built again after :meth:`release_preconditioner`)."""
        if self._preconditioner is None:
            self._preconditioner = v_cycle_preconditioner(self.hierarchy, release=not self.three_d)
        return self._preconditioner

    @preconditioner.setter
    def preconditioner(self, cycle):
        self._preconditioner = cycle

    def release_preconditioner(self):
        """Free the cycle's single-precision copies of the levels (at 10^6 DOFs in 3D, K's values and
        the finest P: ~0.6 GiB) while another cycle preconditions (vemkit.solvers.amg_update's)."""
        self._preconditioner = None

    def solve(self, b, x0=None, tol=None, A=None):
        A = self.A if A is None else A
        tol = self.tol if tol is None else tol
        bnorm = np.linalg.norm(b)
        if bnorm == 0.0:
            self.iterations, self.residual = 0, 0.0
            return np.zeros_like(b)
        count = [0]

        def callback(xk):
            count[0] += 1

        x, info = spla.cg(
            A, b, x0=x0, rtol=tol, atol=0.0, maxiter=self.maxiter, M=self.preconditioner, callback=callback
        )
        self.iterations = count[0]
        self.residual = float(np.linalg.norm(b - A @ x) / bnorm)
        stopped = (
            f"AMG-CG stopped after {count[0]} iterations at relative residual {self.residual:.2e} (asked {tol:.1e})"
        )
        return _converged(x, info, count[0], stopped)

    def newton_systems(self, problem, baseline) -> NewtonSystems:
        return AMGNewtonSystems(problem, self, baseline)

    def boundary_updated_hierarchy(self, support):
        """The hierarchy of K made to follow K + D, D with the pattern of ``support`` (3D Newton steps,
        ``vemkit.solvers.amg_update``): the aggregates and prolongators kept, the operators updated."""
        from vemkit.solvers.amg_update import BoundaryUpdatedHierarchy

        return BoundaryUpdatedHierarchy(
            self.hierarchy, support, nodal=True, precision=CYCLE_PRECISION, reversed_backward=True
        )


class AMGNewtonSystems(IterativeNewtonSystems):
    """Krylov on Z^T (K + D) Z with the projected V-cycle of K's hierarchy (updated or rebuilt for K + D)."""

    method = AMGSolver.method

    def __init__(self, problem, base, baseline):
        self.problem = problem
        self.rebuilds = 0
        self.baseline = baseline  # CG iterations per decade of residual reduction with K
        # 3D: the hierarchy of K follows every step's K + J + stick penalty (vemkit.solvers.amg_update)
        self.updated = None
        if problem.contact.dimension == 3:
            base.release_preconditioner()  # every Newton step's cycle is the updated hierarchy's
            cb, ones = problem.contact, np.ones(problem.contact.normal.shape)
            support = rank_one_blocks(cb, np.ones(cb.size), ones, problem.n_dofs)  # every contact block
            self.updated = base.boundary_updated_hierarchy(support)
        self.preconditioner = None if self.updated is not None else base.preconditioner

    def operator(self, K, *terms):
        """K x + D x: no copy of K's values (formed, on K's index arrays, only for a rebuilt hierarchy)."""
        D = terms[0]
        for term in terms[1:]:
            D = D + term
        return SumOperator(K, D)

    def solve(self, A, Z, rhs, eta, penalty, symmetric=True, atol=0.0):
        b, lift = reduced_right_hand_side(Z, rhs)
        if np.linalg.norm(b) == 0.0:
            return np.zeros(A.shape[0]), 0
        krylov = spla.cg if symmetric else _gmres
        A_red = A if Z is None else reduced_operator(A, Z)  # Z^T A Z never formed (a matrix the size of K)
        if self.updated is not None:  # the V-cycle of K + J + penalty, no rebuild criterion
            self.preconditioner = self.updated.preconditioner(A.J + penalty())
            y, its = self._krylov(krylov, A_red, Z, b, eta, atol)
            return lift(y), its
        y, its = self._krylov(krylov, A_red, Z, b, eta, atol)
        decades = max(np.log10(1.0 / eta), 1.0)
        if its > max(REBUILD_FACTOR * self.baseline * decades, MIN_REBUILD_ITERATIONS) and self.rebuilds < MAX_REBUILDS:
            hierarchy = AMGSolver(as_matrix(A) + penalty(), near_nullspace=self.problem.near_nullspace)
            self.preconditioner = hierarchy.preconditioner
            self.rebuilds += 1
            y, more = self._krylov(krylov, A_red, Z, b, eta, atol, x0=y)
            its += more
        return lift(y), its

    def _krylov(self, krylov, A_red, Z, b, eta, atol, x0=None):
        full, M = self.preconditioner, self.preconditioner
        if Z is not None:
            M = spla.LinearOperator(A_red.shape, matvec=lambda v: Z.T @ (full @ (Z @ v)), dtype=float)
        count = [0]

        def callback(_):
            count[0] += 1

        y, info = krylov(A_red, b, x0=x0, rtol=eta, atol=atol, maxiter=5000, M=M, callback=callback)
        stopped = f"AMG-preconditioned Krylov solve of the Newton step stopped after {count[0]} iterations"
        return _converged(y, info, count[0], stopped), count[0]


def _gmres(A, b, x0, rtol, atol, maxiter, M, callback):
    """GMRES (restart 50) with the cg call signature; callback once per inner iteration."""
    return spla.gmres(
        A, b, x0=x0, rtol=rtol, atol=atol, restart=50, maxiter=maxiter, M=M, callback=callback, callback_type="pr_norm"
    )


BACKEND = AMGSolver


def _converged(x, info: int, iterations: int, stopped: str) -> np.ndarray:
    """x of a Krylov solve that converged (info 0, finite); LinearSolveError saying how it ``stopped``."""
    if info != 0 or not np.all(np.isfinite(x)):
        raise LinearSolveError(f"{stopped}; try solver.linear=direct", solver="amg", iterations=iterations)
    return x
