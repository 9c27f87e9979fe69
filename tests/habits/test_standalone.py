"""The repository stands alone, and its pages can be followed as written (issue 33 items 6 and 7).

- No tracked file names a path outside the repository (the developers' contract and the paper's
  text lived next to it, in ``../shared/``, which a clone does not have) nor a section of that
  contract: every contract is on the project's own pages (``docs/reference/``).
- Every command a page shows is runnable from a clone: the programs installed into ``.venv`` are
  called as ``.venv/bin/…``, as ``make`` installs them (a bare ``vemkit`` or ``snakemake`` is
  "command not found").
"""

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
#: what a reference outside the repository looks like
OUTSIDE = re.compile(r"\.\./shared|shared/SPEC|shared/seed|/work/shared|SPEC\.md|SPEC ?§|\bSPEC \d")
#: the programs `make` installs into .venv and the pages call
PROGRAMS = r"(?:vemkit|snakemake|python3?|pytest|sphinx-build)"
BARE_LINE = re.compile(rf"^\s*(?:\$\s+)?{PROGRAMS}\s")
INLINE = re.compile(r"(?<!`)`([^`\n]+)`(?!`)")
#: a placeholder argument (SCENE.yaml, OUT.nc, N): a synopsis, not a command to run
PLACEHOLDER = re.compile(r"\b[A-Z][A-Z_]*(?:\.[a-z]+)?\b")


def tracked_files() -> list[str]:
    out = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
    return [name for name in out.decode().split("\0") if name]


def text_of(name: str) -> str | None:
    data = (ROOT / name).read_bytes() if (ROOT / name).is_file() else b""
    if b"\0" in data[:8192]:
        return None  # binary: netCDF archives, pictures
    return data.decode("utf-8", errors="replace")


def test_no_tracked_file_names_a_path_or_contract_outside_the_repository():
    found = []
    itself = str(Path(__file__).resolve().relative_to(ROOT))  # spells the patterns out
    for name in tracked_files():
        text = text_of(name) if name != itself else None
        if text is None:
            continue
        for number, line in enumerate(text.splitlines(), 1):
            if OUTSIDE.search(line):
                found.append(f"{name}:{number}: {line.strip()[:100]}")
    assert not found, "references outside the repository:\n" + "\n".join(found)


def test_the_pattern_finds_what_it_must():
    for line in ("see ../shared/SPEC.md", "(SPEC §6)", "SPEC 5", "the seed in shared/seed/x.txt"):
        assert OUTSIDE.search(line), line
    for line in ("SPEC_PAPER = 1", "SPECIALIZE", "specification"):
        assert not OUTSIDE.search(line), line


def doc_pages() -> list[str]:
    return [n for n in tracked_files() if n == "README.md" or (n.startswith("docs/") and n.endswith((".md", ".rst")))]


def code_lines(text: str):
    """(line number, line) of every line of a fenced shell block and of an indented block."""
    fence, language = None, ""
    previous_blank = True
    for number, line in enumerate(text.splitlines(), 1):
        mark = re.match(r"^\s*(`{3,}|~{3,})\s*\{?([\w-]*)\}?", line)
        if mark and fence is None:
            fence, language = mark.group(1), mark.group(2)
        elif mark and line.strip().startswith(fence):
            fence = None
        elif fence is not None:
            if language in ("", "sh", "bash", "shell", "console", "text"):
                yield number, line
        elif line.startswith("    ") and previous_blank is not None:
            yield number, line
        previous_blank = not line.strip()


def runnable(span: str) -> bool:
    """An inline command a reader would copy: a program with arguments, not a synopsis with
    placeholders nor a subcommand named in prose (`vemkit solve`, `vemkit solve --set`)."""
    words = span.split()
    if not re.fullmatch(PROGRAMS, words[0]) or len(words) < 2 or PLACEHOLDER.search(span):
        return False
    if words[0] == "vemkit":
        return any(re.search(r"\.(ya?ml|nc|vtu|msh)$", w) for w in words[2:])
    return True


@pytest.mark.parametrize("page", doc_pages())
def test_every_command_on_a_page_is_called_from_the_venv(page):
    text = (ROOT / page).read_text(encoding="utf-8")
    bare = [f"{page}:{n}: {line.strip()}" for n, line in code_lines(text) if BARE_LINE.match(line)]
    for number, line in enumerate(text.splitlines(), 1):
        bare += [f"{page}:{number}: `{span}`" for span in INLINE.findall(line) if runnable(span)]
    assert not bare, "call these as .venv/bin/…:\n" + "\n".join(bare)


def test_the_command_check_finds_what_it_must():
    page = (
        "text\n\n```sh\nvemkit solve a.yaml -o a.nc\n.venv/bin/vemkit solve a.yaml -o a.nc\n```\n\n    snakemake -j2\n"
    )
    assert [n for n, line in code_lines(page) if BARE_LINE.match(line)] == [4, 8]
    assert runnable("snakemake -j2 three_d") and runnable("vemkit solve block.yaml -o block.nc")
    assert not runnable("vemkit solve SCENE.yaml -o OUT.nc") and not runnable("vemkit solve --set")
    assert not runnable(".venv/bin/snakemake -j2 three_d")


@pytest.mark.parametrize("command", [(), ("solve",), ("mesh",), ("adapt",)])
def test_the_help_is_plain_text_for_a_terminal(command):
    """`vemkit --help` printed the module docstring's first line, raw reST and a contract section."""
    import sys

    run = subprocess.run([sys.executable, "-m", "vemkit.cli", *command, "--help"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "``" not in run.stdout and not OUTSIDE.search(run.stdout) and " ;" not in run.stdout
    if not command:
        assert "frictional contact" in run.stdout and "Exit status 0" in run.stdout
