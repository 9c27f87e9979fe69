"""The built site (docs/_build/html, `make docs` with -W; .ci/run builds it before `make test`):
every scene key, CLI option and public API name is in the reference, every page of the table of
contents was written, every internal link and image resolves, and every gallery example has its
picture. Skipped, with the reason, when the site was not built."""

import html
import re
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

import pytest
from docs_paths import DOCS, HTML, ROOT, vemkit_docs

pytestmark = pytest.mark.skipif(
    not (HTML / "index.html").exists(), reason="docs/_build/html not built: run `make docs` (CI does, before make test)"
)


class _Links(HTMLParser):
    def __init__(self):
        super().__init__()
        self.links, self.ids = [], set()

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if "id" in attrs:
            self.ids.add(attrs["id"])
        for key in ("href", "src"):
            if attrs.get(key) and tag in ("a", "img", "link", "script"):
                self.links.append((tag, attrs[key]))


def _parse(path: Path) -> _Links:
    parser = _Links()
    parser.feed(path.read_text(errors="replace"))
    return parser


def _text(path: Path) -> str:
    return html.unescape(re.sub(r"<[^>]+>", "", path.read_text()))


def test_every_page_was_built():
    for page in (
        "index",
        "getting-started",
        "gallery/index",
        "paper",
        "verification",
        "architecture",
        "reference/scene",
        "reference/cli",
        "reference/files",
        "reference/api",
        "reference/input-rules",
        "tutorials/bodies-and-meshes",
        "tutorials/boundary-conditions",
        "tutorials/contact",
        "tutorials/solvers",
        "tutorials/order2",
        "tutorials/adaptivity",
        "tutorials/three-d",
        "tutorials/sweeps",
        "tutorials/stability",
        "tutorials/slurm",
    ):
        assert (HTML / f"{page}.html").exists(), page


def test_every_internal_link_and_image_resolves():
    broken = []
    parsed = {path: _parse(path) for path in HTML.rglob("*.html")}
    for path, parser in parsed.items():
        for tag, link in parser.links:
            url = urlsplit(link)
            if url.scheme or link.startswith(("//", "mailto:", "data:")):
                continue
            target = path if not url.path else (path.parent / unquote(url.path)).resolve()
            if target.is_dir():
                target = target / "index.html"
            if not target.exists():
                broken.append(f"{path.relative_to(HTML)}: {tag} {link}")
            elif url.fragment and target.suffix == ".html" and target in parsed:
                if unquote(url.fragment) not in parsed[target].ids:
                    broken.append(f"{path.relative_to(HTML)}: anchor {link}")
    assert not broken, "\n".join(broken[:30])


def test_every_scene_key_is_in_the_reference():
    text = _text(HTML / "reference" / "scene.html")
    for row in vemkit_docs.scene_key_rows():
        assert row["path"] in text, row["path"]


def test_every_cli_option_is_in_the_reference():
    from vemkit.cli import build_parser

    text = _text(HTML / "reference" / "cli.html")
    parser = build_parser()
    commands = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    for name, sub in commands.choices.items():
        assert f"vemkit {name}" in text, name
        for action in sub._actions:
            if action.__class__.__name__ == "_HelpAction":  # -h, --help: every command has it
                continue
            for option in action.option_strings:
                assert option in text, f"vemkit {name} {option}"


def test_every_public_name_is_in_the_api_reference():
    for module, name in vemkit_docs.public_names():
        page = HTML / "api" / f"{module}.html"
        assert page.exists(), module
        content = page.read_text()
        assert f"{module}.{name}" in content, f"{module}.{name}"
        assert "&gt;&gt;&gt;" in content.split(f"{module}.{name}", 1)[1] or name == "__version__", f"{module}.{name}"


def test_every_gallery_example_has_its_picture():
    scripts = sorted((DOCS / "examples").glob("plot_*.py"))
    sources = "\n".join(script.read_text() for script in scripts)
    for scene in sorted((ROOT / "config" / "scenes").glob("*.yaml")):
        assert f'"{scene.name}"' in sources, f"shipped scene {scene.name} has no gallery script in docs/examples/"
    for script in scripts:
        page = HTML / "gallery" / f"{script.stem}.html"
        assert page.exists(), script.name
        images = [src for tag, src in _parse(page).links if tag == "img" and "sphx_glr" in src]
        assert images, f"{script.name}: no figure"
        for src in images:
            assert (page.parent / src).resolve().exists(), src


def test_the_paper_page_has_table1_and_the_figures():
    text = _text(HTML / "paper.html")
    assert "1.9114e-01" in text or "0.19114" in text or "1.9114e-1" in text
    for fig in ("fig3", "fig4", "fig5", "fig6", "contact"):
        assert (HTML / "_images" / f"{fig}.png").exists(), fig
