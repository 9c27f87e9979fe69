"""The space of a solution file, for the studies: its order k, its degrees of freedom and Pi of them, and
the refusals of k = 2 where a study measures Pi_1 of vertex values (docs/reference/mathematics.md), which would mis-measure it."""

from __future__ import annotations

import numpy as np

from vemkit.exceptions import InputError, ResultError


def solution_order(ds) -> int:
    """The order k of a solution file (attribute ``order``; files before k = 2 existed are k = 1)."""
    return int(ds.attrs.get("order", 1))


def refuse_order2(ds, what: str) -> None:
    """InputError unless ``ds`` is a k = 1 solution: Pi_1 of vertex values and the paper's measure
    (docs/reference/mathematics.md) would mis-measure a k = 2 solution (its edge and cell means are ignored)."""
    if solution_order(ds) != 1:
        raise InputError(
            f"{what} has discretization.order = {solution_order(ds)}: this error measure (Pi_1 of vertex "
            "values) is for k = 1 only; use discretization.order=1 or the order2 study "
            "(.venv/bin/snakemake -j2 order2)",
            key="discretization.order",
        )


def require_order1(scene, what: str) -> None:
    """SceneError unless ``scene`` has discretization.order 1: ``what`` measures errors with Pi_1 of
    vertex values (docs/reference/mathematics.md), which would mis-measure a k = 2 solution."""
    from vemkit.exceptions import SceneError

    if scene.order != 1:
        raise SceneError(
            f"{what} measures errors with Pi_1 of vertex values (k = 1 only) but the scene has "
            f"discretization.order = {scene.order}: drop the override or use the order2 study "
            "(snakemake -j2 order2) or the speed-accuracy study's `order: 2` families",
            key="discretization.order",
        )


def solution_space(mesh, ds):
    """The virtual element space a solution file was computed in (its ``order`` attribute)."""
    from vemkit.vem.space import VirtualElementSpace

    return VirtualElementSpace(mesh, solution_order(ds))


def solution_node_values(space, ds) -> np.ndarray:
    """(n_nodes, 2) the degrees of freedom of a solution file in ``space``: the vertex values ``u1``,
    ``u2`` and, for the other entities of the element's layout, the means written beside them
    (``vemkit.io.solution_fields.ENTITY_VARIABLES``: k = 2 edge and cell means)."""
    from vemkit.io.solution_fields import ENTITY_VARIABLES

    parts = [np.stack([ds["u1"].values, ds["u2"].values], axis=1)]
    for entity in (e for e in space.element.layout if e != "vertex"):
        if entity == "edge" and not np.array_equal(ds["mesh2d_edge_nodes"].values.astype(np.int64), space.mesh.edges):
            raise ResultError(
                "the solution file's edges are not the mesh's edge order: the edge means cannot be placed"
            )
        suffix = ENTITY_VARIABLES[entity][1]
        parts.append(np.stack([ds[f"u1_{suffix}"].values, ds[f"u2_{suffix}"].values], axis=1))
    return np.concatenate(parts)


def projected_solution_file(mesh, ds):
    """Pi u_h (3.8) of a solution file, in its own space (the projection of k >= 2 depends on the
    scene's Lame parameters, read from its ``scene`` attribute)."""
    from vemkit.config.scene import scene_from_yaml

    space = solution_space(mesh, ds)
    material = space.element.projection_uses_material and ds.attrs.get("scene")
    lam, mu = scene_from_yaml(ds.attrs["scene"]).lame() if material else (None, None)
    return space.project(solution_node_values(space, ds), lam, mu)
