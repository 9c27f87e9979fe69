"""Scene files (docs/reference/files.md): read the YAML, apply ``--set`` overrides, validate, fill the defaults.

One source of truth: ``vemkit/config/schemas/scene.schema.json`` holds the keys, the bounds and the
``default`` values (:mod:`vemkit.config.scene_schema` walks it, :mod:`vemkit.config.overrides` applies
``--set``); this module adds the checks beyond the schema and the :class:`Scene`. Every problem is a :class:`SceneError` (a ``ValueError``)
with a one-line message naming the offending key, e.g.
``material.nu = 0.7: must be < 0.5 (Poisson ratio of plane stress); fix the scene or --set material.nu=...``
"""

from __future__ import annotations

import copy
from functools import partial
from pathlib import Path

import yaml

from vemkit.config.boundary_conditions import (
    MAX_NORMAL_K_OVER_E,
    boundary_expressions,
    check_contact,
    check_mesh_size,
    check_rigid_motions,
    check_sides,
    compile_checked,
    evaluate_checked,
    inside_points,
)
from vemkit.config.contact_laws import PowerLaw, TabulatedLaw, check_normal_compliance, normal_compliance
from vemkit.config.dimension import MODEL_DIMENSION, default_model, fill_model, mesh_file_path
from vemkit.config.domain import UNIT_SQUARE_SIDES, domain_from_spec
from vemkit.config.domain3d import domain3d_from_spec, domain_dimension
from vemkit.config.expressions import Expression
from vemkit.config.loads import DEFAULT_BODY_FORCE_PROJECTION_K2
from vemkit.config.material import lame_parameters
from vemkit.config.mesh_resolution import check_mesh_resolution
from vemkit.config.overrides import apply_override
from vemkit.config.safe_yaml import SceneDumper, read_user_file
from vemkit.config.safe_yaml import parse_yaml as _parse_yaml
from vemkit.config.scene3d import semantic_checks_3d
from vemkit.config.scene_schema import normalized, scene_schema, schema_root, show, validate
from vemkit.config.volumetric import check_volumetric_strain, resolved_volumetric_strain
from vemkit.exceptions import SceneError

__all__ = ["PowerLaw", "Scene", "SceneError", "load_scene", "scene_from_dict", "scene_from_yaml", "scene_schema"]


def _check_order_options(discretization: dict) -> None:
    """Options that exist for one order k only are refused at the other; the k = 2 load's default."""
    check_volumetric_strain(discretization)
    if discretization["order"] >= 2:  # the cell moments of k >= 2 carry the body force
        discretization.setdefault("body_force_projection", DEFAULT_BODY_FORCE_PROJECTION_K2)
    elif discretization.get("body_force_projection", "p0") != "p0":
        raise SceneError(
            f"discretization.body_force_projection = {discretization['body_force_projection']!r} "
            "needs discretization.order = 2 (k = 1 loads the cell mean of f1); drop it or set "
            "discretization.order=2",
            key="discretization.body_force_projection",
        )


def _plane_sides(spec) -> tuple:
    """The side names of a plane scene's ``domain`` entry (the unit square's in their scene order)."""
    domain = domain_from_spec(spec)
    return UNIT_SQUARE_SIDES if domain.is_unit_square else domain.side_names


def _solid_sides(spec) -> tuple:
    return domain3d_from_spec(spec).side_names


#: the side names of a scene's body, by the body's dimension
_SIDE_NAMES = {2: _plane_sides, 3: _solid_sides}


def _plane_checks(data: dict, given: dict) -> dict:
    """The checks of a plane scene beyond the schema (:func:`_semantic_checks`)."""
    check_mesh_size(data["discretization"]["mesh"])
    _check_order_options(data["discretization"])
    domain = domain_from_spec(data["domain"])  # one-line InputError naming the domain entry
    from_file = "file" in data["discretization"]["mesh"]
    check_sides(data, None if from_file else _plane_sides(domain))
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


#: the checks beyond the schema of a scene, by its body's dimension
_CHECKS = {2: _plane_checks, 3: semantic_checks_3d}


