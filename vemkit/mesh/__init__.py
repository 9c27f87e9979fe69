"""Layer 2, geometry: the polygonal mesh and everything that makes or reads one.

Owns :class:`Mesh` (vertices and counter-clockwise polygons as plain arrays, named boundary
parts), the mesh families on any domain (the body itself, :class:`Domain`, is input:
``vemkit.config.domain``) (``families``), the mesh checks (``checks``),
triangulation of cells (``triangulate``), geometry helpers (``geometry``: the shoelace area and
centroid, point binning; ``close_points``: pairs of points within a radius), mesh files (read:
``files``, ``files3d``: UGRID netCDF, gmsh .msh; written, 2D and 3D alike: ``ugrid``, the one
description of a mesh's UGRID topology and its writer, and ``vtu``, the one VTU writer) and the
description of a netCDF file with its two sinks, netCDF4 and xarray (``file_description``: the mesh
and solution files are spelled out there once).
Imports from vemkit: ``exceptions`` and ``config`` only.
"""

from vemkit.mesh.checks import validate_mesh
from vemkit.mesh.families import build_mesh
from vemkit.mesh.mesh import Mesh, from_polygons

__all__ = ["Mesh", "build_mesh", "from_polygons", "validate_mesh"]
