"""The package's shape: layers import only layers below them; the core needs no workflow tools."""

import ast
import json
import subprocess
import sys
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "vemkit"
#: the layers, lowest first (vemkit/__init__.py documents the same order)
LAYERS = ("exceptions", "config", "mesh", "vem", "contact", "solvers", "io", "studies", "report", "cli")


def _layer(module: str) -> int:
    """Layer of a dotted vemkit module name (``vemkit.solvers.ssn`` -> 5)."""
    return LAYERS.index(module.split(".")[1])


def _modules():
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if len(parts) > 1:  # vemkit/__init__.py is the public API, above every layer
            yield ".".join(parts), path


def _imported(path: Path, module: str):
    """Every vemkit module imported anywhere in a file (function-level imports included)."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            yield from (a.name for a in node.names if a.name.startswith("vemkit."))
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = ".".join(
                    package.split(".")[: len(package.split(".")) - node.level + 1] + ([base] if base else [])
                )
            if base == "vemkit":
                yield from (f"vemkit.{a.name}" for a in node.names if a.name in LAYERS)
            elif base.startswith("vemkit."):
                yield base


@pytest.mark.parametrize("module, path", list(_modules()), ids=lambda v: str(v) if isinstance(v, str) else "")
def test_no_module_imports_from_a_layer_above_it(module, path):
    upward = [name for name in _imported(path, module) if _layer(name) > _layer(module)]
    assert not upward, f"{module} (layer {LAYERS[_layer(module)]}) imports {upward} from a layer above it"


def test_every_subpackage_says_what_it_owns_and_may_import():
    for layer in LAYERS[1:-1]:
        doc = " ".join(
            (ast.get_docstring(ast.parse((PACKAGE / layer / "__init__.py").read_text(encoding="utf-8"))) or "").split()
        )
        assert doc and f"Layer {LAYERS.index(layer)}" in doc and "Imports from vemkit" in doc, layer


_BLOCK = """
import importlib.abc, json, os, sys
class Block(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split('.')[0] in {blocked!r}:
            raise ImportError('blocked for this test: ' + name)
sys.meta_path.insert(0, Block())
"""


def _python(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)


def test_the_core_imports_and_solves_without_snakemake_or_matplotlib(tmp_path):
    core = [m for m, _ in _modules() if _layer(m) <= LAYERS.index("studies")]
    scene = Path(__file__).resolve().parents[1] / "config" / "scenes" / "paper.yaml"
    code = (
        _BLOCK.format(blocked=["snakemake", "matplotlib"])
        + f"""
import importlib
for name in {core!r}:
    importlib.import_module(name)
from vemkit.cli import main
assert main(["solve", {str(scene)!r}, "-o", {str(tmp_path / "out.nc")!r}, "--set", "discretization.mesh.n=4", "-q"]) == 0
"""
    )
    run = _python(code)
    assert run.returncode == 0, run.stderr[-2000:]
    assert (tmp_path / "out.nc").is_file()


def test_importing_vemkit_has_no_side_effects():
    run = _python(
        "import json, os, sys; before = dict(os.environ); import vemkit; "
        "print(json.dumps([dict(os.environ) == before, sorted(m for m in sys.modules "
        "if m.split('.')[0] in ('numpy', 'matplotlib', 'numba'))]))"
    )
    unchanged, heavy = json.loads(run.stdout)
    assert unchanged and heavy == []


def test_the_public_api_resolves():
    import vemkit

    for name in vemkit.__all__:
        assert getattr(vemkit, name) is not None


LINEAR_LAYER = PACKAGE / "solvers" / "linear"


def _linear_backend_names() -> set:
    """The values of solver.linear that name a backend (the schema's enum without auto)."""
    schema = json.loads((PACKAGE / "config" / "schemas" / "scene.schema.json").read_text(encoding="utf-8"))
    return set(schema["properties"]["solver"]["properties"]["linear"]["enum"]) - {"auto"}


def test_only_the_linear_solver_layer_names_a_linear_solver():
    """ssn, uzawa and everything else use the backends' interface (vemkit/solvers/linear/base.py): no
    string constant outside vemkit/solvers/linear/ is a backend's name (no ``.method == "amg"``)."""
    names = _linear_backend_names()
    found = [
        f"{module}:{node.lineno} {node.value!r}"
        for module, path in _modules()
        if LINEAR_LAYER not in path.parents
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and node.value in names
    ]
    assert not found, f"linear-solver names outside vemkit/solvers/linear/: {found}"


def test_every_linear_solver_of_the_schema_has_its_backend():
    from vemkit.solvers.linear import backends

    assert set(backends()) == _linear_backend_names()


def test_the_solvers_never_read_a_contact_laws_parameters():
    """The solvers ask the law (vemkit.contact.laws.FoundationLaw) for p_nu, p_nu', the friction bound
    and its derivative; they never read a law's k_ or m_ (a power law's parameters)."""
    found = [
        f"{module}:{node.lineno} .{node.attr}"
        for module, path in _modules()
        if module.startswith("vemkit.solvers")
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
        if isinstance(node, ast.Attribute) and node.attr.startswith(("k_", "m_"))
    ]
    assert not found, f"the solvers read a law's parameters: {found}"


def _import_graph() -> dict:
    """vemkit module -> the vemkit modules it imports (function-level imports included), each import
    resolved to the module it names (``vemkit.contact.boundary.rank_one_blocks`` -> its module)."""
    modules = dict(_modules())

    def resolve(name):
        while name and name not in modules:
            name = name.rpartition(".")[0]
        return name

    graph = {}
    for module, path in modules.items():
        names = set(_imported(path, module))
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("vemkit.") and not node.level:
                names.update(f"{node.module}.{a.name}" for a in node.names)
        graph[module] = {resolve(n) for n in names} - {module, ""}
    return graph


def _cycle_through(graph: dict, start: str) -> list | None:
    """A path of imports from ``start`` back to itself, or None."""
    stack, seen = [(start, [start])], set()
    while stack:
        module, path = stack.pop()
        for nxt in graph.get(module, ()):
            if nxt == start:
                return path + [start]
            if nxt not in seen:
                seen.add(nxt)
                stack.append((nxt, path + [nxt]))
    return None


@pytest.mark.parametrize("layer", ["contact", "solvers"])
def test_one_contact_boundary_and_one_solver_stack_for_both_dimensions(layer):
    """No 3D twin of a module (``*3d*``) in contact/ or solvers/, and no import cycle through them
    (issue 34: the 3D modules that stood beside the 2D ones imported each other inside functions)."""
    twins = sorted(str(p.relative_to(PACKAGE)) for p in (PACKAGE / layer).rglob("*3d*"))
    assert not twins, f"3D twins of modules: {twins}"
    graph = _import_graph()
    cycles = [c for m in graph if m.startswith(f"vemkit.{layer}") and (c := _cycle_through(graph, m))]
    assert not cycles, f"import cycles: {cycles[:3]}"


def test_at_most_eight_branches_on_the_dimension_outside_the_mesh_and_the_elements():
    """Issue 34: the dimension is a parameter; the per-dimension code lives in mesh/ and
    vem/elements/ (the count's rules: tests/dimension_branches.py)."""
    sys.path.insert(0, str(PACKAGE.parent / "tests"))
    from dimension_branches import dimension_branches

    branches = dimension_branches()
    assert len(branches) <= 8, f"{len(branches)} branches on the dimension: {branches}"


@pytest.mark.parametrize("layer", ["contact", "io", "solvers", "report"])
def test_no_3d_twin_of_a_module(layer):
    twins = sorted(str(p.relative_to(PACKAGE)) for p in (PACKAGE / layer).rglob("*3d*"))
    assert not twins, f"3D twins of modules: {twins}"


def test_no_import_cycle_anywhere_in_the_package():
    graph = _import_graph()
    cycles = [c for m in graph if (c := _cycle_through(graph, m))]
    assert not cycles, f"import cycles: {cycles[:3]}"
