"""vemkit's 3D k = 1 element side by side with scikit-fem P1 tetrahedra on the same meshes (issue 22 (d)).

    .venv/bin/python benchmarks/peers3d.py [--quick] [--sizes 8 16 32 48 70]

On tetrahedra the 3D k = 1 VEM is exactly P1 (SPEC §10): both codes solve the same discrete problem,
linear elasticity of the unit cube (E = 1000, nu = 0.3), the bottom face clamped, the traction
(0, 0, -1) on the top face, on the Kuhn tetrahedra of an n^3 grid (`family: tet, kind: structured`,
6 n^3 cells) that `vemkit mesh --scene` wrote. vemkit: `vemkit solve` (linear solver auto: direct up
to its threshold, AMG-CG with the six rigid modes above, tol 1e-12); scikit-fem: spsolve up to
SKFEM_DIRECT_MAX_DOFS_3D, pyamg smoothed aggregation + CG (rtol 1e-12) with the six rigid modes above
(benchmarks/peers/skfem3d_solve.py). Each solve is its own process (wall time and peak RSS by
wait4). Writes benchmarks/out/peers3d.{json,md}.
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
from peers import PEERS, VEMKIT, measured, relative_difference

from _common import MACHINE, write_report

E, NU = 1000.0, 0.3
LAM, MU = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
TRACTION = [0.0, 0.0, -1.0]
#: spsolve up to here, AMG-CG above: in 3D the direct solver's fill grows fast (vemkit's own "auto"
#: switches at 20 000 unknowns, vemkit.solvers.linear.DIRECT_LIMIT; SuperLU at 1e5 3D DOFs takes minutes)
SKFEM_DIRECT_MAX_DOFS_3D = 20_000


def scene(mesh_entry: dict) -> dict:
    return {
        "name": "cube",
        "model": "3d",
        "domain": {"box": [[0, 0, 0], [1, 1, 1]]},
        "material": {"E": E, "nu": NU},
        "boundary": {"dirichlet": ["bottom"], "neumann": {"top": {"traction": TRACTION}}},
        "discretization": {"mesh": mesh_entry},
        "solver": {"tol": 1e-12},
    }


def run_case(n: int, work: Path) -> list[dict]:
    mesh_scene, mesh_path = work / f"mesh-{n}.yaml", work / f"mesh-{n}.nc"
    mesh_scene.write_text(yaml.safe_dump(scene({"family": "tet", "kind": "structured", "n": n})))
    measured([str(VEMKIT), "mesh", "--scene", str(mesh_scene), "-o", str(mesh_path), "-q"])
    solve_scene, out = work / f"solve-{n}.yaml", work / f"solve-{n}.nc"
    solve_scene.write_text(yaml.safe_dump(scene({"file": mesh_path.name})))
    vem = measured([str(VEMKIT), "solve", str(solve_scene), "-o", str(out), "-q", "--max-dofs", "20000000"])
    with xr.open_dataset(out) as ds:
        u_vem = np.stack([ds[f"u{c}"].values for c in (1, 2, 3)], axis=1)
        vertices = np.stack([ds[f"mesh3d_node_{a}"].values for a in "xyz"], axis=1)
        vem.update(
            assembly_s=float(ds.attrs["assembly_time"]),
            solve_s=float(ds.attrs["wall_time"]),
            solver="ssn, linear solver auto",
        )
        faces = ds["mesh3d_face_nodes"].values.astype(np.int64)  # no fill in a tetrahedral mesh
        volumes = ds["mesh3d_volume_faces"].values.astype(np.int64)
    tets = _tetrahedra(faces, volumes)
    dofs = 3 * vertices.shape[0]
    params = {
        "lam": LAM,
        "mu": MU,
        "traction": TRACTION,
        "cg_rtol": 1e-12,
        "solver": "direct" if dofs <= SKFEM_DIRECT_MAX_DOFS_3D else "amg",
    }
    case, result = work / f"case-{n}.npz", work / f"skfem-{n}.npz"
    np.savez(case, vertices=vertices, tetrahedra=tets, params=json.dumps(params))
    peer = measured([sys.executable, str(PEERS / "skfem3d_solve.py"), str(case), str(result)])
    with np.load(result) as r:
        info, u_peer = json.loads(str(r["info"])), r["u"]
    peer.update(assembly_s=info["setup_s"], solve_s=info["solve_s"], solver=info["solver"])
    base = {"n": n, "cells": int(tets.shape[0]), "dofs": dofs}
    return [
        base | {"code": "vemkit"} | vem,
        base
        | {
            "code": "skfem",
            "rel_diff_to_vemkit": relative_difference(u_peer, u_vem),
            "vemkit_over_peer_wall": vem["wall_s"] / peer["wall_s"],
        }
        | peer,
    ]


def _tetrahedra(faces: np.ndarray, volumes: np.ndarray) -> np.ndarray:
    """(M, 4) the vertices of every tetrahedral cell of a mesh3d file (four triangular faces)."""
    signed = volumes[:, :4]
    face = np.where(signed >= 0, signed, -signed - 1)
    corners = faces[face][:, :, :3].reshape(len(volumes), -1)
    tets = np.array([np.unique(row) for row in corners])
    assert tets.shape[1] == 4, "not a tetrahedral mesh"
    return tets.astype(np.int64)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="n = 4, 8 (a smoke test)")
    parser.add_argument("--sizes", type=int, nargs="+", default=[8, 16, 32, 48, 70])
    args = parser.parse_args()
    work = Path(tempfile.mkdtemp(prefix="vemkit-peers3d-"))
    run_case(3, work)  # Numba's on-disk cache compiled before anything is timed
    rows = []
    for n in [4, 8] if args.quick else args.sizes:
        rows += run_case(n, work)
        print(
            rows[-2]["dofs"],
            [f"{r['code']} {r['wall_s']:.2f} s" for r in rows[-2:]],
            f"diff {rows[-1]['rel_diff_to_vemkit']:.1e}",
            flush=True,
        )
    shutil.rmtree(work)
    load = os.getloadavg()[0]
    lines = [
        "# vemkit 3D k = 1 against scikit-fem P1 tetrahedra (benchmarks/peers3d.py)",
        "",
        f"Machine: {MACHINE}, {os.cpu_count()} cores, load average {load:.1f} at the end.",
        "",
        "| n | cells | DOFs | code | solver | rel. diff. | wall s | max RSS MiB | assembly s | solve s "
        "| vemkit/peer wall |",
        "|" + "---|" * 11,
    ]
    for r in rows:
        diff = f"{r['rel_diff_to_vemkit']:.1e}" if "rel_diff_to_vemkit" in r else "–"
        ratio = f"{r['vemkit_over_peer_wall']:.2f}" if "vemkit_over_peer_wall" in r else "–"
        lines.append(
            f"| {r['n']} | {r['cells']:,} | {r['dofs']:,} | {r['code']} | {r['solver']} | {diff} | "
            f"{r['wall_s']:.2f} | {r['max_rss_mib']:.0f} | {r['assembly_s']:.2f} | {r['solve_s']:.2f} "
            f"| {ratio} |"
        )
    write_report("peers3d", {"machine": MACHINE, "load_average": load, "rows": rows}, lines)


if __name__ == "__main__":
    main()
