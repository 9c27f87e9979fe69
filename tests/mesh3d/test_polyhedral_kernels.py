"""PolyhedralMesh's Numba kernels (``vemkit.mesh.polyhedral_kernels``) against their numpy twins
(``polyhedral_reference``) on every 3D family: the same vertex lists and successors of the smallest
vertex exactly, the same face areas and centroids to round-off."""

import numpy as np
import pytest

from vemkit.mesh.families3d import build_mesh3d
from vemkit.mesh.polyhedral_kernels import successor_of_min
from vemkit.mesh.polyhedral_reference import (
    cell_vertex_lists_reference,
    face_geometry_reference,
    successor_of_min_reference,
)

BOX = {"box": [[0, 0, 0], [1, 2, 1]]}
PLATE = {"extrude": {"depth": 0.3}, "polygon": [[0, 0], [2, 0], [2, 1], [0, 1]], "sides": ["b", "r", "t", "l"]}


@pytest.mark.parametrize(
    "family, domain, options",
    [
        ("hex", BOX, {}),
        ("tet", BOX, {}),
        ("voronoi", BOX, {}),
        ("octree", BOX, {"rule": "random", "seed": 2}),
        ("voronoi", PLATE, {}),
    ],
)
def test_kernels_equal_the_numpy_twins(family, domain, options):
    mesh = build_mesh3d(family, domain, n=3, **options)
    offsets, ids = mesh.cell_vertex_lists
    ref_offsets, ref_ids = cell_vertex_lists_reference(mesh)
    assert np.array_equal(offsets, ref_offsets) and np.array_equal(ids, ref_ids)
    va, centroids = face_geometry_reference(mesh.vertices, mesh.face_offsets, mesh.face_vertices)
    scale = np.abs(va).max()
    assert np.abs(mesh.face_vector_areas - va).max() <= 1e-14 * scale
    assert np.abs(mesh.face_centroids - centroids).max() <= 1e-14 * np.abs(mesh.vertices).max()
    reversed_faces = mesh.face_vertices[::-1]  # the same faces run backwards, in reverse order
    for vertices in (mesh.face_vertices, reversed_faces):
        expected = successor_of_min_reference(mesh.face_offsets, vertices)
        assert np.array_equal(successor_of_min(mesh.face_offsets, vertices), expected)
