"""Sphinx configuration of the vemkit documentation (``make docs``: ``docs/_build/html``).

Generated at build time (never typed in, never committed): the scene-key reference from
``vemkit/config/schemas/scene.schema.json``, the API pages from the packages' ``__all__``, the
tables and figures of "Reproducing the paper" and "Verification" from the result files
(``docs/_ext/vemkit_docs.py``), and the gallery from ``docs/examples/`` (sphinx-gallery, every
script executed on a small mesh).
"""

import os
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(DOCS / "_ext"))
sys.path.insert(0, str(ROOT))
os.environ.setdefault("MPLBACKEND", "Agg")

import vemkit  # noqa: E402

project = "vemkit"
author = "the vemkit developers"
copyright = "vemkit developers, MIT licence"
release = version = vemkit.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinxarg.ext",
    "sphinx_gallery.gen_gallery",
    "vemkit_docs",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
# included pieces, not pages of their own: the generated tables and figures, the API examples
exclude_patterns = [
    "_build",
    "examples/README.txt",
    "_generated/*.md",
    "_generated/paper",
    "_generated/verification",
    "_generated/three-d",
    "reference/examples",
    "gallery/*.md5",
    "gallery/*.json",
]
templates_path = []

# MyST: Markdown prose; $...$ maths, ::: fences, heading anchors for links between pages
myst_enable_extensions = ["colon_fence", "dollarmath", "deflist", "fieldlist"]
myst_heading_anchors = 3

# numpydoc-style docstrings through napoleon (tolerant of the prose docstrings already there)
napoleon_google_docstring = False
napoleon_numpy_docstring = True
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {"members": False}

html_theme = "furo"
html_title = f"vemkit {release}"
html_static_path = []

# a warning fails the build (make docs runs sphinx-build -W); references must resolve

sphinx_gallery_conf = {
    "examples_dirs": str(DOCS / "examples"),
    "gallery_dirs": str(DOCS / "gallery"),
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "matplotlib_animations": False,
    "show_memory": False,
    "min_reported_time": 1000,
    "image_scrapers": ("matplotlib", "vemkit_docs.figure_scraper"),
}

# linkcheck (make linkcheck): only the site's own links; the machine has no network
linkcheck_ignore = [r"https?://.*"]
