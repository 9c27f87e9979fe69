"""Boundary data and mesh size of a scene (docs/reference/files.md), checked and compiled: Dirichlet sides with their
components, Neumann tractions and pressures, the contact gap or foundation line, the exact solution.

Each expression is compiled once (:mod:`vemkit.config.expressions`, never ``eval``) and
test-evaluated where it will be used: on the points of its side, or inside the body, so that a
NaN, an infinity or a negative gap is a one-line :class:`SceneError` before any mesh is built.
A scene whose mesh comes from a file has its sides in the file: they are checked when it is read.

Compiled keys (the Scene's ``_expressions``): ``boundary.dirichlet.SIDE`` -> (u1 | None, u2 | None),
``boundary.neumann.SIDE.traction`` -> (f_x, f_y), ``boundary.neumann.SIDE.pressure`` -> p,
``exact.displacement`` -> (u1, u2), ``contact.gap`` -> g.
"""

from __future__ import annotations

import numpy as np

from vemkit.config.body_forms import FORMS
from vemkit.config.domain import Domain
from vemkit.config.expression_tree import shorten
from vemkit.config.expressions import Expression, compile_expression
from vemkit.config.load_poles import check_integrable_on_edges
from vemkit.config.rigid_motions import free_rigid_motion
from vemkit.exceptions import ExpressionError, SceneError

__all__ = [
    "MAX_NORMAL_K_OVER_E",
    "PROBES",
    "boundary_expressions",
    "check_contact",
    "check_expressions_on_mesh",
    "check_file_sides",
    "check_foundation",
    "check_mesh_size",
    "check_rigid_motions",
    "check_sides",
    "free_rigid_motion",
    "side_points",
]

#: contact.normal.k / material.E above this is refused (README "Input rules and limits"): measured,
#: ssn's independent check is 5e-9 at k/E = 5e8 and fails at 5e11 (paper scene, n = 8)
MAX_NORMAL_K_OVER_E = 1e9
PROBES = 16  # points per side (and per direction inside) where expressions are test-evaluated
# points (x, y) of a side of the unit square at the curve parameters s in [0, 1]
_UNIT_SQUARE_SIDE_POINTS = {
    "left": lambda s: (0.0 * s, s),
    "right": lambda s: (0.0 * s + 1.0, s),
    "bottom": lambda s: (s, 0.0 * s),
    "top": lambda s: (s, 0.0 * s + 1.0),
}


def side_points(domain: Domain, side: str, s: np.ndarray):
    """Points (x, y) on a side at the parameters s of each of its edges (the unit square: as one
    straight side)."""
    if domain.is_unit_square:
        return _UNIT_SQUARE_SIDE_POINTS[side](s)
    x0, y0, x1, y1 = domain.bounds
    polygonal = domain.discretize(max(x1 - x0, y1 - y0) / PROBES)
    segments = polygonal.segments[polygonal.segment_sides == side]
    a, b = polygonal.points[segments[:, 0]], polygonal.points[segments[:, 1]]
    points = (a[:, None, :] + s[None, :, None] * (b - a)[:, None, :]).reshape(-1, 2)
    return points[:, 0], points[:, 1]


def inside_points(domain: Domain):
    """A PROBES x PROBES grid over the bounding box of the body (the unit square by default)."""
    s = (np.arange(PROBES) + 0.5) / PROBES
    x, y = np.meshgrid(s, s)
    if domain.is_unit_square:
        return x, y
    x0, y0, x1, y1 = domain.bounds
    return x0 + (x1 - x0) * x, y0 + (y1 - y0) * y


def compile_checked(key: str, value, dimension: int = 2) -> Expression:
    """The expression of scene key ``key``; a 2D scene's expressions take x and y only, a 3D scene's
    x, y and z (docs/reference/files.md)."""
    try:
        expression = compile_expression(value, name=key)
    except ExpressionError as error:
        raise SceneError(str(error), key=key) from None
    beyond = [name for name in "xyz"[dimension:] if name in expression.variables]  # coordinates the body lacks
    if beyond:
        raise SceneError(
            f"{key} = {shorten(expression.text)!r}: uses {beyond[0]}, but this scene is {dimension}D (its expressions "
            f"take {FORMS[dimension].coordinate_words}); remove {beyond[0]}",
            key=key,
        )
    return expression


def evaluate_checked(expression: Expression, points) -> np.ndarray:
    try:
        return expression(*points)
    except ExpressionError as error:
        raise SceneError(str(error)) from None


