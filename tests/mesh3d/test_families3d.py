"""The 3D families: valid meshes that fill their box or prism exactly, with every boundary face named."""

import numpy as np
import pytest

from vemkit.mesh.checks3d import validate_mesh3d
from vemkit.mesh.families import build_mesh
from vemkit.mesh.families3d import extrude, hex, octree, tet, voronoi
from vemkit.mesh.polyhedral import from_polyhedra

BOX = ((0.0, 0.0, 0.0), (1.0, 2.0, 0.5))
SIDES = ("left", "right", "front", "back", "bottom", "top")


def side_area(mesh, name):
    return float(np.linalg.norm(mesh.face_vector_areas[mesh.boundary[name]], axis=1).sum())


def assert_fills_box(mesh, box=BOX, sides=SIDES):
    validate_mesh3d(mesh)
    lower, upper = np.asarray(box[0]), np.asarray(box[1])
    size = upper - lower
    assert abs(mesh.cell_volumes.sum() - np.prod(size)) <= 1e-12 * np.prod(size)
    assert (mesh.cell_volumes > 0).all()
    for k, name in enumerate(sides):
        axis = k // 2
        want = np.prod(np.delete(size, axis))
        assert abs(side_area(mesh, name) - want) <= 1e-12 * want, name
        normals = mesh.face_vector_areas[mesh.boundary[name]]
        normals /= np.linalg.norm(normals, axis=1)[:, None]
        expected = np.zeros(3)
        expected[axis] = 1.0 if k % 2 else -1.0
        assert np.allclose(normals, expected, atol=1e-12), name  # stored outward
    assert sum(len(p) for p in mesh.boundary.values()) == mesh.boundary_faces.size


def test_polyhedral_geometry_of_a_cube():
    v = (
        np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float) * 2
        + 7
    )
    faces = [[0, 4, 7, 3], [1, 2, 6, 5], [0, 1, 5, 4], [3, 7, 6, 2], [0, 3, 2, 1], [4, 5, 6, 7]]
    mesh = from_polyhedra(v, [faces])
    assert mesh.cell_volumes[0] == pytest.approx(8.0, rel=1e-14)
    assert np.allclose(np.linalg.norm(mesh.face_vector_areas, axis=1), 4.0)
    assert np.allclose(mesh.face_centroids[0], [7, 8, 8])
    assert mesh.cell_diameters[0] == pytest.approx(2 * np.sqrt(3))
    assert sorted(mesh.cell_vertex_lists[1].tolist()) == list(range(8))


def test_diameter_kernel_and_its_numpy_twin_agree():
    from vemkit.mesh.polyhedral import _diameters, diameters_numpy

    mesh = voronoi(3, seed=1)
    offsets, ids = mesh.cell_vertex_lists
    assert np.allclose(
        _diameters(mesh.vertices, offsets, ids), diameters_numpy(mesh.vertices, offsets, ids), rtol=1e-15
    )
    mesh = octree(shape=(2, 2, 2), rule="random", seed=2)
    offsets, ids = mesh.cell_vertex_lists
    assert np.array_equal(mesh.cell_diameters, diameters_numpy(mesh.vertices, offsets, ids))


def test_hex():
    mesh = hex(shape=(3, 4, 2), box=BOX)
    assert (mesh.n_cells, mesh.n_vertices, mesh.n_faces) == (24, 4 * 5 * 3, 4 * 4 * 2 + 3 * 5 * 2 + 3 * 4 * 3)
    assert_fills_box(mesh)
    assert hex(4, box=BOX).meta["shape"] == [4, 8, 2]  # round(n L) along each edge


def test_tet():
    mesh = tet(shape=(2, 3, 2), box=BOX)
    assert mesh.n_cells == 6 * 12 and set(np.diff(mesh.cell_offsets)) == {4}
    assert_fills_box(mesh)
    assert np.allclose(mesh.cell_volumes, np.prod(np.subtract(BOX[1], BOX[0])) / 72)


