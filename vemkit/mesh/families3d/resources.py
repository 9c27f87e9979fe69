"""What a 3D box mesh will hold before it is built: cells, vertices, faces, DOFs (3 per vertex).

``estimate_mesh3d(family, domain, n=/h=/cells=, **options)`` on a box (SPEC §10):

- ``hex`` and ``tet``: exact, from the grid (nx, ny, nz) = max(1, round(n L)): hex has nx ny nz
  cells, (nx+1)(ny+1)(nz+1) vertices and (nx+1) ny nz + nx (ny+1) nz + nx ny (nz+1) faces; the
  Kuhn tetrahedra 6 cells per hexahedron, the same vertices, two triangles per grid face and 6
  inside every hexahedron;
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
from vemkit.mesh.families3d.build import box_cells_per_length
from vemkit.mesh.families3d.grid import grid_shape
from vemkit.mesh.families3d.voronoi3d import seed_count

VORONOI_VERTICES_PER_CELL = 6.55
VORONOI_FACES_PER_CELL = 7.55
VORONOI_BOUNDARY_DEFICIT = 5.0  # fewer vertices and faces per count^(2/3) near the box (a cube: the least)


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
    if not isinstance(body, Box):
        raise SceneError(
            "estimate_mesh3d: give a box domain (an extruded body is estimated from its 2D mesh)", key="domain"
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
    nx, ny, nz = grid_shape(box_cells_per_length(family, body, n, h, cells, options), box)
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
