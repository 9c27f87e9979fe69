"""The 3D k = 1 element on one cell: the face integrals are exact for linear functions, Pi (3.8)
reproduces linear fields, the kernel of the local stiffness is exactly the six rigid motions, and
the Numba kernel equals its numpy twin (which solves (3.8) literally)."""

import numpy as np
import pytest
from polyhedra3d import hanging_mesh, hex_grid, l_prism, mapped, random_affine, random_hull, random_star_prism, tet_grid

from vemkit.vem.elasticity import rigid_body_modes
from vemkit.vem.elements import element_for, stabilization_code
from vemkit.vem.elements.k1_3d_kernel import face_weights
from vemkit.vem.elements.k1_3d_reference import element_stiffness_reference, face_integral_weights

ELEMENT = element_for(1, 3)
LAM, MU = 1.7, 0.6


def random_polyhedra(seed=0, count=4):
    rng = np.random.default_rng(seed)
    cells = []
    for _ in range(count):
        cells += [random_hull(rng, 14), random_star_prism(rng, 7)]
        for base in (l_prism(), hanging_mesh(), hex_grid(1), tet_grid(1)[0]):
            cells.append(mapped(base, *random_affine(rng)))
    return cells


def local_matrices(mesh, stabilization="dofi-2mu"):
    """Yield (coords, faces, K) for every cell: the kernel's local stiffness."""
    geometry = ELEMENT.geometry(mesh)
    offsets, ids = ELEMENT.cell_nodes(mesh)
    work = ELEMENT.workspace(int(np.diff(offsets).max()))
    _, cell_face_ptr, face_ptr, face_local = geometry
    for c in range(mesh.n_cells):
        n = offsets[c + 1] - offsets[c]
        K = ELEMENT.cell_matrix(c, geometry, offsets, ids, LAM, MU, stabilization_code(stabilization), work)
        faces = [face_local[face_ptr[t] : face_ptr[t + 1]] for t in range(cell_face_ptr[c], cell_face_ptr[c + 1])]
        yield mesh.vertices[ids[offsets[c] : offsets[c + 1]]], faces, K[: 3 * n, : 3 * n].copy()


def planar_polygon(rng, m):
    """A random star-shaped polygon (m vertices) rotated into space; its area and centroid by the
    shoelace formulas in its own plane."""
    angle = np.sort(rng.uniform(0, 2 * np.pi, m))
    xy = rng.uniform(0.2, 1.0, m)[:, None] * np.c_[np.cos(angle), np.sin(angle)] + rng.standard_normal(2)
    x, y = xy.T
    if (x * np.roll(y, -1) - np.roll(x, -1) * y).sum() < 0:  # a star about a point outside: clockwise
        x, y = x[::-1].copy(), y[::-1].copy()
        xy = np.c_[x, y]
    cross = x * np.roll(y, -1) - np.roll(x, -1) * y
    area = cross.sum() / 2
    centroid = np.array([((x + np.roll(x, -1)) * cross).sum(), ((y + np.roll(y, -1)) * cross).sum()]) / (6 * area)
    Q, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    Q[:, 2] *= np.sign(np.linalg.det(Q))  # a rotation: the counter-clockwise face has normal Q e_3
    shift = rng.standard_normal(3)
    to_space = lambda p: np.c_[p, np.zeros(len(p))] @ Q.T + shift  # noqa: E731
    return to_space(xy), area, to_space(centroid[None])[0], Q[:, 2]


@pytest.mark.parametrize("m", [3, 4, 5, 8])
def test_face_weights_integrate_linear_functions_exactly(m):
    rng = np.random.default_rng(m)
    for _ in range(5):
        p, area, centroid, normal = planar_polygon(rng, m)
        g, c0 = rng.standard_normal(3), rng.standard_normal()
        exact = area * (g @ centroid + c0)  # int_F (g . x + c0) ds = |F| (g . x_F + c0)
        w = np.empty(m)
        n = face_weights(p, np.arange(m), 0, m, w)
        w_ref, n_ref = face_integral_weights(p)
        assert np.allclose(n, normal) and np.allclose(n_ref, normal)
        assert w @ (p @ g + c0) == pytest.approx(exact, rel=1e-13, abs=1e-13)
        assert np.allclose(w, w_ref, rtol=1e-13, atol=1e-14)
        if m == 3:
            assert np.allclose(w, area / 3)  # P1 on triangles


@pytest.mark.parametrize("stabilization", ["dofi", "dofi-2mu", "trace"])
def test_kernel_equals_its_numpy_twin(stabilization):
    worst = 0.0
    for mesh in random_polyhedra():
        for coords, faces, K in local_matrices(mesh, stabilization):
            K_ref, _ = element_stiffness_reference(coords, faces, LAM, MU, stabilization)
            worst = max(worst, np.abs(K - K_ref).max() / np.abs(K_ref).max())
    assert worst < 1e-12


def test_stiffness_kernel_is_exactly_the_rigid_motions():
    for mesh in random_polyhedra(seed=1, count=2):
        for coords, _, K in local_matrices(mesh):
            modes = rigid_body_modes(coords)
            assert modes.shape == (3 * len(coords), 6)
            assert np.abs(K @ modes).max() < 1e-12 * np.abs(K).max() * max(1.0, np.abs(coords).max())
            s = np.linalg.eigvalsh(0.5 * (K + K.T))
            assert np.allclose(K, K.T, atol=1e-13 * np.abs(K).max())
            assert s[6] > 1e-8 * s[-1]  # rank 3n - 6: nothing else is free


def test_projection_reproduces_linear_fields():
    """Pi v = v for every linear v (the patch test on one cell), on every kind of cell."""
    rng = np.random.default_rng(5)
    for mesh in random_polyhedra(seed=2, count=2):
        for coords, faces, _ in local_matrices(mesh):
            _, Pi = element_stiffness_reference(coords, faces, LAM, MU)
            G, c = rng.standard_normal((3, 3)), rng.standard_normal(3)
            v = (coords @ G.T + c).ravel()
            assert np.allclose(Pi @ v, v, atol=1e-12 * np.abs(v).max())
        G, c = rng.standard_normal((3, 3)), rng.standard_normal(3)
        u = ELEMENT.interpolate(mesh, lambda x, y, z: tuple(G @ np.stack([x, y, z]) + c[:, None]))
        projected = ELEMENT.project(mesh, u)
        cells = np.arange(mesh.n_cells)
        points = rng.standard_normal((mesh.n_cells, 3))
        assert np.allclose(projected.evaluate(cells, points), points @ G.T + c, atol=1e-12 * np.abs(G).sum() * 10)
        assert np.allclose(projected.gradient_at(cells, points), G[None], atol=1e-12)
