"""The whitelist expression compiler of scene values (docs/reference/files.md)."""

import builtins
import math
import pickle

import numpy as np
import pytest

from vemkit.config.expressions import ALLOWED, compile_expression
from vemkit.exceptions import ExpressionError


def test_traction_of_the_paper_is_evaluated_vectorised():
    traction = compile_expression("200*(5-y)", name="boundary.neumann.left.traction[0]")
    x = np.zeros((3, 1))
    y = np.array([0.0, 0.25, 0.5, 1.0])
    values = traction(x, y)
    assert values.shape == (3, 4)
    assert values.dtype == np.float64
    np.testing.assert_array_equal(values, np.broadcast_to(200.0 * (5.0 - y), (3, 4)))
    assert traction.text == "200*(5-y)"
    assert traction.variables == frozenset({"y"})
    assert not traction.is_constant
    assert traction.constant_value is None


@pytest.mark.parametrize(
    "value, expected",
    [(0.1, 0.1), (2, 2.0), ("-200", -200.0), ("2*pi", 2 * math.pi), ("1.5e-3", 1.5e-3), ("+(3)", 3.0), ("2**-1", 0.5)],
)
def test_constants_broadcast_to_the_shape_of_the_points(value, expected):
    expression = compile_expression(value, name="contact.gap")
    assert expression.is_constant
    assert expression.variables == frozenset()
    assert expression.constant_value == pytest.approx(expected)
    values = expression(np.zeros(5), 0.0)
    assert values.shape == (5,) and values.dtype == np.float64
    np.testing.assert_allclose(values, expected)
    assert expression(0.0, 0.0).shape == ()


def test_every_function_and_operator_of_the_grammar():
    x = np.linspace(0.1, 0.9, 7)
    y = np.linspace(0.9, 0.2, 7)
    expression = compile_expression(
        "sin(x)*cos(y) + exp(-x)/sqrt(y) - abs(x-y)**2 + min(x, y, 0.5) - max(x, 2*y) + -pi*x", name="body_force[0]"
    )
    expected = (
        np.sin(x) * np.cos(y)
        + np.exp(-x) / np.sqrt(y)
        - np.abs(x - y) ** 2
        + np.minimum(np.minimum(x, y), 0.5)
        - np.maximum(x, 2 * y)
        - np.pi * x
    )
    np.testing.assert_allclose(expression(x, y), expected, rtol=1e-14)
    assert expression.variables == frozenset({"x", "y"})


def test_integer_literals_are_evaluated_in_floating_point():
    assert compile_expression("1/2").constant_value == 0.5
    assert compile_expression("2**0.5 * 2**0.5").constant_value == pytest.approx(2.0)
    np.testing.assert_allclose(compile_expression("x**2")(np.array([3]), 0), [9.0])


REJECTED = {
    "w+1": "name 'w'",
    "__import__('os')": "'__import__'",
    "x.real": "x.real",
    "open('f')": "'open'",
    "lambda: 1": "lambda",
    "[1,2]": "[1,2]",
    "y if x else 1": "y if x else 1",
    "200*(5-": "not a valid expression",
    "x % 2": "'%'",
    "x // 2": "'//'",
    "x < 1": "comparison",
    "x and y": "and/or",
    "not x": "'not'",
    "~x": "'~'",
    "'abc'": "'abc'",
    "True": "True",
    "1j": "1j",
    "sin": "call it as sin(...)",
    "sin(x, y)": "exactly 1",
    "min(x)": "at least 2",
    "max(x=1, y=2)": "keyword",
    "sin(*x)": "starred",
    "(x := 1)": "assignment",
    "f'{x}'": "f-string",
    "x[0]": "indexing",
    "(1, 2)": "tuple",
    "{1: 2}": "dict",
    "[x for x in y]": "comprehension",
    "x.__class__.__bases__": "attribute",
    "(lambda: 1)()": "calling",
    "": "empty",
}


@pytest.mark.parametrize("text", list(REJECTED))
def test_rejections_name_the_key_the_token_and_what_is_allowed(text):
    with pytest.raises(ExpressionError) as caught:
        compile_expression(text, name="contact.gap")
    message = str(caught.value)
    assert "\n" not in message
    assert message.startswith("contact.gap = ")
    assert REJECTED[text] in message
    assert ALLOWED in message
    assert caught.value.name == "contact.gap"
    assert isinstance(caught.value, ValueError)


@pytest.mark.parametrize("value", [True, None, [1, 2], {"a": 1}, math.inf, math.nan])
def test_non_expressions_are_rejected(value):
    with pytest.raises(ExpressionError, match=r"^material\.E = "):
        compile_expression(value, name="material.E")


def test_overflowing_constants_are_rejected_when_compiled():
    for text in ("9**9**9", "1e400", "1" * 400, "exp(1000)", "1/0", "sqrt(-1)", "(-8)**(1/3)", "10**400/10**399"):
        with pytest.raises(ExpressionError, match="must be finite"):
            compile_expression(text, name="contact.gap")


@pytest.mark.parametrize(
    "text, x, y, shown",
    [
        ("1e400*x", [0.5], [0.5], "inf"),
        ("1/x", [1.0, 0.0], [0.0, 0.0], "inf"),
        ("sqrt(y-0.5)", 0.0, [1.0, 0.25], "nan"),
        ("9**9**9*x", 1.0, 1.0, "inf"),
    ],
)
def test_non_finite_values_raise_at_every_evaluation(text, x, y, shown):
    expression = compile_expression(text, name="boundary.neumann.left.traction[1]")
    with pytest.raises(ExpressionError) as caught:
        expression(np.asarray(x), np.asarray(y))
    message = str(caught.value)
    assert "\n" not in message
    assert message.startswith("boundary.neumann.left.traction[1] = ")
    assert shown in message and "x=" in message and "y=" in message


def test_long_and_deeply_nested_text_is_rejected_quickly():
    with pytest.raises(ExpressionError, match="longer than 2000"):
        compile_expression("x+" * 1200 + "1", name="k")
    with pytest.raises(ExpressionError, match="nested more than"):
        compile_expression("-" * 300 + "x", name="k")
    with pytest.raises(ExpressionError, match="k = "):
        compile_expression("(" * 240 + "x" + ")" * 240, name="k")
    assert compile_expression("(" * 50 + "x" + ")" * 50)(2.0, 0.0) == 2.0


def test_user_text_never_reaches_eval_or_exec(monkeypatch):
    def forbidden(*args, **kwargs):
        raise AssertionError("eval/exec called")

    monkeypatch.setattr(builtins, "eval", forbidden)
    monkeypatch.setattr(builtins, "exec", forbidden)
    expression = compile_expression("max(x, y) + sin(pi*x)", name="k")
    np.testing.assert_allclose(expression([0.5], [0.25]), [0.5 + 1.0])
    with pytest.raises(ExpressionError):
        compile_expression("__import__('os').system('true')", name="k")


def test_expressions_survive_pickling():
    expression = compile_expression("200*(5-y)", name="boundary.neumann.left.traction[0]")
    copy = pickle.loads(pickle.dumps(expression))
    assert copy.text == expression.text and copy.name == expression.name
    np.testing.assert_array_equal(copy(0.0, [0.0, 1.0]), [1000.0, 800.0])
