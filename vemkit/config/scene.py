"""Scene files (SPEC §6): read the YAML, apply ``--set`` overrides, validate, fill the defaults.

One source of truth: ``vemkit/config/schemas/scene.schema.json`` holds the keys, the bounds and the
``default`` values; this module walks it. Every problem is a :class:`SceneError` (a ``ValueError``)
with a one-line message naming the offending key, e.g.
``material.nu = 0.7: must be < 0.5 (Poisson ratio of plane stress); fix the scene or --set material.nu=...``
"""

from __future__ import annotations

import copy
import difflib
import json
import re
import sys
from functools import lru_cache, partial
from importlib.resources import files
from pathlib import Path
from typing import NamedTuple

import jsonschema
import yaml

from vemkit.config.boundary_conditions import (
    boundary_expressions,
    check_contact,
    check_mesh_size,
    check_rigid_motions,
    check_sides,
    compile_checked,
    evaluate_checked,
    inside_points,
)
from vemkit.config.domain import UNIT_SQUARE_SIDES, domain_from_spec
from vemkit.config.domain3d import domain3d_from_spec
from vemkit.config.expressions import Expression
from vemkit.config.loads import DEFAULT_BODY_FORCE_PROJECTION_K2
from vemkit.config.material import lame_parameters
from vemkit.config.mesh_resolution import check_mesh_resolution
from vemkit.config.safe_yaml import SceneDumper, read_user_file
from vemkit.config.safe_yaml import parse_yaml as _parse_yaml
from vemkit.config.scene3d import check_model_domain, semantic_checks_3d
from vemkit.exceptions import SceneError

__all__ = ["PowerLaw", "Scene", "SceneError", "load_scene", "scene_from_dict", "scene_from_yaml", "scene_schema"]

NO_DIRICHLET = "no Dirichlet part: the body is not held; add boundary.dirichlet: [right]"
_TYPE_NAMES = {
    "number": "a number",
    "integer": "an integer",
    "string": "a string",
    "object": "a mapping",
    "array": "a list",
    "null": "null",
    "boolean": "true/false",
}


class PowerLaw(NamedTuple):
    """``p(t) = k (t)_+^m`` (5.1)."""

    k: float
    m: float


# -- the schema ----------------------------------------------------------------------------------
def scene_schema() -> dict:
    """The scene JSON Schema (draft 2020-12), read from the package data (a fresh copy)."""
    return json.loads((files("vemkit.config") / "schemas" / "scene.schema.json").read_text(encoding="utf-8"))


@lru_cache(maxsize=1)
def _validator() -> jsonschema.Draft202012Validator:
    return jsonschema.Draft202012Validator(scene_schema())


def _schema() -> dict:
    """The validator's schema: the dict of :func:`scene_schema`, read once."""
    return _validator().schema  # type: ignore[return-value]  # typed as a bool or a Mapping


def _resolve(node: dict) -> dict:
    """``node`` with a local ``$ref`` merged in (sibling keywords win)."""
    while "$ref" in node:
        target = _schema()["$defs"][node["$ref"].rsplit("/", 1)[-1]]
        node = {**target, **{k: v for k, v in node.items() if k != "$ref"}}
    return node


def _key(path) -> str:
    text = ""
    for part in path:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return text or "(scene)"


def _show(value) -> str:
    try:
        text = repr(value) if isinstance(value, str) else json.dumps(value, default=str, ensure_ascii=False)
    except (TypeError, ValueError):
        text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


#: an override of discretization.mesh.KEY removes these keys: one size (SPEC §7), or a file
_MESH_SIZE_KEYS = {
    "n": ("h", "cells", "file"),
    "h": ("n", "cells", "file"),
    "cells": ("n", "h", "file"),
    "file": ("n", "h", "cells", "family"),
}


