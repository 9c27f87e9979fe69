"""The solution file of a 3D body (SPEC §10): the ``mesh3d`` topology and the fields of one solve.

On top of :func:`vemkit.mesh.files3d.mesh3d_to_dataset` (nodes, polygonal faces, the signed faces
of each volume, the named boundary parts): node variables ``u1``, ``u2``, ``u3``
(``mesh3d_nNodes``); volume variables ``strain_IJ`` and ``stress_IJ`` for IJ = 11, 22, 33, 12, 13,
23 (tensor components of eps(Pi u_h), constant per cell for k = 1, and sigma = C eps) and
``von_mises`` (``mesh3d_nVolumes``); the solver history and the global attributes of a 2D file
(:func:`vemkit.io.solution_file.with_solver_record`).
"""

from __future__ import annotations

import xarray as xr

from vemkit.mesh.files3d import TOPOLOGY, mesh3d_to_dataset
from vemkit.vem.projection import COMPONENTS_3D, stress, von_mises

AXES = ("x", "y", "z")


def solution_dataset3d(problem, solution, *, scene_yaml: str = "", extra_attrs=None) -> xr.Dataset:
    """The ``mesh3d`` Dataset of a solved 3D problem (module docstring)."""
    from vemkit.io.solution_file import with_solver_record

    u = problem.vertex_displacement(solution.u)
    strain = problem.projected(solution.u).cell_mean_strain()  # (M, 6), COMPONENTS_3D
    sigma = stress(strain, problem.lam, problem.mu)
    ds = mesh3d_to_dataset(problem.mesh)
    node, volume = f"{TOPOLOGY}_nNodes", f"{TOPOLOGY}_nVolumes"
    for c, axis in enumerate(AXES):
        ds[f"u{c + 1}"] = (
            node,
            u[:, c],
            {"long_name": f"displacement along {axis}", "units": "mm", "mesh": TOPOLOGY, "location": "node"},
        )
    cell = {
        "mesh": TOPOLOGY,
        "location": "volume",
        "comment": "of the projection Pi_1 (3.8): constant per cell (k = 1)",
    }
    for k, ij in enumerate(COMPONENTS_3D):
        ds[f"strain_{ij}"] = (volume, strain[:, k], dict(cell, long_name=f"strain eps{ij} of Pi u", units="1"))
    for k, ij in enumerate(COMPONENTS_3D):
        ds[f"stress_{ij}"] = (
            volume,
            sigma[:, k],
            dict(cell, long_name=f"stress sigma{ij} = C eps(Pi u)", units="daN/mm2"),
        )
    ds["von_mises"] = (
        volume,
        von_mises(sigma),
        dict(cell, long_name="von Mises stress sqrt(3/2 |dev sigma|^2)", units="daN/mm2"),
    )
    return with_solver_record(ds, problem, solution, scene_yaml, extra_attrs)
