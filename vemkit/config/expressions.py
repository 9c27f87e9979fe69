"""Safe, vectorised scalar expressions for scene values such as ``"200*(5-y)"``.

Language (docs/reference/files.md; README "Input rules and limits"): numbers (ints, floats, scientific notation),
the variables ``x``, ``y`` and ``z`` (a 2D scene refuses z: ``vemkit.config.boundary_conditions``),
the constant ``pi``, the operators ``+ - * / **``, unary ``-`` and ``+``, parentheses, the functions
``sin cos tan asin acos atan sinh cosh tanh exp log sqrt abs sign`` (one argument), ``atan2(p, q)``
and ``min max`` (two or more arguments), and ``where(condition, a, b)`` whose condition compares
values (``< <= > >= == !=``, chained ``0 < x < 1``) joined by ``and or not`` (or ``&``, ``|``).

The text is parsed by :mod:`vemkit.config.expression_tree` (a whitelist of ``ast`` nodes into a
small tree; user text is never passed to ``eval``/``exec``) and evaluated with numpy closures.
Everything is evaluated in float64 (integer literals included), so ``9**9**9`` overflows to
``inf`` instead of hanging, and every evaluation checks that the result is finite: a NaN or an
infinity (``log(-1)``, ``1/0`` at a point) raises :class:`ExpressionError` naming the scene key, so
callers cannot forget the check. :meth:`Expression.derivative` is the exact partial derivative
(:mod:`vemkit.config.expression_calculus`), checked the same way.
"""

from __future__ import annotations

import math
from functools import partial
from numbers import Real

import numpy as np

from vemkit.config.expression_calculus import derivative
from vemkit.config.expression_tree import (
    ALLOWED,
    CONSTANTS,
    FUNCTIONS,
    MAX_NESTING_DEPTH,
    VARIABLES,
    Node,
    evaluator,
    fail,
    parse_tree,
    shorten,
    tree_variables,
)
from vemkit.exceptions import ExpressionError

__all__ = [
    "ALLOWED",
    "CONSTANTS",
    "FUNCTIONS",
    "MAX_NESTING_DEPTH",
    "VARIABLES",
    "Expression",
    "ExpressionError",
    "VectorField",
    "compile_expression",
    "vector_field",
]

MAX_EXPRESSION_LENGTH = 2000


class Expression:
    """A compiled scene expression; ``expr(x, y)`` (``expr(x, y, z)`` if it uses z) returns a
    float64 array of the broadcast shape.

    Attributes: ``text`` (the source text, or the number's repr), ``name`` (the scene key, used in
    error messages), ``is_constant`` (no variables), ``variables`` (frozenset of ``"x"``/``"y"``/
    ``"z"``), ``constant_value`` (the float value if constant, else ``None``).
    Every call raises :class:`ExpressionError` if any value is NaN or infinite.
    """

    __slots__ = ("text", "name", "variables", "constant_value", "_function", "_tree", "_origin")

    def __init__(self, text: str, name: str, tree: Node, origin=None):
        self.text = text
        self.name = name
        self.variables = tree_variables(tree)
        kind, compiled = evaluator(tree)
        self.constant_value = compiled if kind == "const" else None
        self._function = compiled if kind == "func" else None
        self._tree = tree
        self._origin = origin  # (expression, variable) of a derivative, for pickling

    @property
    def is_constant(self) -> bool:
        return self.constant_value is not None

    def __call__(self, x, y, z=None) -> np.ndarray:
        if z is None and "z" in self.variables:
            raise ExpressionError(
                f"{self.name} = {shorten(self.text)!r}: uses z, but it is evaluated in the "
                "plane (x, y); z is for 3D scenes",
                name=self.name,
                text=self.text,
            )
        points = [np.asarray(v, dtype=np.float64) for v in ((x, y) if z is None else (x, y, z))]
        shape = np.broadcast_shapes(*(p.shape for p in points))
        if self.constant_value is not None:
            return np.full(shape, self.constant_value, dtype=np.float64)
        with np.errstate(all="ignore"):
            value = self._function(points[0], points[1], points[-1])
        result = np.array(np.broadcast_to(value, shape), dtype=np.float64)
        finite = np.isfinite(result)
        if not finite.all():
            where = tuple(np.argwhere(~finite)[0])
            at = ", ".join(f"{label}={np.broadcast_to(p, shape)[where]:.6g}" for label, p in zip("xyz", points))
            raise ExpressionError(
                f"{self.name} = {shorten(self.text)!r}: evaluates to {result[where]} at "
                f"{at}; the expression must be finite on the domain",
                name=self.name,
                text=self.text,
            )
        return result

    def derivative(self, variable: str) -> Expression:
        """The exact partial derivative d/d``variable`` (x, y or z) as an Expression; its errors
        name ``d/dx of <key>`` and the original text."""
        if variable not in VARIABLES:
            raise ValueError(f"variable {variable!r}: expected one of {', '.join(VARIABLES)}")
        return Expression(
            self.text, f"d/d{variable} of {self.name}", derivative(self._tree, variable), origin=(self, variable)
        )

    def __reduce__(self):
        if self._origin is not None:
            return (Expression.derivative, self._origin)
        return (partial(compile_expression, name=self.name), (self.text,))

    def __repr__(self) -> str:
        return f"Expression({self.text!r}, name={self.name!r})"


