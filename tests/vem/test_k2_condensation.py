"""Static condensation of the k = 2 cell means (vemkit.vem.condensation) against the full system.

The Schur complement assembled cell by cell, the condensed load and the recovered cell means must
give the solution of the full k = 2 system, to round-off, on meshes with polygons, hanging nodes and
a non-polynomial body force; the element-level kernel is pinned against a dense Schur complement.
"""

import numpy as np
import pytest
import scipy.sparse.linalg as spla
from conftest import family_mesh

from vemkit.vem.assembly import condense_interior
from vemkit.vem.condensation import condense_load, interior_load, recover_interior
from vemkit.vem.elasticity import lame_parameters
from vemkit.vem.elements.k2_fields import body_force_k2, traction_load_k2
from vemkit.vem.elements.k2_reference import element_stiffness_k2_reference
from vemkit.vem.space import VirtualElementSpace

LAM, MU = lame_parameters(2000.0, 0.4)


def _force(x, y):
    return 1e3 * np.sin(3 * x) * np.cos(2 * y), 1e3 * np.exp(x * y)


@pytest.mark.parametrize("case", ["voronoi", "hanging-random"])
def test_condensed_solution_is_the_full_solution(case):
    mesh = family_mesh(case, 5)
    space = VirtualElementSpace(mesh, 2)
    load = body_force_k2(mesh, _force) + traction_load_k2(
        mesh, mesh.boundary["left"], lambda x, y: (0 * x + 50, 20 * y)
    )
    full = space.numbering(space.clamped_on(mesh.boundary["right"]))
    u_full = full.node_values(
        spla.spsolve(space.stiffness_matrix(LAM, MU, "dofi-2mu", full).tocsc(), full.restrict(load))
    )
    clamped = np.zeros(full.n_nodes, dtype=bool)
    clamped[full.clamped_nodes] = True
    nodes = space.numbering(clamped, condensed=True)
    assert nodes.n_free == full.n_free - 2 * mesh.n_cells
    K = space.stiffness_matrix(LAM, MU, "dofi-2mu", nodes)
    u_b = spla.spsolve(K.tocsc(), condense_load(space, LAM, MU, "dofi-2mu", nodes, load))
    u = recover_interior(space, LAM, MU, "dofi-2mu", nodes.node_values(u_b), interior_load(space, load))
    np.testing.assert_allclose(u, u_full, rtol=0, atol=1e-11 * np.abs(u_full).max())


def test_the_condensation_kernel_is_the_dense_schur_complement():
    px, py = np.array([0.0, 2.0, 2.5, 1.0, -0.3]), np.array([0.0, 0.1, 1.3, 2.0, 1.0])
    K = element_stiffness_k2_reference(np.stack([px, py], axis=1), LAM, MU, "trace")[0]
    m = K.shape[0]
    b, c = slice(0, m - 2), slice(m - 2, m)
    expected = K[b, b] - K[b, c] @ np.linalg.solve(K[c, c], K[c, b])
    work = K.copy()
    condense_interior(work, 2 * px.size + 1)
    np.testing.assert_allclose(work[b, b], expected, rtol=0, atol=1e-12 * np.abs(K).max())


def test_a_repeated_recovery_is_a_copy_and_any_changed_input_recovers_anew():
    """recover_interior remembers the space's last recovery: the same inputs give an equal, separate
    array (changing it changes nothing remembered); other node values, loads or material recover anew."""
    from vemkit.vem import condensation

    mesh = family_mesh("voronoi", 4)
    space = VirtualElementSpace(mesh, 2)
    rng = np.random.default_rng(3)
    values = rng.normal(size=(space.n_nodes, 2))
    loads = rng.normal(size=(mesh.n_cells, 2))
    first = recover_interior(space, LAM, MU, "dofi-2mu", values, loads)
    assert condensation._LAST_RECOVERY.get(space) is not None
    first_copy = first.copy()
    first[:] = 0.0  # the caller owns its array
    again = recover_interior(space, LAM, MU, "dofi-2mu", values, loads)
    assert np.array_equal(again, first_copy) and again is not first
    condensation._LAST_RECOVERY.clear()
    assert np.array_equal(recover_interior(space, LAM, MU, "dofi-2mu", values, loads), first_copy)
    changed_values, changed_loads = values.copy(), loads.copy()
    changed_values[0, 0] += 1.0  # a vertex value: the cell means of its cells change
    changed_loads[0, 1] += 1.0
    for args in [
        (LAM, MU, "dofi-2mu", changed_values, loads),
        (LAM, MU, "dofi-2mu", values, changed_loads),
        (LAM, 2 * MU, "dofi-2mu", values, loads),
        (LAM, MU, "trace", values, loads),
    ]:
        condensation._LAST_RECOVERY.clear()
        fresh = recover_interior(space, *args)
        recover_interior(space, LAM, MU, "dofi-2mu", values, loads)  # remembered: the unchanged inputs
        assert np.array_equal(recover_interior(space, *args), fresh)
        assert not np.array_equal(fresh, first_copy)
