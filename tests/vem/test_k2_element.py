"""The k = 2 virtual element pinned by mathematics: twin implementations, the kernel's null space,
exact quadratic consistency, and the k = 2 patch test on whole meshes of every family."""

import numpy as np
import pytest
import scipy.sparse.linalg as spla
from conftest import FAMILY_CASES, POLYGONS, family_mesh, nonconvex_mesh

from vemkit.vem.assembly import dirichlet_lift
from vemkit.vem.elasticity import lame_parameters
from vemkit.vem.elements import STABILIZATIONS
from vemkit.vem.elements.k2_fields import body_force_k2, traction_load_k2
from vemkit.vem.elements.k2_reference import element_stiffness_k2_reference, field_dofs
from vemkit.vem.elements.k2_stiffness import element_stiffness_k2_matrix
from vemkit.vem.space import VirtualElementSpace

LAM, MU = lame_parameters(2000.0, 0.4)
SHAPES = dict(POLYGONS, voronoi_like=[[0, 0], [1.1, -0.2], [1.9, 0.4], [2.0, 1.3], [1.2, 2.0], [0.1, 1.6], [-0.4, 0.8]])
SIDES = ("left", "right", "bottom", "top")
# a quadratic displacement (coefficients of 1, x, y, x^2, xy, y^2 for u1 and u2)
QUADRATIC = np.array([[0.1, -0.3, 0.2, 0.5, -0.4, 0.3], [0.2, 0.1, -0.5, -0.2, 0.6, 0.1]])


def quadratic(x, y, A=QUADRATIC):
    x, y = np.asarray(x, float), np.asarray(y, float)
    mono = [np.ones_like(x), x, y, x * x, x * y, y * y]
    return sum(A[0, i] * mono[i] for i in range(6)), sum(A[1, i] * mono[i] for i in range(6))


def quadratic_stacked(A):
    return lambda x, y: np.stack(quadratic(x, y, A), axis=-1)


def quadratic_stress(x, y, A=QUADRATIC):
    """sigma (s11, s22, s12) of the quadratic field at (x, y) (docs/reference/mathematics.md)."""
    a, b = A
    u1x, u1y = a[1] + 2 * a[3] * x + a[4] * y, a[2] + a[4] * x + 2 * a[5] * y
    u2x, u2y = b[1] + 2 * b[3] * x + b[4] * y, b[2] + b[4] * x + 2 * b[5] * y
    tr = u1x + u2y
    return LAM * tr + 2 * MU * u1x, LAM * tr + 2 * MU * u2y, MU * (u1y + u2x)


def quadratic_body_force(A=QUADRATIC):
    """-div sigma(u) = -((lam + mu) grad div u + mu Laplacian u): constant for quadratic u."""
    a, b = A
    grad_div = np.array([2 * a[3] + b[4], a[4] + 2 * b[5]])
    laplacian = np.array([2 * a[3] + 2 * a[5], 2 * b[3] + 2 * b[5]])
    return -((LAM + MU) * grad_div + MU * laplacian)


def clamped_sides(space, sides):
    """The k = 2 numbering with the named boundary parts clamped (as ``dirichlet: [side]``)."""
    return space.numbering(space.clamped_on(np.concatenate([space.mesh.boundary[s] for s in sides])))


def shape(name):
    return np.array(SHAPES[name], float) * 0.37 + [0.2, -0.1]


@pytest.mark.parametrize("name", SHAPES)
@pytest.mark.parametrize("stab", STABILIZATIONS)
def test_numba_kernel_equals_numpy_twin(name, stab):
    coords = shape(name)
    K_ref, _, _ = element_stiffness_k2_reference(coords, LAM, MU, stab)
    K = element_stiffness_k2_matrix(coords, LAM, MU, stab)
    assert np.abs(K - K_ref).max() <= 1e-12 * np.abs(K_ref).max()


