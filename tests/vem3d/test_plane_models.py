"""The 3D element against the 2D models on extruded bodies (docs/reference/files.md, issue 20 item 7).

The paper's body without contact (config/scenes/3d/extruded_paper.yaml: unit square, clamped on the
right, the traction (200 (5 - y), -200) on the left, the contact side `bottom` traction-free,
E = 2000, nu = 0.4), extruded along z; the 2D scene of its base (``three_d.base_scene``) is solved
on the same base mesh (the 3D mesh is the prisms over the 2D family mesh of the same keys).

Plane strain (rollers u3 = 0 on both end faces): docs/reference/files.md says the 3D u1, u2 equal the 2D
`plane_strain` solve. They do to round-off on prisms over triangles, squares and Voronoi polygons,
one layer or several (measured <= 3.4e-14): for a z-independent field with u3 = 0 the consistency
term of a prism of height t is t times the 2D one, and its dofi-dofi stabilization too, because the
3D scaling length of a right prism is t / 2 (``vemkit.vem.elements.k1_3d.stabilization_lengths``;
with the diameter instead, the difference was 1-24 %).

Plane stress (traction-free end faces, the in-plane loads independent of z): the thickness average
of u1, u2 tends to the 2D `plane_stress` solve as the depth shrinks. Measured max relative
differences at depth 1/4, 1/8, 1/16, 1/32 with prisms of a fixed shape (base n = 1 / depth, one
layer): squares 0.0485, 0.0267, 0.0152, 0.0089 (fitted rate 0.81), triangles 0.0642, 0.0339,
0.0195, 0.0137 (0.75), Voronoi 0.047, 0.0254, 0.0129, 0.0084 (0.84); on a fixed base mesh (n = 8)
at depth 0.2, 0.1, 0.05, 0.025: squares 0.0374, 0.0239, 0.0157, 0.0092.
"""

from pathlib import Path

import numpy as np
import pytest

from vemkit.studies.three_d import base_scene, load_scene_data, plane_strain_difference, plane_stress_difference

SCENES = Path(__file__).parents[2] / "config" / "scenes" / "3d"
PLANE_STRAIN_CASES = [
    ("triangle", 4, 1),
    ("triangle", 8, 3),
    ("triangle", 6, 5),
    ("square", 4, 1),
    ("square", 6, 3),
    ("voronoi", 4, 1),
    ("voronoi", 5, 3),
]


@pytest.fixture(scope="module")
def paper3d():
    return load_scene_data(SCENES / "extruded_paper.yaml")


def test_base_scene_is_the_paper_body_without_contact(paper3d):
    flat = base_scene(paper3d, "plane_strain")
    paper = load_scene_data(SCENES.parent / "paper.yaml")
    assert flat["model"] == "plane_strain" and "extrude" not in flat["domain"]
    assert flat["material"] == paper["material"]
    assert flat["boundary"]["dirichlet"] == {"right": [0.0, 0.0]}
    assert flat["boundary"]["neumann"]["left"] == paper["boundary"]["neumann"]["left"]
    assert "contact" not in flat["boundary"] and "layers" not in flat["discretization"]["mesh"]


@pytest.mark.parametrize(("family", "n", "layers"), PLANE_STRAIN_CASES)
def test_plane_strain_equals_the_3d_solve_on_extruded_meshes(paper3d, family, n, layers):
    record, ds2, ds3 = plane_strain_difference(paper3d, family, n, layers, seed=1 if family == "voronoi" else None)
    print(record)
    assert record["cells_3d"] == layers * record["cells_2d"]
    assert ds3.sizes["mesh3d_nNodes"] == (layers + 1) * ds2.sizes["mesh2d_nNodes"]
    assert record["max_difference"] < 1e-10  # measured <= 3.4e-14
    assert record["u3_max"] < 1e-12 * np.abs(ds3["u1"].values).max()


DEPTHS = (0.25, 0.125, 0.0625, 0.03125)


@pytest.mark.parametrize(
    ("family", "min_rate", "max_first"), [("square", 0.7, 0.06), ("triangle", 0.65, 0.08), ("voronoi", 0.7, 0.06)]
)
def test_a_thin_plate_tends_to_plane_stress(family, min_rate, max_first):
    data = load_scene_data(SCENES / "thin_plate.yaml")
    diffs = []
    for depth in DEPTHS:
        record, _, _ = plane_stress_difference(data, family, depth, cells_per_depth=1.0, layers=1)
        print(record)
        diffs.append(record["max_difference"])
    diffs = np.array(diffs)
    rate = np.polyfit(np.log(DEPTHS), np.log(diffs), 1)[0]
    print(family, "differences", diffs, "fitted rate", rate)
    assert diffs[0] < max_first and np.all(diffs[1:] < 0.75 * diffs[:-1])  # a clear decrease
    assert rate >= min_rate  # measured 0.81 (square), 0.75 (triangle), 0.84 (voronoi)


def test_a_thin_plate_on_a_fixed_base_mesh_tends_to_plane_stress():
    data = load_scene_data(SCENES / "thin_plate.yaml")
    diffs = [
        plane_stress_difference(data, "square", depth, n=8, layers=1)[0]["max_difference"]
        for depth in (0.2, 0.1, 0.05, 0.025)
    ]
    print("fixed base mesh", diffs)
    assert np.all(np.diff(diffs) < 0) and diffs[-1] < 0.3 * diffs[0]  # measured 0.0374 -> 0.0092
