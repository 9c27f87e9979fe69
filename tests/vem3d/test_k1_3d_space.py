"""The 3D element in the one space: on tetrahedra the stiffness is that of P1 finite elements
(scikit-fem), the global matrix is symmetric with exactly the six rigid motions in its kernel, and
a linear displacement prescribed on the whole boundary is the discrete solution (patch test) on
hexahedra, tetrahedra, non-convex polyhedra and cells with hanging nodes."""

import numpy as np
import pytest
import scipy.sparse.linalg as spla
from polyhedra3d import boundary_vertices, hanging_mesh, hex_grid, l_stack, mapped, random_affine, tet_grid

from vemkit.vem.elasticity import rigid_body_modes
from vemkit.vem.space import VirtualElementSpace

LAM, MU = 1.7, 0.6


def test_tetrahedra_give_p1_finite_elements():
    skfem = pytest.importorskip("skfem")
    from skfem.models.elasticity import linear_elasticity

    mesh, tets = tet_grid(2)
    mesh = mapped(mesh, *random_affine(np.random.default_rng(3)))
    space = VirtualElementSpace(mesh, 1)
    assert space.element.dimension == 3 and space.n_dofs == 3 * mesh.n_vertices
    basis = skfem.Basis(skfem.MeshTet(mesh.vertices.T.copy(), tets.T.copy()), skfem.ElementVector(skfem.ElementTetP1()))
    K_fem = linear_elasticity(LAM, MU).assemble(basis)
    order = basis.nodal_dofs.T.ravel()  # VEM dof 3 i + k is the finite element dof nodal_dofs[k, i]
    K_fem = K_fem[order][:, order].toarray()
    for stabilization in ("dofi", "dofi-2mu", "trace"):  # Pi = I on tetrahedra: S_K vanishes
        K = space.stiffness_matrix(LAM, MU, stabilization).toarray()
        assert np.abs(K - K_fem).max() < 1e-13 * np.abs(K_fem).max()


def test_global_matrix_symmetric_with_the_six_rigid_motions_as_kernel():
    mesh = hex_grid(2)
    space = VirtualElementSpace(mesh, 1)
    K = space.stiffness_matrix(LAM, MU, "dofi-2mu")
    assert K.shape == (3 * mesh.n_vertices,) * 2
    dense = K.toarray()
    assert np.abs(dense - dense.T).max() < 1e-14 * np.abs(dense).max()
    modes = rigid_body_modes(space.node_coordinates)
    assert np.abs(K @ modes).max() < 1e-13 * np.abs(dense).max()
    s = np.linalg.eigvalsh(dense)
    assert np.all(s[:6] < 1e-12 * s[-1]) and s[6] > 1e-6 * s[-1]  # nothing else is free


def linear_field(seed):
    rng = np.random.default_rng(seed)
    G, c = rng.standard_normal((3, 3)), rng.standard_normal(3)
    return lambda x, y, z: tuple(G @ np.stack(np.broadcast_arrays(x, y, z)) + c[:, None])


MESHES = {
    "hex": lambda: hex_grid(3),
    "tet": lambda: tet_grid(3)[0],
    "non-convex": lambda: mapped(l_stack(3), *random_affine(np.random.default_rng(1))),
    "hanging": hanging_mesh,
    "hanging-mapped": lambda: mapped(hanging_mesh(), *random_affine(np.random.default_rng(2))),
}


@pytest.mark.parametrize("name", sorted(MESHES))
@pytest.mark.parametrize("stabilization", ["dofi", "trace"])
def test_patch_test_linear_displacement_on_the_whole_boundary(name, stabilization):
    mesh = MESHES[name]()
    space = VirtualElementSpace(mesh, 1)
    exact = space.interpolate(linear_field(7))
    clamped = np.zeros(space.n_nodes, dtype=bool)
    clamped[boundary_vertices(mesh)] = True
    assert not clamped.all()
    dofs = space.numbering(clamped)
    K = space.stiffness_matrix(LAM, MU, stabilization, dofs)
    from vemkit.vem.assembly import dirichlet_lift

    load = dirichlet_lift(space, LAM, MU, stabilization, dofs, exact)
    u = dofs.node_values(spla.spsolve(K.tocsc(), load), clamped_values=np.where(clamped[:, None], exact, 0.0))
    assert np.abs(u - exact).max() < 1e-12 * np.abs(exact).max()


def test_constrained_dofs_with_fixed_components():
    """Dirichlet data as fixed dofs of kept nodes (constrain): the linear field again."""
    mesh = hanging_mesh()
    space = VirtualElementSpace(mesh, 1)
    field = linear_field(11)
    sides = {side: tuple((lambda k: lambda x, y, z: field(x, y, z)[k])(k) for k in range(3)) for side in mesh.boundary}
    prescribed, values = space.dirichlet_components(sides)
    dofs = space.constrain(prescribed, values)
    from vemkit.vem.dofs import apply_fixed_dofs

    K, f = apply_fixed_dofs(space.stiffness_matrix(LAM, MU, "dofi-2mu", dofs), np.zeros(dofs.n_free), dofs)
    u = dofs.node_values(spla.spsolve(K.tocsc(), f))
    exact = space.interpolate(field)
    assert np.abs(u - exact).max() < 1e-12 * np.abs(exact).max()


def test_numbering_carries_three_components_per_node():
    """dof = 3 free_index + component; restrict and node_values are inverse on the free nodes."""
    mesh = hanging_mesh()
    space = VirtualElementSpace(mesh, 1)
    clamped = np.zeros(space.n_nodes, dtype=bool)
    clamped[[0, 5]] = True
    dofs = space.numbering(clamped)
    assert dofs.n_free == 3 * (space.n_nodes - 2)
    values = np.random.default_rng(0).standard_normal((space.n_nodes, 3))
    u = dofs.restrict(values)
    node = dofs.free_nodes[4]
    assert np.array_equal(u[3 * dofs.free_index[node] : 3 * dofs.free_index[node] + 3], values[node])
    back = dofs.node_values(u)
    assert np.array_equal(back[~clamped], values[~clamped]) and np.all(back[clamped] == 0)
    assert dofs.expand(u).shape == (mesh.n_vertices, 3)
    prescribed = np.zeros((space.n_nodes, 3), dtype=bool)
    prescribed[3, 1] = True
    fixed = dofs.with_fixed(prescribed, values)
    assert fixed.prescribed_displacement()[3, 1] == values[3, 1] and not fixed.unconstrained_nodes()[3]


def test_clamping_a_side_clamps_the_vertices_of_its_faces():
    mesh = hanging_mesh()
    space = VirtualElementSpace(mesh, 1)
    mask = space.clamped_on(mesh.boundary["right"])
    assert np.array_equal(np.flatnonzero(mask), np.flatnonzero(np.abs(mesh.vertices[:, 0] - 2.0) < 1e-12))
