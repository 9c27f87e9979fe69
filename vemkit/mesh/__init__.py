"""Layer 2, geometry: the polygonal mesh and everything that makes or reads one.

Owns :class:`Mesh` (vertices and counter-clockwise polygons as plain arrays, named boundary
parts), the mesh families on any domain (the body itself, :class:`Domain`, is input:
``vemkit.config.domain``) (``families``), the mesh checks (``checks``),
triangulation of cells (``triangulate``), geometry helpers (``geometry``: the shoelace area and
centroid, point binning) and mesh files (``files``: UGRID netCDF, gmsh .msh, VTU).
Imports from vemkit: ``exceptions`` and ``config`` only.
"""

from vemkit.mesh.checks import validate_mesh
from vemkit.mesh.families import build_mesh
from vemkit.mesh.mesh import Mesh, from_polygons

__all__ = ["Mesh", "build_mesh", "from_polygons", "validate_mesh"]
