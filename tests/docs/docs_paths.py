"""Paths of the documentation tests, and docs/_ext on sys.path for its generators (a plain module,
not a conftest: other test folders import tests/conftest.py as `conftest`).

The documentation's tests: the generators of docs/_ext/vemkit_docs.py (no Sphinx needed), the
doctests of the API examples, the docs pages and the README, and the built site (docs/_build/html,
made by `make docs`, which .ci/run runs before `make test`)."""

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
HTML = DOCS / "_build" / "html"
sys.path.insert(0, str(DOCS / "_ext"))

import vemkit_docs  # noqa: E402 - docs/_ext/vemkit_docs.py, importable once docs/_ext is on sys.path

__all__ = ["DOCS", "HTML", "ROOT", "vemkit_docs"]
