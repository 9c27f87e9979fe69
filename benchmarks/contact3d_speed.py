"""Where the serial 3D contact solve spends its time (issue 37 item 5). Writes benchmarks/out/contact3d_speed.{json,md}.

    .venv/bin/python benchmarks/contact3d_speed.py [--quick] [--sizes 24 40 64 86]

The scene is config/scenes/3d/sheared_box.yaml with ssn (hexahedra, n cells per unit length: n = 64 is
418 275 DOFs, n = 86 is 999 108). Every case is one whole ``vemkit solve`` process, measured by wait4
(wall and CPU time, peak resident memory); inside it, timers around the phases: mesh and assembly,
the AMG set-up of K, the Newton steps' hierarchy (its set-up once, its update for K + D at every
step), the V-cycles, the rest of the solver (Krylov products, Newton and line search), the independent
check, and what is left (start-up, solution fields, the netCDF file). Target: at about 10^6 DOFs
<= 30 s wall and <= 3 GiB.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _common import MACHINE, quick_parser, targets_line, write_report

SCENE = Path(__file__).resolve().parents[1] / "config" / "scenes" / "3d" / "sheared_box.yaml"
TARGET_WALL_S, TARGET_PEAK_GIB = 30.0, 3.0
PHASES = ["assembly", "amg_setup", "newton_hierarchy", "hierarchy_updates", "v_cycles", "solver_rest", "check", "rest"]


def _timed(timers: dict, key: str, function, outermost: list | None = None):
    """``function`` adding its wall time to timers[key] (only the outermost call of a recursion)."""

    def wrapper(*args, **kwargs):
        if outermost is not None and outermost[0]:
            return function(*args, **kwargs)
        if outermost is not None:
            outermost[0] = True
        start = time.perf_counter()
        try:
            return function(*args, **kwargs)
        finally:
            timers[key] = timers.get(key, 0.0) + time.perf_counter() - start
            if outermost is not None:
                outermost[0] = False

    return wrapper


def run_case(n: int, output: str, timers_file: str) -> None:
    """(the child process) ``vemkit solve`` in this process with timers around its phases."""
    import vemkit.solvers.amg_update as amg_update
    import vemkit.solvers.linear.amg as amg
    import vemkit.solvers.linear.cycle as cycle
    import vemkit.studies.scene_solve as scene_solve
    from vemkit.cli import main

    timers: dict = {}
    scene_solve.scene_problem = _timed(timers, "assembly", scene_solve.scene_problem)
    scene_solve.solve = _timed(timers, "solver", scene_solve.solve)
    scene_solve.verify_solution = _timed(timers, "check", scene_solve.verify_solution)
    amg.smoothed_aggregation = _timed(timers, "amg_setup", amg.smoothed_aggregation)
    updated = amg_update.BoundaryUpdatedHierarchy
    updated.__init__ = _timed(timers, "newton_hierarchy", updated.__init__)
    updated.preconditioner = _timed(timers, "hierarchy_updates", updated.preconditioner)
    inside = [False]
    cycle.v_cycle = amg_update.v_cycle = _timed(timers, "v_cycles", cycle.v_cycle, inside)
    start = time.perf_counter()
    status = main(
        ["solve", str(SCENE), "-o", output, "-q", "--max-dofs", "5000000", "--set", f"discretization.mesh.n={n}"]
    )
    timers["total"] = time.perf_counter() - start
    Path(timers_file).write_text(json.dumps({"status": status, **timers}))


def whole_process(command: list[str]) -> dict:
    """Wall time, CPU time (user + system) and peak RSS of one process (wait4); its exit status."""
    start = time.perf_counter()
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(process.pid, 0)
    return {
        "wall_s": time.perf_counter() - start,
        "cpu_s": usage.ru_utime + usage.ru_stime,
        "peak_gib": usage.ru_maxrss / 2**20,
        "exit": os.waitstatus_to_exitcode(status),
        "stderr": process.stderr.read().decode().strip()[-500:],
    }


def measure(n: int, folder: Path) -> dict:
    import netCDF4

    output, timers_file = folder / f"ssn_{n}.nc", folder / f"timers_{n}.json"
    row = {"n": n, **whole_process([sys.executable, __file__, "--case", str(n), str(output), str(timers_file)])}
    if row["exit"] != 0 or not output.exists():
        return row
    with netCDF4.Dataset(output) as ds:
        for key in ("n_dofs", "iterations", "linear_iterations", "check_worst"):
            row[key] = ds.getncattr(key).item()
    output.unlink()
    timers = json.loads(timers_file.read_text())
    solver_parts = ("amg_setup", "newton_hierarchy", "hierarchy_updates", "v_cycles")
    timers["solver_rest"] = timers.get("solver", 0.0) - sum(timers.get(k, 0.0) for k in solver_parts)
    named = ("assembly", "solver", "check")
    timers["rest"] = row["wall_s"] - sum(timers.get(k, 0.0) for k in named)
    row["split_s"] = {k: round(timers.get(k, 0.0), 2) for k in PHASES}
    print(row, flush=True)
    return row


def report(rows: list, quick: bool) -> None:
    lines = [
        "# 3D frictional contact: where the serial solve's time goes (benchmarks/contact3d_speed.py)",
        "",
        f"Machine: {MACHINE}, {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} at the end "
        "(shared: wall times carry the other jobs' load; CPU s is this process's).",
        "Scene config/scenes/3d/sheared_box.yaml, ssn tol 1e-10, AMG. Seconds of wall time per phase.",
        "",
        "| n | DOFs | Newton | CG its | wall s | CPU s | peak GiB | " + " | ".join(PHASES) + " |",
        "|---|---|---|---|---|---|---|" + "---|" * len(PHASES),
    ]
    for r in rows:
        if "split_s" not in r:
            lines.append(f"| {r['n']} | failed (exit {r['exit']}): {r['stderr']} |")
            continue
        split = " | ".join(f"{r['split_s'][k]:.1f}" for k in PHASES)
        lines.append(
            f"| {r['n']} | {r['n_dofs']:,} | {r['iterations']} | {r['linear_iterations']} | {r['wall_s']:.1f} "
            f"| {r['cpu_s']:.1f} | {r['peak_gib']:.2f} | {split} |"
        )
    largest = max((r for r in rows if "split_s" in r), key=lambda r: r["n_dofs"], default=None)
    targets = {}
    if largest is not None and largest["n_dofs"] >= 9e5:
        targets[f"<= {TARGET_WALL_S:.0f} s at 1e6 DOFs"] = largest["wall_s"] <= TARGET_WALL_S
        targets[f"<= {TARGET_PEAK_GIB:.0f} GiB at 1e6 DOFs"] = largest["peak_gib"] <= TARGET_PEAK_GIB
    lines += ["", targets_line(targets) if targets else "Targets: not measured (no run at 1e6 DOFs)"]
    write_report("contact3d_speed", {"machine": MACHINE, "quick": quick, "rows": rows, "targets": targets}, lines)


def main() -> None:
    if len(sys.argv) == 5 and sys.argv[1] == "--case":
        run_case(int(sys.argv[2]), sys.argv[3], sys.argv[4])
        return
    parser = quick_parser(__doc__, "n = 8, 12, 16")
    parser.add_argument("--sizes", type=int, nargs="+", default=[24, 40, 64, 86])
    args = parser.parse_args()
    sizes = [8, 12, 16] if args.quick else args.sizes
    with tempfile.TemporaryDirectory() as tmp:
        measure(4, Path(tmp))  # the Numba caches warm
        rows = [measure(n, Path(tmp)) for n in sizes]
    report(rows, args.quick)


if __name__ == "__main__":
    main()
