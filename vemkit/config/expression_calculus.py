"""Exact (symbolic) partial derivatives of expression trees (:mod:`vemkit.config.expression_tree`).

``derivative(tree, "x")`` applies the rules of calculus to the tree itself and returns a new tree
of the same language, evaluated like any other (no finite differences, no sympy). Piecewise
functions differentiate piecewise, with the derivative of one side at a kink:

    |a|' = sign(a) a',   sign(a)' = 0,   min(a, b)' = where(a <= b, a', b'),
    max(a, b)' = where(a >= b, a', b'),   where(c, a, b)' = where(c, a', b')

(the condition itself is piecewise constant). The constructors below fold numbers and drop
zero terms and unit factors, so the derivative of a polynomial stays a short polynomial.
"""

from __future__ import annotations

from vemkit.config.expression_tree import Node

__all__ = ["derivative"]

ZERO, ONE, TWO = Node("num", value=0.0), Node("num", value=1.0), Node("num", value=2.0)


def _is(node: Node, value: float) -> bool:
    return node.op == "num" and node.value == value


def add(a: Node, b: Node) -> Node:
    if _is(a, 0.0):
        return b
    if _is(b, 0.0):
        return a
    if a.op == "num" and b.op == "num":
        return Node("num", value=a.value + b.value)
    return Node("add", (a, b))


def neg(a: Node) -> Node:
    if a.op == "num":
        return Node("num", value=-a.value)
    return a.args[0] if a.op == "neg" else Node("neg", (a,))


def sub(a: Node, b: Node) -> Node:
    if _is(b, 0.0):
        return a
    if _is(a, 0.0):
        return neg(b)
    if a.op == "num" and b.op == "num":
        return Node("num", value=a.value - b.value)
    return Node("sub", (a, b))


def mul(a: Node, b: Node) -> Node:
    if _is(a, 0.0) or _is(b, 0.0):
        return ZERO
    if _is(a, 1.0):
        return b
    if _is(b, 1.0):
        return a
    if a.op == "num" and b.op == "num":
        return Node("num", value=a.value * b.value)
    return Node("mul", (a, b))


def div(a: Node, b: Node) -> Node:
    if _is(a, 0.0):
        return ZERO
    return a if _is(b, 1.0) else Node("div", (a, b))


def power(a: Node, b: Node) -> Node:
    if _is(b, 1.0):
        return a
    return ONE if _is(b, 0.0) else Node("pow", (a, b))


def call(name: str, *args: Node) -> Node:
    return Node(name, tuple(args))


def _square(a: Node) -> Node:
    return power(a, TWO)


# d f(a) / da for the one-argument functions, as a tree in a: the chain rule multiplies by a'
_OUTER = {
    "sin": lambda a: call("cos", a),
    "cos": lambda a: neg(call("sin", a)),
    "tan": lambda a: div(ONE, _square(call("cos", a))),  # 1 / cos^2 a
    "asin": lambda a: div(ONE, call("sqrt", sub(ONE, _square(a)))),  # 1 / sqrt(1 - a^2)
    "acos": lambda a: neg(div(ONE, call("sqrt", sub(ONE, _square(a))))),
    "atan": lambda a: div(ONE, add(ONE, _square(a))),  # 1 / (1 + a^2)
    "sinh": lambda a: call("cosh", a),
    "cosh": lambda a: call("sinh", a),
    "tanh": lambda a: sub(ONE, _square(call("tanh", a))),  # 1 - tanh^2 a
    "exp": lambda a: call("exp", a),
    "log": lambda a: div(ONE, a),
    "sqrt": lambda a: div(ONE, mul(TWO, call("sqrt", a))),  # 1 / (2 sqrt a)
    "abs": lambda a: call("sign", a),
    "sign": lambda a: ZERO,  # piecewise constant
}


def _product(node: Node, variable: str) -> Node:
    a, b = node.args
    da, db = derivative(a, variable), derivative(b, variable)
    if node.op == "mul":  # (ab)' = a'b + ab'
        return add(mul(da, b), mul(a, db))
    if _is(db, 0.0):  # (a/b)' = a'/b for a constant b
        return div(da, b)
    return div(sub(mul(da, b), mul(a, db)), _square(b))  # (a'b - ab') / b^2


def _power(node: Node, variable: str) -> Node:
    a, b = node.args
    da, db = derivative(a, variable), derivative(b, variable)
    if _is(db, 0.0):  # (a^b)' = b a^(b-1) a' for a constant exponent (no log a: a may be negative)
        return mul(mul(b, power(a, sub(b, ONE))), da)
    if _is(da, 0.0):  # (a^b)' = a^b log(a) b' for a constant base
        return mul(mul(node, call("log", a)), db)
    return mul(node, add(mul(db, call("log", a)), div(mul(b, da), a)))  # a^b (b' log a + b a'/a)


def _pairwise(name: str, args: tuple) -> Node:
    """min/max of several arguments as nested two-argument calls."""
    node = Node(name, args[:2])
    for arg in args[2:]:
        node = Node(name, (node, arg))
    return node


def _kinked(node: Node, variable: str) -> Node:
    """min, max (one-sided at a tie) and where: the derivative of the branch that is taken."""
    if node.op == "where":
        condition, a, b = node.args
        da, db = derivative(a, variable), derivative(b, variable)
        return da if da == db else call("where", condition, da, db)
    if len(node.args) > 2:
        return derivative(_pairwise(node.op, node.args), variable)
    a, b = node.args
    da, db = derivative(a, variable), derivative(b, variable)
    if da == db:
        return da
    return call("where", Node("<=" if node.op == "min" else ">=", (a, b)), da, db)


def derivative(node: Node, variable: str) -> Node:
    """The tree of d(node)/d(variable), exact wherever the expression is differentiable."""
    op = node.op
    if op == "num":
        return ZERO
    if op == "var":
        return ONE if node.value == variable else ZERO
    if op in ("add", "sub"):
        da, db = (derivative(arg, variable) for arg in node.args)
        return add(da, db) if op == "add" else sub(da, db)
    if op == "neg":
        return neg(derivative(node.args[0], variable))
    if op in ("mul", "div"):
        return _product(node, variable)
    if op == "pow":
        return _power(node, variable)
    if op in ("min", "max", "where"):
        return _kinked(node, variable)
    if op == "atan2":  # atan2(p, q)' = (q p' - p q') / (p^2 + q^2)
        p, q = node.args
        dp, dq = derivative(p, variable), derivative(q, variable)
        return div(sub(mul(q, dp), mul(p, dq)), add(_square(p), _square(q)))
    if op in _OUTER:
        inner = derivative(node.args[0], variable)
        return ZERO if _is(inner, 0.0) else mul(_OUTER[op](node.args[0]), inner)
    raise ValueError(f"no derivative of the operation {op!r} (a condition is not differentiated)")
