"""The scene schema (``schemas/scene.schema.json``) walked: validation and its one-line messages.

The schema holds the keys, the bounds and the ``default`` values; this module reads it once, finds
the first problem of a scene in file order and words it as a :class:`SceneError` naming the key and
the fix, and fills the defaults (:func:`normalized`). :mod:`vemkit.config.scene`,
:mod:`vemkit.config.overrides` and :mod:`vemkit.config.mesh_options` (the ``vemkit mesh`` options,
the schema's ``discretization.mesh`` node) use it. Imports from vemkit: ``vemkit.exceptions`` only.
"""

from __future__ import annotations

import copy
import difflib
import json
import sys
from functools import lru_cache
from importlib.resources import files

import jsonschema

from vemkit.exceptions import SceneError

NO_DIRICHLET = "no Dirichlet part: the body is not held; add boundary.dirichlet: [right]"
TYPE_NAMES = {
    "number": "a number",
    "integer": "an integer",
    "string": "a string",
    "object": "a mapping",
    "array": "a list",
    "null": "null",
    "boolean": "true/false",
}


def scene_schema() -> dict:
    """The scene JSON Schema (draft 2020-12), read from the package data (a fresh copy)."""
    return json.loads((files("vemkit.config") / "schemas" / "scene.schema.json").read_text(encoding="utf-8"))


@lru_cache(maxsize=1)
def schema_validator() -> jsonschema.Draft202012Validator:
    return jsonschema.Draft202012Validator(scene_schema())


def schema_root() -> dict:
    """The validator's schema: the dict of :func:`scene_schema`, read once."""
    return schema_validator().schema  # type: ignore[return-value]  # typed as a bool or a Mapping


def resolve(node: dict) -> dict:
    """``node`` with a local ``$ref`` merged in (sibling keywords win)."""
    while "$ref" in node:
        target = schema_root()["$defs"][node["$ref"].rsplit("/", 1)[-1]]
        node = {**target, **{k: v for k, v in node.items() if k != "$ref"}}
    return node


def key_name(path) -> str:
    text = ""
    for part in path:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return text or "(scene)"


def show(value) -> str:
    try:
        text = repr(value) if isinstance(value, str) else json.dumps(value, default=str, ensure_ascii=False)
    except (TypeError, ValueError):
        text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def suggest(word, choices) -> str:
    close = difflib.get_close_matches(str(word), [str(c) for c in choices], n=1)
    allowed = ", ".join(str(c) for c in choices)
    return f" (did you mean {close[0]!r}?); allowed here: {allowed}" if close else f"; allowed here: {allowed}"


def scene_fix(key: str | None) -> str:
    """The fix a message suggests for ``key`` (None: an unknown key)."""
    return "fix the scene" if key is None else f"fix the scene or --set {key}=..."


def check_finite(value, path, fix=scene_fix) -> None:
    if (
        isinstance(value, (int, float)) and not isinstance(value, bool) and not abs(value) <= sys.float_info.max
    ):  # nan, inf, ints beyond the float range
        raise SceneError(
            f"{key_name(path)} = {value}: must be a finite number; {fix(key_name(path))}", key=key_name(path)
        )
    children = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for key, child in children:
        check_finite(child, [*path, key], fix)


def document_order(data, error) -> tuple:
    """Position of ``error`` in the scene, so that the first problem in file order is reported."""
    position, node = [], data
    for part in error.absolute_path:
        keys = list(node) if isinstance(node, dict) else list(range(len(node)))
        position.append(keys.index(part) if part in keys else len(keys))
        node = node[part]
    if error.validator == "required" and isinstance(node, dict):
        position.append(len(node))
    elif error.validator == "additionalProperties" and isinstance(node, dict):
        allowed = resolve(error.schema).get("properties", {})
        position.append(min((i for i, k in enumerate(node) if k not in allowed), default=0))
    return tuple(position)


def branch_names(branches) -> str:
    """What the alternatives of a oneOf accept, in words."""
    names = []
    for branch in map(resolve, branches):
        if "enum" in branch:
            names += [str(v) for v in branch["enum"]]
        elif branch.get("type") == "object" and branch.get("required"):
            names.append(f"a mapping with {', '.join(branch['required'])}")
        else:
            types = branch.get("type", [])
            names += [TYPE_NAMES.get(t, t) for t in ([types] if isinstance(types, str) else types)]
    return " or ".join(names)


def _took_branch(value, branch: dict) -> bool:
    """Whether a mapping has every key a oneOf branch requires (and no key it does not know)."""
    branch = resolve(branch)
    if not isinstance(value, dict) or "properties" not in branch:
        return False
    return set(branch.get("required", ())) <= set(value) and set(value) <= set(branch["properties"])


def _title(schema: dict, model) -> str:
    """`` (title)`` of a schema node; a key whose meaning depends on the model (``material.nu``) has
    one per model (``x-title-by-model``)."""
    titles = schema.get("x-title-by-model", {})
    title = titles.get(model, schema.get("title")) if isinstance(model, str) else schema.get("title")
    return f" ({title})" if title else ""


