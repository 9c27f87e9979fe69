"""Locking on Cook's membrane near nu = 1/2 (issue 35): the cell volumetric strain against the
averaged nodal one (``discretization.volumetric_strain``, vemkit/vem/volumetric.py). Writes
benchmarks/out/cook_locking.{json,md}.

    .venv/bin/python benchmarks/cook_locking.py [--quick]

Cook's membrane in plane strain (the panel of config/scenes/cook.yaml, E = 250, a shear traction
6.25 on the side x = 48, clamped at x = 0), k = 1: u2 at the top corner (48, 60) over the reference
of locking-free Taylor-Hood P2/P1 elements, Richardson-extrapolated (issue 35: 9.2214 at nu = 0.3,
7.8643 at 0.49, 7.7782 at 0.499, 7.7695 at 0.4999). 2D: the families triangle, square and voronoi
at h = 4, 2, 1, 0.5. 3D: gmsh's tetrahedra of the membrane extruded to depth 1 with u3 = 0 on both
end faces (plane strain again; u2 the mean over the vertices of the edge x = 48, y = 60) at h = 4,
2, 1. Every case with ``cell`` and ``nodal_average``, on the same mesh, solved by the scene's
solver (ssn; without contact one linear solve: direct, or AMG-CG above 20 000 (3D: 2 000) unknowns).
Targets at nu = 0.4999 with nodal_average: triangles within 2 % at h = 1, tetrahedra within 3 % at
h = 2, squares and Voronoi no worse than cell.
"""

from __future__ import annotations

import os
import time

import numpy as np

from _common import MACHINE, quick_parser, targets_line, write_report

REFERENCE = {0.3: 9.2214, 0.49: 7.8643, 0.499: 7.7782, 0.4999: 7.7695}  # u2(48, 60), Taylor-Hood
POISSON = tuple(REFERENCE)
TREATMENTS = ("cell", "nodal_average")
FAMILIES_2D = ("triangle", "square", "voronoi")
SIZES = {"2d": (4.0, 2.0, 1.0, 0.5), "3d": (4.0, 2.0, 1.0)}
DEPTH = 1.0  # the extruded membrane's depth
BASE = {"polygon": [[0, 0], [48, 44], [48, 60], [0, 44]], "sides": ["bottom", "load", "top", "clamped"]}


def cook_scene(family: str, h: float, nu: float, treatment: str):
    """The plane-strain Cook scene (``family`` "tet": the extruded membrane in 3D)."""
    from vemkit.config.scene import scene_from_dict

    data = {
        "name": "cook_locking",
        "material": {"E": 250.0, "nu": nu},
        "discretization": {"mesh": {"family": family, "h": h}, "volumetric_strain": treatment},
        "solver": {"method": "ssn", "tol": 1e-10},
    }
    if family == "tet":
        data["model"] = "3d"
        data["domain"] = {**BASE, "extrude": {"depth": DEPTH, "ends": ["front", "back"]}}
        data["boundary"] = {
            "dirichlet": {"clamped": [0.0, 0.0, 0.0], "front": [None, None, 0.0], "back": [None, None, 0.0]},
            "neumann": {"load": {"traction": [0.0, 6.25, 0.0]}},
        }
    else:
        data["model"] = "plane_strain"
        data["domain"] = BASE
        data["boundary"] = {"dirichlet": ["clamped"], "neumann": {"load": {"traction": [0.0, 6.25]}}}
    return scene_from_dict(data)


def tip(problem, u) -> float:
    """u2 at (48, 60): the corner vertex (2D), the mean over the edge's vertices (3D)."""
    displacement = problem.dofs.expand(u)
    at = np.all(np.isclose(problem.mesh.vertices[:, :2], [48.0, 60.0]), axis=1)
    return float(displacement[at, 1].mean())


def run_case(family: str, h: float, mesh=None) -> list:
    """Every (nu, treatment) on one mesh of ``family`` at size h."""
    from vemkit.contact.problem import scene_problem
    from vemkit.mesh import scene_mesh
    from vemkit.solvers.dispatch import solve

    rows = []
    for nu in POISSON:
        for treatment in TREATMENTS:
            scene = cook_scene(family, h, nu, treatment)
            mesh = scene_mesh(scene) if mesh is None else mesh
            start = time.perf_counter()
            problem = scene_problem(scene, mesh)
            solution = solve(problem, scene.solver_options)
            value = tip(problem, solution.u)
            rows.append(
                {
                    "family": family,
                    "h": h,
                    "nu": nu,
                    "treatment": treatment,
                    "resolved_auto": cook_scene(family, h, nu, "auto").volumetric_strain,
                    "dofs": int(problem.n_dofs),
                    "nnz": int(problem.stiffness.nnz),
                    "linear": solution.info.get("linear"),
                    "linear_iterations": int(solution.linear_iterations),
                    "seconds": time.perf_counter() - start,
                    "u2": value,
                    "ratio": value / REFERENCE[nu],
                }
            )
            print(rows[-1], flush=True)
    return rows


