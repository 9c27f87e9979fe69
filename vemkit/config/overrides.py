"""``--set key.path=value`` overrides of a scene, checked key by key against the scene schema.

Every key must exist in the schema (a close match is suggested), every index in the list it
indexes; a new mesh size replaces the scene's own (one size, docs/reference/files.md). Imports from vemkit:
:mod:`vemkit.config.scene_schema`, :mod:`vemkit.config.safe_yaml`, ``vemkit.exceptions``.
"""

from __future__ import annotations

import copy
import re

from vemkit.config.dimension import written_dimension
from vemkit.config.safe_yaml import parse_yaml
from vemkit.config.scene_schema import branch_names, key_name, resolve, schema_root, show, suggest
from vemkit.exceptions import SceneError

#: an override of discretization.mesh.KEY removes these keys: one size (docs/reference/files.md), or a file
_MESH_SIZE_KEYS = {
    "n": ("h", "cells", "file"),
    "h": ("n", "cells", "file"),
    "cells": ("n", "h", "file"),
    "file": ("n", "h", "cells", "family"),
}


def _branch_for(node: dict, segment, container, override: str, path: list) -> dict:
    """The alternative of a oneOf that ``container[segment]`` lives in: for an index a list branch;
    for a key the branch the container's own keys fit (``domain``: a polygon, box or extrude
    mapping), else the first that has the key. A key of another branch than the container's is
    refused: the whole entry must change."""
    branches = [resolve(branch) for branch in node.get("oneOf", ())]
    if not branches:
        return node
    if isinstance(segment, int):
        return next((b for b in branches if "items" in b), node)
    mappings = [b for b in branches if "properties" in b]
    having = [b for b in mappings if segment in b["properties"]]
    keys = set(container) if isinstance(container, dict) else set()
    fitting = [b for b in mappings if keys and keys <= set(b["properties"])]
    if fitting and having and not any(b in having for b in fitting):
        other = branch_names([having[0]])
        raise SceneError(
            f"--set {override}: {key_name([*path, segment])} belongs to another form of {key_name(path)} "
            f"({other}) than the scene's; replace the whole entry, e.g. --set '{key_name(path)}={{{segment}: ...}}'",
            key=key_name([*path, segment]),
        )
    return next((b for b in fitting if b in having), None) or (having or fitting or mappings or [node])[0]


_KEY_PATH = re.compile(r"[\w-]+(?:\.[\w-]+|\[\d+\])*")
_KEY_SEGMENT = re.compile(r"\.?([\w-]+)|\[(\d+)\]")


def _key_segments(override: str, key_text: str) -> list:
    """``a.b[0].c`` as ["a", "b", 0, "c"]; an empty component or a bad index is a true message."""
    if _KEY_PATH.fullmatch(key_text):
        return [int(m[2]) if m[2] is not None else m[1] for m in _KEY_SEGMENT.finditer(key_text)]
    if re.search(r"\.\.|^\.|\.$|\.\[", key_text):
        problem = "a key component is empty (two dots, or a dot at an end)"
    elif (
        re.search(r"\[[^\]]*\]", key_text)
        and not re.search(r"\[\d+\]", key_text)
        or re.search(r"\[(?!\d+\])", key_text)
    ):
        problem = "a list index is a whole number from 0 in brackets, e.g. boundary.dirichlet[0]"
    else:
        problem = "a key is letters, digits, _ and -, joined by dots"
    raise SceneError(
        f"--set {override}: {problem}; expected key.path=value, e.g. --set solver.method=uzawa", key=key_text
    )


def _schema_step(node: dict, segment, container, override: str, path: list) -> dict:
    """The schema of ``container[segment]`` (``container`` the value at ``path``)."""
    node = _branch_for(node, segment, container, override, path)
    if isinstance(segment, int):
        if not isinstance(container, list) or "items" not in node:
            raise SceneError(
                f"--set {override}: {key_name(path)} = {show(container)} is not a list; drop [{segment}]",
                key=key_name(path),
            )
        if segment >= len(container):
            count = len(container)
            indices = {0: "no index", 1: "the index 0"}.get(count, f"an index 0 ... {count - 1}")
            raise SceneError(
                f"--set {override}: {key_name(path)} = {show(container)} has {count} "
                f"entr{'y' if count == 1 else 'ies'}: give {indices}, or set the whole list, "
                f"e.g. --set '{key_name(path)}=[...]'",
                key=key_name(path),
            )
        return resolve(node["items"])
    if isinstance(container, list):
        raise SceneError(
            f"--set {override}: {key_name(path)} = {show(container)} is a list: index it "
            f"({key_name(path)}[0]) or set the whole value, e.g. --set '{key_name(path)}={{{segment}: ...}}'",
            key=key_name(path),
        )
    if not isinstance(container, dict):
        raise SceneError(
            f"--set {override}: {key_name(path)} = {show(container)} has no entry {segment!r}", key=key_name(path)
        )
    if "properties" in node:
        if segment not in node["properties"]:
            raise SceneError(
                f"--set {override}: unknown key {key_name([*path, segment])!r}{suggest(segment, node['properties'])}",
                key=key_name([*path, segment]),
            )
        return resolve(node["properties"][segment])
    if isinstance(node.get("additionalProperties"), dict):  # a map: side name -> entry
        return resolve(node["additionalProperties"])
    raise SceneError(f"--set {override}: {key_name(path)!r} has no key {segment!r}", key=key_name(path))


def _default(node: dict, data: dict):
    """The schema's default of a key not in the scene; a vector's (body_force) has a 3D scene's three
    components (a 3D domain, or model 3d with a mesh file)."""
    value = copy.deepcopy(node.get("default", {}))
    if value == [0.0, 0.0]:  # the zero vector (body_force): one component per dimension of the body
        value = [0.0] * written_dimension(data)
    return value


def apply_override(data: dict, override: str) -> None:
    """Apply ``a.b[0].c=value`` to ``data``; every key must exist in the schema, every index in
    the list it indexes."""
    key_text, separator, value_text = str(override).partition("=")
    if not separator or not key_text.strip():
        raise SceneError(f"--set {override}: expected key.path=value, e.g. --set solver.method=uzawa")
    segments = _key_segments(override, key_text.strip())
    value = parse_yaml(value_text, f"--set {override}")
    node, container, path = resolve(schema_root()), data, list[str | int]()
    for position, segment in enumerate(segments):
        node = _schema_step(node, segment, container, override, path)
        last = position == len(segments) - 1
        if isinstance(segment, str) and not last:
            container.setdefault(segment, _default(node, data))
        path.append(segment)
        if not last:
            container = container[segment]
        else:
            if path[:2] == ["discretization", "mesh"] and segment in _MESH_SIZE_KEYS:
                for other in _MESH_SIZE_KEYS[segment]:  # a new size replaces the scene's own
                    container.pop(other, None)
            container[segment] = value
