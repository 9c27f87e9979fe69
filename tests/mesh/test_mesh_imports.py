"""The modules of vemkit.mesh import one another without a cycle (issue 34 item 1: the 2D and the 3D
families imported each other, the cycle hidden by an import inside a function).

Every import of a module counts, function-level ones included (found with ast). An edge goes to the
module a statement names (``from vemkit.mesh.families.by_name import build_mesh`` ->
``vemkit.mesh.families.by_name``; ``from vemkit.mesh import polyhedral_kernels`` ->
``vemkit.mesh.polyhedral_kernels``); the package ``__init__`` Python runs first is not an edge
(otherwise every package that re-exports its modules would be a cycle). A cycle through a module
outside vemkit.mesh would need a lower layer to import vemkit.mesh: tests/test_architecture.py
forbids that."""

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "vemkit"


def _mesh_modules() -> dict:
    modules = {}
    for path in sorted((PACKAGE / "mesh").rglob("*.py")):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        modules[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return modules


def _absolute(module: str, path: Path, node: ast.ImportFrom) -> str:
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    if not node.level:
        return node.module or ""
    kept = package.split(".")[: len(package.split(".")) - node.level + 1]
    return ".".join(kept + ([node.module] if node.module else []))


def imported_mesh_modules(module: str, path: Path, modules: dict) -> set:
    """The vemkit.mesh modules ``module`` imports anywhere in its file."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names if alias.name in modules}
        elif isinstance(node, ast.ImportFrom):
            base = _absolute(module, path, node)
            for alias in node.names:
                if f"{base}.{alias.name}" in modules:
                    found.add(f"{base}.{alias.name}")
                elif base in modules:
                    found.add(base)
    found.discard(module)
    return found


def import_cycles(graph: dict) -> list:
    """The strongly connected components of more than one module (Tarjan's algorithm, iterative)."""
    index, low, on_stack, stack, components = {}, {}, set(), [], []
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    components.append(sorted(component))
    return components


def test_the_cycle_finder_finds_a_cycle():
    assert import_cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert import_cycles({"a": {"b"}, "b": set()}) == []


def test_the_function_level_imports_are_seen():
    modules = _mesh_modules()
    graph = {m: imported_mesh_modules(m, p, modules) for m, p in modules.items()}
    assert "vemkit.mesh.families.by_name" in graph["vemkit.mesh.families3d.build"]


def test_the_modules_meshing_imports_by_name_do_not_import_it():
    """meshing imports each dimension's functions on first use (a 2D command loads no 3D module): none
    of those modules may import meshing, directly or through others (that would be a cycle)."""
    from vemkit.mesh.meshing import BY_DIMENSION

    modules = _mesh_modules()
    graph = {m: imported_mesh_modules(m, p, modules) for m, p in modules.items()}
    # the mesh modules among them (a lower layer's, e.g. vemkit.config.limits, cannot import meshing:
    # tests/test_architecture.py)
    named = {
        module for role in BY_DIMENSION.values() for module, _ in role.values() if module.startswith("vemkit.mesh")
    }
    assert {"vemkit.mesh.families.by_name", "vemkit.mesh.families3d.build", "vemkit.mesh.files3d"} <= named
    graph["vemkit.mesh.meshing"] = graph["vemkit.mesh.meshing"] | named
    assert import_cycles(graph) == []


def test_no_import_cycle_in_vemkit_mesh():
    modules = _mesh_modules()
    graph = {m: imported_mesh_modules(m, p, modules) for m, p in modules.items()}
    assert import_cycles(graph) == []
