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