def _semantic_checks(data: dict, given: dict, dimension: int) -> dict:
    """Checks beyond the schema; returns the compiled expressions by key. ``given``: the scene as
    written (before the defaults were filled in); ``dimension``: the body's
    (:mod:`vemkit.config.dimension`)."""
    if "contact" in data:  # the law contact.normal names (2D and 3D), its keys and its table
        check_normal_compliance(data["contact"]["normal"], max_slope=MAX_NORMAL_K_OVER_E * data["material"]["E"])
    return _CHECKS[dimension](data, given)


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

    __slots__ = ("_data", "_dimension", "_expressions", "source")
    _data: dict
    _dimension: int
    _expressions: dict
    source: str | None

    def __init__(self, data: dict, expressions: dict, source: str | None = None, dimension: int | None = None):
        object.__setattr__(self, "_data", data)
        object.__setattr__(self, "_expressions", expressions)
        object.__setattr__(self, "source", source)
        # the body's dimension (vemkit.config.dimension); a validated scene's model fits it
        object.__setattr__(self, "_dimension", dimension or MODEL_DIMENSION[data["model"]])

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
    model = _field(
        "model",
        doc="the mechanical model, the constitution C: plane_stress (the paper's) or plane_strain on a 2D "
        "body, 3d on a 3D body (the default: plane_stress in 2D, 3d in 3D)",
    )
    E = _field("material", "E", doc="Young's modulus")
    nu = _field("material", "nu", doc="Poisson ratio (the paper's kappa)")
    dirichlet_sides = _field("boundary", "dirichlet", convert=tuple)
    neumann_sides = _field("boundary", "neumann", convert=tuple)
    contact_sides = _field("boundary", "contact", convert=tuple)
    has_contact = _field("boundary", "contact", convert=bool, doc="True if a side is in contact")
    stabilization = _field("discretization", "stabilization")
    contact_quadrature = _field("discretization", "contact_quadrature")
    volumetric_strain = property(
        lambda self: resolved_volumetric_strain(
            self._data["discretization"]["volumetric_strain"], self.order, self.model, self.nu
        ),
        doc="the treatment of the volumetric part, cell or nodal_average: discretization.volumetric_strain "
        "with auto resolved (vemkit.config.volumetric)",
    )
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
        doc="adaptivity (docs/reference/files.md), defaults filled; max_hanging/reference may be None (a copy)",
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
        """The dimension of the body (docs/reference/files.md): 3 for a ``box`` or ``extrude`` domain or a
        3D mesh file, 2 otherwise; the model (:attr:`model`) fits it."""
        return self._dimension

    @property
    def sides(self) -> tuple:
        """All sides of the domain; sides not listed under boundary are traction-free."""
        return _SIDE_NAMES[self.dimension](self.domain)

    def lame(self) -> tuple[float, float]:
        """``(lambda, mu)`` of C for the scene's model (``vemkit.config.material``; plane stress: the
        paper's Eν/(1−ν²), E/(2(1+ν)), docs/reference/mathematics.md)."""
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
        component (docs/reference/files.md)."""
        return {side: self._expressions[f"boundary.dirichlet.{side}"] for side in self.dirichlet_sides}

    @property
    def exact_displacement(self) -> tuple[Expression, Expression] | None:
        """The scene's exact displacement (docs/reference/files.md ``exact:``), None if it gives none."""
        return self._expressions.get("exact.displacement")

    @property
    def foundation(self) -> tuple | None:
        """((x, y), (n_x, n_y)): a point of the foundation line and its normal towards the body;
        None when the gap is given as an expression."""
        line = self._data.get("contact", {}).get("foundation")
        return None if line is None else (tuple(line["point"]), tuple(line["normal"]))

    @property
    def mesh_file(self) -> Path | None:
        """discretization.mesh.file resolved against the scene file's folder (docs/reference/files.md), or None."""
        name = self._data["discretization"]["mesh"].get("file")
        return None if name is None else mesh_file_path(name, self.source)

    normal_compliance = property(
        lambda self: self._contact_law("normal"),
        doc="PowerLaw p_nu(t) = k (t)_+^m, or TabulatedLaw (contact.normal.law: table); None without contact section",
    )
    friction_bound = property(
        lambda self: self._contact_law("friction"),
        doc="PowerLaw p_tau(t) = k (t)_+^m (m = 0: the paper's reduced law); None without contact section",
    )

    def _contact_law(self, kind: str) -> PowerLaw | TabulatedLaw | None:
        contact = self._data.get("contact")
        if not contact:
            return None
        return normal_compliance(contact["normal"]) if kind == "normal" else PowerLaw(**contact[kind])

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
        raise SceneError(f"the scene must be a mapping of keys (name, material, boundary, ...), got {show(data)}")
    data = copy.deepcopy(data)
    for override in overrides:
        apply_override(data, override)
    validate(data, model=data.get("model") or default_model(domain_dimension(data.get("domain"))))
    dimension = fill_model(data, source)  # the body's dimension; model checked against it, or its default
    filled = normalized(data, schema_root())
    contact = filled.get("contact")
    if contact and "foundation" in contact and "gap" not in data.get("contact", {}):
        del contact["gap"]  # the foundation defines the gap: no default beside it (the scene reads back)
    expressions = _semantic_checks(filled, data, dimension)
    return Scene(filled, expressions, source, dimension)


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
