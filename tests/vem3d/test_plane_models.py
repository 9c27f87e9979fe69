"""The 3D element against the 2D models on extruded bodies (SPEC §10, issue 20 item 7).

The paper's body without contact (config/scenes/3d/extruded_paper.yaml: unit square, clamped on the
right, the traction (200 (5 - y), -200) on the left, the contact side `bottom` traction-free,
E = 2000, nu = 0.4), extruded along z; the 2D scene of its base (``three_d.base_scene``) is solved
on the same base mesh (the 3D mesh is the prisms over the 2D family mesh of the same keys).

Plane strain (rollers u3 = 0 on both end faces): SPEC §10 says the 3D u1, u2 equal the 2D
`plane_strain` solve. They do to round-off (1e-14) on prisms over triangles, one layer or several.
On square and Voronoi bases they do not (measured 3-24 % at n = 4, 8; xfail below): for a
z-independent field the 3D consistency term of a prism of depth d is d/2 times the 2D one per
vertex layer, and its dofi-dofi stabilization equals the 2D one times alpha_3D = 2 mu h_K, h_K the
prism's diameter, where plane strain needs alpha_3D = (d/2) 2 mu. On triangles the 2D part of
(I - Pi) vanishes and the scaling does not matter. The diagnosis is pinned: a square base at the one
depth d* where the 3D `dofi` alpha = h_K equals (d*/2) 2 mu gives the 2D `dofi-2mu` solve to 1e-9.

Plane stress (traction-free end faces, the in-plane loads independent of z): the thickness average
of u1, u2 tends to the 2D `plane_stress` solve as the depth shrinks, with prisms of a fixed shape
(base n = 1 / depth, one layer). Measured max relative differences at depth 1/4, 1/8, 1/16, 1/32:
square bases 0.189, 0.0967, 0.0449, 0.0208 (rates 0.97, 1.11, 1.11), triangles 0.0886, 0.0495,
0.0291, 0.0171 (0.84, 0.76, 0.77). (On a fixed base mesh the square-base difference grows as the
depth shrinks, 0.093 -> 0.22 from d = 0.2 to 0.025 at n = 8, for the same stabilization scaling.)
"""

from pathlib import Path

import numpy as np
import pytest

from vemkit.studies.three_d import (base_scene, load_scene_data, plane_strain_difference,
                                    plane_stress_difference)

SCENES = Path(__file__).parents[2] / "config" / "scenes" / "3d"
PLANE_STRAIN_CASES = [("triangle", 4, 1), ("triangle", 8, 3), ("triangle", 6, 5)]
STABILIZATION_SCALING = "3D dofi-dofi alpha_K = 2 mu h_K, plane strain needs (d/2) 2 mu (module docstring)"


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
def test_plane_strain_equals_the_3d_solve_on_prisms_over_triangles(paper3d, family, n, layers):
    record, ds2, ds3 = plane_strain_difference(paper3d, family, n, layers)
    print(record)
    assert record["cells_3d"] == layers * record["cells_2d"]
    assert ds3.sizes["mesh3d_nNodes"] == (layers + 1) * ds2.sizes["mesh2d_nNodes"]
    assert record["max_difference"] < 1e-10  # measured <= 3.4e-14
    assert record["u3_max"] < 1e-12 * np.abs(ds3["u1"].values).max()


@pytest.mark.xfail(strict=True, reason=STABILIZATION_SCALING)
@pytest.mark.parametrize(("family", "layers"), [("square", 1), ("square", 3), ("voronoi", 1), ("voronoi", 3)])
def test_plane_strain_equals_the_3d_solve_on_polygonal_prisms(paper3d, family, layers):
    record, _, _ = plane_strain_difference(paper3d, family, 4, layers, seed=1 if family == "voronoi" else None)
    print(record)
    assert record["max_difference"] < 1e-10  # measured 0.12 (one layer), 0.24 (three) at n = 4


def test_the_polygonal_prism_difference_is_the_stabilization_scaling(paper3d):
    """2D dofi-2mu (alpha = 2 mu) and 3D dofi (alpha = h_K) on one layer of squares of side 1/4:
    equal alphas per vertex layer at h_K = (d/2) 2 mu, h_K^2 = 1/8 + d^2."""
    mu = 2000.0 / (2 * 1.4)
    depth = np.sqrt(0.125 / (mu * mu - 1.0))
    data = {**paper3d, "domain": {**paper3d["domain"], "extrude": {"depth": float(depth)}}}
    data["discretization"] = {**paper3d["discretization"], "stabilization": "dofi"}
    flat = base_scene(data, "plane_strain")
    flat["discretization"]["stabilization"] = "dofi-2mu"
    from vemkit.studies import three_d

    run = three_d._with_mesh(data, family="square", n=4, layers=1)
    flat = three_d._with_mesh(flat, family="square", n=4)
    _, _, ds2, _ = three_d._solve(flat)
    _, _, ds3, _ = three_d._solve(run)
    worst, _, _ = three_d._compare(ds2, ds3, average=False)
    print("matched stabilization", depth, worst)
    assert worst < 1e-8  # measured 2.5e-10 (thin prisms: aspect ratio 700)
    mismatched, _, _ = plane_strain_difference(paper3d, "square", 4, 1)
    assert mismatched["max_difference"] > 1e3 * worst


DEPTHS = (0.25, 0.125, 0.0625, 0.03125)


@pytest.mark.parametrize(("family", "min_rate", "max_first"), [("square", 0.9, 0.25), ("triangle", 0.65, 0.12)])
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
    assert rate >= min_rate  # measured 1.06 (square), 0.79 (triangle)