@pytest.mark.parametrize("name", SHAPES)
@pytest.mark.parametrize("stab", STABILIZATIONS)
def test_kernel_null_space_is_exactly_the_rigid_motions(name, stab):
    coords = shape(name)
    K = element_stiffness_k2_matrix(coords, LAM, MU, stab)
    ev = np.linalg.eigvalsh(K)
    assert np.all(np.abs(ev[:3]) < 1e-12 * ev[-1]) and ev[3] > 1e-6 * ev[-1]
    for rigid in (
        np.array([[1.0, 0, 0, 0, 0, 0], [0] * 6]),
        np.array([[0] * 6, [1.0, 0, 0, 0, 0, 0]]),
        np.array([[0, 0, -1.0, 0, 0, 0], [0, 1.0, 0, 0, 0, 0]]),
    ):
        assert np.abs(K @ field_dofs(coords, quadratic_stacked(rigid))).max() < 1e-11 * ev[-1]


@pytest.mark.parametrize("name", SHAPES)
def test_projection_reproduces_quadratic_fields(name):
    coords = shape(name)
    _, Pi_D, _ = element_stiffness_k2_reference(coords, LAM, MU)
    dofs = field_dofs(coords, quadratic_stacked(QUADRATIC))
    assert np.abs(Pi_D @ dofs - dofs).max() < 1e-13


def test_consistency_is_the_exact_energy_of_quadratic_fields():
    """u^T K v = a_K(u, v) for quadratic u, v; a_K integrated by hand on the unit square."""
    coords = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    other = np.array([[0.0, 0.2, -0.1, 0.0, 0.7, -0.3], [0.4, 0.0, 0.3, -0.6, 0.1, 0.2]])
    K = element_stiffness_k2_matrix(coords, LAM, MU, "trace")
    u, v = (field_dofs(coords, quadratic_stacked(A)) for A in (QUADRATIC, other))
    # tensor-product Gauss rule with 3 points per direction: exact for the quadratic integrand
    t, w = np.polynomial.legendre.leggauss(3)
    X, Y = np.meshgrid(0.5 * (t + 1), 0.5 * (t + 1))
    W = np.outer(0.5 * w, 0.5 * w)
    s11, s22, s12 = quadratic_stress(X, Y)
    b = other[1]
    a = other[0]
    e11, e22 = a[1] + 2 * a[3] * X + a[4] * Y, b[2] + b[4] * X + 2 * b[5] * Y
    e12 = 0.5 * (a[2] + a[4] * X + 2 * a[5] * Y + b[1] + 2 * b[3] * X + b[4] * Y)
    exact = np.sum(W * (s11 * e11 + s22 * e22 + 2 * s12 * e12))
    assert u @ K @ v == pytest.approx(exact, rel=1e-12)


def patch_mesh(case):
    return nonconvex_mesh() if case == "nonconvex" else family_mesh(case, 5)


@pytest.mark.parametrize("case", list(FAMILY_CASES) + ["nonconvex"])
@pytest.mark.parametrize("stab", STABILIZATIONS)
def test_patch_test_quadratic_displacement_is_reproduced(case, stab):
    """Dirichlet data of a quadratic u on the whole boundary, body force -div sigma(u) (constant):
    the discrete solution is the interpolant of u, every degree of freedom to round-off."""
    mesh = patch_mesh(case)
    space = VirtualElementSpace(mesh, 2)
    nodes = clamped_sides(space, SIDES)
    exact = space.interpolate(quadratic)
    f = quadratic_body_force()
    load = nodes.restrict(body_force_k2(mesh, lambda x, y: (f[0] + 0 * x, f[1] + 0 * x)))
    load += dirichlet_lift(space, LAM, MU, stab, nodes, exact)
    K = space.stiffness_matrix(LAM, MU, stab, nodes)
    u = nodes.node_values(spla.spsolve(K.tocsc(), load), exact)
    assert np.abs(u - exact).max() < 1e-10 * np.abs(exact).max()


