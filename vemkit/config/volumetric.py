"""The scene key ``discretization.volumetric_strain``: how the k = 1 stiffness treats the volumetric
(lambda) part (``vemkit.vem.volumetric``), and what ``auto`` resolves to.

- ``cell``: the paper's form (3.9), lambda |K| div_K(Pi u) div_K(Pi v) per cell;
- ``nodal_average``: the averaged nodal volumetric strain (Bonet & Burton 1998; Dohrmann et al.
  2000), locking-free at k = 1 on every family, triangles and tetrahedra included;
- ``auto`` (the default): ``nodal_average`` for k = 1 when the model can lock (plane strain or 3D,
  where lambda grows without bound as nu -> 1/2) and nu > 0.45, ``cell`` otherwise. Below 0.45 the
  cell form is the paper's method and does not lock measurably (lambda / mu <= 9), so every result
  at nu <= 0.45 is the paper's, bit for bit; plane stress never locks (lambda* <= 2 mu); k = 2
  does not lock (Cook at nu = 0.4999: >= 0.986 of the reference on every family) and keeps ``cell``.
"""

from __future__ import annotations

from vemkit.exceptions import SceneError

VOLUMETRIC_STRAINS = ("auto", "cell", "nodal_average")
#: the models whose lambda grows without bound as nu -> 1/2 (plane stress's lambda* stays <= 2 mu)
LOCKING_MODELS = ("plane_strain", "3d")
#: ``auto`` averages at the nodes above this Poisson ratio (k = 1, a locking model)
NODAL_AVERAGE_ABOVE_NU = 0.45
#: dimension -> how many times the entries of the cell stiffness ``nodal_average`` holds, at most:
#: its lambda term couples a vertex with the vertices of its neighbours' cells (measured on the
#: families: 2D 2.45 squares to 2.8 Voronoi; 3D 4.0 hexahedra, 4.1 tetrahedra, 4.8 Voronoi)
NODAL_AVERAGE_ENTRIES = {2: 3.0, 3: 5.0}


def resolved_volumetric_strain(requested: str, order: int, model: str, nu: float) -> str:
    """``cell`` or ``nodal_average``: the treatment ``requested`` names (``auto``: module docstring)."""
    if requested != "auto":
        return requested
    locks = order == 1 and model in LOCKING_MODELS and nu > NODAL_AVERAGE_ABOVE_NU
    return "nodal_average" if locks else "cell"


def check_volumetric_strain(discretization: dict) -> None:
    """``nodal_average`` exists for k = 1 only: refused in one line at another order."""
    if discretization.get("volumetric_strain") == "nodal_average" and discretization["order"] != 1:
        raise SceneError(
            f"discretization.volumetric_strain = nodal_average needs discretization.order = 1 (k = "
            f"{discretization['order']} does not lock); drop it or set discretization.volumetric_strain=cell",
            key="discretization.volumetric_strain",
        )
