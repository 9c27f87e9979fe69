"""Safe, vectorised scalar expressions for scene values such as ``"200*(5-y)"``.

Grammar (SPEC §6): numbers (ints, floats, scientific notation), the variables ``x`` and ``y``,
the constant ``pi``, the operators ``+ - * / **``, unary ``-`` and ``+``, parentheses, and the
functions ``sin cos exp sqrt abs`` (one argument) and ``min max`` (two or more arguments).

The text is parsed with :func:`ast.parse` in ``mode="eval"`` and the tree is translated node by
node from a whitelist into numpy closures; user text is never passed to ``eval``/``exec``.
Everything is evaluated in float64 (integer literals included), so ``9**9**9`` overflows to
``inf`` instead of hanging, and every evaluation checks that the result is finite: a NaN or an
infinity raises :class:`ExpressionError` naming the scene key, so callers cannot forget the check.
"""

from __future__ import annotations

import ast
import math
from functools import partial, reduce
from numbers import Real

import numpy as np

from vemkit.exceptions import ExpressionError

__all__ = ["Expression", "ExpressionError", "compile_expression", "vector_field"]

MAX_EXPRESSION_LENGTH = 2000
MAX_NESTING_DEPTH = 100
VARIABLES = ("x", "y")
CONSTANTS = {"pi": math.pi}
# name -> (numpy function, minimum number of arguments, maximum number of arguments or None)
FUNCTIONS = {
    "sin": (np.sin, 1, 1),
    "cos": (np.cos, 1, 1),
    "exp": (np.exp, 1, 1),
    "sqrt": (np.sqrt, 1, 1),
    "abs": (np.abs, 1, 1),
    "min": (np.minimum, 2, None),
    "max": (np.maximum, 2, None),
}
ALLOWED = "use x, y, pi, numbers, + - * / ** ( ) and sin cos exp sqrt abs min max"

_BINARY_OPERATORS = {ast.Add: np.add, ast.Sub: np.subtract, ast.Mult: np.multiply,
                     ast.Div: np.true_divide, ast.Pow: np.power}
_UNARY_OPERATORS = {ast.USub: np.negative, ast.UAdd: np.positive}
_OPERATOR_SYMBOLS = {ast.Mod: "%", ast.FloorDiv: "//", ast.MatMult: "@", ast.LShift: "<<",
                     ast.RShift: ">>", ast.BitOr: "|", ast.BitXor: "^", ast.BitAnd: "&",
                     ast.Not: "not", ast.Invert: "~"}
_NODE_DESCRIPTIONS = {
    ast.Attribute: "attribute access", ast.Subscript: "indexing", ast.Slice: "a slice",
    ast.Lambda: "a lambda", ast.IfExp: "a conditional expression", ast.Compare: "a comparison",
    ast.BoolOp: "and/or", ast.List: "a list", ast.Tuple: "a tuple", ast.Dict: "a dict",
    ast.Set: "a set", ast.ListComp: "a comprehension", ast.SetComp: "a comprehension",
    ast.DictComp: "a comprehension", ast.GeneratorExp: "a generator",
    ast.NamedExpr: "an assignment", ast.Starred: "a starred argument",
    ast.JoinedStr: "an f-string", ast.FormattedValue: "an f-string", ast.Await: "await",
    ast.Yield: "yield", ast.YieldFrom: "yield",
}


def _nesting_depth(text: str) -> int:
    """The depth of ``text``'s syntax tree where a chain of one binary operator (a + b + c + ...)
    counts as one level: what a reader calls nesting (only for the message of the depth limit)."""
    try:
        stack, deepest = [(ast.parse(text, mode="eval").body, 0)], 0
    except (SyntaxError, RecursionError, MemoryError, ValueError):
        return MAX_NESTING_DEPTH + 1
    while stack:
        node, depth = stack.pop()
        deepest = max(deepest, depth)
        for child in ast.iter_child_nodes(node):
            chained = isinstance(node, ast.BinOp) and isinstance(child, ast.BinOp) and type(child.op) is type(node.op)
            stack.append((child, depth if chained else depth + 1))
    return deepest


def _shorten(text: str, limit: int = 60) -> str:
    return text if len(text) <= limit else text[: limit - 3] + "..."