# -- overrides -----------------------------------------------------------------------------------
def _branch_for(node: dict, segment: str) -> dict:
    """The alternative of a oneOf (``domain``: unit_square or a mapping) that has ``segment``."""
    for branch in map(_resolve, node.get("oneOf", ())):
        if ("items" in branch) if segment.isdigit() else ("properties" in branch):
            return branch
    return node


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
    node = _branch_for(node, str(segment))
    if isinstance(segment, int):
        if not isinstance(container, list) or "items" not in node:
            raise SceneError(
                f"--set {override}: {_key(path)} = {_show(container)} is not a list; drop [{segment}]", key=_key(path)
            )
        if segment >= len(container):
            count = len(container)
            indices = {0: "no index", 1: "the index 0"}.get(count, f"an index 0 ... {count - 1}")
            raise SceneError(
                f"--set {override}: {_key(path)} = {_show(container)} has {count} "
                f"entr{'y' if count == 1 else 'ies'}: give {indices}, or set the whole list, "
                f"e.g. --set '{_key(path)}=[...]'",
                key=_key(path),
            )
        return _resolve(node["items"])
    if isinstance(container, list):
        raise SceneError(
            f"--set {override}: {_key(path)} = {_show(container)} is a list: index it "
            f"({_key(path)}[0]) or set the whole value, e.g. --set '{_key(path)}={{{segment}: ...}}'",
            key=_key(path),
        )
    if not isinstance(container, dict):
        raise SceneError(
            f"--set {override}: {_key(path)} = {_show(container)} has no entry {segment!r}", key=_key(path)
        )
    if "properties" in node:
        if segment not in node["properties"]:
            raise SceneError(
                f"--set {override}: unknown key {_key([*path, segment])!r}{_suggest(segment, node['properties'])}",
                key=_key([*path, segment]),
            )
        return _resolve(node["properties"][segment])
    if isinstance(node.get("additionalProperties"), dict):  # a map: side name -> entry
        return _resolve(node["additionalProperties"])
    raise SceneError(f"--set {override}: {_key(path)!r} has no key {segment!r}", key=_key(path))


def _apply_override(data: dict, override: str) -> None:
    """Apply ``a.b[0].c=value`` to ``data``; every key must exist in the schema, every index in
    the list it indexes."""
    key_text, separator, value_text = str(override).partition("=")
    if not separator or not key_text.strip():
        raise SceneError(f"--set {override}: expected key.path=value, e.g. --set solver.method=uzawa")
    segments = _key_segments(override, key_text.strip())
    value = _parse_yaml(value_text, f"--set {override}")
    node, container, path = _resolve(_schema()), data, list[str | int]()
    for position, segment in enumerate(segments):
        node = _schema_step(node, segment, container, override, path)
        last = position == len(segments) - 1
        if isinstance(segment, str) and not last:
            container.setdefault(segment, copy.deepcopy(node.get("default", {})))
        path.append(segment)
        if not last:
            container = container[segment]
        else:
            if path[:2] == ["discretization", "mesh"] and segment in _MESH_SIZE_KEYS:
                for other in _MESH_SIZE_KEYS[segment]:  # a new size replaces the scene's own
                    container.pop(other, None)
            container[segment] = value


# -- validation ----------------------------------------------------------------------------------
def _suggest(word, choices) -> str:
    close = difflib.get_close_matches(str(word), [str(c) for c in choices], n=1)
    allowed = ", ".join(str(c) for c in choices)
    return f" (did you mean {close[0]!r}?); allowed here: {allowed}" if close else f"; allowed here: {allowed}"


def _scene_fix(key: str | None) -> str:
    """The fix a message suggests for ``key`` (None: an unknown key)."""
    return "fix the scene" if key is None else f"fix the scene or --set {key}=..."


def _check_finite(value, path, fix=_scene_fix) -> None:
    if (
        isinstance(value, (int, float)) and not isinstance(value, bool) and not abs(value) <= sys.float_info.max
    ):  # nan, inf, ints beyond the float range
        raise SceneError(f"{_key(path)} = {value}: must be a finite number; {fix(_key(path))}", key=_key(path))
    children = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for key, child in children:
        _check_finite(child, [*path, key], fix)


