"""docs/reference/files.md's exact errors on 3D meshes (``vemkit.vem.norms`` with ``exact: {displacement: [u1, u2,
u3]}``): the norms of a known field integrate exactly, a linear field is reproduced (patch test) and
the scene's solution file reports error_h1 / error_l2 on every 3D family."""

import numpy as np
import pytest

from vemkit.config.expressions import vector_field
from vemkit.config.scene import scene_from_dict
from vemkit.studies.scene_solve import solve_scene
from vemkit.vem.norms import difference_gradient, error_quadrature, exact_errors, relative_exact_errors

LINEAR = ["0.01*x + 0.02*y - 0.03*z", "0.005*y - 0.01*x", "0.02*z + 0.01*x"]


class Zero:
    """The zero field as a projection (in ``dimension`` 2 or 3): the norms of the exact solution itself."""

    def __init__(self, dimension: int = 2):
        self.dimension = dimension

    def evaluate(self, cells, points):
        return np.zeros((points.shape[0], self.dimension))

    def gradient_at(self, cells, points):
        return np.zeros((points.shape[0], self.dimension, self.dimension))


def scene(family, exact, n=2):
    held = {s: list(exact) for s in ("left", "right", "front", "back", "bottom", "top")}
    return scene_from_dict(
        {
            "name": "e",
            "model": "3d",
            "domain": {"box": [[0, 0, 0], [1, 2, 1]]},
            "material": {"E": 1.0, "nu": 0.3},
            "boundary": {"dirichlet": held},
            "exact": {"displacement": list(exact)},
            "discretization": {"mesh": {"family": family, "n": n}},
            "solver": {"tol": 1e-12},
        }
    )


@pytest.mark.parametrize("family", ["hex", "tet", "octree", "voronoi"])
def test_a_linear_field_has_no_error_on_any_family(family):
    _, _, ds = solve_scene(scene(family, LINEAR))
    assert ds.attrs["error_h1"] < 1e-10 and ds.attrs["error_l2"] < 1e-10


def test_the_norms_of_a_quadratic_field_are_exact():
    problem, _, _ = solve_scene(scene("voronoi", LINEAR))
    mesh = problem.mesh
    field = vector_field(scene("voronoi", ["x*y", "z", "0"]).exact_displacement)  # on [0,1] x [0,2] x [0,1]
    zero = exact_errors(mesh, Zero(3), field, field.gradient, error_quadrature(mesh))
    # ||u||^2 = int x^2 y^2 + z^2 = (1/3)(8/3) + 2/3; |u|_1^2 = int y^2 + x^2 + 1 = 8/3 + 2/3 + 2
    assert zero["l2"] == pytest.approx(np.sqrt(8 / 9 + 2 / 3), rel=1e-12)
    assert zero["h1_semi"] == pytest.approx(np.sqrt(8 / 3 + 2 / 3 + 2), rel=1e-12)
    plain = lambda x, y, z: field(x, y, z)  # noqa: E731 - no .gradient: by differences
    by_differences = difference_gradient(plain, 1e-3)(np.array([0.3]), np.array([0.7]), np.array([0.2]))
    np.testing.assert_allclose(by_differences[..., 0], field.gradient(0.3, 0.7, 0.2), atol=1e-10)
    assert relative_exact_errors(mesh, Zero(3), plain)["error_h1"] == pytest.approx(1.0, rel=1e-12)


@pytest.mark.parametrize("name", ["box_manufactured", "extruded_manufactured"])
def test_the_manufactured_scenes_carry_the_exact_body_force(name):
    """config/scenes/3d/*_manufactured.yaml: f = -div C eps(u) of their exact u (sympy), and the two
    scenes are the same problem."""
    from pathlib import Path

    from vemkit.studies.three_d import load_scene_data, manufactured_body_force

    data = load_scene_data(Path(__file__).parents[2] / "config" / "scenes" / "3d" / f"{name}.yaml")
    assert (
        manufactured_body_force(data["exact"]["displacement"], data["material"]["E"], data["material"]["nu"])
        == data["body_force"]
    )
    box = load_scene_data(Path(__file__).parents[2] / "config" / "scenes" / "3d" / "box_manufactured.yaml")
    assert data["body_force"] == box["body_force"] and data["exact"] == box["exact"]
    held = data["boundary"]["dirichlet"]
    assert len(held) == 6 and all(v == data["exact"]["displacement"] for v in held.values())
