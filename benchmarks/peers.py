"""vemkit k = 1 side by side with scikit-fem and GetFEM P1 on the same triangle meshes (issue 22).

    .venv/bin/python benchmarks/peers.py [--quick] [--sizes 32 128 512 708] [--delaunay-sizes 32 128]

On triangles the k = 1 VEM is exactly P1 (docs/reference/mathematics.md): every peer solves the same discrete problem
on the mesh that `vemkit mesh` wrote (the paper scene's unit square, structured or Delaunay):
  elasticity  the paper scene without contact (right side clamped, the left traction): vemkit,
              scikit-fem (ElementVector(ElementTriP1()), linear_elasticity), GetFEM (FEM_PK(2,1),
              the isotropic linearized elasticity brick), all with lambda* = E nu/(1 - nu^2), mu;
  compliance  the paper scene, frictionless normal compliance p(t) = 10 t_+ on the bottom, 3 Gauss
              points per edge (vemkit `contact_quadrature: gauss`; GetFEM IM_TRIANGLE(5), whose edge
              rule is the 3-point Gauss rule, and kn*pos_part(u.Normal - gap)*(Test_u.Normal));
  friction    the paper scene itself (k_tau = 450, m_tau = 0) with the nodal rule (GetFEM IM_NC(2,1),
              the trapezoid rule on edges, and a nodal friction multiplier; see getfem_solve.py).
Each solve is its own process, measured by wait4 (wall time, peak RSS). GetFEM runs under the
system /usr/bin/python3 (Debian python3-getfem); without it its rows are skipped with the reason.
Writes benchmarks/out/peers.{json,md,png}.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import xarray as xr
import yaml

from _common import MACHINE, OUT, write_report

ROOT = Path(__file__).resolve().parents[1]
PEERS = Path(__file__).resolve().parent / "peers"
VEMKIT = Path(sys.executable).with_name("vemkit")
SYSTEM_PYTHON = "/usr/bin/python3"
E, NU = 2000.0, 0.4
LAM, MU = E * NU / (1 - NU**2), E / (2 * (1 + NU))  # the paper's plane-stress C (docs/reference/mathematics.md)
TRACTION_LEFT = [[1000.0, 0.0, -200.0], [-200.0, 0.0, 0.0]]  # (200 (5 - y), -200) as a + b x + c y
PROBLEMS = ("elasticity", "compliance", "friction")
FRICTION_K = 450.0  # the paper's k_tau (m_tau = 0): every Gamma_C vertex slides
GNU_TIME, RSS_MARK = "/usr/bin/time", "peak_rss_kib="
SKFEM_DIRECT_MAX_DOFS = 200_000  # spsolve up to here, pyamg SA + CG above (scikit-fem's docs)


def measured(command: list[str]) -> dict:
    """Run a command; its wall time, CPU time (user + system, wait4) and peak resident memory.

    Linux carries a process' peak RSS across fork and exec, so wait4 alone would report at least
    this script's own RSS: the peak comes from GNU time (``%M``, the command forked from a small
    process) when /usr/bin/time exists, else from wait4 (then an upper bound).
    """
    wrapped = [GNU_TIME, "-f", f"{RSS_MARK}%M", *command] if Path(GNU_TIME).exists() else command
    load = os.getloadavg()[0]  # the 2 cores are shared: the 1-minute load when the process starts
    start = time.perf_counter()
    process = subprocess.Popen(wrapped, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(process.pid, 0)
    wall = time.perf_counter() - start
    stderr = process.stderr.read().decode()
    process.returncode = os.waitstatus_to_exitcode(status)
    if process.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} failed: {stderr.strip()[-2000:]}")
    marked = [line for line in stderr.splitlines() if line.startswith(RSS_MARK)]
    rss_kib = int(marked[-1][len(RSS_MARK) :]) if marked else usage.ru_maxrss
    cpu = usage.ru_utime + usage.ru_stime
    return {"wall_s": wall, "cpu_s": cpu, "max_rss_mib": rss_kib / 1024.0, "load_1min": load}


def getfem_missing() -> str | None:
    """Why GetFEM cannot run here (None when it can)."""
    if not Path(SYSTEM_PYTHON).exists():
        return f"{SYSTEM_PYTHON} not found"
    probe = subprocess.run([SYSTEM_PYTHON, "-c", "import getfem"], capture_output=True, text=True)
    if probe.returncode != 0:
        return "python3-getfem is not installed for /usr/bin/python3 (make peers installs it as root)"
    return None


def write_mesh(kind: str, n: int, path: Path) -> None:
    run = [str(VEMKIT), "mesh", "triangle", str(n), "-o", str(path), "--option", f"kind={kind}", "-q"]
    if kind == "delaunay":
        run += ["--option", "seed=1"]
    subprocess.run(run, check=True)


def mesh_case(mesh_path: Path) -> dict:
    """Vertices, triangles and the four sides' edges of a vemkit mesh file (UGRID, docs/reference/files.md)."""
    with xr.open_dataset(mesh_path) as ds:
        case = {
            "vertices": np.stack([ds.mesh2d_node_x.values, ds.mesh2d_node_y.values], axis=1),
            "triangles": ds.mesh2d_face_nodes.values.astype(np.int64),
        }
        for side in ("bottom", "right", "top", "left"):
            case[f"side_{side}"] = ds[f"boundary_{side}"].values.astype(np.int64)
    assert case["triangles"].shape[1] == 3 and case["triangles"].min() >= 0
    return case


