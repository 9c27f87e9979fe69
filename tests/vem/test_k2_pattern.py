"""The k = 2 sparsity pattern (``vemkit.vem.pattern``) pinned by an independent construction: the
free nodes r, c are coupled exactly when some cell holds both, i.e. (B B^T)[r, c] != 0 for the
node-cell incidence B, each coupling a full 2 x 2 block of scalar dofs."""

import numpy as np
import pytest
import scipy.sparse as sp
from conftest import family_mesh

from vemkit.vem.dofs import DofMap
from vemkit.vem.elasticity import lame_parameters
from vemkit.vem.elements.k2_fields import cell_nodes
from vemkit.vem.pattern import dof_pattern, node_cells
from vemkit.vem.space import VirtualElementSpace


def incidence_pattern(mesh, nodes: DofMap) -> sp.csr_matrix:
    """Scalar-dof pattern from B B^T, rows and columns in the free-dof order of ``nodes``."""
    offsets, cn = cell_nodes(mesh)
    cells = np.repeat(np.arange(mesh.n_cells), np.diff(offsets))
    B = sp.csr_matrix((np.ones(cn.size), (cn, cells)), shape=(nodes.n_nodes, mesh.n_cells))
    B = B[nodes.free_nodes]
    coupled = (B @ B.T).tocsr()
    coupled.data[:] = 1.0
    blocks = sp.kron(coupled, np.ones((2, 2)), format="csr")
    blocks.sort_indices()
    return blocks


@pytest.mark.parametrize("case", ["square", "voronoi", "hanging-random", "triangle-delaunay"])
@pytest.mark.parametrize("clamping", ["none", "sides", "condensed"])
def test_pattern_is_the_cell_incidence_product(case, clamping):
    mesh = family_mesh(case, 5)
    space = VirtualElementSpace(mesh, 2)
    if clamping == "none":
        nodes = space.numbering()
    else:
        clamped = space.clamped_on(np.concatenate([mesh.boundary[s] for s in ["left", "bottom"]]))
        nodes = space.numbering(clamped, condensed=clamping == "condensed")
    offsets, cn = cell_nodes(mesh)
    nc_ptr, nc = node_cells(offsets, cn, nodes.n_nodes)
    indptr, indices = dof_pattern(offsets, cn, nc_ptr, nc, nodes.free_nodes, nodes.free_index)
    expected = incidence_pattern(mesh, nodes)
    assert np.array_equal(indptr, expected.indptr) and np.array_equal(indices, expected.indices)
    lam, mu = lame_parameters(2000.0, 0.4)
    A = space.stiffness_matrix(lam, mu, "dofi-2mu", nodes)  # assembled on that pattern, sorted
    assert A.has_sorted_indices and np.array_equal(A.indices, expected.indices)
