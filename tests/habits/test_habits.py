"""The habits of a maintained package (issue 23 item 8): the citation file, the dependency lock,
and the lint configuration's list of public modules."""

import re
from datetime import date
from pathlib import Path

import pytest
import yaml

import vemkit

ROOT = Path(__file__).resolve().parents[2]
tomllib = pytest.importorskip("tomllib")  # Python >= 3.11
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))


def _person_or_entity(author: dict) -> bool:
    return bool(author.get("name") or author.get("family-names"))


def test_citation_file_has_the_keys_cff_requires():
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    assert cff["cff-version"] == "1.2.0"
    for key in ("message", "title", "authors"):
        assert cff.get(key), key
    assert all(_person_or_entity(a) for a in cff["authors"])
    assert cff["type"] == "software"
    assert cff["version"] == vemkit.__version__
    date.fromisoformat(str(cff["date-released"]))
    paper = cff["preferred-citation"]
    assert paper["type"] == "article" and paper["year"] == 2022 and paper["volume"] == 107
    assert paper["title"] == "Virtual element method for a frictional contact problem with normal compliance"
    assert paper["journal"] == "Communications in Nonlinear Science and Numerical Simulation"
    assert [a["family-names"] for a in paper["authors"]] == ["Wu", "Wang", "Han"] and str(paper["start"]) == "106125"
    assert paper["authors"] and all(_person_or_entity(a) for a in paper["authors"])


def _name(requirement: str) -> str:
    return re.split(r"[<>=!~\[; ]", requirement, maxsplit=1)[0].lower().replace("_", "-").replace(".", "-")


def test_the_lock_pins_every_dependency_and_extra():
    lines = [
        line
        for line in (ROOT / "requirements.lock").read_text(encoding="utf-8").splitlines()
        if line.strip() and not line.startswith("#")
    ]
    pins = {}
    for line in lines:
        assert re.fullmatch(r"[A-Za-z0-9._-]+==[A-Za-z0-9.+!_-]+", line), f"not a pin: {line}"
        name, version = line.split("==")
        pins[_name(name)] = version
    assert "vemkit" not in pins
    project = PYPROJECT["project"]
    wanted = list(project["dependencies"])
    extras = re.search(r"^EXTRAS\s*:?=\s*(\S+)", (ROOT / "Makefile").read_text(encoding="utf-8"), re.M)
    for extra in extras.group(1).split(",") + ["docs"]:  # the extras make install installs, and make docs'
        wanted += project["optional-dependencies"][extra]
    missing = sorted({_name(r) for r in wanted} - set(pins))
    assert not missing, f"not in requirements.lock (run make lock): {missing}"


def test_mypy_checks_every_module_of_the_public_api():
    files = set(PYPROJECT["tool"]["mypy"]["files"])
    modules = set(vemkit._API.values()) | {"vemkit", "vemkit.config.scene", "vemkit.cli"}
    for module in modules:
        path = module.replace(".", "/")
        assert f"{path}.py" in files or f"{path}/__init__.py" in files, module
    assert all((ROOT / f).is_file() for f in files)


def test_the_makefile_has_the_habits_targets():
    text = (ROOT / "Makefile").read_text(encoding="utf-8")
    for target in ("lint", "format", "lock", "docs-check"):
        assert re.search(rf"^{re.escape(target)}:", text, re.M), target