def peer_params(problem: str, n_dofs: int, friction_k: float = FRICTION_K) -> dict:
    """The discrete problem as the peers state it (see the module docstring)."""
    return {
        "problem": problem,
        "lam": LAM,
        "mu": MU,
        "traction_affine": TRACTION_LEFT,
        "neumann": "left",
        "dirichlet": ["right"],
        "contact": "bottom",
        "gap": 0.1,
        "kn": 10.0,
        "kt": friction_k,
        "r_friction": 100.0,
        "quadrature": "nodal" if problem == "friction" else "gauss",
        "gauss_points": 3,
        "max_res": 1e-9,
        "lsolver": "auto",
        "solver": "direct" if n_dofs <= SKFEM_DIRECT_MAX_DOFS else "amg",
        "cg_rtol": 1e-12,
    }


def case_from_mesh(mesh) -> dict:
    """The same arrays from a vemkit Mesh in memory (a triangle mesh of the unit square)."""
    case = {"vertices": mesh.vertices, "triangles": mesh.cell_vertices.reshape(-1, 3).astype(np.int64)}
    return case | {
        f"side_{side}": np.asarray(mesh.boundary[side], dtype=np.int64) for side in ("bottom", "right", "top", "left")
    }


def vemkit_scene(problem: str, mesh_entry: dict, friction_k: float = FRICTION_K) -> dict:
    """The paper scene on the given `discretization.mesh` entry, as each problem needs it."""
    scene = yaml.safe_load((ROOT / "config" / "scenes" / "paper.yaml").read_text())
    scene["discretization"]["mesh"] = mesh_entry
    scene["contact"]["friction"]["k"] = friction_k
    scene["solver"]["tol"] = 1e-12
    if problem == "elasticity":
        del scene["boundary"]["contact"], scene["contact"]
    elif problem == "compliance":
        scene["contact"]["friction"] = {"k": 0.0, "m": 0.0}
        scene["discretization"].update(contact_quadrature="gauss", contact_gauss_points=3)
    return scene


def run_vemkit(problem: str, mesh_path: Path, work: Path) -> tuple[np.ndarray, dict]:
    scene_path, out = work / f"{problem}.yaml", work / f"{problem}-vemkit.nc"
    scene_path.write_text(yaml.safe_dump(vemkit_scene(problem, {"file": str(mesh_path)})))
    record = measured([str(VEMKIT), "solve", str(scene_path), "-o", str(out)])
    with xr.open_dataset(out) as ds:
        u = np.stack([ds.u1.values, ds.u2.values], axis=1)
        record.update(
            assembly_s=float(ds.attrs["assembly_time"]),
            solve_s=float(ds.attrs["wall_time"]),
            iterations=int(ds.attrs["iterations"]),
            solver="ssn, linear solver auto",
        )
        xy = np.stack([ds.mesh2d_node_x.values, ds.mesh2d_node_y.values], axis=1)
    return u, record | {"node_xy": xy}