def ratio(rows, family, h, nu, treatment):
    found = [r["ratio"] for r in rows if (r["family"], r["h"], r["nu"], r["treatment"]) == (family, h, nu, treatment)]
    return found[0] if found else None


def table(rows: list, family: str, sizes) -> list:
    lines = [
        f"**{family}** (u2(48, 60) / reference)",
        "",
        "| nu | treatment | " + " | ".join(f"h = {h:g}" for h in sizes) + " |",
        "|---|---|" + "---|" * len(sizes),
    ]
    for nu in POISSON:
        for treatment in TREATMENTS:
            values = [ratio(rows, family, h, nu, treatment) for h in sizes]
            cells = " | ".join("–" if v is None else f"{v:.4f}" for v in values)
            lines.append(f"| {nu:g} | {treatment} | {cells} |")
    dofs = {h: next((r["dofs"] for r in rows if r["family"] == family and r["h"] == h), None) for h in sizes}
    lines += ["", "DOFs: " + ", ".join(f"h = {h:g}: {d}" for h, d in dofs.items()), ""]
    return lines


def targets_of(rows: list) -> dict:
    nu = 0.4999
    tri, tet = ratio(rows, "triangle", 1.0, nu, "nodal_average"), ratio(rows, "tet", 2.0, nu, "nodal_average")
    no_worse = all(
        abs(ratio(rows, family, h, v, "nodal_average") - 1.0) <= abs(ratio(rows, family, h, v, "cell") - 1.0) + 1e-3
        for family in ("square", "voronoi")
        for h in SIZES["2d"]
        for v in POISSON
        if ratio(rows, family, h, v, "cell") is not None
    )
    return {
        "triangles within 2 % at h = 1 (nu = 0.4999)": tri is not None and abs(tri - 1.0) <= 0.02,
        "tetrahedra within 3 % at h = 2 (nu = 0.4999)": tet is not None and abs(tet - 1.0) <= 0.03,
        "squares and Voronoi no worse than cell (to 1e-3)": no_worse,
    }


def main():
    parser = quick_parser(__doc__, "h = 4, 2 only")
    args = parser.parse_args()
    sizes = {key: tuple(h for h in values if h >= 2.0) if args.quick else values for key, values in SIZES.items()}
    start, rows = time.perf_counter(), []
    for family in FAMILIES_2D:
        for h in sizes["2d"]:
            rows += run_case(family, h)
    for h in sizes["3d"]:
        rows += run_case("tet", h)
    targets = targets_of(rows)
    command = "python benchmarks/cook_locking.py" + (" --quick" if args.quick else "")
    record = {
        "command": command,
        "machine": MACHINE,
        "cpu_count": os.cpu_count(),
        "reference": {str(k): v for k, v in REFERENCE.items()},
        "depth_3d": DEPTH,
        "rows": rows,
        "targets": targets,
        "wall_seconds": time.perf_counter() - start,
    }
    lines = [
        "# Cook's membrane in plane strain near nu = 1/2: cell against nodal-averaged volumetric strain (k = 1)",
        "",
        f"`{command}` on {MACHINE}, {os.cpu_count()} cores, {record['wall_seconds']:.0f} s",
        "",
        "u2 at (48, 60) over the Taylor-Hood reference ("
        + ", ".join(f"{v} at nu = {k}" for k, v in REFERENCE.items())
        + f"). 3D: gmsh tetrahedra of the membrane extruded to depth {DEPTH:g}, u3 = 0 on both end faces. "
        "`auto` (the default) is nodal_average for every nu > 0.45 here (plane strain and 3D), cell at nu = 0.3.",
        "",
    ]
    for family in FAMILIES_2D:
        lines += table(rows, family, sizes["2d"])
    lines += table(rows, "tet", sizes["3d"])
    lines.append(targets_line(targets, "Targets"))
    write_report("cook_locking", record, lines)


if __name__ == "__main__":
    main()
