"""vemkit's 3D k = 1 element side by side with scikit-fem and GetFEM P1 tetrahedra on the same meshes (issue 22 (d)).

    .venv/bin/python benchmarks/peers3d.py [--quick] [--sizes 8 16 32 48] [--problems elasticity compliance]

On tetrahedra the 3D k = 1 VEM is exactly P1 (docs/reference/files.md): every code solves the same discrete problem
on the Kuhn tetrahedra of an n^3 grid of the unit cube (`family: tet, kind: structured`, 6 n^3 cells)
that `vemkit mesh --scene` wrote (E = 1000, nu = 0.3):
  elasticity  the bottom face clamped, the traction (0, 0, -1) on the top face: vemkit, scikit-fem
              (spsolve up to SKFEM_DIRECT_MAX_DOFS_3D, pyamg smoothed aggregation + CG, rtol 1e-12,
              with the six rigid modes above; benchmarks/peers/skfem3d_solve.py) and GetFEM
              (FEM_PK(3,1), the linearized elasticity brick, MUMPS);
  compliance  the box pressed onto a curved foundation: the top face moved by (0, 0, -DELTA), the
              bottom face in frictionless normal compliance p(t) = KN t_+ against the gap GAP (a
              paraboloid, part of the bottom in contact); vemkit `contact_quadrature: gauss`,
              `contact_gauss_points: 3` (the 7-point degree-5 rule on every face triangle, the trace
              and the gap P1 on it) and GetFEM with the face rule of IM_TETRAHEDRON(5) (the same
              7 points), kn*pos_part(u.Normal - gap)*(Test_u.Normal) and the gap interpolated P1
              from its vertex values; GetFEM's Newton (its default line search) with MUMPS at every
              size, vemkit ssn (linear solver auto: direct up to 20 000 unknowns, AMG-CG above);
  friction    the same box, its top also moved sideways by SHIFT, with Coulomb's law on the
              compliance pressure, p_tau = COULOMB KN t_+ (vemkit friction k = COULOMB KN, m = 1),
              the nodal rule (GetFEM IM_NC(3, 1): the vertex rule |F|/3 on every face, vemkit's nodal
              weights on triangles) and in GetFEM the friction stress sig_t = p_tau lam as a P1
              field on the bottom with sig_t = Ball_projection(sig_t + r u_T, p_tau) (getfem_solve.py).
vemkit: `vemkit solve`, tol 1e-12. Each solve is its own process (wall time and peak RSS by wait4).
Writes benchmarks/out/peers3d.{json,md,png}.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np
import xarray as xr
import yaml
from peers import PEERS, SYSTEM_PYTHON, VEMKIT, getfem_missing, measured, relative_difference

from vemkit.config.expressions import compile_expression

from _common import MACHINE, OUT, write_report

E, NU = 1000.0, 0.3
LAM, MU = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
TRACTION = [0.0, 0.0, -1.0]
PROBLEMS = ("elasticity", "compliance", "friction")
DELTA, KN = 0.01, 1000.0  # the top face's push and the normal stiffness p(t) = KN t_+
SHIFT = [0.001, 0.0005]  # friction: the top face also moved sideways
COULOMB = 0.1  # friction: p_tau = COULOMB KN t_+ (m_tau = 1), Coulomb's law on the compliance pressure
TANGENTS = [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]  # vemkit's (t1, t2) on the bottom, nu = (0, 0, -1)
GAP = "0.02*((x - 0.4)**2 + (y - 0.55)**2)"  # of x, y (z = 0 on Gamma_C), >= 0
#: spsolve up to here, AMG-CG above: in 3D the direct solver's fill grows fast (vemkit's own "auto"
#: switches at 2 000 unknowns in 3D, vemkit.solvers.linear.DIRECT_LIMIT_3D; SuperLU at 1e5 3D DOFs takes minutes)
SKFEM_DIRECT_MAX_DOFS_3D = 20_000


def scene(mesh_entry: dict, problem: str = "elasticity") -> dict:
    data = {
        "name": "cube",
        "model": "3d",
        "domain": {"box": [[0, 0, 0], [1, 1, 1]]},
        "material": {"E": E, "nu": NU},
        "boundary": {"dirichlet": ["bottom"], "neumann": {"top": {"traction": TRACTION}}},
        "discretization": {"mesh": mesh_entry},
        "solver": {"tol": 1e-12},
    }
    if problem != "elasticity":
        data["boundary"] = {"dirichlet": {"top": top_displacement(problem)}, "contact": ["bottom"]}
        data["contact"] = {"gap": GAP, "normal": {"k": KN, "m": 1.0}, "friction": {"k": 0.0, "m": 0.0}}
        data["discretization"].update(contact_quadrature="gauss", contact_gauss_points=3)
    if problem == "friction":
        data["contact"]["friction"] = {"k": COULOMB * KN, "m": 1.0}
        data["discretization"].update(contact_quadrature="nodal")
    return data


def top_displacement(problem: str) -> list[float]:
    return [*(SHIFT if problem == "friction" else [0.0, 0.0]), -DELTA]


def write_mesh(n: int, work: Path) -> Path:
    mesh_scene, mesh_path = work / f"mesh-{n}.yaml", work / f"mesh-{n}.nc"
    if not mesh_path.exists():
        mesh_scene.write_text(yaml.safe_dump(scene({"family": "tet", "kind": "structured", "n": n})))
        measured([str(VEMKIT), "mesh", "--scene", str(mesh_scene), "-o", str(mesh_path), "-q"])
    return mesh_path


def run_vemkit(n: int, problem: str, work: Path) -> tuple[np.ndarray, dict, dict]:
    """u at the vertices, the process record, and the mesh as the peers' CASE arrays."""
    mesh_path = write_mesh(n, work)
    solve_scene, out = work / f"solve-{problem}-{n}.yaml", work / f"solve-{problem}-{n}.nc"
    solve_scene.write_text(yaml.safe_dump(scene({"file": mesh_path.name}, problem)))
    vem = measured([str(VEMKIT), "solve", str(solve_scene), "-o", str(out), "-q", "--max-dofs", "20000000"])
    with xr.open_dataset(out) as ds:
        u_vem = np.stack([ds[f"u{c}"].values for c in (1, 2, 3)], axis=1)
        vertices = np.stack([ds[f"mesh3d_node_{a}"].values for a in "xyz"], axis=1)
        vem.update(
            assembly_s=float(ds.attrs["assembly_time"]),
            solve_s=float(ds.attrs["wall_time"]),
            iterations=int(ds.attrs.get("iterations", 0)),
            solver="ssn, linear solver auto",
        )
        faces = ds["mesh3d_face_nodes"].values.astype(np.int64)  # no fill in a tetrahedral mesh
        volumes = ds["mesh3d_volume_faces"].values.astype(np.int64)
        sides = {name: faces[ds[f"mesh3d_boundary_{name}"].values] for name in ("bottom", "top")}
    case = {"vertices": vertices, "tetrahedra": _tetrahedra(faces, volumes)}
    return u_vem, vem, case | {f"side_{name}": f for name, f in sides.items()}


