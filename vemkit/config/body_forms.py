"""What a body of each dimension is, for the checks of a scene and of its mesh file: one
:class:`BodyForm` per dimension in :data:`FORMS` (2: a plane body, 3: a solid).

The modules of :mod:`vemkit.config` look a fact up here (``form = FORMS[dimension]; form.mesh_words``)
instead of branching on the dimension: the models that fit the body, the words of the messages, the
budgets of a mesh file's header, the gmsh entity that names a side. Which dimension a scene's body
has is decided in :mod:`vemkit.config.dimension`.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["FORMS", "BodyForm"]


@dataclass(frozen=True)
class BodyForm:
    """The facts of a body of one dimension (module docstring)."""

    dimension: int
    #: the dimension a mesh file of the wrong kind has (a 3D file for a plane scene, and back)
    other_dimension: int
    #: the models (the constitution) that fit the body, the schema's default first
    models: tuple
    #: how a scene whose model does not fit the body is fixed
    model_fix: str
    #: a mesh of this dimension in a message: "more than a plane mesh can have"
    mesh_words: str
    #: the same where the dimension is said after the kind: "the mesh file is a plane (2D) mesh"
    mesh_file_words: str
    #: the refusal of a mesh file of this dimension in a scene of the other (after "<file>: ")
    file_in_other_scene: str
    #: most cells per vertex a mesh can have: a plane mesh (Euler: 2 V + 2 faces), a 3D mesh
    #: (tetrahedra: about 6.5 per vertex in quality meshes, 6 in the Kuhn cubes; 10 leaves a margin)
    cells_per_vertex: int
    #: budget of gmsh elements per node: 2D < 2 V cells + 3 V lines + V points + 1; 3D < 10 V + 6 V faces + 1
    gmsh_items_per_node: int
    #: the netCDF kind of a mesh file of this dimension, as "cannot be read as ..." names it
    netcdf_words: str
    #: the gmsh physical group that names a side (of dimension ``dimension - 1``)
    side_entity: str
    #: the variables of the scene's expressions in words
    coordinate_words: str
    #: the figure of a contact foundation (a line in the plane, a plane in space)
    foundation: str


#: each fact (a field of :class:`BodyForm`) of a plane body and of a solid, side by side
_FACTS = {
    "other_dimension": (3, 2),
    "models": (("plane_stress", "plane_strain"), ("3d",)),
    "model_fix": (
        "drop model, or give a 3D body (domain box, a polygon with extrude, or a 3D mesh file)",
        "drop model or set model: 3d",
    ),
    "mesh_words": ("a plane mesh", "a 3D mesh"),
    "mesh_file_words": ("a plane (2D) mesh", "a 3D mesh"),
    "file_in_other_scene": (
        "is a 2D mesh (it has surfaces but no volumes) but the scene is 3D; give a 3D mesh file, or drop model: 3d",
        "is a 3D mesh (it has volumes) but the scene is 2D; give a 2D mesh file, or write the scene for a 3D body",
    ),
    "cells_per_vertex": (2, 10),
    "gmsh_items_per_node": (7, 17),
    "netcdf_words": ("UGRID netCDF", "a mesh3d netCDF file"),
    "side_entity": ("line", "surface"),
    "coordinate_words": ("x and y", "x, y and z"),
    "foundation": ("line", "plane"),
}
FORMS = {
    dimension: BodyForm(dimension=dimension, **{fact: values[k] for fact, values in _FACTS.items()})
    for k, dimension in enumerate((2, 3))
}
