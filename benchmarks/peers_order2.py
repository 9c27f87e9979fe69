"""vemkit k = 2 against P2 (scikit-fem, GetFEM) at equal error, and k = 1 against P1 (issue 22 (a)).

    .venv/bin/python benchmarks/peers_order2.py [--quick] [--k2-sizes 16 32 64 128 256] [--k1-sizes ...]
        [--square-sizes 32 64 128 256] [--peers skfem getfem]

On triangles the k = 2 virtual element space is not P2 (it also has a cell moment per cell), so
the codes are compared at equal error on the manufactured problem of benchmarks/peers/exact_elasticity.py
(a smooth exact solution, Dirichlet data on two sides, tractions on the others, the body force).
Every code solves on the structured triangle mesh `vemkit mesh triangle N` wrote, each in its own
process (wait4: wall, CPU, peak RSS):
  vemkit  `vemkit solve` (order 1 or 2, no `exact:` block: the timed process only solves); its
          errors afterwards, outside that process, from the solution file: Pi u_h (3.8) of the
          file's degrees of freedom (vemkit.studies.solution_order.projected_solution_file) against
          u_exact with vemkit.vem.norms.exact_errors: the H1 error of a VEM solution is that of its
          projection Pi u_h (k = 1 on triangles: u_h itself);
          `vemkit k = 2 (squares)` (--square-sizes): the same k = 2 solve on `vemkit mesh square N`, the
          family a careful vemkit user picks at k = 2 (about the triangles' error with 2/3 of their DOFs
          at the same N); the peers stay on triangles (P2 is a triangle element);
  peers   scikit-fem (benchmarks/peers/skfem_manufactured.py) and GetFEM (getfem_manufactured.py):
          P1 or P2, their errors of u_h itself computed after the solve inside their process, timed
          apart and subtracted from the process time (`process s` below: neither side pays for it).
All errors use one rule of degree ERROR_ORDER on each triangle (a square: its two triangles). Writes benchmarks/out/peers_order2.{json,md,png}.
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
import yaml
from peers import PEERS, SKFEM_DIRECT_MAX_DOFS, VEMKIT, getfem_missing, measured, mesh_case, peer_process, write_mesh

from _common import MACHINE, OUT, write_report

sys.path.append(str(PEERS))  # benchmarks/peers: the problem's one home
from exact_elasticity import manufactured_problem  # noqa: E402

ERROR_ORDER = 8  # every error integral: a degree-8 rule on every triangle (the integrands are smooth)
LABELS = {("vemkit", 1): "vemkit k = 1", ("vemkit", 2): "vemkit k = 2", ("skfem", 1): "scikit-fem P1"}
LABELS |= {("skfem", 2): "scikit-fem P2", ("getfem", 1): "GetFEM P1", ("getfem", 2): "GetFEM P2"}
LABELS |= {("vemkit_square", 2): "vemkit k = 2 (squares)"}
VEMKIT_CODES = ("vemkit", "vemkit_square")  # vemkit on triangles, on squares


def vemkit_scene(problem: dict, mesh_path: Path, order: int) -> dict:
    """The manufactured problem as a vemkit scene (expressions as in docs/reference/files.md), on the mesh file."""
    dirichlet = {side: list(problem["displacement"]) for side in problem["dirichlet"]}
    neumann = {side: {"traction": list(t)} for side, t in problem["traction"].items()}
    return {
        "name": "manufactured",
        "domain": "unit_square",
        "material": {"E": 2000.0, "nu": 0.4},
        "body_force": list(problem["body_force"]),
        "boundary": {"dirichlet": dirichlet, "neumann": neumann},
        "discretization": {"mesh": {"file": str(mesh_path)}, "order": order},
        "solver": {"method": "ssn", "tol": 1e-12},
    }


def triangle_rule(mesh, order: int = ERROR_ORDER):
    """(points, weights, cells) of a degree-``order`` rule on every triangle of a vemkit mesh; a
    convex polygon (a square) is split into the fan of triangles from its first vertex."""
    from skfem.quadrature import get_quadrature
    from skfem.refdom import RefTri

    reference, weights = get_quadrature(RefTri, order)  # (2, q) on (0,0), (1,0), (0,1); sum 1/2
    sizes, parts = mesh.cell_sizes, []
    for size in np.unique(sizes):
        own = np.flatnonzero(sizes == size)
        corners = mesh.vertices[mesh.cell_vertices[mesh.cell_offsets[own][:, None] + np.arange(size)]]
        for j in range(1, size - 1):  # the fan triangle (0, j, j + 1)
            a, b, c = corners[:, 0], corners[:, j] - corners[:, 0], corners[:, j + 1] - corners[:, 0]
            points = a[:, None] + reference[0][None, :, None] * b[:, None] + reference[1][None, :, None] * c[:, None]
            jacobian = np.abs(b[:, 0] * c[:, 1] - b[:, 1] * c[:, 0])
            parts.append(
                (points.reshape(-1, 2), (jacobian[:, None] * weights[None]).ravel(), np.repeat(own, len(weights)))
            )
    return tuple(np.concatenate(part) for part in zip(*parts))


def vemkit_errors(solution_path: Path, problem: dict) -> dict:
    """Absolute L2 and H1-seminorm errors of Pi u_h (the file's projection) against u_exact."""
    from vemkit import read_solution
    from vemkit.config.expressions import compile_expression, vector_field
    from vemkit.studies.solution_order import projected_solution_file
    from vemkit.vem.norms import exact_errors

    mesh, ds = read_solution(solution_path)
    projection = projected_solution_file(mesh, ds)
    field = vector_field([compile_expression(e) for e in problem["displacement"]])
    errors = exact_errors(mesh, projection, field, field.gradient, triangle_rule(mesh))
    return {"error_l2": errors["l2"], "error_h1_semi": errors["h1_semi"]}


def run_vemkit(order: int, mesh_path: Path, problem: dict, work: Path) -> dict:
    scene_path, out = work / f"vemkit-k{order}.yaml", work / f"vemkit-k{order}.nc"
    scene_path.write_text(yaml.safe_dump(vemkit_scene(problem, mesh_path, order)))
    record = measured([str(VEMKIT), "solve", str(scene_path), "-o", str(out), "-q"])
    start, cpu = time.perf_counter(), time.process_time()
    record |= vemkit_errors(out, problem)
    record |= {"error_s": time.perf_counter() - start, "error_cpu_s": time.process_time() - cpu}
    with xr_open(out) as ds:
        record |= {
            "dofs": int(ds.attrs.get("n_space_dofs", ds.attrs["n_dofs"])),  # k = 1: the same
            "unknowns": int(ds.attrs["n_dofs"]),
            "assembly_s": float(ds.attrs["assembly_time"]),
            "solve_s": float(ds.attrs["wall_time"]),
            "solver": f"ssn, {int(ds.attrs['linear_iterations'])} linear its.",
        }
    out.unlink()
    # the error came after the process: its whole time is the solve's
    return record | {"process_s": record["wall_s"], "process_cpu_s": record["cpu_s"]}


def xr_open(path: Path):
    import xarray as xr

    return xr.open_dataset(path)


def run_peer(peer: str, order: int, case: dict, problem: dict, work: Path) -> dict:
    dofs = 2 * (len(case["vertices"]) + (order - 1) * n_edges(case))
    params = problem | {
        "degree": order,
        "solver": "direct" if dofs <= SKFEM_DIRECT_MAX_DOFS else "amg",
        "cg_rtol": 1e-12,
        "lsolver": "auto",
        "max_res": 1e-9,
        "error_order": ERROR_ORDER,
    }
    record, result = peer_process(peer, f"{peer}_manufactured.py", params, case, work / f"{peer}-p{order}")
    info = json.loads(str(result["info"]))
    return record | {
        "dofs": info["n_dofs"],
        "unknowns": info["n_dofs"],
        "assembly_s": info["setup_s"],
        "solve_s": info["solve_s"],
        "solver": info.get("lsolver") or ("spsolve" if info["solver"] == "direct" else "AMG-CG"),
        "error_l2": info["error_l2"],
        "error_h1_semi": info["error_h1_semi"],
        "error_s": info["error_s"],
        "error_cpu_s": info["error_cpu_s"],
        "process_s": record["wall_s"] - info["error_s"],
        "process_cpu_s": record["cpu_s"] - info["error_cpu_s"],
    }


def n_edges(case: dict) -> int:
    t = case["triangles"]
    edges = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    return len(np.unique(edges, axis=0))


def run_size(n: int, orders, peers, problem: dict, work: Path, getfem_max_dofs: float = np.inf) -> list[dict]:
    """One structured mesh: vemkit and every peer at each order (k = 1 with P1, k = 2 with P2);
    GetFEM only up to ``getfem_max_dofs`` DOFs of its space."""
    mesh_path = work / f"mesh-{n}.nc"
    write_mesh("structured", n, mesh_path)
    case = mesh_case(mesh_path)
    rows = []
    for order in orders:
        fem_dofs = 2 * (len(case["vertices"]) + (order - 1) * n_edges(case))
        chosen = [p for p in peers if p != "getfem" or fem_dofs <= getfem_max_dofs]
        rows.append({"n": n, "order": order, "code": "vemkit"} | run_vemkit(order, mesh_path, problem, work))
        for peer in chosen:
            rows.append({"n": n, "order": order, "code": peer} | run_peer(peer, order, case, problem, work))
        for row in rows[-1 - len(chosen) :]:
            print(
                f"n = {n}: {LABELS[row['code'], order]}: {row['dofs']} DOFs, |e|_1 = {row['error_h1_semi']:.3e}, "
                f"process {row['process_s']:.2f} s",
                flush=True,
            )
    return rows


def run_squares(n: int, problem: dict, work: Path) -> dict:
    """vemkit k = 2 on the n x n squares of `vemkit mesh square n` (the peers stay on triangles)."""
    mesh_path = work / f"squares-{n}.nc"
    subprocess.run([str(VEMKIT), "mesh", "square", str(n), "-o", str(mesh_path), "-q"], check=True)
    row = {"n": n, "order": 2, "code": "vemkit_square"} | run_vemkit(2, mesh_path, problem, work)
    print(
        f"n = {n}: {LABELS['vemkit_square', 2]}: {row['dofs']} DOFs, |e|_1 = {row['error_h1_semi']:.3e}, "
        f"process {row['process_s']:.2f} s",
        flush=True,
    )
    return row


def curve(rows, code, order, x="process_s", y="error_h1_semi"):
    own = sorted((r for r in rows if r["code"] == code and r["order"] == order), key=lambda r: r["dofs"])
    return np.array([r[x] for r in own], float), np.array([r[y] for r in own], float)


def time_at_error(rows, code, order, error, y="error_h1_semi") -> float | None:
    """The process time at ``error``, interpolated linearly on the log-log curve (None outside it)."""
    times, errors = curve(rows, code, order, y=y)
    if len(errors) < 2 or not errors.min() <= error <= errors.max():
        return None
    ordered = np.argsort(errors)
    return float(np.exp(np.interp(np.log(error), np.log(errors[ordered]), np.log(times[ordered]))))


def equal_error_lines(rows, peers, y="error_h1_semi", min_dofs=10**5) -> list[str]:
    """At the error of every vemkit k = 2 run (triangles or squares) of at least ``min_dofs`` DOFs:
    each code's time there and every P2 peer's time over each vemkit k = 2 family's."""
    families = [c for c in VEMKIT_CODES if any(r["code"] == c for r in rows)]
    codes = [(c, 2) for c in families] + [(p, 2) for p in peers] + [("vemkit", 1)] + [(p, 1) for p in peers]
    pairs = [(p, c) for p in peers for c in families]
    anchors = [r for r in rows if r["code"] in families and r["order"] == 2 and r["dofs"] >= min_dofs]
    lines = []
    for r in sorted(anchors, key=lambda r: -r[y]):
        times = {c: time_at_error(rows, *c, r[y], y) for c in codes} | {(r["code"], 2): r["process_s"]}
        cells = [f"{times[c]:.2f}" if times[c] else "–" for c in codes]
        ratios = [f"{times[p, 2] / times[c, 2]:.2f}×" if times[p, 2] and times[c, 2] else "–" for p, c in pairs]
        lines.append(
            f"| {r[y]:.3e} | {LABELS[r['code'], 2]}, {r['dofs']:,} DOFs | " + " | ".join(cells + ratios) + " |"
        )
    head = " | ".join([LABELS[c] + " s" for c in codes] + [f"{LABELS[p, 2]} / {LABELS[c, 2]}" for p, c in pairs])
    return [f"| {y} | at the run | {head} |", "|" + "---|" * (2 + len(codes) + len(pairs))] + lines


def table_lines(rows: list[dict]) -> list[str]:
    lines = [
        "| n | code | DOFs | unknowns | solver | ‖e‖_L2 | \\|e\\|_H1 | process s (CPU s) | wall s | RSS MiB "
        "| assembly s | solve s | error s (apart) |",
        "|" + "---|" * 13,
    ]
    for r in sorted(rows, key=lambda r: (r["order"], r["n"], r["code"])):
        lines.append(
            f"| {r['n']} | {LABELS[r['code'], r['order']]} | {r['dofs']:,} | {r['unknowns']:,} | {r['solver']} | "
            f"{r['error_l2']:.3e} | {r['error_h1_semi']:.3e} | {r['process_s']:.2f} ({r['process_cpu_s']:.2f}) | "
            f"{r['wall_s']:.2f} | {r['max_rss_mib']:.0f} | {r['assembly_s']:.2f} | {r['solve_s']:.2f} | "
            f"{r['error_s']:.2f} |"
        )
    return lines


def figure(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(14, 4.3))
    panels = (("process_s", "error_h1_semi", "process time (s)"), ("dofs", "error_h1_semi", "DOFs"))
    panels += (("process_s", "error_l2", "process time (s)"),)
    for ax, (x, y, xlabel) in zip(axes, panels):
        for (code, order), label in LABELS.items():
            xs, ys = curve(rows, code, order, x, y)
            if len(xs):
                style = {"vemkit": "o-", "vemkit_square": "D-", "skfem": "s--", "getfem": "^:"}[code]
                color = {"vemkit": f"C{order - 1}", "vemkit_square": "C4"}.get(code)
                ax.loglog(xs, ys, style, color=color, label=label)
        ax.set_xlabel(xlabel)
        ax.set_ylabel({"error_h1_semi": "|u - u_h|_H1 (vemkit: Pi u_h)", "error_l2": "||u - u_h||_L2"}[y])
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.suptitle(
        f"manufactured elasticity, structured triangles, 2 shared cores (load {os.getloadavg()[0]:.1f})", fontsize=9
    )
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="n = 8, 16 only (a smoke test)")
    parser.add_argument("--k2-sizes", type=int, nargs="*", default=[16, 32, 64, 128, 256])
    parser.add_argument("--k1-sizes", type=int, nargs="*", default=[16, 32, 64, 128, 256, 512])
    parser.add_argument(
        "--square-sizes", type=int, nargs="*", default=[32, 64, 128, 256], help="vemkit k = 2 on squares"
    )
    parser.add_argument("--peers", nargs="*", default=["skfem", "getfem"], help="of skfem, getfem")
    parser.add_argument("--getfem-max-dofs", type=float, default=np.inf, help="no GetFEM solve above this")
    parser.add_argument("--keep", type=Path, help="keep the meshes and cases in this folder")
    parser.add_argument("--resume", action="store_true", help="keep the runs of benchmarks/out/peers_order2.json")
    args = parser.parse_args()
    k2, k1, squares = ([8, 16], [8, 16], [8, 16]) if args.quick else (args.k2_sizes, args.k1_sizes, args.square_sizes)
    getfem_reason = getfem_missing() if "getfem" in args.peers else "not asked for (--peers)"
    peers = [p for p in args.peers if p == "skfem" or not getfem_reason]
    problem = manufactured_problem()
    work = Path(args.keep or tempfile.mkdtemp(prefix="vemkit-peers-order2-"))
    work.mkdir(parents=True, exist_ok=True)
    warm_up(problem, work)
    rows = json.loads((OUT / "peers_order2.json").read_text())["rows"] if args.resume else []
    done = {(r["n"], r["order"]) for r in rows if r["code"] != "vemkit_square"}
    for n in sorted(set(k1) | set(k2) | set(squares)):
        orders = [o for o, sizes in ((1, k1), (2, k2)) if n in sizes and (n, o) not in done]
        rows += run_size(n, orders, peers, problem, work, args.getfem_max_dofs) if orders else []
        if n in squares and not any(r["code"] == "vemkit_square" and r["n"] == n for r in rows):
            rows.append(run_squares(n, problem, work))
        report(rows, peers, getfem_reason, quiet=True)  # after every size: a stopped run keeps its rows
    if not args.keep:
        shutil.rmtree(work)
    report(rows, peers, getfem_reason)


