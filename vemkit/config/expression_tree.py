"""The whitelisted expression language of scene values (docs/reference/files.md), parsed into a small tree.

User text is parsed by :func:`ast.parse` in ``mode="eval"`` and translated node by node, from a
whitelist only, into :class:`Node` trees; nothing the user writes is ever passed to ``eval``/``exec``.
The same tree is evaluated with numpy (:func:`evaluator`) and differentiated symbolically
(:mod:`vemkit.config.expression_calculus`).

Tree operations (``Node.op``): ``num`` (value: float), ``var`` (value: "x", "y" or "z"), the
arithmetic ``add sub mul div pow neg``, every name of :data:`FUNCTIONS` (``min``/``max`` with two or
more arguments, ``where`` = where(condition, a, b)), the comparisons ``< <= > >= == !=`` and the
logical ``and or not``; comparisons and logical operations are conditions, allowed only as the first
argument of ``where`` (their values are 1.0 for true, 0.0 for false).
"""

from __future__ import annotations

import ast
import math
from functools import reduce
from typing import NamedTuple

import numpy as np

from vemkit.exceptions import ExpressionError

__all__ = [
    "ALLOWED",
    "CONDITIONS",
    "CONSTANTS",
    "FUNCTIONS",
    "MAX_NESTING_DEPTH",
    "Node",
    "VARIABLES",
    "evaluator",
    "fail",
    "parse_tree",
    "shorten",
    "tree_variables",
]

MAX_NESTING_DEPTH = 100
VARIABLES = ("x", "y", "z")
CONSTANTS = {"pi": math.pi}
# name -> (numpy function, least number of arguments, most number of arguments or None)
FUNCTIONS = {
    "sin": (np.sin, 1, 1),
    "cos": (np.cos, 1, 1),
    "tan": (np.tan, 1, 1),
    "asin": (np.arcsin, 1, 1),
    "acos": (np.arccos, 1, 1),
    "atan": (np.arctan, 1, 1),
    "atan2": (np.arctan2, 2, 2),
    "sinh": (np.sinh, 1, 1),
    "cosh": (np.cosh, 1, 1),
    "tanh": (np.tanh, 1, 1),
    "exp": (np.exp, 1, 1),
    "log": (np.log, 1, 1),
    "sqrt": (np.sqrt, 1, 1),
    "abs": (np.abs, 1, 1),
    "sign": (np.sign, 1, 1),
    "min": (np.minimum, 2, None),
    "max": (np.maximum, 2, None),
    "where": (np.where, 3, 3),
}
ALLOWED = (
    "use x, y, pi, numbers, + - * / ** ( ) and "
    + " ".join(name for name in FUNCTIONS if name != "where")
    + ", where(condition, a, b) with < <= > >= == != and or not"
)
ARITHMETIC = {
    "add": np.add,
    "sub": np.subtract,
    "mul": np.multiply,
    "div": np.true_divide,
    "pow": np.power,
    "neg": np.negative,
}
CONDITIONS = {
    "<": np.less,
    "<=": np.less_equal,
    ">": np.greater,
    ">=": np.greater_equal,
    "==": np.equal,
    "!=": np.not_equal,
    "and": np.logical_and,
    "or": np.logical_or,
    "not": np.logical_not,
}

_BINARY = {ast.Add: "add", ast.Sub: "sub", ast.Mult: "mul", ast.Div: "div", ast.Pow: "pow"}
_COMPARISONS = {ast.Lt: "<", ast.LtE: "<=", ast.Gt: ">", ast.GtE: ">=", ast.Eq: "==", ast.NotEq: "!="}
_SYMBOLS = {
    ast.Mod: "%",
    ast.FloorDiv: "//",
    ast.MatMult: "@",
    ast.LShift: "<<",
    ast.RShift: ">>",
    ast.BitOr: "|",
    ast.BitXor: "^",
    ast.BitAnd: "&",
    ast.Not: "not",
    ast.Invert: "~",
    ast.Is: "is",
    ast.IsNot: "is not",
    ast.In: "in",
    ast.NotIn: "not in",
}
_DESCRIPTIONS = {
    ast.Attribute: "attribute access",
    ast.Subscript: "indexing",
    ast.Slice: "a slice",
    ast.Lambda: "a lambda",
    ast.IfExp: "a conditional expression",
    ast.Compare: "a comparison",
    ast.BoolOp: "and/or",
    ast.List: "a list",
    ast.Tuple: "a tuple",
    ast.Dict: "a dict",
    ast.Set: "a set",
    ast.ListComp: "a comprehension",
    ast.SetComp: "a comprehension",
    ast.DictComp: "a comprehension",
    ast.GeneratorExp: "a generator",
    ast.NamedExpr: "an assignment",
    ast.Starred: "a starred argument",
    ast.JoinedStr: "an f-string",
    ast.FormattedValue: "an f-string",
    ast.Await: "await",
    ast.Yield: "yield",
    ast.YieldFrom: "yield",
}
_WHERE_HINT = "write where(condition, a, b), e.g. where(x < 0.5, 1, 0)"


