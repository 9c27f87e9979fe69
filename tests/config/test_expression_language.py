"""The functions, conditions and the variable z of the expression language (issue 18, item 7), against numpy."""

import math

import numpy as np
import pytest

from vemkit.config.expressions import ALLOWED, compile_expression
from vemkit.exceptions import ExpressionError

RNG = np.random.default_rng(18)
X = RNG.uniform(-0.9, 0.9, 200)
Y = RNG.uniform(-0.9, 0.9, 200)
Z = RNG.uniform(-0.9, 0.9, 200)

# text -> the same function written with numpy, on points of (-0.9, 0.9)^2
FUNCTIONS = {
    "atan2(y, x)": lambda x, y: np.arctan2(y, x),
    "atan(x/0.3)": lambda x, y: np.arctan(x / 0.3),
    "tan(x)": lambda x, y: np.tan(x),
    "asin(x)": lambda x, y: np.arcsin(x),
    "acos(y)": lambda x, y: np.arccos(y),
    "log(x**2 + y**2)": lambda x, y: np.log(x**2 + y**2),
    "sinh(2*x)": lambda x, y: np.sinh(2 * x),
    "cosh(x - y)": lambda x, y: np.cosh(x - y),
    "tanh(3*y)": lambda x, y: np.tanh(3 * y),
    "sign(x)": lambda x, y: np.sign(x),
    "pi*x": lambda x, y: np.pi * x,
    "where(x < y, x, y**2)": lambda x, y: np.where(x < y, x, y**2),
    "where(x <= 0, -1, 1)": lambda x, y: np.where(x <= 0, -1.0, 1.0),
    "where(x > 0.1, 1, 0)": lambda x, y: np.where(x > 0.1, 1.0, 0.0),
    "where(x >= y, x, 0)": lambda x, y: np.where(x >= y, x, 0.0),
    "where(x == x, 2, 3)": lambda x, y: np.full_like(x, 2.0),
    "where(x != y, 1, 0)": lambda x, y: np.ones_like(x),
    "where(x > 0 and y > 0, 1, 0)": lambda x, y: ((x > 0) & (y > 0)).astype(float),
    "where(x > 0 or not y > 0, 1, 0)": lambda x, y: ((x > 0) | ~(y > 0)).astype(float),
    "where((x > 0) & (y < 0) | (x < -0.5), 1, 0)": lambda x, y: (((x > 0) & (y < 0)) | (x < -0.5)).astype(float),
    "where(-0.5 < x < 0.5, x, 0)": lambda x, y: np.where((-0.5 < x) & (x < 0.5), x, 0.0),
    # a singular corner solution r^(2/3) cos(2 theta / 3) and a load in polar coordinates
    "sqrt(x**2+y**2)**(2/3)*cos(2*atan2(y,x)/3)": lambda x, y: (
        np.hypot(x, y) ** (2 / 3) * np.cos(2 * np.arctan2(y, x) / 3)
    ),
    "100*cos(atan2(y, x))*exp(-sqrt(x**2+y**2))": lambda x, y: 100 * np.cos(np.arctan2(y, x)) * np.exp(-np.hypot(x, y)),
    "where(x > 0, sqrt(x), 0)": lambda x, y: np.sqrt(np.maximum(x, 0.0)),  # the unused branch may be NaN
}


@pytest.mark.parametrize("text", list(FUNCTIONS))
def test_every_function_and_condition_matches_numpy(text):
    expression = compile_expression(text, name="body_force[0]")
    np.testing.assert_allclose(expression(X, Y), FUNCTIONS[text](X, Y), rtol=1e-14, atol=1e-15)


def test_constant_conditions_fold_to_constants():
    expression = compile_expression("where(pi > 3, 2*atan(1), log(-1))", name="contact.gap")
    assert expression.is_constant and expression.constant_value == pytest.approx(math.pi / 2)


