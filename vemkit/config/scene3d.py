"""The checks of a 3D scene (docs/reference/files.md, a 3D body) beyond the schema, and where its expressions are probed.

A 3D scene is one whose body is a box, an ``extrude`` domain or a 3D mesh file (its model is ``3d``,
:mod:`vemkit.config.dimension`); its vectors have
three components and its expressions take x, y and z. Before any mesh is built every expression is
test-evaluated on its side (:class:`BodyProbes`: a grid on each face of a box; on an extruded body the
2D probes of a lateral side at several heights, the base's boundary on the end faces), the Dirichlet
sides are tested for a free rigid motion (docs/reference/files.md names it), and what 3D does not have yet is refused
in one line: order 2 and the k = 2 load options. Contact (docs/reference/files.md): a foundation
plane (a point and a non-zero normal of three components, every contact side on its body side) or a
gap expression of x, y, z that is >= 0 on the contact sides (:func:`check_contact_3d`).
"""

from __future__ import annotations

import numpy as np

from vemkit.config.boundary_conditions import (
    MAX_NORMAL_K_OVER_E,
    PROBES,
    PlaneProbes,
    _dirichlet,
    boundary_expressions,
    check_mesh_size,
    check_sides,
    compile_checked,
    evaluate_checked,
    refuse_penetration,
    rigid_motion_error,
)
from vemkit.config.domain3d import BOX_FAMILIES, EXTRUDE_FAMILIES_3D, FAMILIES_2D, Box, domain3d_from_spec
from vemkit.config.mesh_resolution import check_mesh_resolution3d
from vemkit.config.rigid_motions import free_rigid_motion
from vemkit.exceptions import SceneError

__all__ = ["BodyProbes", "check_contact_3d", "semantic_checks_3d"]

DIMENSION = 3


class BodyProbes:
    """Probe points (x, y, z) of a 3D body's sides and inside (module docstring); ``s`` in [0, 1]
    are the parameters along each direction of a face (default PROBES midpoints)."""

    dimension = DIMENSION

    def __init__(self, body):
        self.body = body

    def side(self, side: str, s=None):
        s = (np.arange(PROBES) + 0.5) / PROBES if s is None else np.asarray(s, dtype=float)
        if isinstance(self.body, Box):
            return self._box_face(side, s)
        plane, points = PlaneProbes(self.body.base), []
        if side in self.body.ends:  # an end face: the base's boundary at z = 0 and/or z = depth
            rims = [plane.side(name, s) for name in self.body.base.side_names]
            x, y = np.concatenate([np.ravel(r[0]) for r in rims]), np.concatenate([np.ravel(r[1]) for r in rims])
            for end, z in zip(self.body.ends, (0.0, self.body.depth)):
                if end == side:
                    points.append((x, y, np.full_like(x, z)))
        if side in self.body.base.side_names:  # a lateral side: its 2D probes at the heights s depth
            x, y = (np.ravel(c) for c in plane.side(side, s))
            heights = s * self.body.depth
            points.append((np.tile(x, heights.size), np.tile(y, heights.size), np.repeat(heights, x.size)))
        return tuple(np.concatenate(c) for c in zip(*points))

    def _box_face(self, side: str, s):
        lower, upper = np.asarray(self.body.lower), np.asarray(self.body.upper)
        xs = []
        for index, name in enumerate(self.body.sides):
            if name != side:
                continue
            axis, at = index // 2, (lower if index % 2 == 0 else upper)[index // 2]
            a, b = [k for k in range(3) if k != axis]
            u, v = np.meshgrid(lower[a] + s * (upper[a] - lower[a]), lower[b] + s * (upper[b] - lower[b]))
            p = np.empty((u.size, 3))
            p[:, axis], p[:, a], p[:, b] = at, u.ravel(), v.ravel()
            xs.append(p)
        p = np.concatenate(xs)
        return p[:, 0], p[:, 1], p[:, 2]

    def inside(self):
        """A PROBES³ grid over the body's bounding box."""
        if isinstance(self.body, Box):
            lower, upper = np.asarray(self.body.lower), np.asarray(self.body.upper)
        else:
            x0, y0, x1, y1 = self.body.base.bounds
            lower, upper = np.array([x0, y0, 0.0]), np.array([x1, y1, self.body.depth])
        s = (np.arange(PROBES) + 0.5) / PROBES
        grid = np.meshgrid(*(lower[i] + s * (upper[i] - lower[i]) for i in range(3)), indexing="ij")
        return tuple(g.ravel() for g in grid)


def _refuse_2d_only(data: dict, given: dict) -> None:
    discretization = data["discretization"]
    if discretization["order"] != 1:
        raise SceneError(
            f"discretization.order = {discretization['order']}: 3D bodies have the k = 1 element "
            "only; set discretization.order=1",
            key="discretization.order",
        )
    if "body_force_projection" in given.get("discretization", {}):
        raise SceneError(
            "discretization.body_force_projection is a k = 2 option; 3D bodies load the cell mean of f1; drop it",
            key="discretization.body_force_projection",
        )