def _document_order(data, error) -> tuple:
    """Position of ``error`` in the scene, so that the first problem in file order is reported."""
    position, node = [], data
    for part in error.absolute_path:
        keys = list(node) if isinstance(node, dict) else list(range(len(node)))
        position.append(keys.index(part) if part in keys else len(keys))
        node = node[part]
    if error.validator == "required" and isinstance(node, dict):
        position.append(len(node))
    elif error.validator == "additionalProperties" and isinstance(node, dict):
        allowed = _resolve(error.schema).get("properties", {})
        position.append(min((i for i, k in enumerate(node) if k not in allowed), default=0))
    return tuple(position)


def _branch_names(branches) -> str:
    """What the alternatives of a oneOf accept, in words."""
    names = []
    for branch in map(_resolve, branches):
        if "enum" in branch:
            names += [str(v) for v in branch["enum"]]
        elif branch.get("type") == "object" and branch.get("required"):
            names.append(f"a mapping with {', '.join(branch['required'])}")
        else:
            types = branch.get("type", [])
            names += [_TYPE_NAMES.get(t, t) for t in ([types] if isinstance(types, str) else types)]
    return " or ".join(names)


def _took_branch(value, branch: dict) -> bool:
    """Whether a mapping has every key a oneOf branch requires (and no key it does not know)."""
    branch = _resolve(branch)
    if not isinstance(value, dict) or "properties" not in branch:
        return False
    return set(branch.get("required", ())) <= set(value) and set(value) <= set(branch["properties"])


def _schema_error_message(error, fix=_scene_fix) -> str:
    path, keyword, schema = list(error.absolute_path), error.validator, _resolve(error.schema)
    key, value = _key(path), error.instance
    if keyword == "oneOf":  # the value took one branch when the problem lies inside it: report that
        deeper = [e for e in error.context or () if len(e.absolute_path) > len(path)]
        taken = [e for e in deeper if _took_branch(value, error.validator_value[e.relative_schema_path[0]])]
        deeper = taken or deeper  # a mapping with a branch's required keys took that branch (domain: polygon, box)
        if deeper:
            return _schema_error_message(jsonschema.exceptions.best_match(deeper), fix)
        title = f" ({schema['title']})" if "title" in schema else ""
        return f"{key} = {_show(value)}: must be {_branch_names(error.validator_value)}{title}; {fix(key)}"
    if "propertyNames" in error.absolute_schema_path:
        return f"{key}: {_show(value)} is not a side name (letters, digits, _ and -); fix the scene"
    if keyword == "minProperties":
        return (
            f"{key} = {{}}: {NO_DIRICHLET}"
            if key == "boundary.dirichlet"
            else f"{key} = {{}}: must have at least {error.validator_value} entries; {fix(key)}"
        )
    if keyword == "additionalProperties":
        allowed = list(schema.get("properties", {}))
        extra = next(k for k in value if k not in allowed)
        return f"{_key([*path, extra])}: unknown key{_suggest(extra, allowed)}; {fix(None)}"
    if keyword == "required":
        missing = next(k for k in error.validator_value if k not in value)
        title = _resolve(schema["properties"][missing]).get("title", "")
        if _key([*path, missing]) == "boundary.dirichlet":
            return f"boundary.dirichlet is missing: {NO_DIRICHLET}"
        return (
            f"{_key([*path, missing])} is missing ({title}); add it to the scene or --set {_key([*path, missing])}=..."
        )
    if keyword == "minItems" and key == "boundary.dirichlet":
        return f"boundary.dirichlet = []: {NO_DIRICHLET}"
    if keyword == "pattern" and schema == _schema()["$defs"]["side"]:
        return f"{key} = {_show(value)}: not a side name (letters, digits, _ and -); fix the scene"
    bound = error.validator_value
    if keyword == "type":
        types = [bound] if isinstance(bound, str) else bound
        need = "must be " + " or ".join(_TYPE_NAMES.get(t, t) for t in types)
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
    title = f" ({schema['title']})" if "title" in schema else ""
    return f"{key} = {_show(value)}: {need}{title}; {fix(key)}"