class _Compiler:
    """Translates a whitelisted AST into a closure ``f(x, y)``; constant subtrees are folded."""

    def __init__(self, text: str, name: str):
        self.text = text
        self.name = name
        self.variables: set[str] = set()

    def fail(self, problem: str, *, hint: bool = True) -> ExpressionError:
        message = f"{self.name} = {_shorten(self.text)!r}: {problem}"
        return ExpressionError(f"{message}; {ALLOWED}" if hint else message,
                               name=self.name, text=self.text)

    def segment(self, node: ast.AST) -> str:
        try:
            source = ast.get_source_segment(self.text, node)
        except Exception:  # pragma: no cover - get_source_segment is best effort
            source = None
        return _shorten(source or type(node).__name__, 40)

    def compile(self, node: ast.AST, depth: int = 0):
        """Return ``("const", float)`` or ``("func", callable(x, y))`` for ``node``."""
        if depth > MAX_NESTING_DEPTH and _nesting_depth(self.text) > MAX_NESTING_DEPTH:
            raise self.fail(f"nested more than {MAX_NESTING_DEPTH} levels deep", hint=False)
        if depth > MAX_NESTING_DEPTH:  # a long flat chain: a + b + c + ... is not nested
            raise self.fail(f"more than {MAX_NESTING_DEPTH} operations in one chain (a sum or product of "
                            "that many terms); group the terms in parentheses, e.g. (a + b + ...) + (c + ...)",
                            hint=False)
        if isinstance(node, ast.Constant):
            return self.compile_constant(node)
        if isinstance(node, ast.Name):
            return self.compile_name(node)
        if isinstance(node, ast.BinOp):
            operator = _BINARY_OPERATORS.get(type(node.op))
            if operator is None:
                raise self.fail(f"operator {_OPERATOR_SYMBOLS.get(type(node.op), '?')!r} "
                                "is not allowed in an expression")
            return self.combine(operator, [self.compile(node.left, depth + 1),
                                           self.compile(node.right, depth + 1)])
        if isinstance(node, ast.UnaryOp):
            operator = _UNARY_OPERATORS.get(type(node.op))
            if operator is None:
                raise self.fail(f"operator {_OPERATOR_SYMBOLS.get(type(node.op), '?')!r} "
                                "is not allowed in an expression")
            return self.combine(operator, [self.compile(node.operand, depth + 1)])
        if isinstance(node, ast.Call):
            return self.compile_call(node, depth)
        description = _NODE_DESCRIPTIONS.get(type(node), type(node).__name__)
        raise self.fail(f"{self.segment(node)!r} ({description}) is not allowed in an expression")

    def compile_constant(self, node: ast.Constant):
        value = node.value
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.fail(f"{self.segment(node)!r} is not allowed in an expression "
                            "(only real numbers)")
        try:
            return ("const", float(value))
        except OverflowError:  # an integer literal beyond the float range
            return ("const", math.inf)

    def compile_name(self, node: ast.Name):
        if node.id in VARIABLES:
            self.variables.add(node.id)
            index = VARIABLES.index(node.id)
            return ("func", (lambda x, y: x) if index == 0 else (lambda x, y: y))
        if node.id in CONSTANTS:
            return ("const", CONSTANTS[node.id])
        if node.id in FUNCTIONS:
            raise self.fail(f"{node.id!r} is a function; call it as {node.id}(...)")
        raise self.fail(f"name {node.id!r} is not allowed in an expression")

    def compile_call(self, node: ast.Call, depth: int):
        if not isinstance(node.func, ast.Name):
            raise self.fail(f"calling {self.segment(node.func)!r} is not allowed in an expression")
        function_name = node.func.id
        if function_name not in FUNCTIONS:
            raise self.fail(f"function {function_name!r} is not allowed in an expression")
        if node.keywords:
            keyword = node.keywords[0].arg
            raise self.fail(f"keyword argument {(keyword or '**') + '='!r} in "
                            f"{function_name}(...) is not allowed in an expression")
        function, least, most = FUNCTIONS[function_name]
        count = len(node.args)
        if count < least or (most is not None and count > most):
            wanted = f"exactly {least}" if most == least else f"at least {least}"
            raise self.fail(f"{function_name}(...) takes {wanted} argument"
                            f"{'s' if least > 1 else ''}, got {count}")
        arguments = [self.compile(argument, depth + 1) for argument in node.args]
        if most == 1:
            return self.combine(function, arguments)
        return self.combine(lambda *values: reduce(function, values), arguments)

    @staticmethod
    def combine(operator, arguments):
        """Apply ``operator`` to compiled arguments; fold it when every argument is constant."""
        if all(kind == "const" for kind, _ in arguments):
            with np.errstate(all="ignore"):
                return ("const", float(operator(*[np.float64(v) for _, v in arguments])))
        parts = [(lambda x, y, v=np.float64(v): v) if kind == "const" else v
                 for kind, v in arguments]
        if len(parts) == 1:
            (part,) = parts
            return ("func", lambda x, y: operator(part(x, y)))
        if len(parts) == 2:
            first, second = parts
            return ("func", lambda x, y: operator(first(x, y), second(x, y)))
        return ("func", lambda x, y: operator(*[part(x, y) for part in parts]))


