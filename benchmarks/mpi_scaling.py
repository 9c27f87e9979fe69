"""One 3D contact solve on 1 and 2 MPI ranks (issue 37 item 4). Writes benchmarks/out/mpi_scaling.{json,md}.

    .venv/bin/python benchmarks/mpi_scaling.py [--quick] [--sizes 24 40 64 86] [--ranks 1 2] [--largest N]

The scene is config/scenes/3d/sheared_box.yaml (hexahedra, n cells per unit length: n = 64 is 418 275
DOFs, n = 86 is 999 108), ssn, ``solver.linear: petsc`` (CG + GAMG). One rank is ``vemkit solve`` in
one process; N ranks are ``mpiexec -n N vemkit solve``, the problem split across them (each rank
its own cells and rows). Every case is one whole job: its wall time; every rank its own peak
resident memory (each writes it at the end); from the solution file, the Newton steps, the CG
iterations (all of them, and per Newton step: the GAMG-preconditioned Krylov solves), the solver's
and the assembly's wall time, the independent check. ``--largest N`` also runs n = N on the most
ranks given: the largest problem tried in this machine's memory. The report ends with the memory
per DOF the largest runs measured and the problem that 24 GiB would hold at that rate.
"""

from __future__ import annotations

import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _common import MACHINE, quick_parser, write_report

SCENE = Path(__file__).resolve().parents[1] / "config" / "scenes" / "3d" / "sheared_box.yaml"
MACHINE_GIB = 24.0


def run_case(n: int, output: str, memory_file: str) -> None:
    """(every rank) ``vemkit solve`` in this process; its own peak memory to ``memory_file``.RANK."""
    from vemkit.cli import main
    from vemkit.vem.parallel import launched

    args = ["solve", str(SCENE), "-o", output, "-q", "--max-dofs", "200000000"]
    args += ["--set", f"discretization.mesh.n={n}", "--set", "solver.linear=petsc"]
    status = main(args)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20  # KiB -> GiB
    Path(f"{memory_file}.{launched().rank}").write_text(json.dumps({"status": status, "peak_gib": peak}))


def job(n: int, ranks: int, folder: Path) -> dict:
    """One solve of size n on ``ranks`` ranks: wall time, every rank's peak, the file's counts."""
    import netCDF4

    output, memory = folder / f"n{n}_r{ranks}.nc", folder / f"memory_n{n}_r{ranks}"
    command = [sys.executable, __file__, "--case", str(n), str(output), str(memory)]
    if ranks > 1:
        command = [shutil.which("mpiexec") or "mpiexec", "-n", str(ranks), *command]
    start = time.perf_counter()
    run = subprocess.run(command, capture_output=True, text=True)
    row = {"n": n, "ranks": ranks, "wall_s": time.perf_counter() - start, "exit": run.returncode}
    if run.returncode != 0 or not output.exists():
        row["stderr"] = run.stderr.strip()[-500:]
        return row
    peaks = [json.loads(Path(f"{memory}.{r}").read_text())["peak_gib"] for r in range(ranks)]
    row["peak_gib_per_rank"] = [round(p, 3) for p in peaks]
    with netCDF4.Dataset(output) as ds:
        for key in ("n_dofs", "iterations", "linear_iterations", "wall_time", "assembly_time", "check_worst"):
            row[key] = ds.getncattr(key).item()
        steps = ds["history_linear_iterations"][:].tolist()
    row["cg_per_newton_step"] = round(sum(steps) / max(len(steps), 1), 1)
    row["cg_per_step_max"] = int(max(steps, default=0))
    output.unlink()
    print(row, flush=True)
    return row


def table(rows: list) -> list:
    lines = [
        "| n | DOFs | ranks | wall s | solver s | assembly s | peak GiB per rank | Newton | CG its | CG per step (max) "
        "| speed-up |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    one_rank = {r["n"]: r["wall_s"] for r in rows if r["ranks"] == 1 and "n_dofs" in r}
    for r in rows:
        if "n_dofs" not in r:
            lines.append(f"| {r['n']} | | {r['ranks']} | failed (exit {r['exit']}): {r.get('stderr', '')} |")
            continue
        peaks = " / ".join(f"{p:.2f}" for p in r["peak_gib_per_rank"])
        speedup = f"{one_rank[r['n']] / r['wall_s']:.2f}" if r["n"] in one_rank else ""
        lines.append(
            f"| {r['n']} | {r['n_dofs']:,} | {r['ranks']} | {r['wall_s']:.1f} | {r['wall_time']:.1f} "
            f"| {r['assembly_time']:.1f} | {peaks} | {r['iterations']} | {r['linear_iterations']} "
            f"| {r['cg_per_newton_step']} ({r['cg_per_step_max']}) | {speedup} |"
        )
    return lines


def memory_model(rows: list) -> list:
    """Bytes per DOF between the two largest runs of the most ranks, and what 24 GiB holds."""
    done = [r for r in rows if "n_dofs" in r]
    if not done:
        return []
    ranks = max(r["ranks"] for r in done)
    runs = sorted((r for r in done if r["ranks"] == ranks), key=lambda r: r["n_dofs"])
    if len(runs) < 2:
        return []
    small, large = runs[-2], runs[-1]
    total = [sum(r["peak_gib_per_rank"]) for r in (small, large)]
    per_dof = (total[1] - total[0]) * 2**30 / (large["n_dofs"] - small["n_dofs"])
    fits = large["n_dofs"] + (MACHINE_GIB * 0.9 - total[1]) * 2**30 / per_dof
    return [
        "",
        f"Memory on {ranks} ranks grows by {per_dof:,.0f} bytes per DOF (all ranks together, between "
        f"{small['n_dofs']:,} and {large['n_dofs']:,} DOFs); at that rate 90 % of {MACHINE_GIB:.0f} GiB holds "
        f"about {fits:,.0f} DOFs.",
    ]


def main() -> None:
    if len(sys.argv) == 5 and sys.argv[1] == "--case":
        run_case(int(sys.argv[2]), sys.argv[3], sys.argv[4])
        return
    parser = quick_parser(__doc__, "n = 8, 12")
    parser.add_argument("--sizes", type=int, nargs="+", default=[24, 40, 64, 86])
    parser.add_argument("--ranks", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--largest", type=int, default=None, help="also n = LARGEST on the most ranks")
    args = parser.parse_args()
    sizes = [8, 12] if args.quick else args.sizes
    with tempfile.TemporaryDirectory() as tmp:
        job(4, max(args.ranks), Path(tmp))  # the Numba caches warm
        rows = [job(n, ranks, Path(tmp)) for n in sizes for ranks in args.ranks]
        if args.largest:
            rows.append(job(args.largest, max(args.ranks), Path(tmp)))
    lines = [
        "# One 3D contact solve on several MPI ranks (benchmarks/mpi_scaling.py)",
        "",
        f"Machine: {MACHINE}, {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} at the end "
        "(shared: wall times carry the other jobs' load).",
        "Scene config/scenes/3d/sheared_box.yaml, ssn tol 1e-10, solver.linear petsc (CG + GAMG); one rank is "
        "one process, N ranks mpiexec -n N. wall: the whole job; solver, assembly: inside it (rank 0). "
        "CG its: the Krylov iterations of all the GAMG-preconditioned solves.",
        "",
        *table(rows),
        *memory_model(rows),
    ]
    write_report("mpi_scaling", {"machine": MACHINE, "quick": args.quick, "rows": rows}, lines)


if __name__ == "__main__":
    main()
