"""User YAML is plain data read with YAML 1.2 numbers, bounded in size and depth (issue 9)."""

import os
import time

import pytest
import yaml

from vemkit.config.mesh_options import mesh_request
from vemkit.config.safe_yaml import MAX_FILE_BYTES, SceneDumper, parse_yaml, read_user_file
from vemkit.exceptions import SceneError


@pytest.mark.parametrize(
    "text, value",
    [
        ("1e-10", 1e-10),
        ("2e3", 2000.0),
        ("1E3", 1000.0),
        ("1.", 1.0),
        (".5", 0.5),
        ("+3", 3),
        ("010", 10),
        ("0x1f", 31),
        ("0o17", 15),
        ("1:20", "1:20"),
        ("1_000", "1_000"),
        ("yes", "yes"),
        ("on", "on"),
        ("true", True),
        ("2001-12-14", "2001-12-14"),
        ("~", None),
        ("", None),
        ("-.inf", float("-inf")),
    ],
)
def test_yaml_1_2_core_scalars(text, value):
    assert parse_yaml(f"a: {text}", "t") == {"a": value}


@pytest.mark.parametrize(
    "text, says",
    [
        ("a: &x 1\nb: *x", "anchors and aliases"),
        ("a: !!float 1:20", "explicit tags"),
        ("a: !!python/object/apply:os.system [ls]", "explicit tags"),
        ("a: 1\na: 2", "duplicate key 'a'"),
        ("a: " + "[" * 33 + "]" * 33, "nested more than 32"),
        ("a: " + "[" * 5000 + "]" * 5000, "nested more than 32"),
        ("a: " + "9" * 5000, "integer with 5000 digits"),
    ],
)
def test_refused_yaml_is_one_line_naming_the_source(text, says):
    with pytest.raises(SceneError) as caught:
        parse_yaml(text, "scene.yaml")
    assert says in str(caught.value) and str(caught.value).startswith("scene.yaml:")
    assert "\n" not in str(caught.value)


def test_billion_laughs_is_refused_at_once():
    text = 'a: &a ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]\n' + "".join(
        f"{c}: &{c} [*{p},*{p},*{p},*{p},*{p},*{p},*{p},*{p},*{p}]\n" for p, c in zip("abcdefgh", "bcdefghi")
    )
    start = time.perf_counter()
    with pytest.raises(SceneError, match="aliases"):
        parse_yaml(text, "laughs.yaml")
    assert time.perf_counter() - start < 1.0


def test_dumped_strings_read_back_as_strings_with_both_yaml_versions():
    data = {"s": ["1e3", "yes", "1:20", "null", "0o17", "1_000", "2001-12-14", "true", ""], "f": [1e-10, 2000.0]}
    text = yaml.dump(data, Dumper=SceneDumper, sort_keys=False)
    assert parse_yaml(text, "t") == data and yaml.safe_load(text) == data


def test_only_small_regular_files_are_read(tmp_path):
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    with pytest.raises(SceneError, match="FIFO"):
        read_user_file(fifo)  # must not block waiting for a writer
    with pytest.raises(SceneError, match="directory"):
        read_user_file(tmp_path)
    big = tmp_path / "big.yaml"
    big.write_bytes(b"#" * (MAX_FILE_BYTES + 1))
    with pytest.raises(SceneError, match="larger than 256 KiB"):
        read_user_file(big)
    fits = tmp_path / "fits.yaml"
    fits.write_bytes(b"#" * MAX_FILE_BYTES)
    assert len(read_user_file(fits)) == MAX_FILE_BYTES


def test_mesh_options_use_the_scene_rules():
    assert mesh_request("voronoi", 4, ["merge_tol=1e-3", "seed=0x10"]) == {
        "family": "voronoi",
        "n": 4,
        "merge_tol": 0.001,
        "seed": 16,
    }
    with pytest.raises(SceneError, match=r"^--option seed = 'abc': must be an integer"):
        mesh_request("voronoi", 4, ["seed=abc"])
    with pytest.raises(SceneError, match=r"^--option anisotropy = 1e\+300: must be <= 100"):
        mesh_request("voronoi", 4, ["anisotropy=1e300"])
    with pytest.raises(SceneError, match=r"^n = 0: must be >= 1"):
        mesh_request("square", 0)
