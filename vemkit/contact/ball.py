"""The closed unit ball of R^(d-1), where the friction multiplier lives: the interval [-1, 1] on a
plane body, the unit disk of the tangent plane in 3D.

Tangential quantities (u_tau, lambda, sigma_tau) are (n_c, d - 1) arrays, their components along the
tangent basis of each contact point (``vemkit.contact.boundary``); 2D is the case d - 1 = 1. One
formula serves both: |x| the Euclidean norm, P(x) = x / max(1, |x|) the projection onto the ball
(5.5), x / |x| the direction. For one component the norm is computed as abs(x): sqrt(x * x) is not
|x| once x * x underflows (|x| < 1e-154), and with abs the projection is bit for bit the clip to
[-1, 1] (x / |x| = +-1 exactly in IEEE arithmetic) and the direction the sign.
"""

from __future__ import annotations

import numpy as np


def norm(x) -> np.ndarray:
    """(n,) |x_c| of tangential quantities x (n, k): abs for k = 1 (exact), the Euclidean norm else."""
    x = np.asarray(x, dtype=float)
    return np.abs(x[:, 0]) if x.shape[1] == 1 else np.linalg.norm(x, axis=1)


def project(x) -> np.ndarray:
    """P(x) = x / max(1, |x|) row by row: onto [-1, 1] (k = 1) or the unit disk (k = 2)."""
    x = np.asarray(x, dtype=float)
    return x / np.maximum(norm(x), 1.0)[:, None]


def direction(x) -> np.ndarray:
    """x / |x| row by row, 0 where x = 0 (the sign for k = 1)."""
    x = np.asarray(x, dtype=float)
    size = norm(x)
    return np.where(size[:, None] > 0.0, x / np.where(size > 0.0, size, 1.0)[:, None], 0.0)


def dot(a, b) -> np.ndarray:
    """(n,) a_c . b_c (for k = 1 the product: a sum of one term is that term)."""
    return np.sum(np.asarray(a, dtype=float) * np.asarray(b, dtype=float), axis=1)


def times(scalar, x) -> np.ndarray:
    """scalar_c x_c: a value per contact point times tangential quantities (n, k)."""
    return np.asarray(scalar)[..., None] * np.asarray(x, dtype=float)


def inner(a, b) -> float:
    """sum_c a_c . b_c of two tangential quantities: the dot product of the one column for k = 1 (as
    vectors of scalars: a @ b), else the sum of the products."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return float(a[:, 0] @ b[:, 0]) if a.shape[1] == 1 else float(np.sum(a * b))


def perpendiculars(unit) -> list:
    """An orthonormal basis of the complement of each unit vector (rows of ``unit``, (n, k)) in R^k,
    as a list of (n, k) arrays: none for k = 1, the vector turned by 90 degrees for k = 2."""
    return [np.stack([-unit[:, 1], unit[:, 0]], axis=1) for _ in range(unit.shape[1] - 1)]
