"""The dimension of a scene's body, and the models that fit it (docs/reference/files.md).

The body says the dimension: a ``domain`` with ``box`` or ``extrude``, or a mesh file whose header
says 3D (:func:`vemkit.config.mesh_file_header.mesh_file_dimension`), is 3D; ``unit_square``, a
polygon and a plane mesh file are 2D. The ``model`` key says the constitution only (the elasticity
tensor's lambda and mu, :mod:`vemkit.config.material`): ``plane_stress`` or ``plane_strain`` on a 2D
body, ``3d`` on a 3D body; omitted, it is the body's default (``x-default-by-dimension`` of the
schema: plane_stress in 2D, 3d in 3D). A model that does not fit the body is a one-line
:class:`SceneError` naming ``model``, the body's dimension and the models that fit. The facts of
each dimension (its models, the words of the messages) are :data:`vemkit.config.body_forms.FORMS`.

A mesh file that does not say its dimension (a binary gmsh 2 file without a physical volume, a
file that cannot be opened) keeps the rule of before: 3D with ``model: 3d`` or a 3D ``domain``,
2D otherwise; the file's own problems are reported when the scene is solved.
"""

from __future__ import annotations

from pathlib import Path

from vemkit.config.body_forms import FORMS
from vemkit.config.domain3d import domain_dimension
from vemkit.config.mesh_file_header import mesh_file_dimension
from vemkit.config.scene_schema import schema_root
from vemkit.exceptions import SceneError

__all__ = [
    "MODELS_BY_DIMENSION",
    "MODEL_DIMENSION",
    "body_dimension",
    "default_model",
    "fill_model",
    "mesh_file_path",
    "written_dimension",
]

#: the models (the constitution) that fit a body of each dimension, the default first
MODELS_BY_DIMENSION = {dimension: form.models for dimension, form in FORMS.items()}
#: the dimension of the body each model fits
MODEL_DIMENSION = {model: dimension for dimension, models in MODELS_BY_DIMENSION.items() for model in models}


def default_model(dimension: int) -> str:
    """The model of a scene that names none: the schema's ``x-default-by-dimension``."""
    return schema_root()["properties"]["model"]["x-default-by-dimension"][str(dimension)]


def mesh_file_path(name: str, source: str | None) -> Path:
    """``discretization.mesh.file`` resolved against the scene file's folder (a scene that is not
    a file, ``source`` None or ``<...>``: against the working directory)."""
    folder = Path(source).parent if source and not source.startswith("<") else Path(".")
    return folder / name


def _domain_words(domain) -> str:
    if isinstance(domain, dict):
        kind = next((k for k in ("box", "extrude", "polygon") if k in domain), "")
        return f"domain.{kind}" if kind else "the domain"
    return f"domain {domain}"


def written_dimension(data: dict) -> int:
    """The dimension the scene's words say, its mesh file unread: the larger of its domain's and its
    model's (``3d``: 3; a plane model or none: 2), the rule of before for a mesh file that does not
    say (module docstring)."""
    model_dimension = MODEL_DIMENSION.get(data.get("model"), min(FORMS))
    return max(domain_dimension(data.get("domain", "unit_square")), model_dimension)


def body_dimension(data: dict, source: str | None = None) -> tuple[int, str]:
    """``(dimension, body)`` of a scene given as plain data (schema-valid, before the defaults):
    the dimension of its body and the words naming that body in a message."""
    domain = data.get("domain", "unit_square")
    name = data.get("discretization", {}).get("mesh", {}).get("file")
    if name is None:
        return domain_dimension(domain), _domain_words(domain)
    dimension = mesh_file_dimension(mesh_file_path(name, source))
    if dimension is None:  # the file does not say: the rule of before (module docstring)
        return written_dimension(data), f"the mesh file {name}"
    solid = domain_dimension(domain)
    if dimension < solid:  # a 3D domain beside a plane mesh file
        raise SceneError(
            f"{_domain_words(domain)} is a {solid}D body but the mesh file {name} is "
            f"{FORMS[dimension].mesh_file_words}; with a mesh file the file is the body: drop domain or give a "
            f"{solid}D mesh file",
            key="domain",
        )
    if data.get("model") is None:
        _check_vectors_fit(data, dimension, name)
    return dimension, f"the mesh file {name}"


def _scene_vectors(data: dict):
    """(key, vector) of every vector the scene writes: body force, Dirichlet values, tractions, exact field."""
    if isinstance(data.get("body_force"), list):
        yield "body_force", data["body_force"]
    boundary = data.get("boundary", {})
    dirichlet = boundary.get("dirichlet", {})
    for side, value in dirichlet.items() if isinstance(dirichlet, dict) else ():
        yield f"boundary.dirichlet.{side}", value
    for side, load in (boundary.get("neumann") or {}).items():
        if isinstance(load, dict) and isinstance(load.get("traction"), list):
            yield f"boundary.neumann.{side}.traction", load["traction"]
    exact = (data.get("exact") or {}).get("displacement")
    if isinstance(exact, list):
        yield "exact.displacement", exact


def _check_vectors_fit(data: dict, dimension: int, name: str) -> None:
    """A scene without ``model`` whose mesh file is the body: its vectors must have the file's
    dimension; the first that does not says which dimension the scene was written for."""
    for key, vector in _scene_vectors(data):
        if isinstance(vector, list) and len(vector) in FORMS and len(vector) != dimension:
            raise SceneError(
                f"{name}: is a {dimension}D mesh but the scene is written for {len(vector)}D ({key} has "
                f"{len(vector)} components); give a {len(vector)}D mesh file, or {dimension} components "
                f"in every vector of the scene",
                key=key,
            )


def fill_model(data: dict, source: str | None = None) -> int:
    """Check ``model`` against the body of ``data`` (module docstring) and fill in the body's
    default when it is omitted; returns the body's dimension."""
    dimension, body = body_dimension(data, source)
    valid = MODELS_BY_DIMENSION[dimension]
    model = data.get("model")
    if model is None:
        data["model"] = default_model(dimension)
    elif model not in valid:
        names = ", ".join(f"{m} (the default)" if m == default_model(dimension) else m for m in valid)
        raise SceneError(
            f"model = {model!r} does not fit the body: {body} is {dimension}D; the models of a "
            f"{dimension}D body: {names}; {FORMS[dimension].model_fix}",
            key="model",
        )
    return dimension