def _validate(data) -> None:
    if not isinstance(data, dict):
        raise SceneError(f"the scene must be a mapping of keys (name, material, boundary, ...), got {_show(data)}")
    _check_finite(data, [])
    errors = list(_validator().iter_errors(data))
    if errors:
        first = min(errors, key=lambda e: (_document_order(data, e), e.validator != "type"))
        raise SceneError(_schema_error_message(first))


def _normalized(value, node: dict):
    """Defaults filled, keys in schema order, numbers as float and integers as int."""
    node = _resolve(node)
    types = node.get("type")
    types = [types] if isinstance(types, str) else (types or [])
    if isinstance(value, dict) and "properties" in node:
        result = {}
        for name, child in node["properties"].items():
            if name in value:
                result[name] = _normalized(value[name], child)
            elif "default" in _resolve(child):
                result[name] = _normalized(copy.deepcopy(_resolve(child)["default"]), child)
        return result
    if isinstance(value, list) and "items" in node:
        return [_normalized(item, node["items"]) for item in value]
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return int(value) if "integer" in types else float(value)
    return value


def _check_order_options(discretization: dict) -> None:
    """Options that exist for one order k only are refused at the other; the k = 2 load's default."""
    if discretization["order"] >= 2:  # the cell moments of k >= 2 carry the body force
        discretization.setdefault("body_force_projection", DEFAULT_BODY_FORCE_PROJECTION_K2)
    elif discretization.get("body_force_projection", "p0") != "p0":
        raise SceneError(
            f"discretization.body_force_projection = {discretization['body_force_projection']!r} "
            "needs discretization.order = 2 (k = 1 loads the cell mean of f1); drop it or set "
            "discretization.order=2",
            key="discretization.body_force_projection",
        )


def _semantic_checks(data: dict, given: dict) -> dict:
    """Checks beyond the schema; returns the compiled expressions by key. ``given``: the scene as
    written (before the defaults were filled in)."""
    check_model_domain(data)
    if data["model"] == "3d":
        return semantic_checks_3d(data, given)
    check_mesh_size(data["discretization"]["mesh"])
    _check_order_options(data["discretization"])
    domain = domain_from_spec(data["domain"])  # one-line InputError naming the domain entry
    from_file = "file" in data["discretization"]["mesh"]
    check_sides(data, None if from_file else (UNIT_SQUARE_SIDES if domain.is_unit_square else domain.side_names))
    probed = None if from_file else domain
    check_mesh_resolution(data["discretization"]["mesh"], domain)
    compiled = boundary_expressions(data, probed)
    check_rigid_motions(data, probed)
    compiled["body_force"] = tuple(compile_checked(f"body_force[{i}]", data["body_force"][i]) for i in (0, 1))
    for expression in compiled["body_force"] if not from_file else ():  # a file's body: at its vertices
        evaluate_checked(expression, inside_points(domain))
    if "contact" in data:
        check_contact(data, given.get("contact", {}), probed, compiled)
    return compiled


# -- the scene -----------------------------------------------------------------------------------
def _field(*path, doc: str = "", convert=None):
    """A read-only property for ``scene.data[path[0]][path[1]]...``."""

    def get(self):
        value = self._data
        for part in path:
            value = value[part]
        return convert(value) if convert else value

    return property(get, doc=doc)


