"""The k = 1 VEM pinned by mathematics: twin implementations, kernel, patch tests, P1 equality, rates."""

import numpy as np
import pytest
import scipy.sparse as sp
from conftest import FAMILY_CASES, POLYGONS, family_mesh, nonconvex_mesh

from vemkit.contact.problem import discrete_problem
from vemkit.solvers.linear import linear_solver
from vemkit.vem.elasticity import lame_parameters
from vemkit.vem.elements import STABILIZATIONS
from vemkit.vem.elements.k1_fields import projected_solution
from vemkit.vem.elements.k1_kernel import element_stiffness
from vemkit.vem.elements.k1_reference import element_stiffness_reference
from vemkit.vem.norms import exact_errors
from vemkit.vem.projection import shear_energy_density, stress
from vemkit.vem.space import VirtualElementSpace

LAM, MU = lame_parameters(2000.0, 0.4)


def kernel(coords, stab):
    n = len(coords)
    m = 2 * n
    K, B, P, R = np.zeros((m, m)), np.zeros((3, m)), np.zeros((6, m)), np.zeros((m, m))
    c = np.asarray(coords, float)
    element_stiffness(c[:, 0].copy(), c[:, 1].copy(), LAM, MU, STABILIZATIONS.index(stab), K, B, P, R)
    return K


def rigid_modes(coords):
    c = np.asarray(coords, float)
    n = len(c)
    Z = np.zeros((2 * n, 3))
    Z[0::2, 0] = 1
    Z[1::2, 1] = 1
    Z[0::2, 2] = -c[:, 1]
    Z[1::2, 2] = c[:, 0]
    return Z


@pytest.mark.parametrize("name", POLYGONS)
@pytest.mark.parametrize("stab", STABILIZATIONS)
def test_numba_kernel_equals_numpy_twin(name, stab):
    coords = np.array(POLYGONS[name], float) * 0.37 + [0.2, -0.1]
    K_ref, _ = element_stiffness_reference(coords, LAM, MU, stab)
    assert np.allclose(kernel(coords, stab), K_ref, rtol=0, atol=1e-12 * np.abs(K_ref).max())


@pytest.mark.parametrize("name", POLYGONS)
@pytest.mark.parametrize("stab", STABILIZATIONS)
def test_kernel_is_exactly_the_rigid_motions(name, stab):
    coords = np.array(POLYGONS[name], float)
    K = kernel(coords, stab)
    assert np.allclose(K, K.T, atol=1e-12 * np.abs(K).max())
    ev = np.linalg.eigvalsh(K)
    scale = ev.max()
    assert np.all(np.abs(ev[:3]) < 1e-12 * scale)
    assert ev[3] > 1e-6 * scale
    assert np.abs(K @ rigid_modes(coords)).max() < 1e-11 * scale


@pytest.mark.parametrize("name", POLYGONS)
def test_projection_reproduces_linear_fields(name):
    coords = np.array(POLYGONS[name], float)
    G = np.array([[0.3, -1.2], [0.7, 0.25]])
    u = (coords @ G.T + [0.5, -2.0]).ravel()
    _, Pi = element_stiffness_reference(coords, LAM, MU)
    assert np.allclose(Pi @ u, u, atol=1e-13)


def test_consistency_matches_exact_energy_of_linear_fields():
    coords = np.array(POLYGONS["nonconvex-arrow"], float)
    area = 2.5  # 2 x 2 square minus the notch triangle (0,2)-(1,0.5)-(2,2) of area 1.5
    for G in (np.array([[1.0, 0.0], [0.0, 0.0]]), np.array([[0.2, 0.5], [-0.1, 0.3]])):
        u = (coords @ G.T).ravel()
        eps = 0.5 * (G + G.T)
        sig = LAM * np.trace(eps) * np.eye(2) + 2 * MU * eps
        assert u @ kernel(coords, "dofi") @ u == pytest.approx(area * np.tensordot(sig, eps), rel=1e-12)


@pytest.mark.parametrize("case", list(FAMILY_CASES) + ["nonconvex"])
@pytest.mark.parametrize("stab", STABILIZATIONS)
def test_patch_test_linear_displacement_is_reproduced(case, stab):
    """The linear field u = (x - 1) c (zero on the clamped right edge), tractions sigma n elsewhere."""
    mesh = nonconvex_mesh() if case == "nonconvex" else family_mesh(case, 6)
    c = np.array([0.02, -0.013])
    grad = np.outer(c, [1.0, 0.0])
    eps = 0.5 * (grad + grad.T)
    sig = LAM * np.trace(eps) * np.eye(2) + 2 * MU * eps
    tractions = {
        "left": lambda x, y: (-sig[0, 0] + 0 * x, -sig[1, 0] + 0 * x),
        "top": lambda x, y: (sig[0, 1] + 0 * x, sig[1, 1] + 0 * x),
        "bottom": lambda x, y: (-sig[0, 1] + 0 * x, -sig[1, 1] + 0 * x),
    }
    pb = discrete_problem(mesh, 2000.0, 0.4, dirichlet=("right",), neumann=tractions, stabilization=stab)
    u = pb.dofs.expand(linear_solver(pb.stiffness, "direct").solve(pb.load))
    exact = (mesh.vertices[:, 0:1] - 1.0) * c[None, :]
    assert np.abs(u - exact).max() < 1e-10 * np.abs(exact).max()


