"""The unit ball of the friction multiplier (vemkit.contact.ball): one formula for [-1, 1] (2D) and
the unit disk (3D), and for one component bit for bit the clip and sign the 2D solvers used before
tangential quantities became (n_c, d - 1) arrays (issue 34)."""

import numpy as np

from vemkit.contact import ball


def _values():
    rng = np.random.default_rng(34)
    special = [0.0, -0.0, 1.0, -1.0, 1.0 + 2e-16, -1.0 - 2e-16, 1e-200, -1e-170, 5e-324, 1e300, -1e300]
    return np.concatenate([rng.standard_normal(20_000) * 3.0, rng.standard_normal(2_000) * 1e-160, special])


def test_one_component_is_the_clip_and_the_sign_bit_for_bit():
    x = _values()
    column = x[:, None]
    assert np.array_equal(ball.project(column)[:, 0], np.clip(x, -1.0, 1.0))
    assert np.array_equal(ball.direction(column)[:, 0], np.sign(x))
    assert np.array_equal(ball.norm(column), np.abs(x))
    with np.errstate(over="ignore"):
        assert np.array_equal(ball.dot(column, 2.0 * column), x * (2.0 * x))
        assert ball.inner(column, column) == float(x @ x)
    assert ball.perpendiculars(ball.direction(column)) == []


def test_two_components_are_the_disk_projection():
    x = _values()[:20_000].reshape(-1, 2)  # of ordinary size (the Euclidean norm underflows below 1e-154)
    size = np.linalg.norm(x, axis=1)
    assert np.array_equal(ball.project(x), x / np.maximum(size, 1.0)[:, None])
    assert np.all(ball.norm(ball.project(x)) <= 1.0 + 1e-15)
    unit = ball.direction(x)
    (e,) = ball.perpendiculars(unit)
    assert np.allclose(np.sum(e * unit, axis=1), 0.0) and np.allclose(ball.norm(e), 1.0)
