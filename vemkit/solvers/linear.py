"""Linear solves for the symmetric positive definite systems of vemkit.

``linear_solver(A, method, near_nullspace=B)`` builds a solver once (a pyamg smoothed
aggregation hierarchy with the rigid-body modes as near-nullspace, or a sparse LU
factorization) and ``.solve(b, x0=...)`` reuses it for every right-hand side. The contact
solvers also pass a modified matrix (``A + contact Jacobian``) to ``.solve``: the AMG solver keeps
its hierarchy as a preconditioner for it, the direct solver refactorizes.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse.linalg as spla

from vemkit.exceptions import InputError, LinearSolveError, SceneError

DIRECT_LIMIT = 20_000  # "auto" picks the direct solver up to this many unknowns (measured crossover, 2D)
#: the same in 3D, where LU's fill grows much faster: the sheared box (config/scenes/3d/sheared_box.yaml),
#: ssn solve seconds direct / AMG: 1 254 DOFs 0.06 / 0.11, 3 198: 0.33 / 0.18, 13 629: 12.5 / 0.60
DIRECT_LIMIT_3D = 2_000
RIGID_MODES_3D = 6  # columns of a 3D body's near-nullspace (three translations, three rotations)


def v_cycle(levels, coarse_solver, level, b):
    """One V-cycle from x = 0 on ``level`` (the smoothers and transfers of the hierarchy)."""
    here = levels[level]
    x = np.zeros_like(b)
    here.presmoother(here.A, x, b)
    coarse_b = here.R @ (b - here.A @ x)
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
    """What :func:`v_cycle` reads of a level: A, the transfers P and R, the two smoothers."""

    def __init__(self, A, P=None, R=None, presmoother=None, postsmoother=None):
        self.A, self.P, self.R = A, P, R
        self.presmoother, self.postsmoother = presmoother, postsmoother


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

    def matvec(b):
        return v_cycle(cycle, coarse, 0, np.ravel(b).astype(precision)).astype(float)

    return spla.LinearOperator(levels[0].A.shape, dtype=float, matvec=matvec)


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
    hierarchy = pyamg.smoothed_aggregation_solver(A.tobsr(blocksize=(3, 3)), B=near_nullspace, **options)
    hierarchy.levels[0].A = A
    return hierarchy


class AMGSolver:
    """pyamg smoothed aggregation (rigid-body near-nullspace) as the preconditioner of CG."""

    method = "amg"

    def __init__(self, A, near_nullspace=None, tol=1e-10, maxiter=2000):
        self.A = A.tocsr()
        self.tol = tol
        self.maxiter = maxiter
        self.hierarchy = smoothed_aggregation(self.A, near_nullspace)
        # 2D: only the cycle reads the transfers after the set-up; 3D: vemkit.solvers.amg_update too
        self.preconditioner = v_cycle_preconditioner(self.hierarchy, release=not _three_d(near_nullspace))
        self.iterations = 0
        self.residual = 0.0

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
        if info != 0 or not np.all(np.isfinite(x)):
            raise LinearSolveError(
                f"AMG-CG stopped after {count[0]} iterations at relative residual {self.residual:.2e} "
                f"(asked {tol:.1e}); try solver.linear=direct",
                solver="amg",
                iterations=count[0],
            )
        return x


class DirectSolver:
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


def _three_d(near_nullspace) -> bool:
    """Whether the near-nullspace is a 3D body's (the six rigid motions)."""
    return near_nullspace is not None and np.shape(near_nullspace)[1] == RIGID_MODES_3D


def direct_limit(near_nullspace) -> int:
    """The most unknowns ``auto`` solves directly: :data:`DIRECT_LIMIT_3D` for a 3D body (its
    near-nullspace holds the six rigid motions), :data:`DIRECT_LIMIT` otherwise."""
    return DIRECT_LIMIT_3D if _three_d(near_nullspace) else DIRECT_LIMIT


def linear_solver(A, method="auto", near_nullspace=None, tol=1e-10, maxiter=2000):
    """One solver object for repeated solves with A: ``method`` is amg, direct or auto.

    ``method`` may also be a solver built earlier for the same matrix (a sweep over contact
    parameters keeps the stiffness matrix): it is returned as it is, set-up reused.
    """
    if isinstance(method, (AMGSolver, DirectSolver)):
        if method.A.shape != A.shape or method.A.nnz != A.nnz:
            raise InputError("the prebuilt linear solver was made for another stiffness matrix", key="linear")
        return method
    if method == "auto":
        method = "direct" if A.shape[0] <= direct_limit(near_nullspace) else "amg"
    if method == "amg":
        return AMGSolver(A, near_nullspace=near_nullspace, tol=tol, maxiter=maxiter)
    if method == "direct":
        return DirectSolver(A)
    raise SceneError(f"solver.linear = {method!r} is unknown; use amg, direct or auto", key="solver.linear")
