"""The 3D element's loads (Section 3.3): the body force int_K P_0 f . Pi v dx, the tractions
int_F g . v ds; with them a linear displacement is the discrete solution of a mixed problem
(Dirichlet on one side, its tractions on the others: the patch test with Neumann data)."""

import numpy as np
import pytest
import scipy.sparse.linalg as spla
from polyhedra3d import hanging_mesh, hex_grid, l_stack, mapped, random_affine

from vemkit.vem.dofs import apply_fixed_dofs
from vemkit.vem.space import VirtualElementSpace

LAM, MU = 1.3, 0.9


def linear(rng):
    G, c = rng.standard_normal((3, 3)), rng.standard_normal(3)
    return G, c, (lambda x, y, z: tuple(G @ np.stack(np.broadcast_arrays(x, y, z)) + c[:, None]))


@pytest.mark.parametrize("make", [lambda: hex_grid(2), hanging_mesh])
def test_body_force_is_the_cell_mean_against_pi_v(make):
    """For linear f, P_0 f = f(x_K) and int_K P_0 f . Pi v = |K| f(x_K) . v(x_K) for linear v."""
    rng = np.random.default_rng(4)
    base = make()
    offsets, ids = base.cell_vertex_lists
    box_centres = np.array(
        [
            0.5
            * (
                base.vertices[ids[offsets[c] : offsets[c + 1]]].min(axis=0)
                + base.vertices[ids[offsets[c] : offsets[c + 1]]].max(axis=0)
            )
            for c in range(base.n_cells)
        ]
    )
    A, b = random_affine(rng)
    mesh = mapped(base, A, b)
    space = VirtualElementSpace(mesh, 1)
    Gf, cf, f = linear(rng)
    Gv, cv, v = linear(rng)
    load = space.body_force_load(f, LAM, MU)
    centres = box_centres @ A.T + b
    volumes = base.cell_volumes * np.linalg.det(A)
    exact = sum(vol * (Gf @ x + cf) @ (Gv @ x + cv) for vol, x in zip(volumes, centres))
    assert np.sum(load * space.interpolate(v)) == pytest.approx(exact, rel=1e-12)
    assert np.allclose(load.sum(axis=0), sum(vol * (Gf @ x + cf) for vol, x in zip(volumes, centres)))


def test_traction_is_exact_for_polynomial_data_and_linear_fields():
    rng = np.random.default_rng(6)
    mesh = mapped(hex_grid(2), *random_affine(rng))
    space = VirtualElementSpace(mesh, 1)
    Gv, cv, v = linear(rng)
    g = lambda x, y, z: (x * y + 1.0, z * z, np.ones_like(x) * 2.0)  # noqa: E731
    faces = mesh.boundary["top"]
    load = space.traction_load(faces, g)
    gauss, weights = np.polynomial.legendre.leggauss(4)
    gauss, weights = (gauss + 1) / 2, weights / 2
    exact = 0.0
    for f in faces:  # the faces are parallelograms: Gauss on their bilinear map
        p = mesh.vertices[mesh.face(f)]
        e1, e2 = p[1] - p[0], p[3] - p[0]
        jac = np.linalg.norm(np.cross(e1, e2))
        for s, ws in zip(gauss, weights):
            for t, wt in zip(gauss, weights):
                x = p[0] + s * e1 + t * e2
                exact += ws * wt * jac * np.dot(g(*x), Gv @ x + cv)
    assert np.sum(load * space.interpolate(v)) == pytest.approx(exact, rel=1e-12)


@pytest.mark.parametrize("make", [hanging_mesh, lambda: l_stack(2)])
def test_patch_test_with_tractions(make):
    rng = np.random.default_rng(8)
    mesh = mapped(make(), *random_affine(rng))
    space = VirtualElementSpace(mesh, 1)
    G, c, field = linear(rng)
    E = 0.5 * (G + G.T)
    sigma = LAM * np.trace(E) * np.eye(3) + 2 * MU * E
    load = np.zeros((space.n_nodes, 3))
    for side, faces in mesh.boundary.items():
        if side == "left":
            continue
        for f in faces:  # sigma n on each (planar, outward) boundary face
            n = mesh.face_vector_areas[f] / np.linalg.norm(mesh.face_vector_areas[f])
            t = sigma @ n
            load += space.traction_load([f], lambda x, y, z: (t[0] + 0 * x, t[1] + 0 * x, t[2] + 0 * x))
    components = tuple((lambda k: lambda x, y, z: field(x, y, z)[k])(k) for k in range(3))
    prescribed, values = space.dirichlet_components({"left": components})
    assert prescribed.any() and not prescribed.all()
    dofs = space.constrain(prescribed, values)
    K, rhs = apply_fixed_dofs(space.stiffness_matrix(LAM, MU, "dofi-2mu", dofs), dofs.restrict(load), dofs)
    u = dofs.node_values(spla.spsolve(K.tocsc(), rhs))
    exact = space.interpolate(field)
    assert np.abs(u - exact).max() < 1e-11 * np.abs(exact).max()