def peer_process(peer: str, script: str, params: dict, case: dict, stem: Path):
    """(the process record, the arrays it wrote) of one peer script on the case (``stem``-case.npz in,
    ``stem``.npz out); GetFEM under the system python."""
    case_path, out = stem.with_name(stem.name + "-case.npz"), stem.with_suffix(".npz")
    np.savez(case_path, params=json.dumps(params), **case)
    python = SYSTEM_PYTHON if peer == "getfem" else sys.executable
    record = measured([python, str(PEERS / script), str(case_path), str(out)])
    with np.load(out) as result:
        return record, {key: result[key] for key in result.files}


def run_peer(peer: str, problem: str, case: dict, work: Path, params: dict | None = None):
    """u at the case's vertices and the process record of one peer's solve."""
    params = params or peer_params(problem, 2 * len(case["vertices"]))
    record, result = peer_process(peer, f"{peer}_solve.py", params, case, work / f"{problem}-{peer}")
    info, u = json.loads(str(result["info"])), result["u"]
    record.update(
        assembly_s=info["setup_s"],
        solve_s=info["solve_s"],
        solver=info.get("lsolver") or info.get("solver"),
        iterations=info.get("iterations"),
    )
    return u, record


def relative_difference(u: np.ndarray, reference: np.ndarray) -> float:
    """max over nodes of |u - reference| / max over nodes of |reference| (Euclidean at a node)."""
    return float(np.linalg.norm(u - reference, axis=1).max() / np.linalg.norm(reference, axis=1).max())


def compare_case(kind: str, n: int, problem: str, peers: list[str], work: Path) -> list[dict]:
    """One mesh, one problem: vemkit and each peer, the peers' difference to vemkit."""
    mesh_path = work / f"mesh-{kind}-{n}.nc"
    if not mesh_path.exists():
        write_mesh(kind, n, mesh_path)
    case = mesh_case(mesh_path)
    u_vem, vem = run_vemkit(problem, mesh_path, work)
    assert np.abs(vem.pop("node_xy") - case["vertices"]).max() == 0.0, "vemkit renumbered the vertices"
    base = {"mesh": kind, "n": n, "problem": problem, "dofs": 2 * len(case["vertices"])}
    rows = [base | {"code": "vemkit"} | vem]
    for peer in peers:
        u, record = run_peer(peer, problem, case, work)
        rows.append(base | {"code": peer, "rel_diff_to_vemkit": relative_difference(u, u_vem)} | record)
        rows[-1]["vemkit_over_peer_wall"] = vem["wall_s"] / record["wall_s"]
    return rows


def peers_for(problem: str, dofs: int, getfem_reason: str | None, getfem_contact_max: int) -> list[str]:
    """scikit-fem on elasticity; GetFEM unless missing, or a contact problem above the limit."""
    peers = ["skfem"] if problem == "elasticity" else []
    too_big = problem != "elasticity" and dofs > getfem_contact_max
    return peers + ([] if getfem_reason or too_big else ["getfem"])


def warm_up(work: Path, problems) -> None:
    """Numba's on-disk cache compiled before anything is timed: the direct path (n = 4) and the
    AMG-CG path (the first n above vemkit's DIRECT_LIMIT; in a fresh checkout the first AMG solve
    otherwise pays ~1.7 s of compilation: 1.94 s instead of 0.20 s at 33 282 DOFs)."""
    from vemkit.solvers.linear import DIRECT_LIMIT

    amg_n = next(n for n in range(4, 10**4) if 2 * (n + 1) ** 2 > DIRECT_LIMIT)
    for problem in problems:
        for n in (4, amg_n):
            compare_case("structured", n, problem, [], work)


def table_lines(rows: list[dict], header: list[str]) -> list[str]:
    lines = [
        "| mesh | n | DOFs | problem | code | solver | rel. diff. to vemkit | wall s | max RSS MiB "
        "| assembly s | solve s | vemkit/peer wall | load |",
        "|" + "---|" * 13,
    ]
    for r in rows:
        diff = f"{r['rel_diff_to_vemkit']:.1e}" if "rel_diff_to_vemkit" in r else "–"
        ratio = f"{r['vemkit_over_peer_wall']:.2f}" if "vemkit_over_peer_wall" in r else "–"
        lines.append(
            f"| {r['mesh']} | {r['n']} | {r['dofs']:,} | {r['problem']} | {r['code']} | "
            f"{r['solver']} | {diff} | {r['wall_s']:.2f} | {r['max_rss_mib']:.0f} | "
            f"{r['assembly_s']:.2f} | {r['solve_s']:.2f} | {ratio} | {r.get('load_1min', float('nan')):.1f} |"
        )
    return header + lines