def getfem_params(problem: str) -> dict:
    """The discrete problem as getfem_solve.py states it (see the module docstring). max_res 1e-9:
    with the top's displacement imposed by a multiplier the reactions stay in the residual, whose
    round-off floor is 1.6e-10 at n = 16 (1e-10 was never reached; eliminated, 5.6e-13)."""
    common = {"problem": problem, "lam": LAM, "mu": MU, "max_res": 1e-9, "lsolver": "mumps"}
    if problem == "elasticity":
        return common | {"dirichlet": ["bottom"], "neumann": "top", "traction_affine": [[t, 0, 0, 0] for t in TRACTION]}
    contact = {
        "dirichlet": ["top"],
        "dirichlet_values": {"top": top_displacement(problem)},
        "contact": "bottom",
        "kn": KN,
        "quadrature": "gauss",
        "gauss_points": 3,
    }
    if problem == "friction":  # the vertex rule IM_NC(3, 1) on faces: vemkit's nodal weights on triangles
        contact |= {
            "quadrature": "nodal",
            "kt": COULOMB * KN,
            "friction_m": 1,
            "tangents": TANGENTS,
            "r_friction": 100.0,
        }
    return common | contact


def gap_at(vertices: np.ndarray) -> np.ndarray:
    """GAP at the vertices, evaluated as vemkit evaluates the scene's contact.gap."""
    return np.broadcast_to(compile_expression(GAP, name="contact.gap")(*vertices.T), vertices.shape[:1]).copy()


