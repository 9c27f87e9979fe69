"""docs/architecture.md names every module of the package, and only modules that exist.

The page names a module by its path from the repository root, ``vemkit/mesh/interface.py`` (a
package by its ``__init__.py``); a folder as ``vemkit/solvers/linear/``. A dotted name on the page
(``vemkit.contact.laws.TabulatedContactLaw``) must be a module, or an attribute of one: everything
before its last part a module or package of vemkit.
"""

import re

from docs_paths import DOCS, ROOT

PAGE = DOCS / "architecture.md"
PACKAGE = ROOT / "vemkit"
#: a module path as the page writes it (not the tail of a longer path such as tests/vemkit/...)
MODULE_PATH = re.compile(r"(?<![\w./-])vemkit/(?:[A-Za-z_]\w*/)*[A-Za-z_]\w*\.py\b")
#: a folder of the package as the page writes it
FOLDER_PATH = re.compile(r"(?<![\w./-])vemkit/(?:[A-Za-z_]\w*/)+(?![\w.])")
#: a dotted vemkit name (a module, or an attribute of one)
DOTTED_NAME = re.compile(r"(?<![\w./-])vemkit(?:\.[A-Za-z_]\w*)+")


def page_text() -> str:
    return PAGE.read_text(encoding="utf-8")


def package_modules() -> set[str]:
    """Every .py file of vemkit, as the page names it."""
    return {path.relative_to(ROOT).as_posix() for path in PACKAGE.rglob("*.py") if "__pycache__" not in path.parts}


def is_module(dotted: str) -> bool:
    path = ROOT.joinpath(*dotted.split("."))
    return path.with_suffix(".py").is_file() or (path / "__init__.py").is_file()


def test_the_page_names_every_module_of_the_package():
    named = set(MODULE_PATH.findall(page_text()))
    missing = sorted(package_modules() - named)
    assert not missing, (
        f"docs/architecture.md does not name {len(missing)} module(s) of vemkit; add a line for each to its "
        "layer's table:\n" + "\n".join(missing)
    )


def test_every_module_the_page_names_exists():
    text = page_text()
    gone = sorted(set(MODULE_PATH.findall(text)) - package_modules())
    gone += sorted(name for name in set(FOLDER_PATH.findall(text)) if not (ROOT / name).is_dir())
    gone += sorted(
        name
        for name in set(DOTTED_NAME.findall(text))
        if not is_module(name) and not is_module(name.rpartition(".")[0])
    )
    assert not gone, "docs/architecture.md names what vemkit does not have:\n" + "\n".join(gone)


def test_the_patterns_find_what_they_must():
    line = (
        "`vemkit/mesh/mesh.py`, vemkit/vem/elements/base.py; `vemkit/solvers/linear/` and "
        "vemkit.contact.laws.TabulatedContactLaw, not tests/vemkit/x.py nor docs/vemkit.md"
    )
    assert MODULE_PATH.findall(line) == ["vemkit/mesh/mesh.py", "vemkit/vem/elements/base.py"]
    assert FOLDER_PATH.findall(line) == ["vemkit/solvers/linear/"]
    assert DOTTED_NAME.findall(line) == ["vemkit.contact.laws.TabulatedContactLaw"]
    assert is_module("vemkit.contact.laws") and is_module("vemkit.vem") and not is_module("vemkit.nothing")
