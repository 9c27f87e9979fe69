"""Overlapping cells (issue 33): the divergence theorem's volume identity holds whatever the cells do,
so validate_mesh3d checks the winding number just outside the boundary (vemkit.mesh.cover3d)."""

import numpy as np
import pytest

from vemkit.exceptions import MeshError
from vemkit.mesh.checks3d import validate_mesh3d
from vemkit.mesh.cover3d import OUTSIDE_OFFSET, check_cover3d
from vemkit.mesh.families3d import build_mesh3d
from vemkit.mesh.polyhedral import from_polyhedra

CUBE = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
FACES = [[0, 4, 7, 3], [1, 2, 6, 5], [0, 1, 5, 4], [3, 7, 6, 2], [0, 3, 2, 1], [4, 5, 6, 7]]


def two_cubes(shift, scale=1.0):
    """Cube [0, 1]^3 and a second cube of side ``scale`` at ``shift``: no face shared."""
    vertices = np.concatenate([CUBE, CUBE * scale + np.asarray(shift, float)])
    cells = [FACES, [[v + 8 for v in face] for face in FACES]]
    return from_polyhedra(vertices, cells, {"all": [f for cell in cells for f in cell]})


def enclosed_volume(mesh):
    """The volume the boundary surface encloses, by the divergence theorem over the boundary faces
    turned outward: (1/3) sum x_F . (|F| n_F)."""
    cf = mesh.cell_faces
    sign = np.zeros(mesh.n_faces)
    np.add.at(sign, np.where(cf >= 0, cf, -cf - 1), np.where(cf >= 0, 1.0, -1.0))
    faces = mesh.boundary_faces  # interior faces: +1 - 1 = 0, they cancel
    return float(
        np.sum(sign[faces] * np.einsum("ij,ij->i", mesh.face_centroids[faces], mesh.face_vector_areas[faces])) / 3
    )


def test_the_volume_identity_cannot_see_the_overlap_of_two_shifted_cubes():
    """Cells 2.0, body 1 + 1 - 0.7^3 = 1.657: the boundary's divergence-theorem volume is 2.0 as well
    (each point counted with its winding number), so comparing volumes would pass the overlap."""
    mesh = two_cubes([0.3, 0.3, 0.3])
    assert np.isclose(mesh.cell_volumes.sum(), 2.0) and np.isclose(enclosed_volume(mesh), 2.0)
    with pytest.raises(MeshError, match=r"^cells overlap: the point .* just outside boundary face \d+ \(of cell \d\)"):
        validate_mesh3d(mesh)


@pytest.mark.parametrize(
    "shift, scale",
    [
        ([0.3, 0.3, 0.3], 1.0),  # a corner of each inside the other
        ([0.9, 0.9, 0.9], 1.0),  # only the corners overlap: the samples near the vertices see it
        ([0.5, 0.0, 0.0], 1.0),  # half of each
        ([0.25, 0.25, 0.25], 0.5),  # one inside the other
    ],
)
def test_overlapping_cells_are_refused_in_one_line(shift, scale):
    with pytest.raises(MeshError) as info:
        check_cover3d(two_cubes(shift, scale))
    assert "\n" not in str(info.value) and "remove or fix the overlapping cells" in str(info.value)


def test_disjoint_bodies_and_a_gap_wider_than_the_offset_pass():
    check_cover3d(two_cubes([2.0, 0.0, 0.0]))
    check_cover3d(two_cubes([1.0 + 100 * OUTSIDE_OFFSET, 0.3, 0.0]))


@pytest.mark.parametrize(
    "family, domain",
    [
        ("hex", {"box": [[0, 0, 0], [1, 1, 0.5]]}),
        ("tet", {"box": [[0, 0, 0], [1, 1, 0.5]]}),
        ("voronoi", {"box": [[0, 0, 0], [1, 1, 0.5]]}),
        ("octree", {"box": [[0, 0, 0], [1, 1, 0.5]]}),
        (
            "triangle",
            {
                "polygon": [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]],
                "sides": ["a", "b", "c", "d", "e", "f"],
                "extrude": {"depth": 1},
            },
        ),
        (
            "voronoi",
            {
                "polygon": [[0, 0], [2, 0], [2, 2], [0, 2]],
                "sides": ["a", "b", "c", "d"],
                "holes": [{"circle": [1, 1, 0.5], "side": "bore"}],
                "extrude": {"depth": 0.5},
            },
        ),
    ],
)
def test_the_families_cover_their_body_once(family, domain):
    check_cover3d(build_mesh3d(family, domain=domain, n=5))
