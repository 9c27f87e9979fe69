"""Layer 2, geometry: the polygonal mesh and everything that makes or reads one.

Owns :class:`Mesh` (vertices and counter-clockwise polygons as plain arrays, named boundary
parts), the body to mesh (``domain``: :class:`Domain`, an outer polygon and holes with named
sides, SPEC §7), the mesh families on any domain (``families``), the mesh checks (``checks``),
triangulation of cells (``triangulate``), geometry helpers (``geometry``: the shoelace area and
centroid, point binning) and mesh files (``files``: UGRID netCDF, gmsh .msh, VTU).
Imports from vemkit: ``exceptions`` and ``config`` only.
"""

from vemkit.mesh.mesh import Mesh, from_polygons
from vemkit.mesh.checks import validate_mesh
from vemkit.mesh.domain import Domain, domain_from_spec
from vemkit.mesh.families import build_mesh

__all__ = ["Domain", "Mesh", "build_mesh", "domain_from_spec", "from_polygons", "validate_mesh"]
