"""What a 3D box mesh will hold before it is built: cells, vertices, faces, DOFs (3 per vertex).

``estimate_mesh3d(family, domain, n=/h=/cells=, **options)`` on a box (docs/reference/files.md):

- ``hex`` and ``tet`` with ``kind: structured``: exact, from the grid (nx, ny, nz) = max(1, round(n L)):
  hex has nx ny nz cells, (nx+1)(ny+1)(nz+1) vertices and (nx+1) ny nz + nx (ny+1) nz + nx ny (nz+1)
  faces; the Kuhn tetrahedra 6 cells per hexahedron, the same vertices, two triangles per grid face
  and 6 inside every hexahedron;
- ``tet`` (``kind: delaunay``, gmsh; on a box or an extruded domain, the one family estimated on
  both): cells 6 n³ V + c n² A (V the volume, A the surface area), vertices and faces from the
  cells and the boundary triangles (``gmsh_tet.tet_counts``), fitted on gmsh's meshes of cubes,
  flat boxes, an extruded plate with an arc and a hole and an extruded annulus of 1.9 10³ ... 2.1 10⁵
  cells: cells and faces within 10 %, vertices within 11 % of those meshes (gmsh's counts jump a
  little from one size to the next; the largest misses on the smallest meshes), ``TET_TOLERANCE`` =
  15 % stated (not exact);
- ``octree``: exact cells (C + 7 r for r refined cells: the layer at the contact side, or
  round(fraction C)); vertices and faces an upper bound (19 new vertices and 30 new faces per refined
  cell, as if no two refined cells touched);
- ``voronoi``: exact cells (the seeds); vertices and faces 6.55 and 7.55 per cell less 5 count^(2/3)
  (the cells at the box have fewer), fitted to the family's meshes of 500 ... 10^5 cells on a cube
  (1 to 4 % above them; a flatter box has more boundary, so fewer).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from vemkit.config.domain3d import Box, cells_per_length3d, domain3d_from_spec
from vemkit.exceptions import SceneError
from vemkit.mesh.families3d.build import box_cells_per_length, tet_cells_per_length, tet_kind
from vemkit.mesh.families3d.gmsh_tet import surface_area, tet_counts
from vemkit.mesh.families3d.grid import grid_shape
from vemkit.mesh.families3d.voronoi3d import seed_count

VORONOI_VERTICES_PER_CELL = 6.55
VORONOI_FACES_PER_CELL = 7.55
VORONOI_BOUNDARY_DEFICIT = 5.0  # fewer vertices and faces per count^(2/3) near the box (a cube: the least)
#: the stated relative error of the Delaunay tet estimate (cells, vertices, faces; module doc)
TET_TOLERANCE = 0.15


class Mesh3dEstimate(NamedTuple):
    cells: int
    vertices: int
    faces: int
    dofs: int
    exact: bool


def _grid_counts(nx, ny, nz) -> tuple:
    cells = nx * ny * nz
    vertices = (nx + 1) * (ny + 1) * (nz + 1)
    faces = (nx + 1) * ny * nz + nx * (ny + 1) * nz + nx * ny * (nz + 1)
    return cells, vertices, faces


def estimate_mesh3d(family: str, domain, n=None, h=None, cells=None, **options) -> Mesh3dEstimate:
    """The counts of ``family`` on a box domain (module doc); SceneError for another body or family."""
    body = domain3d_from_spec(domain)
    if family == "tet":
        options = dict(options)
        kind = tet_kind(options)
        if kind == "delaunay":
            c, v, f = tet_counts(tet_cells_per_length(body, n, h, cells), body.volume, surface_area(body))
            return Mesh3dEstimate(c, v, f, 3 * v, False)
        if not isinstance(body, Box):
            raise SceneError(
                "tet kind structured meshes a box only; use kind delaunay on an extrude domain",
                key="discretization.mesh.kind",
            )
    if not isinstance(body, Box):
        raise SceneError(
            "estimate_mesh3d: give a box domain (an extruded body is estimated from its 2D mesh; family tet on both)",
            key="domain",
        )
    box = (body.lower, body.upper)
    if family == "voronoi":
        count = seed_count(cells_per_length3d(body, n, h, None) if cells is None else None, box, cells)
        deficit = VORONOI_BOUNDARY_DEFICIT * count ** (2.0 / 3.0)
        vertices = max(4, int(VORONOI_VERTICES_PER_CELL * count - deficit))
        faces = max(4, int(VORONOI_FACES_PER_CELL * count - deficit))
        return Mesh3dEstimate(count, vertices, faces, 3 * vertices, False)
    if family not in ("hex", "tet", "octree"):
        raise SceneError(
            f"estimate_mesh3d: unknown box family {family!r}; valid: hex, tet, octree, voronoi",
            key="discretization.mesh.family",
        )
    nx, ny, nz = grid_shape(box_cells_per_length(family, body, n, h, cells, {**options, "kind": "structured"}), box)
    c, v, f = _grid_counts(nx, ny, nz)
    if family == "hex":
        return Mesh3dEstimate(c, v, f, 3 * v, True)
    if family == "tet":
        return Mesh3dEstimate(6 * c, v, 2 * f + 6 * c, 3 * v, True)
    r = _refined(options, (nx, ny, nz), body.sides, c)
    return Mesh3dEstimate(c + 7 * r, v + 19 * r, f + 30 * r, 3 * (v + 19 * r), False)


def _refined(options: dict, shape, sides, count: int) -> int:
    if options.get("rule", "contact") == "random":
        return int(round(float(options.get("fraction", 0.3)) * count))
    axis = list(sides).index(options.get("contact_side", "bottom")) // 2
    return int(np.prod(np.delete(np.asarray(shape), axis)))


def scene_resources3d(scene):
    """Cells, DOFs and peak memory of solving the 3D ``scene`` (``vemkit.config.limits.Resources``),
    predicted before any mesh is built: ``estimate_mesh3d`` on a box; on an extruded body the 2D
    estimate of the base (``vemkit.config.limits.estimate_mesh``, the n of the 3D size) times the
    layers; a mesh file: the counts its header declares (``vemkit.config.mesh_file_header``)."""
    from vemkit.config.limits import estimate_mesh, estimate_resources3d
    from vemkit.config.mesh_file_header import mesh_file_header

    options = scene.mesh_options
    if "family" not in options:  # a mesh file: the counts it declares (tetrahedra: about 2 faces per cell)
        header = mesh_file_header(scene.mesh_file, dimension=3)
        return estimate_resources3d(header.cells, header.vertices, 2 * header.cells + header.vertices)
    family = options.pop("family")
    sizes = {key: options.pop(key) for key in ("n", "h", "cells") if key in options}
    layers = options.pop("layers", None)
    body = domain3d_from_spec(scene.domain)
    if isinstance(body, Box):
        counts = estimate_mesh3d(family, body, **sizes, **options)
        return estimate_resources3d(counts.cells, counts.vertices, counts.faces)
    n = cells_per_length3d(body, cells_per_cube=2.0 if family == "triangle" else 1.0, **sizes)
    cells, vertices = estimate_mesh({"family": family, "n": n, **options}, body.base.exact_area)
    layers = int(layers) if layers is not None else max(1, int(round(body.depth * n)))
    edges = cells + vertices  # Euler: about V + C edges in the base
    return estimate_resources3d(cells * layers, vertices * (layers + 1), cells * (layers + 1) + edges * layers)


def check_scene_resources3d(scene, max_dofs, layout: dict | None = None, ranks: tuple[int, int] = (1, 1)):
    """The prediction of :func:`scene_resources3d`, checked as in 2D
    (``vemkit.config.limits.check_scene_estimate``). ``layout`` (the element's nodes per entity) is
    the 2D check's argument: the 3D element has one node per vertex."""
    from vemkit.config.limits import check_scene_estimate

    return check_scene_estimate(scene, scene_resources3d(scene), max_dofs, dimension=3, ranks=ranks)


def refinement_resources3d(mesh, marked, circles=None):
    """Cells, DOFs and peak memory of solving ``mesh`` after its ``marked`` cells are refined
    (``vemkit.mesh.refine_polyhedra``), predicted before the refined mesh is built: the refinement's
    exact counts (``predict_refinement``) in the model of ``vemkit.config.limits.estimate_resources3d``."""
    from vemkit.config.limits import estimate_resources3d
    from vemkit.mesh.refine_polyhedra import predict_refinement

    return estimate_resources3d(*predict_refinement(mesh, marked, circles))


def check_refinable3d(mesh, circles=None) -> None:
    """MeshError naming the first cell of ``mesh`` that ``vemkit.mesh.refine_polyhedra`` cannot split
    and the families that refine: checked before an adaptive run solves its first mesh."""
    from vemkit.mesh.refine_polyhedra import predict_refinement

    predict_refinement(mesh, np.arange(mesh.n_cells), circles)