def test_z_is_a_variable_of_the_language_evaluated_with_three_coordinates():
    expression = compile_expression("x*y + sin(z)", name="body_force[2]")
    assert expression.variables == frozenset({"x", "y", "z"})
    np.testing.assert_allclose(expression(X, Y, Z), X * Y + np.sin(Z), rtol=1e-14)
    with pytest.raises(ExpressionError, match=r"^body_force\[2\] = 'x\*y \+ sin\(z\)': uses z"):
        expression(X, Y)
    assert compile_expression("x + y")(1.0, 2.0, 5.0) == 3.0  # z given, not used


@pytest.mark.parametrize(
    "text, x, y, shown",
    [
        ("log(x)", [0.5, -0.25], 0.0, "nan"),
        ("log(x)", [0.5, 0.0], 0.0, "-inf"),
        ("1/(x - y)", [0.5, 0.25], [0.0, 0.25], "inf"),
        ("asin(2*x)", [0.1, 0.75], 0.0, "nan"),
        ("tan(x)**1000", [0.1, 1.5], 0.0, "inf"),
        ("where(x > 0, 1/y, 0)", [1.0], [0.0], "inf"),
    ],
)
def test_domain_errors_raise_at_the_point_like_sqrt_does(text, x, y, shown):
    expression = compile_expression(text, name="boundary.neumann.left.traction[0]")
    with pytest.raises(ExpressionError) as caught:
        expression(np.asarray(x), np.asarray(y))
    message = str(caught.value)
    assert "\n" not in message and message.startswith("boundary.neumann.left.traction[0] = ")
    assert f"evaluates to {shown} at x=" in message and "must be finite" in message


REFUSED = {
    "ln(x)": "function 'ln'",
    "atan2(y)": "atan2(...) takes exactly 2 arguments, got 1",
    "log(x, 10)": "log(...) takes exactly 1 argument, got 2",
    "where(x < 0, 1)": "where(...) takes exactly 3 arguments, got 2",
    "where(x, 1, 0)": "the condition 'x' of where(...) must be a comparison",
    "where(x < 0 and y, 1, 0)": "the condition 'y' of where(...) must be a comparison",
    "where(x < 1, y < 1, 0)": "not allowed outside the condition of where",
    "x < 1": "(a comparison) is not allowed outside the condition",
    "x > 0 and y > 0": "(and/or) is not allowed outside the condition",
    "where(x < 1 & y < 1, 1, 0)": "write (x < 1) & (y < 1)",
    "where(x is y, 1, 0)": "operator 'is' is not allowed in a condition",
    "where(x in y, 1, 0)": "operator 'in' is not allowed in a condition",
    "x if x > 0 else 0": "write where(condition, a, b)",
    "math.atan2(y, x)": "calling 'math.atan2'",
    "atan2.__call__": "attribute access",
    "where": "call it as where(...)",
    "e": "name 'e'",
    "log('x')": "only real numbers",
}


@pytest.mark.parametrize("text", list(REFUSED))
def test_bad_text_is_refused_naming_the_key_and_the_fix(text):
    with pytest.raises(ExpressionError) as caught:
        compile_expression(text, name="contact.gap")
    message = str(caught.value)
    assert "\n" not in message and message.startswith("contact.gap = ")
    assert REFUSED[text] in message
    assert "where(condition, a, b)" in ALLOWED and "atan2" in ALLOWED


@pytest.mark.parametrize(
    "override, key",
    [
        ("body_force=[0, 'z']", "body_force[1]"),
        ("contact.gap=0.1+z", "contact.gap"),
        ("boundary.neumann.top.traction=['sin(z)', 0]", "boundary.neumann.top.traction[0]"),
        ("boundary.dirichlet={right: [0, 'z*y']}", "boundary.dirichlet.right[1]"),
        ("exact={displacement: [x, 'x*z']}", "exact.displacement[1]"),
    ],
)
def test_a_2d_scene_refuses_z_naming_the_key(override, key):
    from pathlib import Path

    from vemkit.config.scene import load_scene
    from vemkit.exceptions import SceneError

    paper = load_scene(Path(__file__).resolve().parents[2] / "config" / "scenes" / "paper.yaml")
    with pytest.raises(SceneError) as caught:
        paper.with_overrides([override])
    message = str(caught.value)
    assert message.startswith(f"{key} = ") and "uses z, but this scene is 2D" in message and "\n" not in message
    assert caught.value.key == key
