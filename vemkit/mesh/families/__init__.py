"""Mesh families by name: ``build_mesh("voronoi", 32, seed=1)``, on any domain (docs/reference/files.md):
``build_mesh("square", h=2.0, domain={"polygon": ..., "sides": ..., "holes": ...})``.
On the unit square (the default):

- ``square``: n x n squares (no options);
- ``triangle``: ``kind="delaunay"`` (default; options ``seed``, ``min_angle``) about 2 n² quality
  Delaunay triangles, or ``kind="structured"`` the n x n grid cut along diagonals;
- ``voronoi``: about n² centroidal Voronoi cells (``seed``, ``lloyd_iterations``, ``anisotropy``,
  ``merge_tol``);
- ``hanging``: n x n squares quadrisected ``levels`` times (``levels``, ``rule``, ``seed``,
  ``fraction``, ``contact_side``).

On any other domain: ``triangle`` (delaunay) respects every side and hole, ``voronoi`` is clipped
to it (holes included), ``square`` and ``hanging`` are cut cells (``cut.py``); every boundary edge
is named after the side it lies on.
"""

from vemkit.mesh.families.by_name import FAMILIES, TRIANGLE_KINDS, build_mesh, family_builder
from vemkit.mesh.families.hanging import hanging
from vemkit.mesh.families.square import square, structured_triangle
from vemkit.mesh.families.triangle import delaunay_triangle
from vemkit.mesh.families.voronoi import voronoi

# scene_mesh and checked_mesh live in vemkit.mesh.meshing (public: vemkit.mesh); importable from here
# until vemkit.contact.problem imports them from there, then this line goes

__all__ = [
    "FAMILIES",
    "TRIANGLE_KINDS",
    "build_mesh",
    "family_builder",
    "square",
    "structured_triangle",
    "delaunay_triangle",
    "voronoi",
    "hanging",
]
