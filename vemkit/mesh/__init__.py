"""Layer 2, geometry: the mesh (polygonal, polyhedral) and everything that makes or reads one.

Owns the one mesh interface of d = 2, 3 (:class:`MeshInterface`, ``interface``: vertices, cells,
facets, their normals, areas and centroids, cell volumes and centroids, named sides as facet ids),
:class:`Mesh` (vertices and counter-clockwise polygons as plain arrays, named boundary parts) and
``PolyhedralMesh`` (``polyhedral``: faces and the cells' signed faces), which both implement it,
the mesh families (2D ``families``, 3D ``families3d``; ``meshing`` the one module that knows both:
a scene's mesh of either dimension) on any domain (the body itself, :class:`Domain`, is input:
``vemkit.config.domain``), the mesh checks (``checks``, ``checks3d``),
triangulation of cells (``triangulate``), geometry helpers (``geometry``: the shoelace area and
centroid, point binning; ``close_points``: pairs of points within a radius), mesh files (read:
``files``, ``files3d``: UGRID netCDF, gmsh .msh; written, 2D and 3D alike: ``ugrid``, the one
description of a mesh's UGRID topology and its writer, and ``vtu``, the one VTU writer) and the
description of a netCDF file with its two sinks, netCDF4 and xarray (``file_description``: the mesh
and solution files are spelled out there once), and the split of the cells for a solve across MPI
ranks (``partition``, METIS).
Imports from vemkit: ``exceptions`` and ``config`` only.
"""

from vemkit.mesh.checks import validate_mesh
from vemkit.mesh.families import build_mesh
from vemkit.mesh.interface import MeshInterface
from vemkit.mesh.mesh import Mesh, from_polygons
from vemkit.mesh.meshing import checked_mesh, scene_mesh

__all__ = ["Mesh", "MeshInterface", "build_mesh", "checked_mesh", "from_polygons", "scene_mesh", "validate_mesh"]