def schema_error_message(error, fix=scene_fix, model: str | None = "plane_stress") -> str:
    """The one line of a schema ``error`` (``model``: the scene's, for titles that depend on it)."""
    path, keyword, schema = list(error.absolute_path), error.validator, resolve(error.schema)
    key, value = key_name(path), error.instance
    if keyword == "oneOf":  # the value took one branch when the problem lies inside it: report that
        deeper = [e for e in error.context or () if len(e.absolute_path) > len(path)]
        taken = [e for e in deeper if _took_branch(value, error.validator_value[e.relative_schema_path[0]])]
        deeper = taken or deeper  # a mapping with a branch's required keys took that branch (domain: polygon, box)
        if deeper:
            return schema_error_message(jsonschema.exceptions.best_match(deeper), fix, model)
        title = f" ({schema['title']})" if "title" in schema else ""
        return f"{key} = {show(value)}: must be {branch_names(error.validator_value)}{title}; {fix(key)}"
    if "propertyNames" in error.absolute_schema_path:
        what = schema.get("x-name", "a side name (letters, digits, _ and -)")  # the names' own words
        return f"{key}: {show(value)} is not {what}; fix the scene"
    if keyword == "minProperties":
        return (
            f"{key} = {{}}: {NO_DIRICHLET}"
            if key == "boundary.dirichlet"
            else f"{key} = {{}}: must have at least {error.validator_value} entries; {fix(key)}"
        )
    if keyword == "additionalProperties":
        allowed = list(schema.get("properties", {}))
        extra = next(k for k in value if k not in allowed)
        return f"{key_name([*path, extra])}: unknown key{suggest(extra, allowed)}; {fix(None)}"
    if keyword == "required":
        missing = next(k for k in error.validator_value if k not in value)
        title = resolve(schema["properties"][missing]).get("title", "")
        if key_name([*path, missing]) == "boundary.dirichlet":
            return f"boundary.dirichlet is missing: {NO_DIRICHLET}"
        return f"{key_name([*path, missing])} is missing ({title}); add it to the scene or --set {key_name([*path, missing])}=..."
    if keyword == "minItems" and key == "boundary.dirichlet":
        return f"boundary.dirichlet = []: {NO_DIRICHLET}"
    if keyword == "pattern" and schema == schema_root()["$defs"]["side"]:
        return f"{key} = {show(value)}: not a side name (letters, digits, _ and -); fix the scene"
    bound = error.validator_value
    if keyword == "type":
        types = [bound] if isinstance(bound, str) else bound
        need = "must be " + " or ".join(TYPE_NAMES.get(t, t) for t in types)
    elif keyword in ("enum", "const"):
        need = "must be one of " + ", ".join(map(str, bound if keyword == "enum" else [bound]))
    else:
        need = {
            "exclusiveMinimum": f"must be > {bound}",
            "minimum": f"must be >= {bound}",
            "exclusiveMaximum": f"must be < {bound}",
            "maximum": f"must be <= {bound}",
            "minItems": f"must have at least {bound} entries",
            "maxItems": f"must have at most {bound} entries",
            "uniqueItems": "lists an entry twice",
            "minLength": "must not be empty",
            "maxLength": f"must be at most {bound} characters",
        }.get(keyword, error.message)
    return f"{key} = {show(value)}: {need}{_title(schema, model)}; {fix(key)}"


def first_problem(errors, data):
    """The schema error to report: the first in file order, a wrong type before the rest."""
    return min(errors, key=lambda e: (document_order(data, e), e.validator != "type"))


def validate(data, model: str | None = None) -> None:
    """A one-line SceneError for the first problem of ``data`` (the scene as plain data); ``model``:
    the scene's model for the titles that depend on it, when ``data`` omits it (its body's default)."""
    if not isinstance(data, dict):
        raise SceneError(f"the scene must be a mapping of keys (name, material, boundary, ...), got {show(data)}")
    check_finite(data, [])
    errors = list(schema_validator().iter_errors(data))
    if errors:
        raise SceneError(
            schema_error_message(first_problem(errors, data), model=data.get("model") or model or "plane_stress")
        )


def normalized(value, node: dict):
    """Defaults filled, keys in schema order, numbers as float and integers as int."""
    node = resolve(node)
    types = node.get("type")
    types = [types] if isinstance(types, str) else (types or [])
    if isinstance(value, dict) and "properties" in node:
        result = {}
        for name, child in node["properties"].items():
            if name in value:
                result[name] = normalized(value[name], child)
            elif "default" in resolve(child):
                result[name] = normalized(copy.deepcopy(resolve(child)["default"]), child)
        return result
    if isinstance(value, list) and "items" in node:
        return [normalized(item, node["items"]) for item in value]
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return int(value) if "integer" in types else float(value)
    return value