class Scene:
    """A validated scene with every default filled in; immutable (use :meth:`with_overrides`).

    Build it with :func:`load_scene`, :func:`scene_from_yaml` or :func:`scene_from_dict`.
    """

    __slots__ = ("_data", "_expressions", "source")
    _data: dict
    _expressions: dict
    source: str | None

    def __init__(self, data: dict, expressions: dict, source: str | None = None):
        object.__setattr__(self, "_data", data)
        object.__setattr__(self, "_expressions", expressions)
        object.__setattr__(self, "source", source)

    def __setattr__(self, name, value):
        raise AttributeError("a Scene is immutable; use scene.with_overrides([...])")

    def __reduce__(self):
        return (partial(scene_from_yaml, source=self.source), (self.to_yaml(),))

    def __eq__(self, other):
        return isinstance(other, Scene) and self._data == other._data

    __hash__ = None  # type: ignore[assignment]  # equal scenes compare equal: unhashable

    def __repr__(self) -> str:
        return f"Scene(name={self.name!r}, source={self.source!r})"

    @property
    def data(self) -> dict:
        """The validated, defaults-filled scene as plain data (a copy)."""
        return copy.deepcopy(self._data)

    name = _field("name")
    domain = _field("domain")
    model = _field("model", doc="the mechanical model: plane_stress (the paper's), plane_strain or 3d (SPEC §10)")
    E = _field("material", "E", doc="Young's modulus")
    nu = _field("material", "nu", doc="Poisson ratio (the paper's kappa)")
    dirichlet_sides = _field("boundary", "dirichlet", convert=tuple)
    neumann_sides = _field("boundary", "neumann", convert=tuple)
    contact_sides = _field("boundary", "contact", convert=tuple)
    has_contact = _field("boundary", "contact", convert=bool, doc="True if a side is in contact")
    stabilization = _field("discretization", "stabilization")
    contact_quadrature = _field("discretization", "contact_quadrature")
    contact_gauss_points = _field(
        "discretization",
        "contact_gauss_points",
        doc="N of contact_quadrature: gauss: Gauss points per Gamma_C edge (2D), a rule of degree 2N - 1 per Gamma_C triangle (3D)",
    )
    order = _field("discretization", "order", convert=int, doc="polynomial order k of the virtual elements: 1 or 2")
    body_force_projection = property(
        lambda self: self._data["discretization"].get("body_force_projection", "p0"),
        doc="the k = 2 load: p1 (the default at order 2: P_1 f1 against Pi_2 v) or p0 (the paper's "
        "P_0 f1); p0 at order 1, where it is irrelevant",
    )
    mesh_options = _field(
        "discretization",
        "mesh",
        convert=dict,
        doc="discretization.mesh: family, n / h / cells (or file) and the family options given (a copy)",
    )
    solver_options = _field(
        "solver", convert=dict, doc="solver, defaults filled; rho/eps_u/eps_lambda may be None (a copy)"
    )
    adaptivity_options = _field(
        "adaptivity",
        convert=copy.deepcopy,
        doc="adaptivity (SPEC §9), defaults filled; max_hanging/reference may be None (a copy)",
    )
    body_force = property(
        lambda self: self._expressions["body_force"], doc="(Expression, Expression) (3D: three): the volume force f1"
    )
    gap_expression = property(
        lambda self: self._expressions.get("contact.gap"),
        doc="Expression of the initial gap g_a; None without contact section",
    )

    @property
    def dimension(self) -> int:
        """3 for a ``model: 3d`` scene (SPEC §10), 2 otherwise."""
        return 3 if self.model == "3d" else 2

    @property
    def sides(self) -> tuple:
        """All sides of the domain; sides not listed under boundary are traction-free."""
        if self.dimension == 3:
            return domain3d_from_spec(self.domain).side_names
        domain = domain_from_spec(self.domain)
        return UNIT_SQUARE_SIDES if domain.is_unit_square else domain.side_names

    def lame(self) -> tuple[float, float]:
        """``(lambda, mu)`` of C for the scene's model (``vemkit.config.material``; plane stress: the
        paper's Eν/(1−ν²), E/(2(1+ν)), SPEC §1)."""
        return lame_parameters(self.E, self.nu, self.model)

    def traction(self, side: str) -> tuple[Expression, Expression]:
        """The prescribed traction f2 on a Neumann side; KeyError for other sides (and pressure sides)."""
        key = f"boundary.neumann.{side}.traction"
        if key not in self._expressions:
            raise KeyError(
                f"{side!r} is not a Neumann side with a traction in this scene "
                f"(neumann sides: {', '.join(self.neumann_sides) or 'none'})"
            )
        return self._expressions[key]

    def pressure(self, side: str) -> Expression | None:
        """The normal pressure p of a Neumann side (traction = -p nu); None for a traction side."""
        return self._expressions.get(f"boundary.neumann.{side}.pressure")

    @property
    def dirichlet(self) -> dict:
        """side -> (u1, u2) (3D: (u1, u2, u3)) prescribed on Gamma_D: Expressions, None for a free
        component (SPEC §7, §10)."""
        return {side: self._expressions[f"boundary.dirichlet.{side}"] for side in self.dirichlet_sides}

    @property
    def exact_displacement(self) -> tuple[Expression, Expression] | None:
        """The scene's exact displacement (SPEC §7 ``exact:``), None if it gives none."""
        return self._expressions.get("exact.displacement")

    @property
    def foundation(self) -> tuple | None:
        """((x, y), (n_x, n_y)): a point of the foundation line and its normal towards the body;
        None when the gap is given as an expression."""
        line = self._data.get("contact", {}).get("foundation")
        return None if line is None else (tuple(line["point"]), tuple(line["normal"]))

    @property
    def mesh_file(self) -> Path | None:
        """discretization.mesh.file resolved against the scene file's folder (SPEC §8), or None."""
        name = self._data["discretization"]["mesh"].get("file")
        if name is None:
            return None
        folder = Path(self.source).parent if self.source and not self.source.startswith("<") else Path(".")
        return folder / name

    normal_compliance = property(
        lambda self: self._contact_law("normal"), doc="PowerLaw p_nu(t) = k (t)_+^m; None without contact section"
    )
    friction_bound = property(
        lambda self: self._contact_law("friction"),
        doc="PowerLaw p_tau(t) = k (t)_+^m (m = 0: the paper's reduced law); None without contact section",
    )

    def _contact_law(self, kind: str) -> PowerLaw | None:
        contact = self._data.get("contact")
        return PowerLaw(**contact[kind]) if contact else None

    def to_yaml(self) -> str:
        """The full, defaults-filled scene as YAML; loads back to an equal scene."""
        return yaml.dump(self._data, Dumper=SceneDumper, sort_keys=False, default_flow_style=None, allow_unicode=True)

    def with_overrides(self, overrides) -> Scene:
        """A new scene with ``key.path=value`` overrides applied (as ``--set``)."""
        return scene_from_dict(self._data, overrides, source=self.source)


