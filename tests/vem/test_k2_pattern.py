"""The k = 2 sparsity pattern (``vemkit.vem.pattern_k2``) pinned by an independent construction: the
free nodes r, c are coupled exactly when some cell holds both, i.e. (B B^T)[r, c] != 0 for the
node-cell incidence B, each coupling a full 2 x 2 block of scalar dofs."""

import numpy as np
import pytest
import scipy.sparse as sp

from conftest import family_mesh
from vemkit.vem.assembly import vertex_cells
from vemkit.vem.assembly_k2 import NodeMapK2, cell_nodes, stiffness_matrix_k2
from vemkit.vem.elasticity import lame_parameters
from vemkit.vem.pattern_k2 import dof_pattern_k2


def incidence_pattern(mesh, nodes: NodeMapK2) -> sp.csr_matrix:
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
    if clamping == "none":
        nodes = NodeMapK2.from_clamped_edges(mesh)
    else:
        clamped = np.zeros(NodeMapK2.natural(mesh).n_nodes, dtype=bool)
        clamped[NodeMapK2.from_sides(mesh, ["left", "bottom"]).clamped_nodes] = True
        nodes = NodeMapK2.from_clamped_nodes(mesh, clamped, condensed=clamping == "condensed")
    offsets, cn = cell_nodes(mesh)
    nc_ptr, nc = vertex_cells(offsets, cn, nodes.n_nodes)
    indptr, indices = dof_pattern_k2(offsets, cn, nc_ptr, nc, nodes.free_nodes, nodes.free_index)
    expected = incidence_pattern(mesh, nodes)
    assert np.array_equal(indptr, expected.indptr) and np.array_equal(indices, expected.indices)
    lam, mu = lame_parameters(2000.0, 0.4)
    A = stiffness_matrix_k2(mesh, lam, mu, "dofi-2mu", nodes)  # assembled on that pattern, sorted
    assert A.has_sorted_indices and np.array_equal(A.indices, expected.indices)