def run_peer(peer: str, problem: str, n: int, case: dict, work: Path) -> tuple[np.ndarray, dict]:
    case_path, result = work / f"case-{peer}-{problem}-{n}.npz", work / f"{peer}-{problem}-{n}.npz"
    dofs = 3 * case["vertices"].shape[0]
    if peer == "skfem":
        params = {"lam": LAM, "mu": MU, "traction": TRACTION, "cg_rtol": 1e-12}
        params["solver"] = "direct" if dofs <= SKFEM_DIRECT_MAX_DOFS_3D else "amg"
        arrays = {"vertices": case["vertices"], "tetrahedra": case["tetrahedra"]}
        command = [sys.executable, str(PEERS / "skfem3d_solve.py")]
    else:
        params = getfem_params(problem)
        arrays = case | ({"gap": gap_at(case["vertices"])} if problem != "elasticity" else {})
        command = [SYSTEM_PYTHON, str(PEERS / "getfem_solve.py")]
    np.savez(case_path, params=json.dumps(params), **arrays)
    record = measured(command + [str(case_path), str(result)])
    with np.load(result) as r:
        info, u_peer = json.loads(str(r["info"])), r["u"]
    record.update(
        assembly_s=info["setup_s"],
        solve_s=info["solve_s"],
        solver=info.get("lsolver") or info["solver"],
        iterations=info.get("iterations"),
    )
    return u_peer, record


def run_case(n: int, work: Path, problem: str = "elasticity", peers: tuple = ("skfem",)) -> list[dict]:
    """One mesh, one problem: vemkit and each peer, the peers' difference to vemkit."""
    u_vem, vem, case = run_vemkit(n, problem, work)
    base = {"n": n, "problem": problem, "cells": int(case["tetrahedra"].shape[0]), "dofs": u_vem.size}
    rows = [base | {"code": "vemkit"} | vem]
    for peer in peers:
        u_peer, record = run_peer(peer, problem, n, case, work)
        rows.append(
            base
            | {"code": peer, "rel_diff_to_vemkit": relative_difference(u_peer, u_vem)}
            | {"vemkit_over_peer_wall": vem["wall_s"] / record["wall_s"]}
            | record
        )
    return rows


def _tetrahedra(faces: np.ndarray, volumes: np.ndarray) -> np.ndarray:
    """(M, 4) the vertices of every tetrahedral cell of a mesh3d file (four triangular faces)."""
    signed = volumes[:, :4]
    face = np.where(signed >= 0, signed, -signed - 1)
    corners = faces[face][:, :, :3].reshape(len(volumes), -1)
    tets = np.array([np.unique(row) for row in corners])
    assert tets.shape[1] == 4, "not a tetrahedral mesh"
    return tets.astype(np.int64)