def scene_from_dict(data, overrides=(), *, source: str | None = None) -> Scene:
    """Validate a scene given as plain data; ``overrides`` are ``"a.b.c=value"`` strings."""
    if isinstance(overrides, str):
        overrides = [overrides]
    if not isinstance(data, dict):
        raise SceneError(f"the scene must be a mapping of keys (name, material, boundary, ...), got {_show(data)}")
    data = copy.deepcopy(data)
    for override in overrides:
        _apply_override(data, override)
    _validate(data)
    normalized = _normalized(data, _schema())
    contact = normalized.get("contact")
    if contact and "foundation" in contact and "gap" not in data.get("contact", {}):
        del contact["gap"]  # the foundation defines the gap: no default beside it (the scene reads back)
    expressions = _semantic_checks(normalized, data)
    return Scene(normalized, expressions, source)


def scene_from_yaml(text: str, overrides=(), *, source: str = "<string>") -> Scene:
    """Validate a scene given as YAML text (e.g. the attribute stored in a solution file)."""
    data = _parse_yaml(text, source)
    if data is None:
        raise SceneError(f"{source}: the scene is empty")
    return scene_from_dict(data, overrides, source=source)


def load_scene(path, overrides=()) -> Scene:
    """Read, override and validate a scene file; every problem is a one-line SceneError."""
    path = Path(path)
    text = read_user_file(path, "scene file")  # a regular file of at most 256 KiB (safe_yaml)
    return scene_from_yaml(text, overrides, source=str(path))
