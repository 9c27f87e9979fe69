"""The rules of the ``gauss`` contact quadrature: N points per Gamma_C edge (2D), a rule of the same
degree 2N - 1 per Gamma_C triangle (3D), N = ``discretization.contact_gauss_points``.

- ``gauss_rule(N)``: Gauss-Legendre on [0, 1], N points, exact for degree 2N - 1;
- ``triangle_rule(N)``: barycentric points and weights (summing to 1) on a triangle, exact for
  degree 2N - 1, positive weights: N = 3 is the symmetric 7-point degree-5 rule (Radon;
  ``vemkit.vem.quadrature.TRIANGLE_RULE``, GetFEM's IM_TRIANGLE(5), the face rule of its
  IM_TETRAHEDRON(5)); every other N is Stroud's conical product of N Gauss-Legendre points along
  one direction and N Gauss-Jacobi points (weight 1 - eta) across it, N^2 points (N = 1: the centroid,
  GetFEM's IM_TETRAHEDRON(1) face rule).
"""

from __future__ import annotations

import numpy as np

from vemkit.exceptions import SceneError
from vemkit.vem.quadrature import TRIANGLE_RULE

MAX_GAUSS_POINTS = 10


def check_points(points) -> int:
    """``points`` as an int, or a SceneError naming contact_gauss_points."""
    if not (isinstance(points, (int, np.integer)) and 1 <= points <= MAX_GAUSS_POINTS):
        raise SceneError(
            f"discretization.contact_gauss_points = {points!r}: give an integer from 1 to {MAX_GAUSS_POINTS}",
            key="discretization.contact_gauss_points",
        )
    return int(points)


def gauss_rule(points: int):
    """Gauss-Legendre points and weights on [0, 1] (weights sum to 1), exact for degree 2 points - 1."""
    x, w = np.polynomial.legendre.leggauss(check_points(points))
    return 0.5 * (x + 1.0), 0.5 * w


def triangle_rule(points: int):
    """((n_q, 3) barycentric points, (n_q,) weights summing to 1), exact for degree 2 points - 1."""
    n = check_points(points)
    if n == 3:
        return TRIANGLE_RULE[:, :3].copy(), TRIANGLE_RULE[:, 3].copy()
    from scipy.special import roots_jacobi  # here: scipy.special costs 0.05-0.1 s of every start-up

    xi, w_xi = gauss_rule(n)
    x, w_x = roots_jacobi(n, 1.0, 0.0)  # weight (1 - x) on [-1, 1]
    eta, w_eta = 0.5 * (x + 1.0), w_x / np.sum(w_x)  # weight (1 - eta) on [0, 1], normalized
    a = (xi[:, None] * (1.0 - eta[None, :])).ravel()  # (x, y) = (xi (1 - eta), eta)
    b = np.broadcast_to(eta[None, :], (n, n)).ravel()
    return np.stack([1.0 - a - b, a, b], axis=1), (w_xi[:, None] * w_eta[None, :]).ravel()
