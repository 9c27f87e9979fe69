"""config/scenes/3d/lshape_edge.yaml (issue 36, item 4): the extruded L whose re-entrant edge carries
the exact field u = (Re f, -Im f, 0), f = (x + iy)^(2/3). The scene's expressions are that field
(numpy's complex power, whose branch cut y = 0, x < 0 is the L's side), divergence-free and harmonic
(so a solution of Lame-Navier without body force for any material), independent of z with u3 = 0
(so the free end faces are traction-free); uniform box meshes converge in H1 as h^(2/3)."""

from pathlib import Path

import numpy as np
import pytest

from vemkit.config.expressions import vector_field
from vemkit.config.scene import scene_from_dict
from vemkit.studies.scene_solve import solve_scene
from vemkit.studies.three_d import load_scene_data

SCENE = Path(__file__).parents[2] / "config" / "scenes" / "3d" / "lshape_edge.yaml"
#: points of the body (x > 0 or y > 0) away from the edge x = y = 0, two of them close to the sides
#: y = 0, x < 0 and x = 0, y < 0 (where theta nears pi and -pi/2)
POINTS = np.array([[0.5, 0.3, 0.2], [-0.6, 0.4, 0.7], [0.3, -0.7, 0.5], [-0.8, 0.02, 0.1], [0.02, -0.8, 0.9]])
STEP = 1e-3


@pytest.fixture(scope="module")
def data():
    return load_scene_data(SCENE)


@pytest.fixture(scope="module")
def field(data):
    return vector_field(scene_from_dict(data).exact_displacement)


def values(field, points):
    return np.array(field(*points.T))  # (3, P)


def test_the_field_is_the_real_and_minus_imaginary_part_of_z_to_the_two_thirds(field):
    u = values(field, POINTS)
    f = (POINTS[:, 0] + 1j * POINTS[:, 1]) ** (2 / 3)
    np.testing.assert_allclose(u[0], f.real, atol=1e-14)
    np.testing.assert_allclose(u[1], -f.imag, atol=1e-14)
    np.testing.assert_allclose(u[2], 0.0, atol=0)
    # on the side y = 0, x < 0: theta = pi, whatever the sign of the zero
    for zero in (0.0, -0.0):
        side = values(field, np.array([[-0.5, zero, 0.3]]))
        np.testing.assert_allclose(
            side[:2, 0], [0.5 ** (2 / 3) * np.cos(2 * np.pi / 3), -(0.5 ** (2 / 3)) * np.sin(2 * np.pi / 3)]
        )


def test_the_field_is_divergence_free_harmonic_and_independent_of_z(field):
    """Central differences (error O(STEP^2) times third derivatives, far below the tolerances)."""
    shifts = STEP * np.eye(3)
    d1 = [(values(field, POINTS + s) - values(field, POINTS - s)) / (2 * STEP) for s in shifts]  # d_a u
    centre = values(field, POINTS)
    d2 = [(values(field, POINTS + s) - 2 * centre + values(field, POINTS - s)) / STEP**2 for s in shifts]
    divergence = d1[0][0] + d1[1][1] + d1[2][2]
    laplacian = d2[0] + d2[1] + d2[2]
    scale = np.abs(d1[0]).max()
    assert np.abs(divergence).max() < 1e-5 * scale
    assert np.abs(laplacian).max() < 1e-4 * scale
    assert np.abs(d1[2]).max() < 1e-12  # d_z u = 0: with u3 = 0 and div u = 0, sigma e3 = 0 on the ends


def test_the_exact_field_is_held_on_the_lateral_sides_and_the_ends_are_free(data):
    held = data["boundary"]["dirichlet"]
    assert set(held) == set(data["domain"]["sides"]) and all(v == data["exact"]["displacement"] for v in held.values())
    assert "body_force" not in data and "neumann" not in data["boundary"]


def test_uniform_box_meshes_converge_as_h_to_the_two_thirds(data):
    """error_h1 of n = 4 and n = 8 (h = 1/4, 1/8): 0.1003 and 0.0645, the rate 0.64 of the
    singularity's h^(2/3) (a smooth field would give 1)."""
    errors = []
    for n in (4, 8):
        scene = scene_from_dict(
            {**data, "discretization": {**data["discretization"], "mesh": {"family": "square", "n": n}}}
        )
        _, _, ds = solve_scene(scene)
        errors.append(ds.attrs["error_h1"])
    rate = np.log2(errors[0] / errors[1])
    assert 0.58 < rate < 0.72, errors
