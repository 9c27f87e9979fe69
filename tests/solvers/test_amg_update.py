"""The hierarchy of K as the preconditioner of K + D (vemkit.solvers.amg_update): its levels are the
Galerkin operators of K + D on K's prolongators, exactly; the values of D are added in the levels'
patterns (widened once where K stores no entry); the V-cycle is that of those operators."""

import numpy as np
import pytest
import scipy.sparse as sp

from vemkit.config.scene import scene_from_dict
from vemkit.contact.boundary import rank_one_blocks
from vemkit.contact.problem import scene_problem
from vemkit.solvers.amg_update import BoundaryUpdatedHierarchy, _summed, block_positions, pattern_positions, widened
from vemkit.solvers.linear import linear_solver


@pytest.mark.parametrize("seed", range(6))
def test_widened_keeps_the_values_and_holds_the_new_pattern(seed):
    A = sp.random(80, 80, density=0.1, format="csr", random_state=seed) + sp.eye(80)
    A = A.tocsr()
    A.sort_indices()
    D = _summed(sp.random(80, 80, density=0.04, format="csr", random_state=50 + seed))
    wide = widened(A, D)
    assert wide.nnz == (abs(A) + abs(D)).nnz and abs(wide - A).max() == 0.0
    assert all(np.all(np.diff(wide.indices[wide.indptr[i] : wide.indptr[i + 1]]) > 0) for i in range(80))
    assert pattern_positions(A, D) is None or D.nnz == 0
    positions = pattern_positions(wide, D)
    summed = wide.copy()
    summed.data[positions] += D.data
    assert abs(summed - (A + D)).max() < 1e-15


@pytest.mark.parametrize("seed", range(4))
def test_block_positions_find_every_entry_of_d_in_the_blocks(seed):
    A = (sp.random(60, 60, density=0.05, format="csr", random_state=seed) + sp.eye(60)).tobsr(blocksize=(3, 3))
    A.sort_indices()
    scattered = _summed(sp.random(60, 60, density=0.03, format="csr", random_state=20 + seed))
    inside = _summed(scattered.multiply(A.tocsr() != 0) + sp.eye(60))  # in A's blocks
    for D in (scattered, inside):
        positions = block_positions(A, D)
        held = (abs(A.tocsr()) + abs(D)).tobsr(blocksize=(3, 3)).indices.size == A.indices.size
        assert (positions is not None) == held and (D is scattered or held)
        if positions is not None:
            summed = A.copy()
            summed.data.reshape(-1)[positions] += D.data
            assert abs(summed - (A + D)).max() < 1e-15
    assert block_positions(A, sp.csr_matrix(A.shape)).size == 0


def _box_problem(n):
    data = {
        "model": "3d",
        "domain": {"box": [[0, 0, 0], [1, 1, 0.5]]},
        "material": {"E": 1000.0, "nu": 0.3},
        "boundary": {"dirichlet": {"top": [0.0, 0.0, -0.01]}, "contact": ["bottom"]},
        "contact": {"gap": "0.002*x", "normal": {"k": 200.0, "m": 1.0}, "friction": {"k": 3.0, "m": 0.0}},
        "discretization": {"mesh": {"family": "hex", "n": n}},
    }
    return scene_problem(scene_from_dict(data))


def test_the_levels_are_the_galerkin_operators_of_k_plus_d_and_the_cycle_is_theirs():
    problem = _box_problem(12)
    cb, n = problem.contact, problem.n_dofs
    hierarchy = linear_solver(problem.stiffness, "amg", near_nullspace=problem.near_nullspace).hierarchy
    assert len(hierarchy.levels) >= 2
    rng = np.random.default_rng(3)
    tilted = rng.normal(size=cb.normal.shape)  # blocks off K's pattern at the axis-aligned grid's vertices
    updated = BoundaryUpdatedHierarchy(hierarchy, rank_one_blocks(cb, np.ones(cb.size), np.ones_like(tilted), n))
    for step in range(3):  # the same object follows a new D each time
        D = rank_one_blocks(cb, rng.uniform(0, 1e4, cb.size), tilted, n) + rank_one_blocks(
            cb, rng.uniform(0, 1e3, cb.size), cb.normal, n
        )
        M = updated.preconditioner(D)
        expected = (problem.stiffness + D).tocsr()
        levels = hierarchy.levels
        for index, operator in enumerate(updated.operators):
            now = operator.current
            assert abs(now - expected).max() <= 1e-12 * abs(expected).max(), (step, index)
            if index < len(levels) - 1:
                expected = (levels[index].R @ expected @ levels[index].P).tocsr()
        b = rng.normal(size=n)
        x = M @ b
        assert np.all(np.isfinite(x)) and b @ x > 0  # SPD preconditioner for SPD K + D