def figure(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    fig, axes = plt.subplots(1, len(PROBLEMS), figsize=(13, 4.2), sharey=True)
    for ax, problem in zip(axes, PROBLEMS):
        for code, color in (("vemkit", "C0"), ("skfem", "C1"), ("getfem", "C2")):
            own = sorted(
                (r for r in rows if r["problem"] == problem and r["code"] == code and r["mesh"] == "structured"),
                key=lambda r: r["dofs"],
            )
            if own:
                dofs = [r["dofs"] for r in own]
                ax.loglog(dofs, [r["wall_s"] for r in own], "o-", color=color, label=f"{code}: process")
                ax.loglog(
                    dofs,
                    [r["assembly_s"] + r["solve_s"] for r in own],
                    "s--",
                    color=color,
                    label=f"{code}: assembly + solve",
                )
        ax.set_title(f"{problem} (structured triangles)")
        ax.set_xlabel("DOFs")
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("time (s)")
    axes[0].legend(fontsize=7)
    fig.suptitle(f"wall time, 2 shared cores (load average {os.getloadavg()[0]:.1f})", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="n = 8, 16 only (a smoke test)")
    parser.add_argument("--sizes", type=int, nargs="+", default=[32, 128, 512, 708])
    parser.add_argument("--delaunay-sizes", type=int, nargs="*", default=[32, 128])
    parser.add_argument("--problems", nargs="+", default=list(PROBLEMS), choices=PROBLEMS)
    parser.add_argument(
        "--getfem-contact-max-dofs",
        type=int,
        default=10**9,
        help="no GetFEM contact solves above this (its Newton refactorizes every step)",
    )
    parser.add_argument("--keep", type=Path, help="keep the meshes and solutions in this folder")
    parser.add_argument("--resume", action="store_true", help="keep the cases of benchmarks/out/peers.json")
    args = parser.parse_args()
    sizes, delaunay = ([8, 16], [8]) if args.quick else (args.sizes, args.delaunay_sizes)
    getfem_reason = getfem_missing()
    work = Path(args.keep or tempfile.mkdtemp(prefix="vemkit-peers-"))
    work.mkdir(parents=True, exist_ok=True)
    warm_up(work, args.problems)
    rows = json.loads((OUT / "peers.json").read_text())["rows"] if args.resume else []
    done = {(r["mesh"], r["n"], r["problem"]) for r in rows}
    for kind, ns in (("structured", sizes), ("delaunay", delaunay)):
        for n in ns:
            for problem in (p for p in args.problems if (kind, n, p) not in done):
                dofs = 2 * (n + 1) ** 2
                chosen = peers_for(problem, dofs, getfem_reason, args.getfem_contact_max_dofs)
                rows += compare_case(kind, n, problem, chosen, work)
                report(rows, getfem_reason, quiet=True)  # after every case: a stopped run keeps its rows
    if not args.keep:
        shutil.rmtree(work)
    report(rows, getfem_reason)


def report(rows: list[dict], getfem_reason: str | None, quiet: bool = False) -> None:
    load = os.getloadavg()
    header = [
        "# vemkit k = 1 against scikit-fem and GetFEM P1 (benchmarks/peers.py)",
        "",
        f"Machine: {MACHINE}, {os.cpu_count()} cores, load average {load[0]:.1f} at the end "
        "(timings taken under this load).",
        "GetFEM: " + (getfem_reason or "python3-getfem under /usr/bin/python3."),
        "",
        "Relative difference: max nodal |u_peer - u_vemkit| / max nodal |u_vemkit|. Wall time and "
        "max RSS: the whole process (wait4). vemkit: assembly_time and the solver's wall_time "
        "attributes; GetFEM: solve s is model.solve (its assembly included), assembly s the mesh "
        "and model set-up.",
        "",
    ]
    OUT.mkdir(parents=True, exist_ok=True)
    record = {"machine": MACHINE, "load_average": load, "getfem": getfem_reason or "installed", "rows": rows}
    lines = table_lines(rows, header)
    if quiet:
        (OUT / "peers.json").write_text(json.dumps(record, indent=2))
        (OUT / "peers.md").write_text("\n".join(lines) + "\n")
        print(lines[-1], flush=True)
    else:
        write_report("peers", record, lines)
        figure(rows, OUT / "peers.png")


if __name__ == "__main__":
    main()
