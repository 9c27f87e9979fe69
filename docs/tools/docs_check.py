"""Open a built HTML site in headless Chromium, page by page, and take a screenshot of each.

    python docs/tools/docs_check.py docs/_build/html --out docs/_build/screenshots

A page fails when its file is missing, when an image, stylesheet or script it references (a local
file) or a page it links to is missing, when the browser cannot load it (Page.navigate's error, no
load event), when a local resource fails to load in the browser, or when an image is not drawn (not
complete or zero natural width after the page loaded: a missing or broken file). Each page that
loads gets a screenshot, <out>/<page path with / as __>.png.

The pages: every ``*.html`` of the site except Sphinx's generated utility pages (genindex, search,
py-modindex) and files in folders starting with ``_`` (``_static``, ``_sources``, ...), or the
``--pages`` given (paths relative to the site). The static checks (files referenced exist) need no
browser; without ``chromium`` on PATH the browser part is skipped with one line (exit status 0 if
the static checks pass), unless ``--require-browser``.

The browser is driven over the DevTools protocol on a pipe (``--remote-debugging-pipe``: JSON
messages ending in NUL on file descriptors 3 and 4), with the standard library only.
"""

from __future__ import annotations

import argparse
import base64
import html.parser
import json
import os
import select
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from urllib.parse import unquote, urlsplit

SKIPPED_PAGES = {"genindex.html", "search.html", "py-modindex.html"}
LOAD_TIMEOUT = 30.0  # seconds for a page's load event
IMAGE_TIMEOUT = 10.0  # seconds for the images still loading after it (lazy ones made eager)


# -- the pages and the static checks -------------------------------------------------------
def site_pages(root: Path) -> list[str]:
    """The main pages of a built site: its HTML files, utility pages and _folders left out."""
    pages = []
    for path in sorted(root.rglob("*.html")):
        rel = path.relative_to(root)
        if any(part.startswith("_") for part in rel.parts[:-1]) or rel.as_posix() in SKIPPED_PAGES:
            continue
        pages.append(rel.as_posix())
    return pages