@pytest.mark.parametrize("case", list(FAMILY_CASES) + ["nonconvex"])
def test_stiffness_times_quadratic_is_its_load(case):
    """K u_I = <f, phi> + int_dOmega (sigma n) . phi for quadratic u, no Dirichlet part (tractions
    integrated on the quadratic traces): the consistency (3.6) on a whole mesh."""
    mesh = patch_mesh(case)
    space = VirtualElementSpace(mesh, 2)
    K = space.stiffness_matrix(LAM, MU, "dofi-2mu", space.numbering(natural=True))
    f = quadratic_body_force()
    load = body_force_k2(mesh, lambda x, y: (f[0] + 0 * x, f[1] + 0 * x))
    normals = {"left": (-1, 0), "right": (1, 0), "bottom": (0, -1), "top": (0, 1)}
    for side, (n1, n2) in normals.items():

        def traction(x, y, n1=n1, n2=n2):
            s11, s22, s12 = quadratic_stress(x, y)
            return s11 * n1 + s12 * n2, s12 * n1 + s22 * n2

        load += traction_load_k2(mesh, mesh.boundary[side], traction)
    u = space.interpolate(quadratic).ravel()
    assert np.abs(K @ u - load.ravel()).max() < 1e-10 * np.abs(load).max()


def test_eliminated_assembly_is_the_restriction_of_the_full_matrix():
    mesh = family_mesh("hanging-random", 4)
    space = VirtualElementSpace(mesh, 2)
    nodes = clamped_sides(space, ["right", "bottom"])
    full = space.stiffness_matrix(LAM, MU, "trace", space.numbering(natural=True)).toarray()
    free = (2 * nodes.free_nodes[:, None] + np.arange(2)).ravel()
    reduced = space.stiffness_matrix(LAM, MU, "trace", nodes).toarray()
    assert np.abs(reduced - full[np.ix_(free, free)]).max() <= 1e-12 * np.abs(full).max()
    values = space.interpolate(quadratic)
    clamped = (2 * nodes.clamped_nodes[:, None] + np.arange(2)).ravel()
    expected = -full[np.ix_(free, clamped)] @ values.ravel()[clamped]
    assert np.allclose(
        dirichlet_lift(space, LAM, MU, "trace", nodes, values), expected, rtol=0, atol=1e-10 * np.abs(expected).max()
    )


@pytest.mark.parametrize("case", ["triangle-delaunay", "voronoi", "nonconvex"])
def test_body_force_loads_integrate_exactly_against_quadratics(case):
    """<f_h, v> for quadratic v: the P_1 load is int f . v for linear f; the paper's P_0 load is
    int P_0 f . v (equal to int f . v for constant f only)."""
    from vemkit.vem.elements.k2_fields import body_force_p1_k2
    from vemkit.vem.quadrature import reference_quadrature

    mesh = patch_mesh(case)
    v = VirtualElementSpace(mesh, 2).interpolate(quadratic).ravel()
    points, weights, _ = reference_quadrature(mesh, degree=5)

    def linear(x, y):
        return 1.0 + 2.0 * x - 3.0 * y, -0.5 + x + 4.0 * y

    exact = np.sum(weights * sum(a * b for a, b in zip(linear(*points.T), quadratic(*points.T))))
    assert body_force_p1_k2(mesh, linear, LAM, MU).ravel() @ v == pytest.approx(exact, rel=1e-12)
    constant = lambda x, y: (0.7 + 0 * x, -1.3 + 0 * x)  # noqa: E731
    exact_constant = np.sum(weights * sum(a * b for a, b in zip(constant(*points.T), quadratic(*points.T))))
    assert body_force_k2(mesh, constant).ravel() @ v == pytest.approx(exact_constant, rel=1e-12)
    assert body_force_k2(mesh, linear).ravel() @ v != pytest.approx(exact, rel=1e-6)


def test_basis_moments_are_the_sums_of_the_basis_fields_against_the_weights():
    """The written-out moments of body_force_p1_k2 are sum_p q_b(xi_p, eta_p) . wg_p per cell for
    the 12 fields of the kernel's basis (_basis_at), on random points in 5 cells."""
    from vemkit.vem.elements.k2_fields import _basis_at, basis_moments, cell_sums

    rng = np.random.default_rng(7)
    xi, eta, wg = rng.uniform(-1, 1, 40), rng.uniform(-1, 1, 40), rng.normal(size=(40, 2))
    cells = rng.integers(0, 5, 40)
    expected = np.zeros((5, 12))
    np.add.at(expected, cells, np.einsum("pbc,pc->pb", _basis_at(xi, eta), wg))
    assert np.allclose(basis_moments(xi, eta, wg, cells, 5), expected, rtol=0, atol=1e-14)
    blocks = rng.normal(size=(40, 3, 2))
    summed = np.zeros((5, 3, 2))
    np.add.at(summed, cells, blocks)
    assert np.allclose(cell_sums(cells, blocks, 5), summed, rtol=0, atol=1e-14)