def warm_up(problem: dict, work: Path) -> None:
    """Numba's on-disk cache compiled (k = 1 and 2) before anything is timed."""
    write_mesh("structured", 4, work / "warm.nc")
    for order in (1, 2):
        scene = warm_scene(problem, work, order)
        subprocess.run([str(VEMKIT), "solve", str(scene), "-o", str(work / "w.nc"), "-q"], check=True)


def warm_scene(problem: dict, work: Path, order: int) -> Path:
    path = work / f"warm-k{order}.yaml"
    path.write_text(yaml.safe_dump(vemkit_scene(problem, work / "warm.nc", order)))
    return path


def report(rows: list[dict], peers, getfem_reason: str | None, quiet: bool = False) -> None:
    load = os.getloadavg()
    lines = [
        "# vemkit k = 2 against P2 at equal error, k = 1 against P1 (benchmarks/peers_order2.py)",
        "",
        f"Machine: {MACHINE}, {os.cpu_count()} cores shared with other jobs, load average "
        f"{load[0]:.1f} / {load[1]:.1f} / {load[2]:.1f} at the end (timings taken under this load).",
        "GetFEM: " + (getfem_reason or "python3-getfem under /usr/bin/python3, MUMPS."),
        "",
        "Errors are absolute, against the exact solution, under a degree-8 rule per triangle; vemkit's are "
        "those of its projection Pi u_h. `process s`: the whole process (wait4), less the peers' error "
        "evaluation (timed apart in their process; vemkit's runs after its process). DOFs: all degrees "
        "of freedom of the space (vemkit k = 2: vertices, edges and cells); unknowns: vemkit's solved "
        "system (cell moments condensed). `vemkit k = 2 (squares)`: vemkit on the n x n squares (the same "
        "manufactured problem); every peer is on the structured triangles.",
        "",
        "## Time at equal H1 error (log-log interpolation; – outside a code's range)",
        "",
        *equal_error_lines(rows, peers),
        "",
        "## Time at equal L2 error",
        "",
        *equal_error_lines(rows, peers, y="error_l2"),
        "",
        "## Every run",
        "",
        *table_lines(rows),
    ]
    record = {"machine": MACHINE, "load_average": load, "getfem": getfem_reason or "installed", "rows": rows}
    if quiet:
        OUT.mkdir(parents=True, exist_ok=True)
        (OUT / "peers_order2.json").write_text(json.dumps(record, indent=2))
        (OUT / "peers_order2.md").write_text("\n".join(lines) + "\n")
    else:
        write_report("peers_order2", record, lines)
        figure(rows, OUT / "peers_order2.png")


if __name__ == "__main__":
    main()