def _check_family(mesh: dict, body) -> None:
    family = mesh.get("family")
    valid = BOX_FAMILIES if isinstance(body, Box) else FAMILIES_2D + EXTRUDE_FAMILIES_3D
    if family is not None and family not in valid:
        what = (
            "a box" if isinstance(body, Box) else "an extrude domain (a 2D family: prisms over the 2D mesh of the base)"
        )
        raise SceneError(
            f"discretization.mesh.family = {family!r} does not mesh {what}; valid families: {', '.join(valid)}",
            key="discretization.mesh.family",
        )
    if "layers" in mesh and isinstance(body, Box):
        raise SceneError(
            "discretization.mesh.layers applies to an extrude domain only; remove it", key="discretization.mesh.layers"
        )


def _check_rigid_motions(data: dict, probes: BodyProbes) -> None:
    """The Dirichlet sides hold the six rigid motions, tested at probe points of their faces (the
    corners of each face included: s from 0 to 1)."""
    points, held = [], []
    for side, components in _dirichlet(data["boundary"], DIMENSION).items():
        p = np.stack(probes.side(side, np.linspace(0.0, 1.0, 5)), axis=1)
        points.append(p)
        held.append(np.tile([c is not None for c in components], (p.shape[0], 1)))
    motion = free_rigid_motion(np.concatenate(points), np.concatenate(held))
    if motion is not None:
        raise rigid_motion_error(motion)


def semantic_checks_3d(data: dict, given: dict) -> dict:
    """The checks of a 3D scene (module docstring); returns the compiled expressions by key (those
    of a 2D scene, with three components). ``given``: the scene as written."""
    check_mesh_size(data["discretization"]["mesh"])
    _refuse_2d_only(data, given)
    if "body_force" not in given:
        data["body_force"] = [0.0, 0.0, 0.0]
    from_file = "file" in data["discretization"]["mesh"]
    body = None if from_file else domain3d_from_spec(data["domain"])
    if body is not None:
        _check_family(data["discretization"]["mesh"], body)
        check_mesh_resolution3d(data["discretization"]["mesh"], body)
    check_sides(data, None if body is None else body.side_names)
    probes = None if body is None else BodyProbes(body)
    compiled = boundary_expressions(data, None, probes, DIMENSION)
    if probes is not None:
        _check_rigid_motions(data, probes)
    force = data["body_force"]
    if len(force) != DIMENSION:
        raise SceneError(
            f"body_force has {len(force)} components; this 3D scene needs 3 ([f1_x, f1_y, f1_z]); fix the scene",
            key="body_force",
        )
    compiled["body_force"] = tuple(compile_checked(f"body_force[{i}]", force[i], DIMENSION) for i in range(3))
    if "contact" in data:
        check_contact_3d(data, given.get("contact", {}), probes, compiled)
    for expression in compiled["body_force"] if probes is not None else ():
        evaluate_checked(expression, probes.inside())
    return compiled


def check_contact_3d(data: dict, given_contact: dict, probes: BodyProbes | None, compiled: dict) -> None:
    """The contact section of a 3D scene (module docstring); ``probes`` None: a mesh file's body."""
    contact, sides = data["contact"], data["boundary"]["contact"]
    if "k" in contact["normal"] and contact["normal"]["k"] > MAX_NORMAL_K_OVER_E * data["material"]["E"]:
        raise SceneError(
            f"contact.normal.k = {contact['normal']['k']:g}: must be at most {MAX_NORMAL_K_OVER_E:g} "
            "material.E (stiffer is rigid contact, beyond double precision); fix the scene",
            key="contact.normal.k",
        )
    s = np.linspace(0.0, 1.0, PROBES + 1)
    if "foundation" in contact:
        if "gap" in given_contact:
            raise SceneError(
                "contact: give either gap or foundation, not both (the foundation plane defines the gap)",
                key="contact.foundation",
            )
        _check_plane(contact["foundation"], sides, probes, s)
        return
    gap = compiled["contact.gap"] = compile_checked("contact.gap", contact["gap"], DIMENSION)
    for side in sides if probes is not None else ():
        points = probes.side(side, s)
        values = np.broadcast_to(evaluate_checked(gap, points), points[0].shape)
        if not values.min() >= 0:
            i = int(np.argmin(np.where(np.isnan(values), -np.inf, values)))
            raise SceneError(
                f"contact.gap = {contact['gap']!r}: is {values[i]:.6g} < 0 at x={points[0][i]:.6g}, "
                f"y={points[1][i]:.6g}, z={points[2][i]:.6g} on {side} (the initial gap g_a must be "
                ">= 0); fix the scene",
                key="contact.gap",
            )


def _check_plane(foundation: dict, sides, probes, s) -> None:
    for key in ("point", "normal"):
        if len(foundation[key]) != DIMENSION:
            raise SceneError(
                f"contact.foundation.{key} has {len(foundation[key])} components; a 3D scene's "
                "foundation is a plane: give 3",
                key=f"contact.foundation.{key}",
            )
    normal = np.asarray(foundation["normal"], dtype=float)
    if not np.linalg.norm(normal) > 0:
        raise SceneError(
            "contact.foundation.normal = [0, 0, 0]: give the plane's normal pointing towards the "
            "body, e.g. [0, 0, 1] for a floor",
            key="contact.foundation.normal",
        )
    point = np.asarray(foundation["point"], dtype=float)
    for side in sides if probes is not None else ():
        x = np.stack(probes.side(side, s), axis=1)
        distance = (x - point) @ normal / np.linalg.norm(normal)
        refuse_penetration(side, distance, tuple(x.T))
