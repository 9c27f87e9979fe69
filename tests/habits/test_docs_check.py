"""docs/tools/docs_check.py (make docs-check) on a tiny site made here: the static checks always,
the browser's (page loads, images drawn, screenshots) where Chromium is installed."""

import importlib.util
import shutil
import struct
import zlib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
spec = importlib.util.spec_from_file_location("docs_check", ROOT / "docs" / "tools" / "docs_check.py")
docs_check = importlib.util.module_from_spec(spec)
spec.loader.exec_module(docs_check)

needs_browser = pytest.mark.skipif(shutil.which("chromium") is None, reason="chromium is not installed")


def png(width: int, height: int) -> bytes:
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    rows = b"".join(b"\x00" + b"\xc8\x50\x28" * width for _ in range(height))
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b"")


def page(title: str, body: str, head: str = "") -> str:
    return f"<!doctype html><html><head><title>{title}</title>{head}</head><body>{body}</body></html>"


@pytest.fixture
def site(tmp_path):
    root = tmp_path / "html"
    (root / "_static").mkdir(parents=True)
    (root / "guide").mkdir()
    (root / "_static" / "figure.png").write_bytes(png(40, 20))
    (root / "_static" / "style.css").write_text("h1 { color: #246; }")
    (root / "index.html").write_text(
        page(
            "vemkit",
            '<h1>vemkit</h1><img src="_static/figure.png">'
            '<a href="guide/start.html#solve">start</a> <a href="https://example.org">x</a>',
            '<link rel="stylesheet" href="_static/style.css">',
        )
    )
    (root / "guide" / "start.html").write_text(
        page(
            "Start",
            '<h1>Start</h1><a href="../index.html">home</a>'
            '<img loading="lazy" src="../_static/figure.png" style="margin-top:3000px">',
        )
    )
    (root / "genindex.html").write_text(page("Index", "index"))  # a Sphinx utility page: not checked
    (root / "_static" / "skipped.html").write_text(page("no", "no"))
    return root


def test_the_main_pages_of_a_site(site):
    assert docs_check.site_pages(site) == ["guide/start.html", "index.html"]


def test_static_checks_name_the_missing_files(site):
    (site / "broken.html").write_text(
        page(
            "Broken",
            '<img src="_static/gone.png"><a href="nowhere.html">x</a>',
            '<script src="_static/gone.js"></script>',
        )
    )
    assert docs_check.static_problems(site, "index.html") == []
    assert docs_check.static_problems(site, "broken.html") == [
        "broken.html: script _static/gone.js is missing",
        "broken.html: img _static/gone.png is missing",
        "broken.html: link nowhere.html leads to no file",
    ]
    assert docs_check.static_problems(site, "absent.html") == ["absent.html: no such page"]


def test_without_a_browser_the_check_skips_with_one_line(site, tmp_path, capsys):
    assert docs_check.main([str(site), "--out", str(tmp_path / "shots"), "--browser", "no-such-browser"]) == 0
    assert "browser check skipped" in capsys.readouterr().err
    assert (
        docs_check.main(
            [str(site), "--out", str(tmp_path / "shots"), "--browser", "no-such-browser", "--require-browser"]
        )
        == 1
    )


@needs_browser
def test_every_page_loads_and_gets_a_screenshot(site, tmp_path):
    shots = tmp_path / "shots"
    assert docs_check.main([str(site), "--out", str(shots), "--window-size", "800,600"]) == 0
    assert sorted(p.name for p in shots.iterdir()) == ["guide__start.png", "index.png"]
    assert (shots / "index.png").read_bytes().startswith(b"\x89PNG")


@needs_browser
def test_the_browser_sees_an_image_that_is_not_one(site, tmp_path, capsys):
    (site / "_static" / "figure.png").write_bytes(b"not a picture")  # present: the static checks pass
    assert docs_check.static_problems(site, "index.html") == []
    assert docs_check.main([str(site), "--out", str(tmp_path / "shots"), "--pages", "index.html"]) == 1
    assert "index.html: image _static/figure.png is not drawn" in capsys.readouterr().err
