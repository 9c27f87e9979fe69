"""``vemkit mesh FAMILY N --option key=value``: the same rules as a scene's ``discretization.mesh``.

The options are read by the scene's YAML loader (:mod:`vemkit.config.safe_yaml`: ``1e-3`` is a
number) and validated by the scene schema's ``discretization.mesh`` node, so a value refused in a
scene is refused on the command line with the same one-line message, naming ``--option key``.
"""

from __future__ import annotations

from vemkit.config.safe_yaml import parse_yaml
from vemkit.config.scene_schema import check_finite, first_problem, normalized, schema_error_message, schema_root
from vemkit.exceptions import SceneError

__all__ = ["mesh_request", "validate_mesh_options"]


def _cli_fix(key: str | None) -> str:
    if key is None:
        return "see vemkit mesh --help"
    if key == "n":
        return "give N >= 1 (cells per side)"
    if key == "family":
        return "give FAMILY as square, triangle, voronoi or hanging"
    return f"fix --option {key}=..."


def _mesh_schema() -> dict:
    root = schema_root()
    node = root["properties"]["discretization"]["properties"]["mesh"]
    return {**node, "$defs": root["$defs"]}


def validate_mesh_options(data: dict, fix=_cli_fix) -> dict:
    """``data`` ({family, n, options...}) checked by the schema; defaults-free, numbers typed."""
    import jsonschema

    try:
        check_finite(data, [], fix)
    except SceneError as error:
        prefix = "" if error.key in ("family", "n") else "--option "
        raise SceneError(prefix + str(error), key=error.key) from None
    validator = jsonschema.Draft202012Validator(_mesh_schema())
    errors = list(validator.iter_errors(data))
    if errors:
        first = first_problem(errors, data)
        message = schema_error_message(first, fix)
        key = next(iter(first.absolute_path), None)
        prefix = "" if key in ("family", "n") or first.validator == "required" else "--option "
        raise SceneError(prefix + message, key=str(key))
    return normalized(data, _mesh_schema())


def mesh_request(family: str, n, options=()) -> dict:
    """``{"family": ..., "n": ..., **options}`` from the ``vemkit mesh`` arguments, validated."""
    data = {"family": family, "n": n}
    for text in options:
        key, separator, value = str(text).partition("=")
        key = key.strip()
        if not separator or not key:
            raise SceneError(f"--option {text}: write it as key=value, e.g. --option seed=3", key="--option")
        if key in ("family", "n"):
            raise SceneError(
                f"--option {text}: give the {key} as the {'FAMILY' if key == 'family' else 'N'} argument",
                key="--option",
            )
        if key in data:
            raise SceneError(f"--option {key} is given twice; give it once", key="--option")
        data[key] = parse_yaml(value, f"--option {text}")
    return validate_mesh_options(data)
