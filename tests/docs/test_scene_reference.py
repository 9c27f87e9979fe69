"""The scene-key reference cannot drift: it is generated from the schema, and every key of the
schema must say what it means."""

import json

from docs_paths import ROOT, vemkit_docs

SCHEMA = json.loads((ROOT / "vemkit" / "config" / "schemas" / "scene.schema.json").read_text())


def _all_property_paths(node, path=""):
    """Every property of the schema, by a walk independent of the generator's."""
    defs = SCHEMA["$defs"]
    if not isinstance(node, dict):
        return
    if "$ref" in node:
        node = {**defs[node["$ref"].rsplit("/", 1)[-1]], **{k: v for k, v in node.items() if k != "$ref"}}
    for key, child in node.get("properties", {}).items():
        sub = f"{path}.{key}" if path else key
        yield sub, child
        yield from _all_property_paths(child, sub)
    for alt in [*node.get("oneOf", ()), *node.get("anyOf", ())]:
        yield from _all_property_paths(alt, path)
    if isinstance(node.get("items"), dict):
        yield from _all_property_paths(node["items"], f"{path}[]")
    if isinstance(node.get("additionalProperties"), dict):
        yield from _all_property_paths(node["additionalProperties"], f"{path}.<side>")


def test_every_scene_key_has_a_title_or_description():
    defs = SCHEMA["$defs"]
    missing = []
    for path, child in _all_property_paths(SCHEMA):
        resolved = {**defs[child["$ref"].rsplit("/", 1)[-1]], **child} if "$ref" in child else child
        if not (resolved.get("title") or resolved.get("description")):
            missing.append(path)
    assert not missing, f"scene keys without a title or description in scene.schema.json: {missing}"


def test_the_reference_lists_every_key_with_its_meaning():
    rows = {row["path"]: row for row in vemkit_docs.scene_key_rows(SCHEMA)}
    paths = {path for path, _ in _all_property_paths(SCHEMA)}
    assert paths <= set(rows), sorted(paths - set(rows))
    text = vemkit_docs.scene_keys_markdown(SCHEMA)
    for path in paths:
        assert f"| `{path}` |" in text, path
        assert rows[path]["title"] or rows[path]["description"], path


def test_the_reference_shows_type_range_and_default():
    rows = {row["path"]: row for row in vemkit_docs.scene_key_rows(SCHEMA)}
    assert rows["material.nu"]["range"] == "≥ -0.999, < 0.5"
    assert rows["solver.method"]["type"] == 'one of `"ssn"`, `"uzawa"`'
    assert rows["model"]["default_by_dimension"] == {"2": "plane_stress", "3": "3d"}  # the body says the default
    assert (
        '| `model` | one of `"plane_stress"`, `"plane_strain"`, `"3d"` | – | `"plane_stress"` (2D body), `"3d"` (3D body) |'
        in (vemkit_docs.scene_keys_markdown(SCHEMA))
    )
    assert rows["discretization.mesh.n"]["type"] == "integer"
    assert rows["material"]["required"]
