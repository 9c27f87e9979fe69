"""Manufactured elasticity solutions for the tests: the body force and the exact fields, from sympy."""

from __future__ import annotations

import numpy as np
import sympy

X, Y = sympy.symbols("x y")


def elasticity_solution(u1: str, u2: str, E: float, nu: float) -> dict:
    """The paper's plane-stress C (docs/reference/mathematics.md) applied to u = (u1, u2) (sympy text in x, y).

    Returns the body force f = −div σ(u) as scene expressions, and numpy callables of u, ∇u and of
    the traction σ n for a constant normal n.
    """
    u = sympy.Matrix([sympy.sympify(u1), sympy.sympify(u2)])
    grad = u.jacobian([X, Y])
    eps = (grad + grad.T) / 2
    lam, mu = E * nu / (1 - nu**2), E / (2 * (1 + nu))
    sigma = lam * eps.trace() * sympy.eye(2) + 2 * mu * eps
    force = -sympy.Matrix([sympy.diff(sigma[i, 0], X) + sympy.diff(sigma[i, 1], Y) for i in range(2)])
    as_numpy = lambda expr: sympy.lambdify((X, Y), expr, "numpy")  # noqa: E731
    u_f, g_f, s_f = as_numpy(list(u)), as_numpy(grad.tolist()), as_numpy(sigma.tolist())

    def broadcast(f):
        return lambda x, y: np.asarray(np.broadcast_arrays(*_flat(f(x, y)), x), dtype=float)[:-1]

    return {
        "body_force": [str(sympy.factor(sympy.simplify(c))) for c in force],
        "u": lambda x, y: tuple(broadcast(u_f)(x, y)),
        "grad": lambda x, y: broadcast(g_f)(x, y).reshape(2, 2, *np.shape(x)),
        "stress": lambda x, y: broadcast(s_f)(x, y).reshape(2, 2, *np.shape(x)),
    }


def _flat(value):
    return [v for row in value for v in (row if isinstance(row, (list, tuple)) else [row])]