def compile_expression(value, *, name: str = "expression") -> Expression:
    """Compile a number or an expression string into an :class:`Expression`.

    ``name`` is the scene key (e.g. ``"contact.gap"``) used in every error message.
    Raises :class:`ExpressionError` (a ``ValueError``) with a one-line message.
    """
    if isinstance(value, Real) and not isinstance(value, bool):
        constant = float(value)
        if not math.isfinite(constant):
            raise ExpressionError(f"{name} = {constant}: must be a finite number", name=name, text=repr(constant))
        return Expression(repr(constant), name, Node("num", value=constant))
    if not isinstance(value, str):
        raise ExpressionError(
            f"{name} = {shorten(repr(value))}: expected a number or an expression string; {ALLOWED}", name=name
        )
    text = value.strip()
    if not text:
        raise fail(name, text, "empty expression")
    if len(text) > MAX_EXPRESSION_LENGTH:
        raise fail(name, text, f"longer than {MAX_EXPRESSION_LENGTH} characters", hint=False)
    expression = Expression(text, name, parse_tree(text, name))
    if expression.is_constant and not math.isfinite(expression.constant_value):
        raise fail(name, text, f"evaluates to {expression.constant_value}; the expression must be finite", hint=False)
    return expression


class VectorField:
    """Expressions (f1, f2, ...) as one field: ``field(x, y)`` -> (f1(x, y), f2(x, y), ...) (each
    broadcast to x, y; 3D: ``field(x, y, z)``); ``field.gradient(x, y)`` -> array (components, 2,
    *shape) of the exact derivatives [i, j] = d f_i / d x_j (x_1 = x, x_2 = y; 3D: (components, 3,
    *shape) from ``field.gradient(x, y, z)``)."""

    __slots__ = ("components", "_derivatives")

    def __init__(self, expressions):
        self.components = tuple(expressions)
        self._derivatives = None  # compiled on the first gradient

    def __call__(self, x, y, z=None):
        return tuple(f(x, y, z) for f in self.components)

    def gradient(self, x, y, z=None) -> np.ndarray:
        """(components, d, *shape): d = 2 for points (x, y), 3 for (x, y, z)."""
        variables = ("x", "y") if z is None else ("x", "y", "z")
        if self._derivatives is None or len(self._derivatives[0]) != len(variables):
            self._derivatives = [[f.derivative(v) for v in variables] for f in self.components]
        return np.array([[d(x, y, z) for d in row] for row in self._derivatives], dtype=np.float64)

    def __reduce__(self):
        return (VectorField, (self.components,))


def vector_field(expressions) -> VectorField:
    """(fx, fy) Expressions as one :class:`VectorField` with an exact gradient."""
    return VectorField(expressions)