class Node(NamedTuple):
    """One operation of an expression tree (module docstring); ``args`` are Nodes."""

    op: str
    args: tuple = ()
    value: object = None


def shorten(text: str, limit: int = 60) -> str:
    return text if len(text) <= limit else text[: limit - 3] + "..."


def nesting_depth(text: str) -> int:
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


def fail(name: str, text: str, problem: str, *, hint: bool = True) -> ExpressionError:
    """The one-line error of scene key ``name`` = ``text``, with the language summary if ``hint``."""
    message = f"{name} = {shorten(text)!r}: {problem}"
    return ExpressionError(f"{message}; {ALLOWED}" if hint else message, name=name, text=text)


class _Parser:
    """Whitelist translation of a Python AST into a :class:`Node` tree."""

    def __init__(self, text: str, name: str):
        self.text, self.name = text, name

    def fail(self, problem: str, *, hint: bool = True) -> ExpressionError:
        return fail(self.name, self.text, problem, hint=hint)

    def too_deep(self) -> ExpressionError:
        """The depth limit: truly nested, or a long flat chain a + b + c + ... (which is not nested)."""
        if nesting_depth(self.text) > MAX_NESTING_DEPTH:
            return self.fail(f"nested more than {MAX_NESTING_DEPTH} levels deep", hint=False)
        return self.fail(
            f"more than {MAX_NESTING_DEPTH} operations in one chain (a sum or product of that many "
            "terms); group the terms in parentheses, e.g. (a + b + ...) + (c + ...)",
            hint=False,
        )

    def segment(self, node: ast.AST) -> str:
        try:
            source = ast.get_source_segment(self.text, node)
        except Exception:  # pragma: no cover - get_source_segment is best effort
            source = None
        return shorten(source or type(node).__name__, 40)

    def refuse(self, node: ast.AST, where: str = "in an expression", extra: str = ""):
        description = _DESCRIPTIONS.get(type(node), type(node).__name__)
        return self.fail(f"{self.segment(node)!r} ({description}) is not allowed {where}{extra}")

    def value(self, node: ast.AST, depth: int = 0) -> Node:
        """A numeric subtree (conditions are refused here)."""
        if depth > MAX_NESTING_DEPTH:
            raise self.too_deep()
        if isinstance(node, ast.Constant):
            return self.constant(node)
        if isinstance(node, ast.Name):
            return self.name_node(node)
        if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
            return Node(_BINARY[type(node.op)], (self.value(node.left, depth + 1), self.value(node.right, depth + 1)))
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
            operand = self.value(node.operand, depth + 1)
            return Node("neg", (operand,)) if isinstance(node.op, ast.USub) else operand
        if isinstance(node, (ast.BinOp, ast.UnaryOp)):
            symbol = _SYMBOLS.get(type(node.op), "?")
            where = (
                f" (it joins conditions in where(...): write (x < 1) {symbol} (y < 1))"
                if symbol in ("&", "|")
                else " (it negates a condition in where(...))"
                if symbol == "not"
                else ""
            )
            raise self.fail(f"operator {symbol!r} is not allowed in an expression{where}")
        if isinstance(node, ast.Call):
            return self.call(node, depth)
        if isinstance(node, (ast.Compare, ast.BoolOp)):
            raise self.refuse(node, "outside the condition of where(condition, a, b)")
        if isinstance(node, ast.IfExp):
            raise self.refuse(node, extra=f"; {_WHERE_HINT}")
        raise self.refuse(node)

    def condition(self, node: ast.AST, depth: int) -> Node:
        """A condition: comparisons (chained ones as ``and``) joined by and/or/not or & |."""
        if depth > MAX_NESTING_DEPTH:
            raise self.too_deep()
        if isinstance(node, ast.Compare):
            operands = [self.value(part, depth + 1) for part in [node.left, *node.comparators]]
            pairs = []
            for op, left, right in zip(node.ops, operands, operands[1:]):
                if type(op) not in _COMPARISONS:
                    raise self.fail(f"operator {_SYMBOLS.get(type(op), '?')!r} is not allowed in a condition")
                pairs.append(Node(_COMPARISONS[type(op)], (left, right)))
            return pairs[0] if len(pairs) == 1 else Node("and", tuple(pairs))
        if isinstance(node, ast.BoolOp):
            op = "and" if isinstance(node.op, ast.And) else "or"
            return Node(op, tuple(self.condition(part, depth + 1) for part in node.values))
        if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.BitAnd, ast.BitOr)):
            op = "and" if isinstance(node.op, ast.BitAnd) else "or"
            return Node(op, (self.condition(node.left, depth + 1), self.condition(node.right, depth + 1)))
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not):
            return Node("not", (self.condition(node.operand, depth + 1),))
        raise self.fail(
            f"the condition {self.segment(node)!r} of where(...) must be a comparison such as "
            "x < 0.5 (joined by and, or, not)"
        )

    def constant(self, node: ast.Constant) -> Node:
        value = node.value
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.fail(f"{self.segment(node)!r} is not allowed in an expression (only real numbers)")
        try:
            return Node("num", value=float(value))
        except OverflowError:  # an integer literal beyond the float range
            return Node("num", value=math.inf)

    def name_node(self, node: ast.Name) -> Node:
        if node.id in VARIABLES:
            return Node("var", value=node.id)
        if node.id in CONSTANTS:
            return Node("num", value=CONSTANTS[node.id])
        if node.id in FUNCTIONS:
            raise self.fail(f"{node.id!r} is a function; call it as {node.id}(...)")
        raise self.fail(f"name {node.id!r} is not allowed in an expression")

    def call(self, node: ast.Call, depth: int) -> Node:
        if not isinstance(node.func, ast.Name):
            raise self.fail(f"calling {self.segment(node.func)!r} is not allowed in an expression")
        function = node.func.id
        if function not in FUNCTIONS:
            raise self.fail(f"function {function!r} is not allowed in an expression")
        if node.keywords:
            keyword = node.keywords[0].arg
            raise self.fail(
                f"keyword argument {(keyword or '**') + '='!r} in {function}(...) is not allowed in an expression"
            )
        _, least, most = FUNCTIONS[function]
        count = len(node.args)
        if count < least or (most is not None and count > most):
            wanted = f"exactly {least}" if most == least else f"at least {least}"
            raise self.fail(f"{function}(...) takes {wanted} argument{'s' if least > 1 else ''}, got {count}")
        if function == "where":
            condition = self.condition(node.args[0], depth + 1)
            return Node("where", (condition, *(self.value(arg, depth + 1) for arg in node.args[1:])))
        return Node(function, tuple(self.value(arg, depth + 1) for arg in node.args))


