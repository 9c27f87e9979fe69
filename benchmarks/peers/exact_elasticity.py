"""The manufactured elasticity problem of the k = 2 / P2 comparison (benchmarks/peers_order2.py).

The unit square in plane stress with the paper's E = 2000, nu = 0.4 (docs/reference/mathematics.md), the smooth exact
displacement u = (sin(3x + 2y), cos(2x - 3y)) / 100, u = u_exact on the sides `left` and `bottom`,
the traction sigma(u_exact) n on `right` (n = (1, 0)) and `top` (n = (0, 1)), and the body force
f = -div sigma(u_exact). Everything is text in x and y that three languages read alike: vemkit's
scene expressions, numpy (`evaluate`) and GetFEM's weak form language (`in_getfem`: x -> X(1),
y -> X(2)); only +, -, *, /, sin and cos occur (no powers). Derived with sympy, in exact rationals.
"""

from __future__ import annotations

import re

import numpy as np

DISPLACEMENT = ("sin(3*x + 2*y)/100", "cos(2*x - 3*y)/100")
DIRICHLET = ("left", "bottom")
NORMALS = {"right": (1, 0), "top": (0, 1)}  # the traction sides and their outward normals
YOUNG, POISSON = 2000, "2/5"
NUMPY = {"__builtins__": {}, "sin": np.sin, "cos": np.cos}


def manufactured_problem() -> dict:
    """{lam, mu, displacement: [u1, u2], gradient: [[du1/dx, du1/dy], [du2/dx, du2/dy]],
    body_force: [f1, f2], traction: {side: [t1, t2]}, dirichlet: [sides]} (expressions as text)."""
    import sympy

    x, y = sympy.symbols("x y")
    E, nu = sympy.Integer(YOUNG), sympy.Rational(POISSON)
    lam, mu = E * nu / (1 - nu**2), E / (2 * (1 + nu))  # the paper's plane-stress C
    u = sympy.Matrix([sympy.sympify(c, locals={"x": x, "y": y}) for c in DISPLACEMENT])
    grad = u.jacobian([x, y])
    eps = (grad + grad.T) / 2
    sigma = lam * eps.trace() * sympy.eye(2) + 2 * mu * eps
    force = [-(sympy.diff(sigma[i, 0], x) + sympy.diff(sigma[i, 1], y)) for i in range(2)]
    traction = {side: [sigma[i, 0] * n[0] + sigma[i, 1] * n[1] for i in range(2)] for side, n in NORMALS.items()}
    text = lambda e: _checked(str(sympy.simplify(e)))  # noqa: E731
    return {
        "lam": float(lam),
        "mu": float(mu),
        "displacement": list(DISPLACEMENT),
        "gradient": [[text(grad[i, j]) for j in range(2)] for i in range(2)],
        "body_force": [text(f) for f in force],
        "traction": {side: [text(t) for t in values] for side, values in traction.items()},
        "dirichlet": list(DIRICHLET),
    }


def _checked(expression: str) -> str:
    assert "**" not in expression and "pi" not in expression, expression
    return expression


def evaluate(expressions, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """(len(expressions), *x.shape) the expressions at the points (numpy)."""
    return np.stack([np.broadcast_to(eval(e, NUMPY, {"x": x, "y": y}), np.shape(x)) for e in expressions])


def in_getfem(expression: str) -> str:
    """The same expression in GetFEM's weak form language (the coordinates X(1), X(2))."""
    return re.sub(r"\by\b", "X(2)", re.sub(r"\bx\b", "X(1)", expression))
