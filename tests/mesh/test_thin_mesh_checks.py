"""Mesh validation on long thin bodies: the winding test of ``validate_mesh`` runs its rays along the
mesh's thinner direction (it compared every pair of boundary edges: minutes for a 1 x 1e-5 strip)."""

import time

import numpy as np
import pytest

from vemkit.exceptions import MeshError
from vemkit.mesh.checks import validate_mesh
from vemkit.mesh.families import build_mesh
from vemkit.mesh.mesh import from_polygons

NESTED = ([[0, 0], [3, 0], [3, 3], [0, 3], [1, 1], [2, 1], [2, 2], [1, 2]], [[0, 1, 2, 3], [4, 5, 6, 7]])


@pytest.mark.parametrize(
    "stretch", [(1.0, 1.0), (1e4, 1.0), (1.0, 1e4), (1e-6, 1.0)], ids=["square", "wide", "tall", "narrow"]
)
def test_a_cell_inside_another_is_found_however_the_mesh_is_stretched(stretch):
    vertices, cells = NESTED
    with pytest.raises(MeshError, match="just outside boundary edge"):
        validate_mesh(from_polygons(np.asarray(vertices, float) * stretch, cells))


def test_a_long_thin_strip_is_validated_in_seconds():
    """16 384 triangles of a 1 x 1e-4 strip (Triangle's quality mesh at h = 0.25: 2 L / w triangles):
    16 386 boundary edges, validated well within a second (pairwise: 2.7e8 ray tests)."""
    mesh = build_mesh(
        "triangle", domain={"polygon": [[0, 0], [1, 0], [1, 1e-4], [0, 1e-4]], "sides": ["s"] * 4}, h=0.25
    )
    assert mesh.boundary_edges.shape[0] > 16_000
    start = time.perf_counter()
    validate_mesh(mesh)
    assert time.perf_counter() - start < 5.0