@pytest.mark.parametrize(
    "options",
    [{}, {"contact_side": "left"}, {"rule": "random", "seed": 3}, {"rule": "random", "fraction": 0.7, "seed": 1}],
)
def test_octree(options):
    mesh = octree(shape=(3, 4, 3), box=BOX, **options)
    assert_fills_box(mesh)
    refined = mesh.meta["refined"]
    assert mesh.n_cells == 36 + 7 * refined
    faces = np.diff(mesh.cell_offsets)
    assert faces.max() > 6  # coarse cells next to refined ones have split faces
    sizes = np.diff(mesh.face_offsets)
    if options.get("fraction") == 0.7:
        assert sizes.max() > 4  # an edge-only neighbour puts a hanging node on a whole face


def test_octree_hanging_nodes_are_coarse_vertices():
    mesh = octree(shape=(2, 1, 1), rule="random", fraction=0.5, seed=0)
    coarse = int(np.argmax(np.diff(mesh.cell_offsets)))
    assert np.diff(mesh.cell_offsets)[coarse] == 9  # 5 whole faces and 4 quarters
    offsets, ids = mesh.cell_vertex_lists
    assert offsets[coarse + 1] - offsets[coarse] == 8 + 5  # its corners, 4 edge midpoints and the face centre


@pytest.mark.parametrize(
    "options",
    [
        {"n": 3},
        {"cells": 150, "box": BOX, "seed": 4},
        {"n": 4, "lloyd_iterations": 0},
        {"n": 4, "jitter": 0.0, "lloyd_iterations": 0},
        {"n": 3, "lloyd_samples": 0, "seed": 5},
    ],
)
def test_voronoi(options):
    mesh = voronoi(**options)
    box = options.get("box", ((0, 0, 0), (1, 1, 1)))
    assert_fills_box(mesh, box)
    assert mesh.n_cells == options.get("cells", round(options.get("n", 0) ** 3 * np.prod(np.subtract(box[1], box[0]))))


def test_voronoi_is_deterministic_and_lloyd_evens_the_cells():
    a, b = voronoi(4, seed=2), voronoi(4, seed=2)
    assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.cell_faces, b.cell_faces)
    rough = voronoi(5, seed=1, lloyd_iterations=0).cell_volumes
    assert voronoi(5, seed=1, lloyd_iterations=4).cell_volumes.std() < rough.std()
    assert voronoi(5, seed=1, lloyd_iterations=2, lloyd_samples=0).cell_volumes.std() < rough.std()


@pytest.mark.parametrize("family", ["square", "triangle", "voronoi", "hanging"])
def test_extrude_any_2d_family(family):
    domain = {
        "polygon": [[0, 0], [2, 0], [2, 1], [0, 1]],
        "sides": ["bottom", "right", "top", "left"],
        "holes": [{"circle": [1.0, 0.5, 0.25], "side": "bore"}],
    }
    base = build_mesh(family, 6, domain=domain)
    mesh = extrude(base, 3, 0.25)
    validate_mesh3d(mesh)
    area = base.cell_areas.sum()
    assert abs(mesh.cell_volumes.sum() - 0.25 * area) <= 1e-12 * area
    assert mesh.n_cells == 3 * base.n_cells
    assert abs(side_area(mesh, "front") - area) <= 1e-12 and abs(side_area(mesh, "back") - area) <= 1e-12
    for name, part in base.boundary.items():
        length = np.linalg.norm(np.diff(base.vertices[part], axis=1)[:, 0], axis=1).sum()
        assert abs(side_area(mesh, name) - 0.25 * length) <= 1e-12 * length, name
    centres = mesh.face_centroids[mesh.boundary["front"]]
    assert np.allclose(centres[:, 2], 0.0) and np.allclose(mesh.face_centroids[mesh.boundary["back"], 2], 0.25)


def test_extrude_names_and_hanging_nodes():
    base = build_mesh("hanging", 4, levels=2)
    mesh = extrude(base, 2, 1.0, z0=-1.0, ends=("bottom_end", "top_end"))
    validate_mesh3d(mesh)
    assert set(mesh.boundary) == set(base.boundary) | {"bottom_end", "top_end"}
    assert np.diff(mesh.cell_offsets).max() > 6  # coarse prisms list their hanging nodes' lateral faces
    assert mesh.vertices[:, 2].min() == -1.0 and mesh.vertices[:, 2].max() == 0.0
