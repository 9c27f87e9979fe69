"""Count the branches on the space dimension (issue 34): the tests of an ``if``, a conditional
expression, a ``while`` or a comprehension's filter that compare the dimension with a literal (1, 2
or 3) or call an ``is_*3d*`` predicate. "The dimension" is a name or attribute ``dimension``/``dim``,
a coordinate width ``x.shape[1]`` or ``getattr(x, "dimension", ...)``. A comparison with another
quantity (``len(vector) != dimension``) is a parameter, not a branch. ``mesh/`` and
``vem/elements/`` own the per-dimension code and are not counted.

Run ``python tests/dimension_branches.py`` to list them."""

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "vemkit"
OWNERS = ("mesh/", "vem/elements/")
_NAMES = {"dimension", "dim"}


def _is_dimension(node) -> bool:
    for n in ast.walk(node):
        if isinstance(n, ast.Name) and n.id in _NAMES or isinstance(n, ast.Attribute) and n.attr in _NAMES:
            return True
        if (
            isinstance(n, ast.Subscript)
            and isinstance(n.value, ast.Attribute)
            and n.value.attr == "shape"
            and isinstance(n.slice, ast.Constant)
            and n.slice.value == 1
        ):
            return True
    return False


def _literal(node) -> bool:
    return isinstance(node, ast.Constant) and type(node.value) is int and node.value in (1, 2, 3)


def _tests_the_dimension(test) -> bool:
    for n in ast.walk(test):
        if isinstance(n, ast.Compare):
            sides = [n.left, *n.comparators]
            if any(map(_literal, sides)) and any(_is_dimension(s) for s in sides if not _literal(s)):
                return True
        elif isinstance(n, ast.Call):
            name = n.func.id if isinstance(n.func, ast.Name) else getattr(n.func, "attr", "")
            if name.startswith("is_") and ("3d" in name or "2d" in name):
                return True
            if name == "getattr" and len(n.args) > 1 and getattr(n.args[1], "value", None) in _NAMES:
                return True
    return False


def dimension_branches() -> list[str]:
    """``path:line`` of every branch on the dimension outside mesh/ and vem/elements/."""
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        relative = path.relative_to(PACKAGE).as_posix()
        if relative.startswith(OWNERS):
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            tests = [node.test] if isinstance(node, (ast.If, ast.IfExp, ast.While)) else []
            tests += node.ifs if isinstance(node, ast.comprehension) else []
            found += [f"{relative}:{t.lineno}" for t in tests if _tests_the_dimension(t)]
    return sorted(found)


if __name__ == "__main__":
    branches = dimension_branches()
    print("\n".join(branches))
    print(f"{len(branches)} branches on the dimension outside {', '.join(OWNERS)}")
