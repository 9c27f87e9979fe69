"""3D mesh families by name (docs/reference/files.md): every one returns a :class:`~vemkit.mesh.polyhedral.PolyhedralMesh`
with named sides and ``meta``, valid for :func:`~vemkit.mesh.checks3d.validate_mesh3d`.

On a box ``[lower, upper]`` (sides xmin, xmax, ymin, ymax, zmin, zmax, default ``left, right, front,
back, bottom, top``):

- ``hex``: the grid of max(1, round(n L)) hexahedra along each edge of length L;
- ``tet``: ``kind="delaunay"`` (the default) gmsh's quality Delaunay tetrahedra, about 6 n³ per unit
  volume (``delaunay_tet``, ``families3d.gmsh_tet``), or ``kind="structured"`` the same grid as hex,
  each hexahedron cut into its 6 Kuhn tetrahedra (``tet``);
- ``octree``: the hex grid with the cells at a side (``contact_side``) or a random ``fraction`` cut
  into 8 (one level): coarse neighbours gain the hanging nodes as vertices;
- ``voronoi``: about n³ per unit volume clipped centroidal Voronoi polyhedra (``seed``,
  ``lloyd_iterations``, ``jitter``).

On an extruded 2D domain: ``tet`` (delaunay) meshes the body itself (``delaunay_tet_extruded``);
every 2D family gives prisms over its 2D mesh of the base.

``extrude(mesh2d, layers, depth)``: prisms over any 2D mesh (``families3d.extrude``). Domains and
sizes (n, h, cells): ``build_mesh3d`` (``families3d.build``).
"""

from vemkit.mesh.families3d.build import BOX_FAMILIES, build_mesh3d
from vemkit.mesh.families3d.extrude import extrude
from vemkit.mesh.families3d.gmsh_tet import delaunay_tet, delaunay_tet_extruded
from vemkit.mesh.families3d.grid import BOX_SIDES, UNIT_BOX, hex, tet
from vemkit.mesh.families3d.octree import octree
from vemkit.mesh.families3d.voronoi3d import voronoi

__all__ = [
    "BOX_FAMILIES",
    "build_mesh3d",
    "BOX_SIDES",
    "UNIT_BOX",
    "delaunay_tet",
    "delaunay_tet_extruded",
    "extrude",
    "hex",
    "octree",
    "tet",
    "voronoi",
]
