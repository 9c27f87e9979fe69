"""The order k of a solution or scene, for the studies: Pi_2 of a k = 2 solution file, and the refusals of
k = 2 where a study measures Pi_1 of vertex values (SPEC 5), which would mis-measure it."""

from __future__ import annotations

import numpy as np

from vemkit.exceptions import InputError, ResultError


def solution_order(ds) -> int:
    """The order k of a solution file (attribute ``order``; files before k = 2 existed are k = 1)."""
    return int(ds.attrs.get("order", 1))


def refuse_order2(ds, what: str) -> None:
    """InputError unless ``ds`` is a k = 1 solution: Pi_1 of vertex values and the paper's measure
    (SPEC 5) would mis-measure a k = 2 solution (its edge and cell means are ignored)."""
    if solution_order(ds) != 1:
        raise InputError(f"{what} has discretization.order = {solution_order(ds)}: this error measure (Pi_1 of vertex "
                         "values, SPEC 5) is for k = 1 only; use discretization.order=1 or the order2 study "
                         "(snakemake -j2 order2)", key="discretization.order")


def require_order1(scene, what: str) -> None:
    """SceneError unless ``scene`` has discretization.order 1: ``what`` measures errors with Pi_1 of
    vertex values (SPEC 5), which would mis-measure a k = 2 solution."""
    from vemkit.exceptions import SceneError

    if scene.order != 1:
        raise SceneError(f"{what} measures errors with Pi_1 of vertex values (k = 1 only) but the scene has "
                         f"discretization.order = {scene.order}: drop the override or use the order2 study "
                         "(snakemake -j2 order2) or the speed-accuracy study's `order: 2` families",
                         key="discretization.order")


def solution_node_values(mesh, ds) -> np.ndarray:
    """k = 1: (n_vertices, 2) vertex values; k = 2: (n_nodes, 2) vertex values, edge and cell means."""
    u = np.stack([ds["u1"].values, ds["u2"].values], axis=1)
    if solution_order(ds) == 1:
        return u
    if not np.array_equal(ds["mesh2d_edge_nodes"].values.astype(np.int64), mesh.edges):
        raise ResultError("the solution file's edges are not the mesh's edge order: the edge means cannot be placed")
    edge = np.stack([ds["u1_edge_mean"].values, ds["u2_edge_mean"].values], axis=1)
    face = np.stack([ds["u1_face_mean"].values, ds["u2_face_mean"].values], axis=1)
    return np.concatenate([u, edge, face])


def projected_k2(mesh, ds):
    """Pi_2 u_h (3.8) of a k = 2 solution file (the projection depends on the scene's Lame parameters)."""
    from vemkit.config.scene import scene_from_yaml
    from vemkit.vem.norms_k2 import projected_solution_k2

    lam, mu = scene_from_yaml(ds.attrs["scene"]).lame()
    return projected_solution_k2(mesh, solution_node_values(mesh, ds), lam, mu)
