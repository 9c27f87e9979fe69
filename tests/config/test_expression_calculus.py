"""Exact derivatives of scene expressions (issue 18, item 6) against sympy's diff, on random points.

Piecewise functions (abs, sign, min, max, where) are compared away from their kinks, where the
derivative is the derivative of the branch taken; sympy's DiracDelta (the derivative of sign at 0)
is zero there.
"""

import pickle

import numpy as np
import pytest
import sympy

from vemkit.config.expressions import compile_expression, vector_field
from vemkit.exceptions import ExpressionError

x, y, z = sympy.symbols("x y z", real=True)
SYMPY_NAMES = {
    "x": x,
    "y": y,
    "z": z,
    "pi": sympy.pi,
    "sin": sympy.sin,
    "cos": sympy.cos,
    "tan": sympy.tan,
    "asin": sympy.asin,
    "acos": sympy.acos,
    "atan": sympy.atan,
    "atan2": sympy.atan2,
    "sinh": sympy.sinh,
    "cosh": sympy.cosh,
    "tanh": sympy.tanh,
    "exp": sympy.exp,
    "log": sympy.log,
    "sqrt": sympy.sqrt,
    "abs": sympy.Abs,
    "sign": sympy.sign,
    "min": sympy.Min,
    "max": sympy.Max,
    "where": lambda c, a, b: sympy.Piecewise((a, c), (b, True)),
}
RNG = np.random.default_rng(6)
POINTS = [RNG.uniform(0.05, 0.95, 400) for _ in range(3)]  # inside (0, 1)^3: log, sqrt, asin defined

EXPRESSIONS = [
    "3*x**2*y - y**3 + 7",
    "x*y*z + z**2",
    "(x - y)/(x + y)",
    "1/(x + 2*y)**3",
    "-x/y",
    "x**-0.5",
    "+x*(-y)",
    "x**y",
    "2**(x*y)",
    "(1 + x)**(y + 1)",
    "pi*x**pi",
    "sin(x)*cos(y)",
    "tan(x*y)",
    "asin(x*y)",
    "acos(x - y)",
    "atan(y/x)",
    "atan2(y, x)",
    "atan2(y - 0.5, x - 0.5)",
    "sinh(x) + cosh(y)*tanh(x*y)",
    "exp(-x*y)",
    "log(x + y)",
    "sqrt(x**2 + y**2)",
    "exp(sin(x))*log(1 + y**2)",
    "cos(2*pi*x)*sin(pi*y)",
    "sqrt(x**2+y**2)**(2/3)*cos(2*atan2(y,x)/3)",
    "5/3*sqrt(x**2+y**2)**(2/3)*sin(2*atan2(y - 0.5, x - 0.5)/3)",
    "abs(x - 0.5)*y",
    "abs(sin(3*x) - y)",
    "sign(y - 0.4)*x**2",
    "min(x, y)",
    "max(x, y, 0.5)",
    "min(x**2, y, x*y)",
    "max(x - y, y**2)*min(x, 1 - y)",
    "where(x < y, x*y, x + y)",
    "where((x > 0.3) & (y < 0.6), sin(x), cos(y))",
    "where(x >= 0.5, x**2, 0.25)",
    "where(x > y, 2, 3)*x",
    "where(x <= 0.5, where(y > 0.5, x*y, y), exp(x))",
]


def sympy_derivative(text: str, variable):
    """d(text)/d(variable) by sympy, as a numpy function of (x, y, z)."""
    derivative = sympy.diff(sympy.sympify(text, locals=SYMPY_NAMES), variable)
    derivative = derivative.replace(sympy.DiracDelta, lambda *args: 0)
    return sympy.lambdify((x, y, z), derivative, modules="numpy")


@pytest.mark.parametrize("text", EXPRESSIONS)
def test_derivatives_equal_sympy_diff(text):
    expression = compile_expression(text, name="exact.displacement[0]")
    for variable, symbol in zip("xyz", (x, y, z)):
        mine = expression.derivative(variable)(*POINTS)
        theirs = np.broadcast_to(sympy_derivative(text, symbol)(*POINTS), mine.shape)
        np.testing.assert_allclose(mine, theirs, rtol=1e-11, atol=1e-12, err_msg=f"d/d{variable} {text}")


def test_a_polynomial_field_has_its_polynomial_gradient_to_rounding():
    field = vector_field(
        [compile_expression("1e-3*(2*x - 3*y + 1)", name="u1"), compile_expression("x**2*y", name="u2")]
    )
    px, py = POINTS[0], POINTS[1]
    gradient = field.gradient(px, py)
    assert gradient.shape == (2, 2, px.size)
    np.testing.assert_array_equal(gradient[0, 0], 2e-3)
    np.testing.assert_array_equal(gradient[0, 1], -3e-3)
    np.testing.assert_allclose(gradient[1], [2 * px * py, px**2], rtol=1e-15)
    values = field(px, py)
    np.testing.assert_allclose(values[1], px**2 * py, rtol=1e-15)


def test_a_constant_field_has_a_zero_gradient_of_the_points_shape():
    field = vector_field([compile_expression(0.5, name="u1"), compile_expression("2*pi", name="u2")])
    assert np.array_equal(field.gradient(np.zeros((3, 4)), 1.0), np.zeros((2, 2, 3, 4)))


def test_a_singular_derivative_is_refused_where_it_is_infinite():
    derivative = compile_expression("sqrt(x**2 + y**2)**(2/3)", name="exact.displacement[1]").derivative("x")
    assert np.isfinite(derivative(1e-12, 0.0))
    with pytest.raises(ExpressionError, match=r"^d/dx of exact\.displacement\[1\] = .*evaluates to nan at x=0, y=0"):
        derivative(0.0, 0.0)


def test_derivatives_and_fields_survive_pickling():
    field = vector_field([compile_expression("atan2(y, x)", name="u1"), compile_expression("x*y", name="u2")])
    copy = pickle.loads(pickle.dumps(field))
    np.testing.assert_array_equal(copy.gradient(POINTS[0], POINTS[1]), field.gradient(POINTS[0], POINTS[1]))
    derivative = pickle.loads(pickle.dumps(field.components[0].derivative("y")))
    assert derivative.name == "d/dy of u1"
    np.testing.assert_allclose(derivative(2.0, 1.0), 2.0 / 5.0, rtol=1e-15)


def test_the_derivative_of_a_deep_chain_is_the_chain_rule_product_in_linear_time():
    """d/dx of sin(sin(...sin(x))) (99 deep) = the product of cos of every inner value; its tree
    shares the inner values, so it is evaluated at 1e5 points in well under 3 s (2 shared cores)."""
    import time

    points = np.linspace(0.1, 0.9, 100_000)
    started = time.perf_counter()
    mine = compile_expression("sin(" * 99 + "x" + ")" * 99, name="u").derivative("x")(points, 0.0)
    elapsed = time.perf_counter() - started
    inner, product = points, np.ones_like(points)
    for _ in range(99):
        product *= np.cos(inner)
        inner = np.sin(inner)
    np.testing.assert_allclose(mine, product, rtol=1e-12)
    assert elapsed < 3.0, elapsed