def _dirichlet(boundary: dict, dimension: int = 2) -> dict:
    """side -> [u1 | None, u2 | None (, u3 | None)] (the list form: u = 0 on every listed side)."""
    entries = boundary["dirichlet"]
    if isinstance(entries, list):
        return {side: [0.0] * dimension for side in entries}
    return entries


class PlaneProbes:
    """Where a 2D scene's expressions are test-evaluated: PROBES points on each edge of a side, a
    PROBES x PROBES grid over the body's bounding box (``vemkit.config.scene3d`` has the 3D ones)."""

    dimension = 2

    def __init__(self, domain: Domain):
        self.domain = domain

    def side(self, side: str, s=None):
        return side_points(self.domain, side, (np.arange(PROBES) + 0.5) / PROBES if s is None else s)

    def inside(self):
        return inside_points(self.domain)


def _components(key: str, value, dimension: int) -> list:
    """The list of a vector entry, which has one component per dimension (docs/reference/files.md)."""
    if len(value) != dimension:
        names = ", ".join(
            f"u{i + 1}" if "dirichlet" in key or "exact" in key else f"f_{'xyz'[i]}" for i in range(dimension)
        )
        raise SceneError(
            f"{key} has {len(value)} components; this {dimension}D scene needs {dimension} ([{names}]); fix the scene",
            key=key,
        )
    return list(value)


def _compiled_entries(data: dict, probes, dimension: int):
    """(key, expression(s), points | None) of every boundary and exact expression of the scene
    (``probes`` None: a mesh file's body, the points are unknown yet)."""
    at_side = probes.side if probes is not None else (lambda side: None)
    inside = probes.inside() if probes is not None else None
    for side, components in _dirichlet(data["boundary"], dimension).items():
        key = f"boundary.dirichlet.{side}"
        pair = tuple(
            None if value is None else compile_checked(f"{key}[{i}]", value, dimension)
            for i, value in enumerate(_components(key, components, dimension))
        )
        if pair == (None,) * dimension:
            raise SceneError(
                f"{key} = [{', '.join(['null'] * dimension)}]: prescribes nothing; give a value for "
                "at least one component or move the side to neumann",
                key=key,
            )
        yield key, pair, at_side(side)
    for side, entry in data["boundary"]["neumann"].items():
        if len(entry) != 1:
            raise SceneError(
                f"boundary.neumann.{side}: give exactly one of traction: [f_x, f_y] or pressure: p; fix the scene",
                key=f"boundary.neumann.{side}",
            )
        kind, value = next(iter(entry.items()))
        key = f"boundary.neumann.{side}.{kind}"
        compiled = (
            compile_checked(key, value, dimension)
            if kind == "pressure"
            else tuple(
                compile_checked(f"{key}[{i}]", v, dimension) for i, v in enumerate(_components(key, value, dimension))
            )
        )
        yield key, compiled, at_side(side)
    if "exact" in data:
        key = "exact.displacement"
        value = _components(key, data["exact"]["displacement"], dimension)
        yield key, tuple(compile_checked(f"{key}[{i}]", v, dimension) for i, v in enumerate(value)), inside


def boundary_expressions(data: dict, domain: Domain | None, probes=None, dimension: int = 2) -> dict:
    """The compiled boundary and exact expressions by key (vectors of ``dimension`` components), each
    test-evaluated on its points (``domain`` and ``probes`` None: the mesh comes from a file, the
    points are unknown yet; ``probes``: the points of a 3D body, ``vemkit.config.scene3d.BodyProbes``)."""
    if probes is None and domain is not None:
        probes = PlaneProbes(domain)
    compiled = {}
    for key, value, points in _compiled_entries(data, probes, dimension):
        compiled[key] = value
        for expression in value if isinstance(value, tuple) else (value,):
            if expression is not None and points is not None:
                evaluate_checked(expression, points)
    return compiled


def check_foundation(foundation: dict, sides, domain: Domain | None) -> None:
    """The foundation line's normal is not zero and every contact side lies on its body side."""
    for key in ("point", "normal"):
        if len(foundation[key]) != 2:
            raise SceneError(
                f"contact.foundation.{key} has {len(foundation[key])} components; a 2D scene's "
                "foundation is a line: give 2",
                key=f"contact.foundation.{key}",
            )
    normal = np.asarray(foundation["normal"], dtype=float)
    if not np.hypot(*normal) > 0:
        raise SceneError(
            "contact.foundation.normal = [0, 0]: give the line's normal pointing towards "
            "the body, e.g. [0, 1] for a floor",
            key="contact.foundation.normal",
        )
    if domain is None:
        return
    point = np.asarray(foundation["point"], dtype=float)
    for side in sides:
        x, y = side_points(domain, side, np.linspace(0.0, 1.0, PROBES + 1))
        distance = ((x - point[0]) * normal[0] + (y - point[1]) * normal[1]) / np.hypot(*normal)
        refuse_penetration(side, distance, (x, y))


