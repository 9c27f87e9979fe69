"""Every family meshes a body with curved sides (``domain.arcs``): a half-disk, flat side up, with its
rim split into a contact arc and two flanks. Meshes are valid, cover the discretized body exactly,
and every boundary edge carries the side it lies on (rim edges have both ends on the circle)."""

import math

import numpy as np
import pytest

from vemkit.config.domain import domain_from_spec
from vemkit.mesh.checks import validate_mesh
from vemkit.mesh.families import build_mesh

R = 1.0
# corners (-1, 0), (-0.6, -0.8), (0.6, -0.8), (1, 0) on the unit circle: three arcs and the flat top
HALF_DISK = {
    "polygon": [[-R, 0], [-0.6, -0.8], [0.6, -0.8], [R, 0]],
    "sides": ["flank", "contact", "flank", "top"],
    "arcs": [[0, 0], [0, 0], [0, 0], None],
}
CASES = [
    ("square", {}),
    ("triangle", {"seed": 1}),
    ("voronoi", {"seed": 2}),
    ("hanging", {"levels": 2, "contact_side": "contact"}),
    ("hanging", {"levels": 1, "rule": "random", "seed": 3, "fraction": 0.3}),
]
IDS = ["square", "triangle", "voronoi", "hanging-contact", "hanging-random"]
N = 8


@pytest.fixture(scope="module", params=CASES, ids=IDS)
def half_disk_mesh(request):
    family, options = request.param
    return build_mesh(family, N, domain=HALF_DISK, **options)


def test_each_family_meshes_the_half_disk_validly(half_disk_mesh):
    validate_mesh(half_disk_mesh)
    meta = half_disk_mesh.meta  # hanging: the curved sides are chords of its finest squares
    chord = 1.0 / N / (2 ** meta["levels"] if meta["family"] == "hanging" else 1)
    polygonal = domain_from_spec(HALF_DISK).discretize(chord)
    assert (half_disk_mesh.cell_areas > 0).all()
    assert half_disk_mesh.cell_areas.sum() == pytest.approx(polygonal.shape.area, rel=1e-12)
    assert polygonal.shape.area == pytest.approx(math.pi / 2, rel=2e-2)


def test_every_boundary_edge_lies_on_its_side(half_disk_mesh):
    mesh = half_disk_mesh
    assert set(mesh.boundary) == {"flank", "contact", "top"}
    parts = np.concatenate(list(mesh.boundary.values()))
    assert sorted(map(tuple, parts)) == sorted(map(tuple, mesh.boundary_edges))  # a partition
    v = mesh.vertices
    for name, edges in mesh.boundary.items():
        ends = v[edges]  # (edges, 2 ends, xy)
        if name == "top":
            assert np.abs(ends[..., 1]).max() < 1e-12
            continue
        # a rim edge is a piece of a chord of the arc: its ends are within the chord's sagitta of the circle
        radius = np.hypot(ends[..., 0], ends[..., 1])
        assert radius.max() <= R * (1 + 1e-12) and radius.min() >= R * math.cos(0.5 / (N * R)) - 1e-12
        low = ends[..., 1] < -0.8 + 1e-9
        assert (low.all(axis=1) if name == "contact" else ~low.all(axis=1)).all()
    contact = np.unique(mesh.boundary["contact"])
    on_circle = np.isclose(np.hypot(v[contact, 0], v[contact, 1]), R, rtol=0, atol=1e-12)
    assert on_circle.sum() >= 6  # the chord ends of the contact arc are mesh vertices on the circle
