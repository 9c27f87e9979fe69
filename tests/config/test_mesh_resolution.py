"""What a mesh size can do on a body (vemkit.config.mesh_resolution): the triangles Triangle puts in
thin parts are predicted before it runs, an upper bound within a factor 3; a size beyond the body's
scales is a one-line SceneError naming discretization.mesh."""

import pytest

from vemkit.config.domain import domain_from_spec
from vemkit.config.mesh_resolution import check_mesh_resolution, thin_part_triangles
from vemkit.exceptions import SceneError
from vemkit.mesh.families import build_mesh

SIDES = ["a", "b", "c", "d"]
THIN = {
    "strip 1e-3": {"polygon": [[0, 0], [1, 0], [1, 1e-3], [0, 1e-3]], "sides": SIDES},
    "strip 1e-4": {"polygon": [[0, 0], [1, 0], [1, 1e-4], [0, 1e-4]], "sides": SIDES},
    "fin": {
        "polygon": [[0, 0], [1, 0], [1, 1], [0.5, 1], [0.5, 2], [0.499, 2], [0.499, 1], [0, 1]],
        "sides": ["a"] * 8,
    },
}


@pytest.mark.parametrize("name", THIN)
def test_thin_parts_are_counted_before_triangle_fills_them(name):
    domain = domain_from_spec(THIN[name])
    made = build_mesh("triangle", domain=THIN[name], h=0.25).n_cells
    predicted = thin_part_triangles(domain, 0.25) + 2 * domain.exact_area / 0.25**2
    assert made <= predicted <= 3.5 * made, (made, predicted)


@pytest.mark.parametrize(
    "spec",
    [
        {"polygon": [[0, 0], [48, 44], [48, 60], [0, 44]], "sides": SIDES},  # Cook's membrane
        {"polygon": [[0, 0], [1, 0], [0, 0.01]], "sides": SIDES[:3]},  # a sharp wedge: Triangle leaves it alone
    ],
)
def test_bodies_without_thin_parts_add_nothing(spec):
    assert thin_part_triangles(domain_from_spec(spec), 2.0 if len(spec["sides"]) == 4 else 0.25) == 0


@pytest.mark.parametrize(
    "mesh, spec, message",
    [
        ({"family": "square", "h": 30.0}, {"polygon": [[0, 0], [2, 0], [2, 1], [0, 1]], "sides": SIDES}, "larger side"),
        (
            {"family": "voronoi", "n": 4},
            {"polygon": [[1e6, 0], [1e6 + 2, 0], [1e6 + 2, 1], [1e6, 1]], "sides": SIDES},
            "too fine for double precision",
        ),
        (
            {"family": "triangle", "n": 4},
            {
                "polygon": [[0, 0], [2, 0], [2, 1], [0, 1]],
                "sides": SIDES,
                "holes": [{"circle": [1, 0.5, 1e-7], "side": "h"}],
            },
            "feature of",
        ),
    ],
)
def test_a_size_beyond_the_body_is_refused(mesh, spec, message):
    with pytest.raises(SceneError, match=message) as error:
        check_mesh_resolution(mesh, domain_from_spec(spec))
    assert error.value.key in ("discretization.mesh", "domain")