def refuse_penetration(side: str, distance: np.ndarray, points: tuple) -> None:
    """SceneError when a point of ``side`` (coordinates ``points``: x, y (, z)) lies beyond the
    foundation, ``distance`` being its signed distance to it (positive on the body's side)."""
    if not distance.min() < -1e-12 * max(1.0, np.abs(distance).max()):
        return
    i = int(np.argmin(distance))
    at = ", ".join(f"{name}={c[i]:.6g}" for name, c in zip("xyz", points))
    figure = FORMS[len(points)].foundation  # a line in the plane, a plane in space
    raise SceneError(
        f"contact.foundation: {side} is {-distance[i]:.6g} beyond the foundation {figure} at {at} (the body "
        "starts out penetrating it); move contact.foundation.point or flip contact.foundation.normal",
        key="contact.foundation",
    )


def check_mesh_size(mesh: dict) -> None:
    sizes = [key for key in ("n", "h", "cells") if key in mesh]
    if "\0" in mesh.get("file", ""):
        raise SceneError(
            "discretization.mesh.file: a file name cannot contain a NUL character; fix the scene",
            key="discretization.mesh.file",
        )
    if "file" in mesh:
        extra = sizes + [key for key in mesh if key not in ("file", *sizes)]
        if extra:
            raise SceneError(
                f"discretization.mesh: file = {mesh['file']!r} is the whole mesh; drop {', '.join(extra)}",
                key="discretization.mesh",
            )
        return
    if "family" not in mesh:
        raise SceneError(
            "discretization.mesh.family is missing (mesh family); add it to the scene or "
            "--set discretization.mesh.family=... (or give discretization.mesh.file)",
            key="discretization.mesh.family",
        )
    if len(sizes) != 1:
        named = ", ".join(f"{k} = {mesh[k]}" for k in sizes) or "none given"
        raise SceneError(
            f"discretization.mesh: give exactly one of n, h and cells ({named}); fix the "
            "scene or --set discretization.mesh.n=...",
            key="discretization.mesh",
        )


def check_sides(data: dict, sides) -> None:
    """Every boundary side exists (``sides`` None: the mesh file names them) and has one condition."""
    boundary, owner = data["boundary"], {}
    for part in ("dirichlet", "neumann", "contact"):
        for index, side in enumerate(boundary[part]):
            if sides is not None and side not in sides:
                where = (
                    f"boundary.{part}[{index}] = {side!r}"
                    if isinstance(boundary[part], list)
                    else f"boundary.{part}.{side}"
                )
                raise SceneError(
                    f"{where}: unknown boundary name {side!r}; the {_domain_name(data)} has "
                    f"sides {', '.join(sides)}; fix the scene",
                    key=f"boundary.{part}",
                )
            if side in owner:
                raise SceneError(
                    f"boundary: side {side!r} is listed in both {owner[side]} and "
                    f"{part}; a side has one boundary condition"
                )
            owner[side] = part
    if boundary["contact"] and "contact" not in data:
        raise SceneError(
            f"contact is missing: boundary.contact lists {', '.join(boundary['contact'])}; "
            "add contact: {gap: ..., normal: {k: ..., m: ...}, friction: {k: ..., m: ...}}"
        )


def check_contact(data: dict, given_contact: dict, domain, compiled: dict) -> None:
    contact, sides = data["contact"], data["boundary"]["contact"]
    if "k" in contact["normal"] and contact["normal"]["k"] > MAX_NORMAL_K_OVER_E * data["material"]["E"]:
        raise SceneError(
            f"contact.normal.k = {contact['normal']['k']:g}: must be at most "
            f"{MAX_NORMAL_K_OVER_E:g} material.E = {MAX_NORMAL_K_OVER_E * data['material']['E']:g} "
            "(stiffer is rigid contact, beyond double precision); fix the scene or "
            "--set contact.normal.k=...",
            key="contact.normal.k",
        )
    if "foundation" in contact:
        if "gap" in given_contact:
            raise SceneError(
                "contact: give either gap or foundation, not both (the foundation line defines the gap)",
                key="contact.foundation",
            )
        check_foundation(contact["foundation"], sides, domain)
        return
    gap = compiled["contact.gap"] = compile_checked("contact.gap", contact["gap"])
    for side in sides if domain is not None else ():
        x, y = side_points(domain, side, np.linspace(0.0, 1.0, PROBES + 1))
        values = evaluate_checked(gap, (x, y))
        if values.min() < 0:
            i = int(np.argmin(values))
            raise SceneError(
                f"contact.gap = {repr(contact['gap'])}: is {values[i]:.6g} "
                f"< 0 at x={x[i]:.6g}, y={y[i]:.6g} on {side} (the initial gap "
                "g_a must be >= 0); fix the scene or --set contact.gap=..."
            )