class Expression:
    """A compiled scene expression; ``expr(x, y)`` returns a float64 array of the broadcast shape.

    Attributes: ``text`` (the source text, or the number's repr), ``name`` (the scene key, used in
    error messages), ``is_constant`` (no variables), ``variables`` (frozenset of ``"x"``/``"y"``),
    ``constant_value`` (the float value if constant, else ``None``).
    Every call raises :class:`ExpressionError` if any value is NaN or infinite.
    """

    __slots__ = ("text", "name", "variables", "constant_value", "_function")

    def __init__(self, text: str, name: str, variables: frozenset, constant_value, function):
        self.text = text
        self.name = name
        self.variables = variables
        self.constant_value = constant_value
        self._function = function

    @property
    def is_constant(self) -> bool:
        return self.constant_value is not None

    def __call__(self, x, y) -> np.ndarray:
        x = np.asarray(x, dtype=np.float64)
        y = np.asarray(y, dtype=np.float64)
        shape = np.broadcast_shapes(x.shape, y.shape)
        if self.constant_value is not None:
            return np.full(shape, self.constant_value, dtype=np.float64)
        with np.errstate(all="ignore"):
            value = self._function(x, y)
        result = np.array(np.broadcast_to(value, shape), dtype=np.float64)
        finite = np.isfinite(result)
        if not finite.all():
            where = tuple(np.argwhere(~finite)[0])
            x_bad = np.broadcast_to(x, shape)[where]
            y_bad = np.broadcast_to(y, shape)[where]
            raise ExpressionError(
                f"{self.name} = {_shorten(self.text)!r}: evaluates to {result[where]} at "
                f"x={x_bad:.6g}, y={y_bad:.6g}; the expression must be finite on the domain",
                name=self.name, text=self.text)
        return result

    def __reduce__(self):
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
            raise ExpressionError(f"{name} = {constant}: must be a finite number",
                                  name=name, text=repr(constant))
        return Expression(repr(constant), name, frozenset(), constant, None)
    if not isinstance(value, str):
        raise ExpressionError(f"{name} = {_shorten(repr(value))}: expected a number or an "
                              f"expression string; {ALLOWED}", name=name)
    text = value.strip()
    compiler = _Compiler(text, name)
    if not text:
        raise compiler.fail("empty expression")
    if len(text) > MAX_EXPRESSION_LENGTH:
        raise compiler.fail(f"longer than {MAX_EXPRESSION_LENGTH} characters", hint=False)
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as error:
        reason = error.msg or "invalid syntax"
        column = f" at column {error.offset}" if error.offset else ""
        raise compiler.fail(f"not a valid expression ({reason}{column})") from None
    except (RecursionError, MemoryError, ValueError):
        raise compiler.fail("not a valid expression (too complex)", hint=False) from None
    kind, compiled = compiler.compile(tree.body)
    variables = frozenset(compiler.variables)
    if kind == "const":
        if not math.isfinite(compiled):
            raise compiler.fail(f"evaluates to {compiled}; the expression must be finite", hint=False)
        return Expression(text, name, variables, compiled, None)
    return Expression(text, name, variables, None, compiled)


def vector_field(expressions):
    """(fx, fy) Expressions as one field (x, y) -> (fx(x, y), fy(x, y)) (each broadcast to x, y)."""
    fx, fy = expressions
    return lambda x, y: (fx(x, y), fy(x, y))
