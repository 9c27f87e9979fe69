"""Hertz's sphere on a stiff foundation in 3D (issue 21 items 4-5): the gmsh mesh of the lower
hemisphere, one solve per mesh, its measures against Hertz.

The body (benchmarks/hertz_sphere.yaml): the lower half of a sphere of radius R = 1 centred at the
origin, of that the quarter x >= 0, z >= 0 (``half``: x >= 0 only, for a tangential load along z);
physical surfaces sphere (Gamma_C), sym_x (x = 0), sym_z (z = 0) and top (y = 0). gmsh tetrahedra
refined near the contact point (0, -R, 0) by a size field (the distance to the point as a MathEval
field through a Threshold): edge ``h`` within ``refined`` of the point, growing to ``H`` at 0.6.

Measures (``hertz_measures``): the total force P = symmetry sum_i w_i p_i; the contact radius a_zero
from the area where the piecewise linear interpolant of the nodal penetration u_nu - g on Gamma_C's
triangles is positive (projected on the foundation plane, a = sqrt(symmetry A / pi)); a_fit and
p0_fit from a least-squares fit of p^2 = p0^2 (1 - r^2 / a^2) over the vertices in contact; p0_nodal
the largest nodal pressure. Hertz for a rigid foundation (K. L. Johnson, Contact Mechanics, 1985,
section 4.2): a = (3 P R / (4 E*))^(1/3), p0 = 3 P / (2 pi a^2), E* = E / (1 - nu^2), at the measured P.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import time
from pathlib import Path

import numpy as np

from vemkit.contact.boundary import FoundationLine, normals_in_roller_planes
from vemkit.mesh.polyhedral_build import csr_rows
from vemkit.solvers.solution import contact_state

R = 1.0  # the sphere's radius of the scene
A_REF = 0.1  # about the contact radius at delta = 0.01 R: the refined zone is 1.5 A_REF around the point


def sphere_msh(path, h: float, H: float, half: bool = False, refined: float = 1.5 * A_REF) -> None:
    """A gmsh 4.1 file of the quarter lower hemisphere (``half``: x >= 0 only; module docstring)."""
    import gmsh

    gmsh.initialize([], readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.Verbosity", 1)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.model.add("hertz_sphere")
        occ = gmsh.model.occ
        ball = occ.addSphere(0, 0, 0, R)
        box = occ.addBox(0, -R, -R, R, R, 2 * R) if half else occ.addBox(0, -R, 0, R, R, R)
        occ.intersect([(3, ball)], [(3, box)])
        occ.synchronize()
        groups: dict[str, list[int]] = {}
        for dim, tag in gmsh.model.getEntities(2):
            bounds = np.asarray(gmsh.model.getBoundingBox(dim, tag)).reshape(2, 3)
            flat = np.flatnonzero(bounds[1] - bounds[0] < 1e-4 * R)  # the plane faces are flat in x, y or z
            name = ("sym_x", "top", "sym_z")[flat[0]] if flat.size else "sphere"
            groups.setdefault(name, []).append(tag)
        assert set(groups) == {"sphere", "sym_x", "top"} | (set() if half else {"sym_z"}), groups
        for name, tags in groups.items():
            gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, tags), name)
        gmsh.model.addPhysicalGroup(3, [t for _, t in gmsh.model.getEntities(3)])
        field = gmsh.model.mesh.field
        distance = field.add("MathEval")
        field.setString(distance, "F", f"Sqrt(x*x + (y + {R})*(y + {R}) + z*z)")
        threshold = field.add("Threshold")
        field.setNumber(threshold, "InField", distance)
        field.setNumber(threshold, "SizeMin", h)
        field.setNumber(threshold, "SizeMax", H)
        field.setNumber(threshold, "DistMin", refined)
        field.setNumber(threshold, "DistMax", 0.6)
        field.setAsBackgroundMesh(threshold)
        for key, value in {
            "Mesh.MeshSizeExtendFromBoundary": 0,
            "Mesh.MeshSizeFromPoints": 0,
            "Mesh.MeshSizeFromCurvature": 0,
            "Mesh.Algorithm": 6,
            "Mesh.Algorithm3D": 1,
            "Mesh.Optimize": 1,
            "Mesh.MshFileVersion": 4.1,
        }.items():
            gmsh.option.setNumber(key, value)
        gmsh.model.mesh.generate(3)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()


def hertz_peak_pressure(P: float, a: float) -> float:
    """Hertz's peak pressure p0 = 3 P / (2 pi a^2) of a contact of radius a under the force P (Johnson,
    Contact Mechanics, section 4.2)."""
    return 3.0 * P / (2.0 * math.pi * a**2)


def positive_area(xz: np.ndarray, p: np.ndarray) -> float:
    """Area of {p_h > 0} of the piecewise linear p on triangles (n, 3, 2) with vertex values (n, 3)."""
    total = 0.0
    for tri, val in zip(xz, p, strict=True):
        pos = val > 0
        if not pos.any():
            continue
        (ax, ay), (bx, by) = tri[1] - tri[0], tri[2] - tri[0]
        full = 0.5 * abs(ax * by - ay * bx)
        if pos.all():
            total += full
            continue
        # one vertex alone on its side: the small triangle cut off at the zero level
        lone = int(np.flatnonzero(pos)[0] if pos.sum() == 1 else np.flatnonzero(~pos)[0])
        s = [val[lone] / (val[lone] - val[j]) for j in range(3) if j != lone]
        small = full * s[0] * s[1]
        total += small if pos.sum() == 1 else full - small
    return total


def hertz_measures(problem, solution, E: float, nu: float, symmetry: float = 4.0) -> dict:
    """P, a (zero level, fit), p0 (nodal, fit) against Hertz at the measured P (module docstring), and
    the profile r, p of the Gamma_C vertices (under "profile")."""
    cb, mesh = problem.contact, problem.mesh
    state = contact_state(problem, solution.u, solution.multiplier)
    p = state.normal_pressure
    P = symmetry * float(np.sum(cb.weight * p))
    r = np.hypot(cb.coords[:, 0], cb.coords[:, 2])
    nodal = np.full(mesh.n_vertices, -np.inf)  # the signed penetration u_nu - g (> 0: in contact)
    nodal[cb.vertices] = state.penetration
    tri = np.asarray(csr_rows(mesh.face_offsets, mesh.face_vertices)[mesh.boundary["sphere"]])
    tri = tri[(nodal[tri] > 0).any(axis=1)]
    a_zero = math.sqrt(symmetry * positive_area(mesh.vertices[tri][:, :, [0, 2]], nodal[tri]) / math.pi)
    on = p > 0
    c0, c1 = np.linalg.lstsq(np.stack([np.ones(on.sum()), r[on] ** 2], axis=1), p[on] ** 2, rcond=None)[0]
    p0_fit = math.sqrt(max(c0, 0.0))
    a_fit = math.sqrt(c0 / -c1) if c1 < 0 < c0 else float("nan")
    a_h = (3.0 * P * R * (1 - nu**2) / (4.0 * E)) ** (1.0 / 3.0)
    p0_h = hertz_peak_pressure(P, a_h)
    return {
        "P": P,
        "a_zero": a_zero,
        "a_fit": a_fit,
        "a_hertz": a_h,
        "p0_nodal": float(p.max()),
        "p0_fit": p0_fit,
        "p0_hertz": p0_h,
        "err_a_zero": a_zero / a_h - 1,
        "err_a_fit": a_fit / a_h - 1,
        "err_p0_nodal": float(p.max()) / p0_h - 1,
        "err_p0_fit": p0_fit / p0_h - 1,
        "contact_vertices": int(on.sum()),
        "profile": {"r": r, "p": p},
    }


def sphere_problem(data: dict, msh, k: float):
    """The scene ``data`` (the Hertz sphere) on the mesh file ``msh`` with k_nu = k E / R, the Gamma_C
    normals on the roller planes in the planes (``normals_in_roller_planes``)."""
    from vemkit.config.scene import scene_from_dict
    from vemkit.contact.problem import scene_problem

    data = copy.deepcopy(data)
    data["discretization"]["mesh"] = {"file": str(msh)}
    data["contact"]["normal"]["k"] = k * data["material"]["E"] / R
    scene = scene_from_dict(data, source="hertz sphere")
    problem = scene_problem(scene)
    contact = normals_in_roller_planes(problem.contact, FoundationLine(*scene.foundation))
    return dataclasses.replace(problem, contact=contact)


def hertz_run(data: dict, h: float, H: float, k: float, folder) -> dict:
    """One mesh (edge h near the contact point, H far) of the quarter sphere: the solve's size, ssn
    iterations, times and ``hertz_measures``."""
    from vemkit.solvers.dispatch import solve

    start = time.perf_counter()
    msh = Path(folder) / f"sphere_{h:g}_{H:g}.msh"
    if not msh.exists():
        sphere_msh(msh, h, H)
    problem = sphere_problem(data, msh, k)
    solution = solve(problem, dict(data["solver"]))
    row = {
        "h": h,
        "H": H,
        "k": k,
        "cells": int(problem.mesh.n_cells),
        "dofs": int(problem.n_dofs),
        "iterations": int(solution.iterations),
        "converged": bool(solution.converged),
        "seconds_solve": solution.wall_time,
        "wall": time.perf_counter() - start,
    }
    row.update(hertz_measures(problem, solution, data["material"]["E"], data["material"]["nu"]))
    return row


def with_profiles(ds, rows, dims, keys, point: str = "point"):
    """``ds`` (``records_dataset(rows, dims)``) with the per-vertex arrays ``row["profile"][key]`` as
    variables on (dims..., point), NaN-padded to the longest (the meshes differ in Gamma_C vertices)."""
    width = max(len(r["profile"][keys[0]]) for r in rows)
    shape = tuple(ds.sizes[d] for d in dims) + (width,)
    out = {key: np.full(shape, np.nan) for key in keys}
    for r in rows:
        at = tuple(list(ds[d].values).index(r[d]) for d in dims)
        for key in keys:
            v = np.asarray(r["profile"][key], dtype=float)
            out[key][at + (slice(0, v.size),)] = v
    return ds.assign({key: (tuple(dims) + (point,), v) for key, v in out.items()})