def peers_for(problem: str, getfem_reason: str | None, dofs: int = 0, getfem_contact_max: int = 10**9) -> tuple:
    """scikit-fem on elasticity; GetFEM on every problem unless it is missing, or a contact problem
    above the limit (its Newton refactorizes the MUMPS matrix at every step)."""
    too_big = problem != "elasticity" and dofs > getfem_contact_max
    return (("skfem",) if problem == "elasticity" else ()) + (() if getfem_reason or too_big else ("getfem",))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="n = 4, 8 (a smoke test)")
    parser.add_argument("--sizes", type=int, nargs="+", default=[8, 16, 32, 48])
    parser.add_argument("--problems", nargs="+", default=list(PROBLEMS), choices=PROBLEMS)
    parser.add_argument("--getfem-contact-max-dofs", type=int, default=10**9, help="no GetFEM contact solves above")
    parser.add_argument("--resume", action="store_true", help="keep the cases of benchmarks/out/peers3d.json")
    args = parser.parse_args()
    getfem_reason = getfem_missing()
    work = Path(tempfile.mkdtemp(prefix="vemkit-peers3d-"))
    for problem in args.problems:
        run_case(3, work, problem, ())  # Numba's on-disk cache compiled before anything is timed
    rows: list[dict] = json.loads((OUT / "peers3d.json").read_text())["rows"] if args.resume else []
    done = {(r["n"], r["problem"]) for r in rows}
    for n in [4, 8] if args.quick else args.sizes:
        for problem in (p for p in args.problems if (n, p) not in done):
            chosen = peers_for(problem, getfem_reason, 3 * (n + 1) ** 3, args.getfem_contact_max_dofs)
            rows += run_case(n, work, problem, chosen)
            report(rows, getfem_reason, quiet=True)  # after every case: a stopped run keeps its rows
    shutil.rmtree(work)
    report(rows, getfem_reason)


def report(rows: list[dict], getfem_reason: str | None, quiet: bool = False) -> None:
    load = os.getloadavg()[0]
    lines = [
        "# vemkit 3D k = 1 against scikit-fem and GetFEM P1 tetrahedra (benchmarks/peers3d.py)",
        "",
        f"Machine: {MACHINE}, {os.cpu_count()} cores, load average {load:.1f} at the end (timings under this load).",
        "GetFEM: " + (getfem_reason or "python3-getfem under /usr/bin/python3, Newton with MUMPS."),
        "",
        "| n | cells | DOFs | problem | code | solver | Newton steps | rel. diff. | wall s | max RSS MiB "
        "| assembly s | solve s | vemkit/peer wall | load |",
        "|" + "---|" * 14,
    ]
    for r in rows:
        diff = f"{r['rel_diff_to_vemkit']:.1e}" if "rel_diff_to_vemkit" in r else "–"
        ratio = f"{r['vemkit_over_peer_wall']:.2f}" if "vemkit_over_peer_wall" in r else "–"
        steps = r.get("iterations") if r["problem"] != "elasticity" else "–"
        lines.append(
            f"| {r['n']} | {r['cells']:,} | {r['dofs']:,} | {r['problem']} | {r['code']} | {r['solver']} | "
            f"{steps} | {diff} | {r['wall_s']:.2f} | {r['max_rss_mib']:.0f} | {r['assembly_s']:.2f} | "
            f"{r['solve_s']:.2f} | {ratio} | {r.get('load_1min', float('nan')):.1f} |"
        )
    record = {"machine": MACHINE, "load_average": load, "getfem": getfem_reason or "installed", "rows": rows}
    if quiet:
        OUT.mkdir(parents=True, exist_ok=True)
        (OUT / "peers3d.json").write_text(json.dumps(record, indent=2))
        (OUT / "peers3d.md").write_text("\n".join(lines) + "\n")
        print(lines[-1], flush=True)
    else:
        write_report("peers3d", record, lines)
        figure(rows, OUT / "peers3d.png")


def figure(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(PROBLEMS), figsize=(13, 4.2), sharey=True)
    for ax, problem in zip(axes, PROBLEMS):
        for code, color in (("vemkit", "C0"), ("skfem", "C1"), ("getfem", "C2")):
            own = sorted((r for r in rows if r["problem"] == problem and r["code"] == code), key=lambda r: r["dofs"])
            if own:
                dofs = [r["dofs"] for r in own]
                ax.loglog(dofs, [r["wall_s"] for r in own], "o-", color=color, label=f"{code}: process")
                ax.loglog(dofs, [r["solve_s"] for r in own], "s--", color=color, label=f"{code}: solve")
        ax.set_title(f"{problem} (P1 tetrahedra)")
        ax.set_xlabel("DOFs")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("time (s)")
    axes[0].legend(fontsize=7)
    fig.suptitle(f"wall time, 2 shared cores (load average {os.getloadavg()[0]:.1f})", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


if __name__ == "__main__":
    main()