@pytest.mark.parametrize("case", ["triangle-delaunay", "voronoi", "nonconvex"])
def test_the_load_kernels_sum_what_the_numpy_twin_sums_bit_for_bit(case):
    """k2_load_kernel's two point loops give the numpy twin's (cell_sums, basis_moments) mass
    matrices and moments exactly: the same products, summed in the same order."""
    from vemkit.vem.elements.k2_fields import basis_moments, cell_frames, cell_sums
    from vemkit.vem.elements.k2_load_kernel import p1_basis_moments, scaled_points_and_p1_sums
    from vemkit.vem.quadrature import reference_quadrature

    mesh = patch_mesh(case)
    frame = cell_frames(mesh)
    points, weights, cells = reference_quadrature(mesh, degree=5)
    f = np.stack([np.sin(3 * points[:, 0] + 2 * points[:, 1]), np.exp(points[:, 0]) * points[:, 1]], axis=1)
    xi, eta = np.empty(len(points)), np.empty(len(points))
    mass, moments_f = np.zeros((mesh.n_cells, 3, 3)), np.zeros((mesh.n_cells, 3, 2))
    scaled_points_and_p1_sums(points, weights, cells, frame, f, xi, eta, mass, moments_f)
    assert np.array_equal(xi, (points[:, 0] - frame[cells, 0]) / frame[cells, 2])
    assert np.array_equal(eta, (points[:, 1] - frame[cells, 1]) / frame[cells, 2])
    mono = np.stack([np.ones_like(xi), xi, eta], axis=1)
    twin = cell_sums(cells, weights[:, None, None] * mono[:, :, None] * mono[:, None, :], mesh.n_cells)
    assert np.array_equal(mass, twin)
    assert np.array_equal(
        moments_f, cell_sums(cells, weights[:, None, None] * mono[:, :, None] * f[:, None, :], mesh.n_cells)
    )
    p1 = np.linalg.solve(mass, moments_f)
    moments = np.zeros((mesh.n_cells, 12))
    p1_basis_moments(xi, eta, weights, cells, p1, moments)
    g = xi[:, None] * p1[cells, 1] + eta[:, None] * p1[cells, 2]
    assert np.array_equal(moments, basis_moments(xi, eta, weights[:, None] * g, cells, mesh.n_cells))


@pytest.mark.parametrize("case", list(FAMILY_CASES) + ["nonconvex"])
def test_global_null_space_is_the_three_rigid_motions(case):
    """With no Dirichlet part the assembled k = 2 matrix is singular exactly on the rigid motions."""
    mesh = family_mesh(case, 3) if case != "nonconvex" else nonconvex_mesh()
    space = VirtualElementSpace(mesh, 2)
    K = space.stiffness_matrix(LAM, MU, "dofi-2mu", space.numbering(natural=True)).toarray()
    ev = np.linalg.eigvalsh(K)
    assert np.all(np.abs(ev[:3]) < 1e-11 * ev[-1]) and ev[3] > 1e-8 * ev[-1]
    rotation = space.interpolate(lambda x, y: (-y, x)).ravel()
    assert np.abs(K @ rotation).max() < 1e-11 * ev[-1]


@pytest.mark.parametrize("stab", STABILIZATIONS)
def test_element_matrix_is_invariant_under_scaling_and_translation(stab):
    """In 2D a_K is scale invariant; with the moments scaled as means every dof is a displacement,
    so the dofi-dofi stabilization is too (raw moments would scale it by |e|^2 and |K|^2)."""
    coords = np.array(SHAPES["voronoi_like"], float)
    K = element_stiffness_k2_matrix(coords, LAM, MU, stab)
    for scale, shift in ((1e-3, (5.0, -2.0)), (1e3, (-7e3, 1e4))):
        moved = element_stiffness_k2_matrix(coords * scale + shift, LAM, MU, stab)
        assert np.abs(moved - K).max() < 1e-11 * np.abs(K).max()
