"""Every example in the documentation runs: the runnable example of each public API name
(docs/reference/examples/), every `>>>` block of a docs page, and the README's."""

import doctest
from pathlib import Path

import pytest
from docs_paths import DOCS, ROOT, vemkit_docs

PAGES = sorted(
    p for p in DOCS.rglob("*.md") if "_build" not in p.parts and "_generated" not in p.parts and ">>>" in p.read_text()
)
FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE


def _run(path: Path, monkeypatch):
    monkeypatch.chdir(ROOT)  # the examples name files from the repository's root
    monkeypatch.setenv("MPLBACKEND", "Agg")
    result = doctest.testfile(str(path), module_relative=False, optionflags=FLAGS, verbose=False, report=True)
    assert result.attempted > 0, f"{path}: no example"
    assert result.failed == 0, f"{path}: {result.failed} of {result.attempted} examples failed (see above)"


@pytest.mark.parametrize("path", PAGES, ids=[str(p.relative_to(DOCS)) for p in PAGES])
def test_docs_examples_run(path, monkeypatch):
    _run(path, monkeypatch)


def test_readme_examples_run(monkeypatch):
    _run(ROOT / "README.md", monkeypatch)


def test_every_public_name_has_a_runnable_example():
    missing = [
        f"{module}.{name}"
        for module, name in vemkit_docs.public_names()
        if not vemkit_docs.example_file(module, name).exists()
    ]
    assert not missing, f"public names without an example in docs/reference/examples/<module>.<name>.md: {missing}"
    for module, name in vemkit_docs.public_names():
        assert ">>>" in vemkit_docs.example_file(module, name).read_text(), f"{module}.{name}: no >>> example"


def test_no_orphan_examples():
    names = {f"{module}.{name}" for module, name in vemkit_docs.public_names()}
    orphans = [p.stem for p in (DOCS / "reference" / "examples").glob("*.md") if p.stem not in names]
    assert not orphans, f"examples of names that are not public (any more): {orphans}"


def _public_docstring_tests():
    """doctest's tests of the docstrings of every public name (and of the public packages), the
    ones with a `>>>` example: a new docstring example is tested without being listed here."""
    import importlib

    finder = doctest.DocTestFinder(exclude_empty=True)
    seen, tests = set(), []
    objects = [(module, importlib.import_module(module)) for module in vemkit_docs.PUBLIC_MODULES]
    objects += [
        (f"{module}.{name}", getattr(importlib.import_module(module), name))
        for module, name in vemkit_docs.public_names()
    ]
    for label, obj in objects:
        if id(obj) in seen or not isinstance(getattr(obj, "__doc__", None), str):
            continue
        seen.add(id(obj))
        for test in finder.find(obj, label, globs={}):
            if test.examples and "site-packages" not in (test.filename or ""):
                tests.append(test)
    return tests


DOCSTRING_TESTS = _public_docstring_tests()


@pytest.mark.parametrize("test", DOCSTRING_TESTS, ids=[t.name for t in DOCSTRING_TESTS])
def test_public_docstring_examples_run(test, monkeypatch):
    monkeypatch.chdir(ROOT)
    runner = doctest.DocTestRunner(optionflags=FLAGS)
    runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, f"{test.name}: {result.failed} of {result.attempted} examples failed (see above)"


def test_docstring_examples_are_found():
    assert any(t.name == "vemkit.solve" for t in DOCSTRING_TESTS), [t.name for t in DOCSTRING_TESTS]