class _References(html.parser.HTMLParser):
    """The local files a page references: images, stylesheets and scripts, and linked pages."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.resources: list[tuple[str, str]] = []  # (tag, url)
        self.links: list[str] = []

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "img" and attrs.get("src"):
            self.resources.append(("img", attrs["src"]))
        elif tag == "source" and attrs.get("srcset"):
            self.resources += [("img", s.strip().split()[0]) for s in attrs["srcset"].split(",") if s.strip()]
        elif tag == "script" and attrs.get("src"):
            self.resources.append(("script", attrs["src"]))
        elif tag == "link" and attrs.get("href") and "stylesheet" in (attrs.get("rel") or "").split():
            self.resources.append(("stylesheet", attrs["href"]))
        elif tag == "a" and attrs.get("href"):
            self.links.append(attrs["href"])


def _local_target(page: Path, url: str) -> Path | None:
    """The file a relative URL of ``page`` names, or None for an external, data or anchor-only URL."""
    parts = urlsplit(url)
    if parts.scheme or parts.netloc or not parts.path:
        return None
    return (page.parent / unquote(parts.path)).resolve()


def static_problems(root: Path, page: str) -> list[str]:
    """What is missing for ``page``: its file, the local files it references, the pages it links to."""
    path = root / page
    if not path.is_file():
        return [f"{page}: no such page"]
    parser = _References()
    parser.feed(path.read_text(encoding="utf-8", errors="replace"))
    problems = []
    for tag, url in parser.resources:
        target = _local_target(path, url)
        if target is not None and not target.is_file():
            problems.append(f"{page}: {tag} {url} is missing")
    for url in parser.links:
        target = _local_target(path, url)
        if target is not None and not (target.is_file() or (target / "index.html").is_file()):
            problems.append(f"{page}: link {url} leads to no file")
    return problems


# -- the browser ---------------------------------------------------------------------------
class Browser:
    """Headless Chromium over the DevTools protocol on a pipe: one page (tab) reused for every URL."""

    def __init__(self, executable: str, width: int, height: int):
        self.width, self.height = width, height
        self.profile = tempfile.mkdtemp(prefix="docs-check-chromium-")
        to_child_r, self._to_child = os.pipe()
        self._from_child, from_child_w = os.pipe()

        def child_fds():  # the protocol's descriptors: 3 reads commands, 4 writes answers
            a, b = os.dup(to_child_r), os.dup(from_child_w)
            os.dup2(a, 3)
            os.dup2(b, 4)

        args = [
            executable,
            "--headless",
            "--remote-debugging-pipe",
            f"--user-data-dir={self.profile}",
            "--disable-gpu",
            "--hide-scrollbars",
            "--no-first-run",
            "--no-default-browser-check",
            "--disable-extensions",
            "--mute-audio",
            "--allow-file-access-from-files",
            "about:blank",
        ]
        if hasattr(os, "geteuid") and os.geteuid() == 0:
            args.insert(1, "--no-sandbox")  # Chromium refuses to run as root with its sandbox
        self.process = subprocess.Popen(
            args,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            preexec_fn=child_fds,
            pass_fds=(3, 4),
        )
        os.close(to_child_r)
        os.close(from_child_w)
        self._buffer = b""
        self._next_id = 0
        self.events: list[dict] = []
        target = self.call("Target.createTarget", url="about:blank")["targetId"]
        self.session = self.call("Target.attachToTarget", targetId=target, flatten=True)["sessionId"]
        for domain in ("Page", "Network", "Runtime"):
            self.call(f"{domain}.enable", session=True)
        self.call(
            "Emulation.setDeviceMetricsOverride",
            session=True,
            width=width,
            height=height,
            deviceScaleFactor=1,
            mobile=False,
        )

    def _read(self, timeout: float) -> dict | None:
        while b"\0" not in self._buffer:
            ready, _, _ = select.select([self._from_child], [], [], timeout)
            if not ready:
                return None
            chunk = os.read(self._from_child, 1 << 20)
            if not chunk:
                raise RuntimeError("the browser closed its DevTools pipe (it exited)")
            self._buffer += chunk
        message, self._buffer = self._buffer.split(b"\0", 1)
        return json.loads(message)

    def call(self, method: str, session: bool = False, timeout: float = LOAD_TIMEOUT, **params) -> dict:
        """Send one command and wait for its answer (events read meanwhile are kept in ``events``)."""
        self._next_id += 1
        message = {"id": self._next_id, "method": method, "params": params}
        if session:
            message["sessionId"] = self.session
        os.write(self._to_child, json.dumps(message).encode() + b"\0")
        deadline = time.monotonic() + timeout
        while True:
            answer = self._read(max(0.0, deadline - time.monotonic()))
            if answer is None:
                raise TimeoutError(f"{method}: no answer within {timeout:g} s")
            if answer.get("id") == self._next_id:
                if "error" in answer:
                    raise RuntimeError(f"{method}: {answer['error'].get('message', answer['error'])}")
                return answer.get("result", {})
            if "method" in answer:
                self.events.append(answer)

    def wait_for(self, method: str, timeout: float) -> bool:
        """Whether the event ``method`` came (already read or within ``timeout`` seconds)."""
        deadline = time.monotonic() + timeout
        while not any(e["method"] == method for e in self.events):
            event = self._read(max(0.0, deadline - time.monotonic()))
            if event is None:
                return False
            if "method" in event:
                self.events.append(event)
        return True

    def check_page(self, url: str, screenshot: Path) -> list[str]:
        """Load ``url``; the problems seen (an empty list: loaded, every image drawn, screenshot written)."""
        self.events = []
        result = self.call("Page.navigate", session=True, url=url)
        if result.get("errorText"):
            return [f"the browser could not load it ({result['errorText']})"]
        if not self.wait_for("Page.loadEventFired", LOAD_TIMEOUT):
            return [f"no load event within {LOAD_TIMEOUT:g} s"]
        script = """(async () => {
            const images = [...document.images];
            for (const image of images) image.loading = "eager";
            await Promise.all(images.map(image => image.complete ? null : new Promise(done => {
                image.addEventListener("load", done); image.addEventListener("error", done);
                setTimeout(done, IMAGE_TIMEOUT_MS); })));
            return {broken: images.filter(i => !(i.complete && i.naturalWidth > 0))
                                  .map(i => i.getAttribute("src") || i.currentSrc),
                    text: document.body ? document.body.innerText.trim().length : 0,
                    title: document.title};
        })()""".replace("IMAGE_TIMEOUT_MS", str(int(IMAGE_TIMEOUT * 1000)))
        state = self.call(
            "Runtime.evaluate",
            session=True,
            expression=script,
            awaitPromise=True,
            returnByValue=True,
            timeout=IMAGE_TIMEOUT + LOAD_TIMEOUT,
        )["result"]["value"]
        problems = [f"image {src} is not drawn (missing or not an image)" for src in state["broken"]]
        requested = {
            e["params"]["requestId"]: e["params"]["request"]["url"]
            for e in self.events
            if e["method"] == "Network.requestWillBeSent"
        }
        for event in self.events:
            if event["method"] == "Network.loadingFailed" and not event["params"].get("canceled"):
                where = requested.get(event["params"]["requestId"], "?")
                if where.startswith("file:"):
                    problems.append(f"{where} failed to load ({event['params'].get('errorText', '')})")
        if state["text"] == 0 and not state["broken"]:
            problems.append("the page shows no text")
        shot = self.call("Page.captureScreenshot", session=True, format="png")["data"]
        screenshot.write_bytes(base64.b64decode(shot))
        return problems

    def close(self):
        try:
            self.call("Browser.close", timeout=5.0)
        except (RuntimeError, TimeoutError, OSError):
            pass
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        for fd in (self._to_child, self._from_child):
            try:
                os.close(fd)
            except OSError:
                pass
        shutil.rmtree(self.profile, ignore_errors=True)


def screenshot_name(page: str) -> str:
    return page.removesuffix(".html").replace("/", "__") + ".png"


# -- the command ---------------------------------------------------------------------------
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("site", type=Path, help="the built site's folder (e.g. docs/_build/html)")
    parser.add_argument("--out", type=Path, default=Path("docs/_build/screenshots"), help="screenshots' folder")
    parser.add_argument("--pages", nargs="+", help="pages to check, relative to the site (default: its main pages)")
    parser.add_argument("--window-size", default="1280,900", help="WIDTH,HEIGHT of the browser window")
    parser.add_argument("--browser", default=os.environ.get("CHROMIUM", "chromium"), help="Chromium's executable")
    parser.add_argument("--require-browser", action="store_true", help="fail (instead of skip) without Chromium")
    args = parser.parse_args(argv)

    root = args.site.resolve()
    if not root.is_dir():
        print(f"docs-check: {args.site} is no folder; build the site first (make docs)", file=sys.stderr)
        return 1
    pages = args.pages or site_pages(root)
    if not pages:
        print(f"docs-check: {args.site} has no HTML pages", file=sys.stderr)
        return 1
    problems = [p for page in pages for p in static_problems(root, page)]

    executable = shutil.which(args.browser)
    if executable is None:
        line = f"docs-check: browser check skipped ({args.browser} is not installed; docs/tools/install_chromium.sh)"
        print(line, file=sys.stderr)
        if args.require_browser:
            return 1
    else:
        width, height = (int(v) for v in args.window_size.split(","))
        args.out.mkdir(parents=True, exist_ok=True)
        browser = Browser(executable, width, height)
        try:
            for page in pages:
                if not (root / page).is_file():
                    continue  # reported by the static checks
                shot = args.out / screenshot_name(page)
                found = browser.check_page((root / page).as_uri(), shot)
                problems += [f"{page}: {p}" for p in found]
                print(f"docs-check: {page} -> {shot}" if not found else f"docs-check: {page} FAILED")
        finally:
            browser.close()

    for problem in problems:
        print(f"docs-check: {problem}", file=sys.stderr)
    verdict = "failed" if problems else "passed"
    print(f"docs-check: {len(pages)} pages, {len(problems)} problems: {verdict}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
