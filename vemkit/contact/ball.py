"""The closed unit ball of R^(d-1), where the friction multiplier lives: the interval [-1, 1] on a
plane body, the unit disk of the tangent plane in 3D.

Tangential quantities (u_tau, lambda, sigma_tau) are (n_c, d - 1) arrays, their components along the
tangent basis of each contact point (``vemkit.contact.boundary``); 2D is the case d - 1 = 1. One
formula serves both: |x| the Euclidean norm, P(x) = x / max(1, |x|) the projection onto the ball
(5.5), x / |x| the direction.

The ball is the contact layer's per-dimension plug-in, as an element is the VEM space's: the
:class:`Disk` of R^k (k >= 2) has the Euclidean formulas, the :class:`Interval` declares what is
particular to one component:
- its norm is abs(x): sqrt(x * x) is not |x| once x * x underflows (|x| < 1e-154), and with abs the
  projection is bit for bit the clip to [-1, 1] (x / |x| = +-1 exactly in IEEE arithmetic) and the
  direction the sign;
- its projection gives the direction: P(q) at |q| > 1 is sign(q) = the slip's direction exactly,
  whatever gamma, so (2.7)-(2.8) hold at a converged iterate with no re-alignment of lambda
  (``direction_from_projection``). In the disk, P(q) points along q = lambda + gamma u_tau, whose
  direction follows the slip's only as gamma |u_tau| grows: the solvers resolve it (vemkit.solvers.ssn).
:data:`BALLS` holds one of each, by the number of tangential components.
"""

from __future__ import annotations

import numpy as np


class Disk:
    """The unit ball of R^k, k >= 2 (the disk of a tangent plane for k = 2): Euclidean formulas."""

    #: P(q) is the slip's direction at a sliding point (module docstring): not in a disk
    direction_from_projection = False

    def __init__(self, components: int = 2):
        self.components = components

    def norm(self, x: np.ndarray) -> np.ndarray:
        return np.linalg.norm(x, axis=1)

    def inner(self, a: np.ndarray, b: np.ndarray) -> float:
        return float(np.sum(a * b))

    def trial_multiplier(self, stiffness, slip, scale) -> np.ndarray:
        """(stiffness / scale) u_tau, point by point: the multiplier a slip needs at a local stiffness
        (ssn's start, before the projection)."""
        return times(stiffness / scale, slip)

    def power_start(self, sqrt_weight) -> np.ndarray:
        """A start for the power iteration on tangential loads: seeded random components, since a
        symmetric start misses the twisting modes (measured on a pressed box: the largest one)."""
        v = np.random.default_rng(0).standard_normal((sqrt_weight.size, self.components)) * sqrt_weight[:, None]
        return v / np.linalg.norm(v)


class Interval(Disk):
    """[-1, 1]: the ball of one tangential component (module docstring)."""

    direction_from_projection = True

    def __init__(self):
        super().__init__(1)

    def norm(self, x: np.ndarray) -> np.ndarray:
        return np.abs(x[:, 0])

    def inner(self, a: np.ndarray, b: np.ndarray) -> float:
        return float(a[:, 0] @ b[:, 0])  # as vectors of scalars

    def trial_multiplier(self, stiffness, slip, scale) -> np.ndarray:
        return times(stiffness, slip) / scale[:, None]  # the order of the operations of the plane solver

    def power_start(self, sqrt_weight) -> np.ndarray:
        return (sqrt_weight / np.linalg.norm(sqrt_weight))[:, None]  # the one tangent: no twisting mode


#: the ball of k tangential components (k = d - 1)
BALLS = {1: Interval(), 2: Disk(2)}


def of(x) -> Disk:
    """The ball where rows of the tangential quantities ``x`` (n, k) live."""
    return BALLS[np.shape(x)[1]]


def norm(x) -> np.ndarray:
    """(n,) |x_c| of tangential quantities x (n, k)."""
    x = np.asarray(x, dtype=float)
    return of(x).norm(x)


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
    """sum_c a_c . b_c of two tangential quantities."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return of(a).inner(a, b)


def perpendiculars(unit) -> list:
    """An orthonormal basis of the complement of each unit vector (rows of ``unit``, (n, k)) in R^k,
    as a list of (n, k) arrays: none for k = 1, the vector turned by 90 degrees for k = 2."""
    return [np.stack([-unit[:, 1], unit[:, 0]], axis=1) for _ in range(unit.shape[1] - 1)]