@pytest.mark.parametrize("case", list(FAMILY_CASES) + ["nonconvex"])
def test_stiffness_times_any_linear_field_is_its_boundary_traction(case):
    """K u_I = int_dOmega (sigma n) . phi for every linear u: the patch test with no Dirichlet part."""
    mesh = nonconvex_mesh() if case == "nonconvex" else family_mesh(case, 5)
    G = np.array([[0.3, -1.2], [0.7, 0.25]])
    b = np.array([0.4, -0.9])
    K = VirtualElementSpace(mesh, 1).stiffness_matrix(LAM, MU, "dofi-2mu")
    u = (mesh.vertices @ G.T + b).ravel()
    eps = 0.5 * (G + G.T)
    sig = LAM * np.trace(eps) * np.eye(2) + 2 * MU * eps
    from vemkit.vem.elements.k1_fields import traction_load

    f = np.zeros((mesh.n_vertices, 2))
    normals = {"left": [-1, 0], "right": [1, 0], "bottom": [0, -1], "top": [0, 1]}
    for side, nrm in normals.items():
        t = sig @ np.array(nrm, float)
        f += traction_load(mesh, mesh.boundary[side], lambda x, y, t=t: (t[0] + 0 * x, t[1] + 0 * x))
    assert np.abs(K @ u - f.ravel()).max() < 1e-10 * np.abs(f).max()


@pytest.mark.parametrize("stab", STABILIZATIONS)
def test_triangles_give_exactly_the_p1_fem_matrix(stab):
    skfem = pytest.importorskip("skfem")
    from skfem.models.elasticity import linear_elasticity

    mesh = family_mesh("triangle-delaunay", 10)
    K = VirtualElementSpace(mesh, 1).stiffness_matrix(LAM, MU, stab)
    tri = mesh.cell_vertices.reshape(-1, 3)
    m = skfem.MeshTri(mesh.vertices.T.copy(), tri.T.copy())
    basis = skfem.Basis(m, skfem.ElementVector(skfem.ElementTriP1()))
    A = skfem.asm(linear_elasticity(LAM, MU), basis)
    perm = np.empty(2 * mesh.n_vertices, dtype=np.int64)
    perm[0::2] = basis.nodal_dofs[0]
    perm[1::2] = basis.nodal_dofs[1]
    A = sp.csr_matrix(A)[perm][:, perm]
    assert abs(K - A).max() <= 1e-10 * abs(A).max()


# ---- manufactured smooth solution: observed orders ---------------------------------------------
def exact_u(x, y):
    return (1 - x) * np.exp(y) * 0.01, (1 - x) ** 2 * np.sin(2 * y) * 0.01


def exact_grad(x, y):
    return (
        (-np.exp(y) * 0.01, (1 - x) * np.exp(y) * 0.01),
        (-2 * (1 - x) * np.sin(2 * y) * 0.01, 2 * (1 - x) ** 2 * np.cos(2 * y) * 0.01),
    )


def exact_stress(x, y):
    (a, b), (c, d) = exact_grad(x, y)
    tr = a + d
    return LAM * tr + 2 * MU * a, LAM * tr + 2 * MU * d, MU * (b + c)


def body_force(x, y, step=1e-4):
    """f1 = -div sigma by central differences of the exact stress (error ~1e-8 relative)."""
    s11p, _, s12p = exact_stress(x + step, y)
    s11m, _, s12m = exact_stress(x - step, y)
    _, s22p, s12q = exact_stress(x, y + step)
    _, s22m, s12r = exact_stress(x, y - step)
    return -((s11p - s11m) + (s12q - s12r)) / (2 * step), -((s12p - s12m) + (s22p - s22m)) / (2 * step)


def manufactured_errors(mesh, stab="dofi-2mu"):
    def traction(normal):
        def f(x, y):
            s11, s22, s12 = exact_stress(x, y)
            return s11 * normal[0] + s12 * normal[1], s12 * normal[0] + s22 * normal[1]

        return f

    pb = discrete_problem(
        mesh,
        2000.0,
        0.4,
        dirichlet=("right",),
        neumann={"left": traction((-1, 0)), "top": traction((0, 1)), "bottom": traction((0, -1))},
        body_force=body_force,
        stabilization=stab,
    )
    u = pb.dofs.expand(linear_solver(pb.stiffness, "direct").solve(pb.load))
    return exact_errors(mesh, projected_solution(mesh, u), exact_u, exact_grad)


@pytest.mark.parametrize("case", FAMILY_CASES)
def test_manufactured_solution_converges_at_optimal_rates(case):
    ns = [4, 8, 16, 32, 64]
    meshes = [family_mesh(case, n) for n in ns]
    errs = [manufactured_errors(m) for m in meshes]
    h = np.array([1.0 / np.sqrt(m.n_cells) for m in meshes])
    h1 = np.array([e["h1_semi"] for e in errs])
    l2 = np.array([e["l2"] for e in errs])
    rate_h1 = np.polyfit(np.log(h[1:]), np.log(h1[1:]), 1)[0]
    rate_l2 = np.polyfit(np.log(h[1:]), np.log(l2[1:]), 1)[0]
    assert rate_h1 >= 0.95, (case, h1, rate_h1)
    assert rate_l2 >= 1.9, (case, l2, rate_l2)


def test_shear_energy_density_formula():
    # pure shear: sigma11 = sigma22 = 0 -> |dev sigma|^2 = 2 s12^2
    sig = np.array([[0.0, 0.0, 3.0]])
    assert shear_energy_density(sig, LAM, MU)[0] == pytest.approx(2 * 9 / (4 * MU))
    strain = np.array([[1e-3, -2e-3, 5e-4]])
    s = stress(strain, LAM, MU)
    assert s[0, 2] == pytest.approx(2 * MU * 5e-4)
    assert s[0, 0] == pytest.approx(LAM * -1e-3 + 2 * MU * 1e-3)