def parse_tree(text: str, name: str) -> Node:
    """The tree of a stripped, non-empty expression text; :class:`ExpressionError` if not allowed."""
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as error:
        reason = error.msg or "invalid syntax"
        column = f" at column {error.offset}" if error.offset else ""
        raise fail(name, text, f"not a valid expression ({reason}{column})") from None
    except UnicodeEncodeError as error:  # a lone surrogate (the scene loader joins pairs, refuses halves)
        bad = f"\\u{ord(error.object[error.start]):04x}"
        where = f"the lone surrogate {bad} at column {error.start + 1}"
        raise fail(name, text, f"not a valid expression ({where})") from None
    except (RecursionError, MemoryError, ValueError):
        raise fail(name, text, "not a valid expression (too complex)", hint=False) from None
    return _Parser(text, name).value(tree.body)


def tree_variables(node: Node) -> frozenset:
    """The variables a tree uses."""
    if node.op == "var":
        return frozenset((node.value,))
    return frozenset().union(*(tree_variables(arg) for arg in node.args))


def _operation(op: str):
    """The numpy function of a tree operation (n-ary min/max/and/or reduce pairwise)."""
    function = ARITHMETIC.get(op) or CONDITIONS.get(op) or FUNCTIONS[op][0]
    if op in ("min", "max", "and", "or"):
        return lambda *values: reduce(function, values)
    return function


def _program(node: Node, steps: list, slots: dict):
    """Append the steps computing ``node`` once (a subtree shared by several parents, as derivatives
    share them, is computed once); returns its slot index or its folded constant (np.float64)."""
    key = id(node)
    if key in slots:
        return slots[key]
    if node.op == "num":
        result = np.float64(node.value)
    elif node.op == "var":
        result = VARIABLES.index(node.value)  # slots 0, 1, 2 hold x, y, z
    else:
        operator = _operation(node.op)
        arguments = [_program(arg, steps, slots) for arg in node.args]
        if all(isinstance(a, np.float64) for a in arguments):
            with np.errstate(all="ignore"):
                result = np.float64(operator(*arguments))
        else:
            steps.append((operator, arguments))
            result = len(VARIABLES) + len(steps) - 1
    slots[key] = result  # id() is safe: every node stays referenced by the tree while this runs
    return result


def evaluator(node: Node):
    """``("const", float)`` or ``("func", f(x, y, z))`` evaluating ``node`` with numpy in float64
    (conditions as 1.0/0.0) in time linear in the number of distinct subtrees; constant subtrees are
    folded. Non-finite values are not checked here."""
    steps: list = []
    result = _program(node, steps, {})
    if isinstance(result, np.float64):
        return ("const", float(result))
    if not steps:  # a bare variable
        return ("func", lambda *points: points[result])
    last_use = {}
    for index, (_, arguments) in enumerate(steps):
        for a in arguments:
            if not isinstance(a, np.float64):
                last_use[a] = index
    plan = [
        (
            operator,
            arguments,
            {a for a in arguments if not isinstance(a, np.float64) and a >= len(VARIABLES) and last_use[a] == index},
        )
        for index, (operator, arguments) in enumerate(steps)
    ]

    def run(x, y, z):
        values = [x, y, z] + [None] * len(plan)
        for index, (operator, arguments, done) in enumerate(plan, start=len(VARIABLES)):
            values[index] = operator(*[a if isinstance(a, np.float64) else values[a] for a in arguments])
            for a in done:  # free intermediate arrays after their last use
                values[a] = None
        return values[-1]

    return ("func", run)