def _domain_name(data) -> str:
    return "unit_square" if data["domain"] == "unit_square" else "domain"


# -- rigid motions (before assembly), mesh files' sides, expressions at the mesh's vertices ------
def rigid_motion_error(motion: str) -> SceneError:
    return SceneError(
        f"boundary.dirichlet leaves {motion} of the body free (the stiffness is singular); "
        "prescribe a component that stops it, e.g. clamp a side",
        key="boundary.dirichlet",
    )


def check_rigid_motions(data: dict, domain: Domain | None) -> None:
    """The Dirichlet sides hold every rigid motion, tested on the corners of their edges (every mesh
    of the body has them as vertices, and its other vertices on those edges add no constraint);
    ``domain`` None (a mesh file): tested once the mesh is read."""
    if domain is None:
        return
    x0, y0, x1, y1 = domain.bounds
    polygonal = domain.discretize(max(x1 - x0, y1 - y0) / PROBES)
    points, held = [], []
    for side, components in _dirichlet(data["boundary"]).items():
        ends = polygonal.points[polygonal.segments[polygonal.segment_sides == side].ravel()]
        points.append(ends)
        held.append(np.tile([c is not None for c in components], (ends.shape[0], 1)))
    motion = free_rigid_motion(np.concatenate(points), np.concatenate(held))
    if motion is not None:
        raise rigid_motion_error(motion)


def check_file_sides(scene, header) -> None:
    """Every side the scene's boundary names is in its mesh file (``header``: what the file declares,
    :func:`vemkit.config.mesh_file_header.mesh_file_header`); a gmsh side that may still come from an
    unnamed physical group (a number) or ``untagged`` is checked when the file is read."""
    boundary = scene.data["boundary"]
    for part in ("dirichlet", "neumann", "contact"):
        for side in boundary[part]:
            if side in header.sides or (not header.sides_complete and (side.isdigit() or side == "untagged")):
                continue
            if side in getattr(header, "other_sides", ()):
                scene_form = FORMS[scene.dimension]
                file_form = FORMS[scene_form.other_dimension]
                raise SceneError(
                    f"boundary.{part}: side {side!r} is a physical {file_form.side_entity} in the mesh file "
                    f"{scene.mesh_options['file']}: the file is a {file_form.dimension}D mesh but the scene is "
                    f"{scene_form.dimension}D; give a {scene_form.dimension}D mesh file",
                    key=f"boundary.{part}",
                )
            listed = ", ".join(header.sides) or "none"
            raise SceneError(
                f"boundary.{part}: side {side!r} is not in the mesh file {scene.mesh_options['file']} "
                f"(its {'sides' if header.sides_complete else 'named sides'}: {listed}); fix the scene "
                "or the file",
                key=f"boundary.{part}",
            )


def check_expressions_on_mesh(scene, mesh) -> None:
    """Every expression finite at the vertices where it acts (a pole at a vertex that the probes
    before meshing missed, or any point of a mesh file's body): tractions and pressures on their
    sides, and integrable along their edges (3D: the edges of their faces;
    :mod:`vemkit.config.load_poles`), the body force and the exact solution everywhere. The gap and the Dirichlet values are
    evaluated at their vertices when they are used."""
    coordinates = tuple(mesh.vertices.T)  # x, y (and z)
    for side in scene.neumann_sides:
        if side not in mesh.boundary:
            continue  # the problem names the missing side
        on_side = mesh.boundary_vertices(side)  # vemkit.mesh.interface: any dimension
        pressure = scene.pressure(side)
        edges = mesh.side_edges(side)  # its edges (2D), the sides of its faces (3D)
        for expression in (pressure,) if pressure is not None else scene.traction(side):
            evaluate_checked(expression, tuple(c[on_side] for c in coordinates))
            # and between the vertices: a pole inside an edge (3D: on the faces' edges, where a
            # singular plane or surface such as 1/(x - 0.37) crosses them)
            check_integrable_on_edges(expression, mesh.vertices[edges[:, 0]], mesh.vertices[edges[:, 1]], side)
    for expression in (*scene.body_force, *(scene.exact_displacement or ())):
        evaluate_checked(expression, coordinates)
