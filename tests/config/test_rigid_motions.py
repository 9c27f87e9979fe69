"""The rigid-motion test of a Dirichlet set (vemkit.config.rigid_motions): the free motion named in
2D and 3D, decided by the rank of the constraint functionals, against a dense rank computation on
small sets; linear in the number of points."""

import itertools
import time

import numpy as np
import pytest

from vemkit.config.rigid_motions import free_rigid_motion


def _dense_rank(points, prescribed) -> int:
    """The rank of the N x 3 (N x 6) constraint matrix, computed densely (small N only)."""
    d = points.shape[1]
    rows = []
    for x, held in zip(points, prescribed):
        for i in np.flatnonzero(held):
            mode = np.zeros(3 if d == 2 else 6)
            mode[i] = 1.0
            if d == 2:
                mode[2] = (-x[1], x[0])[i]
            else:
                mode[3:] = np.cross(x, np.eye(3)[i])  # (omega x x)_i = omega . (x x e_i)
            rows.append(mode)
    return int(np.linalg.matrix_rank(np.array(rows), tol=1e-9 * np.linalg.norm(rows, 2))) if rows else 0


def test_random_small_sets_agree_with_the_dense_rank_2d_and_3d():
    rng = np.random.default_rng(5)
    for d, _trial in itertools.product((2, 3), range(300)):
        n = int(rng.integers(1, 6))
        points = rng.integers(-2, 3, size=(n, d)).astype(float) * rng.choice([1.0, 1e-3, 1e4])
        prescribed = rng.random((n, d)) < 0.6
        free = free_rigid_motion(points, prescribed)
        full = 3 if d == 2 else 6
        assert (free is None) == (_dense_rank(points, prescribed) == full), (points, prescribed, free)


@pytest.mark.parametrize(
    "points, prescribed, motion",
    [
        ([[0, 0], [1, 0]], [[True, False], [True, False]], "a translation in y"),
        ([[0, 0], [0, 1]], [[False, True], [False, True]], "a translation in x"),
        ([[2.0, 3.0]], [[True, True]], "a rotation about (2, 3)"),
        # u1 held along y = 0.5 (rollers), u2 at one point x = 4: rotation about (4, 0.5)
        (
            [[0, 0.5], [1, 0.5], [4, 0.5], [4, 7]],
            [[True, False], [True, False], [False, False], [False, True]],
            "a rotation about (4, 0.5)",
        ),
        ([[1e6, 1e6], [1e6 + 1, 1e6]], [[True, True], [False, True]], None),
        ([[0, 0], [1, 0], [1, 1]], [[False, False], [False, False], [False, False]], "every rigid motion"),
    ],
)
def test_the_free_motion_is_named_with_its_point(points, prescribed, motion):
    found = free_rigid_motion(np.array(points, float), np.array(prescribed))
    assert found == motion if motion is None else found.startswith(motion), found


def test_a_3d_axis_is_named_and_a_clamped_face_holds_all_six():
    face = np.array([[x, y, 0.0] for x in range(3) for y in range(3)])
    assert free_rigid_motion(face, np.ones_like(face, bool)) is None
    line = np.array([[0.0, 0.0, z] for z in range(4)])  # a clamped line leaves the spin about it
    found = free_rigid_motion(line, np.ones_like(line, bool))
    assert found.startswith("a rotation about the axis along (0, 0, 1") or "(0, 0, -1" in found, found
    assert "through (0, 0, 0)" in found.replace("-0", "0")
    assert free_rigid_motion(face, np.array([[True, True, False]] * 9)) == "a translation in z"


def test_a_million_points_take_well_under_a_second_and_linear_memory():
    t = np.linspace(0.0, 2.0 * np.pi, 1_000_000, endpoint=False)
    points = np.stack([np.cos(t), np.sin(t)], axis=1)
    start = time.perf_counter()
    assert free_rigid_motion(points, np.ones_like(points, bool)) is None
    assert time.perf_counter() - start < 3.0
    strip = np.stack([np.linspace(0, 200, 200_001), np.zeros(200_001)], axis=1)  # clamped straight base
    assert free_rigid_motion(strip, np.ones_like(strip, bool)) is None
    assert free_rigid_motion(strip, np.array([[True, False]] * strip.shape[0])) == "a translation in y"


def test_the_3d_test_is_relative_per_axis():
    """A thin plate clamped on a narrow face holds the spin about its thin axis (an eigenvalue of S
    1e-15 of the others); a clamped line in any direction, at any scale, leaves the spin about it."""
    s = np.linspace(0.0, 1.0, 5)
    for thin in (1e-3, 1e-7):  # the face x = 0 of [0, 1] x [0, 1] x [0, thin], and of its transpose
        face = np.array([[0.0, y, z * thin] for y in s for z in s])
        assert free_rigid_motion(face, np.ones_like(face, bool)) is None
        assert free_rigid_motion(face[:, [1, 2, 0]] * 1e3, np.ones_like(face, bool)) is None
    rng = np.random.default_rng(1)
    for _ in range(50):
        d, scale = rng.normal(size=3), 10 ** rng.uniform(-3, 6)
        line = rng.normal(size=3) * scale + np.outer(rng.uniform(-1, 1, 20) * scale * 10 ** rng.uniform(-6, 3), d)
        assert free_rigid_motion(line, np.ones_like(line, bool)).startswith("a rotation about the axis")