def test_the_updated_cycle_preconditions_k_plus_a_stick_penalty_as_a_new_set_up_does():
    """CG on K + D (D a penalty 1e3 x the stiffness diagonal on the tangents of half the contact
    vertices): the updated hierarchy of K needs about the iterations of a hierarchy built for K + D,
    and far fewer than the plain hierarchy of K (measured at n = 16: 10, 7 and 141 iterations)."""
    import scipy.sparse.linalg as spla

    problem = _box_problem(16)
    cb, n, K = problem.contact, problem.n_dofs, problem.stiffness
    solver = linear_solver(K, "amg", near_nullspace=problem.near_nullspace)
    stuck = np.where(cb.coords[:, 0] < 0.5, 1e3 * K.diagonal().max(), 0.0)
    D = rank_one_blocks(cb, stuck, cb.tangent, n) + rank_one_blocks(cb, stuck, cb.tangent2, n)
    A = (K + D).tocsr()
    b = A @ np.random.default_rng(0).normal(size=n)

    def iterations(M):
        count = [0]
        spla.cg(A, b, rtol=1e-8, M=M, maxiter=2000, callback=lambda _: count.__setitem__(0, count[0] + 1))
        return count[0]

    updated = iterations(BoundaryUpdatedHierarchy(solver.hierarchy).preconditioner(D))
    rebuilt = iterations(linear_solver(A, "amg", near_nullspace=problem.near_nullspace).preconditioner)
    plain = iterations(solver.preconditioner)
    assert updated <= 1.5 * rebuilt + 2 and 2 * updated < plain, (updated, rebuilt, plain)


def test_the_single_precision_cycle_is_the_double_one_to_its_rounding():
    """The cycle of the 3D Newton steps runs in float32 (vemkit.solvers.ssn_steps.CYCLE_PRECISION):
    the same operator to ~1e-6 and the same CG iterations; CG itself, in double, reaches 1e-10."""
    import scipy.sparse.linalg as spla

    problem = _box_problem(10)
    cb, n, K = problem.contact, problem.n_dofs, problem.stiffness
    hierarchy = linear_solver(K, "amg", near_nullspace=problem.near_nullspace).hierarchy
    D = rank_one_blocks(cb, np.full(cb.size, 1e3 * K.diagonal().max()), cb.tangent, n)
    cycles = [
        BoundaryUpdatedHierarchy(hierarchy, nodal=True, precision=precision).preconditioner(D)
        for precision in (np.float64, np.float32)
    ]
    b = (K + D) @ np.random.default_rng(4).normal(size=n)
    double, single = (M @ b for M in cycles)
    assert single.dtype == np.float64
    assert 1e-9 < np.max(np.abs(single - double)) / np.max(np.abs(double)) < 1e-5
    counts = [0, 0]
    for index, M in enumerate(cycles):

        def counted(_, index=index):
            counts[index] += 1

        x, info = spla.cg(K + D, b, rtol=1e-10, M=M, callback=counted)
        assert info == 0 and np.linalg.norm((K + D) @ x - b) <= 1e-10 * np.linalg.norm(b)
    assert abs(counts[0] - counts[1]) <= 1, counts


@pytest.mark.parametrize("precision", [np.float64, np.float32])
def test_the_block_transfers_are_p_and_its_transpose(precision):
    from vemkit.solvers.amg_update import BlockTransfer

    rng = np.random.default_rng(8)
    P = sp.random(60, 48, density=0.2, format="csr", random_state=8, dtype=precision)
    transfer = BlockTransfer(P.tobsr(blocksize=(3, 6)))
    coarse, fine = rng.normal(size=48).astype(precision), rng.normal(size=60).astype(precision)
    rounding = 1e-12 if precision == np.float64 else 1e-5
    for ours, theirs in ((transfer @ coarse, P @ coarse), (transfer.T @ fine, P.T @ fine)):
        assert ours.dtype == precision and ours.shape == theirs.shape
        assert np.max(np.abs(ours - theirs)) <= rounding * np.max(np.abs(theirs))


def test_the_nodal_finest_level_is_k_plus_d_in_blocks_widened_where_d_leaves_them():
    """nodal: the finest level is 3 x 3 BSR; a D coupling vertices that share no cell widens its
    blocks, and the next D (back in the pattern) leaves K's values where the last one was."""
    problem = _box_problem(12)
    K, n = problem.stiffness.tocsr(), problem.n_dofs
    hierarchy = linear_solver(K, "amg", near_nullspace=problem.near_nullspace).hierarchy
    assert len(hierarchy.levels) >= 2
    updated = BoundaryUpdatedHierarchy(hierarchy, nodal=True)
    far = sp.csr_matrix(([5.0, 5.0], ([0, n - 1], [n - 1, 0])), shape=(n, n))  # corner to corner
    near = _summed(rank_one_blocks(problem.contact, np.ones(problem.contact.size), problem.contact.normal, n))
    for D in (_summed(far), near):
        updated.preconditioner(D)
        finest = updated.operators[0].current
        assert finest.format == "bsr" and finest.blocksize == (3, 3)
        expected = (K + D).toarray()
        assert np.max(np.abs(finest.toarray() - expected)) <= 1e-6 * np.max(np.abs(expected))
