"""Shared by the benchmark scripts: the machine they ran on, the command line, the output files."""

from __future__ import annotations

import argparse
import json
import platform
import time
from pathlib import Path

OUT = Path(__file__).resolve().parent / "out"  # ignored by git
PAPER_SCENE = Path(__file__).resolve().parents[1] / "config" / "scenes" / "paper.yaml"
MACHINE = f"{platform.machine()}, {platform.python_implementation()} {platform.python_version()}"


def quick_parser(doc: str, quick_help: str, repeat: int | None = None) -> argparse.ArgumentParser:
    """--quick (a smoke test, not the target) and, if given, --repeat (best of how many runs)."""
    parser = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help=f"{quick_help} (a smoke test, not the target)")
    if repeat is not None:
        parser.add_argument("--repeat", type=int, default=repeat)
    return parser


def write_report(name: str, record: dict, lines: list) -> None:
    """benchmarks/out/NAME.json (the record) and NAME.md (the lines), and the lines on stdout."""
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / f"{name}.json").write_text(json.dumps(record, indent=2))
    (OUT / f"{name}.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


def targets_line(targets: dict, prefix: str = "Targets") -> str:
    return f"{prefix}: " + ", ".join(f"{k}: {'met' if v else 'NOT met'}" for k, v in targets.items())


def shared_machine_lines(record: dict) -> list:
    """The closing lines of a report timed in wall and CPU seconds on a shared machine: the load
    average ``record["load_average"]`` and the targets ``record["targets"]`` (judged on wall time)."""
    return [
        "",
        f"Load average at the end (1, 5, 15 min): {record['load_average']}. On a shared machine the wall time "
        "includes waiting for a core; the CPU time is the process's own.",
        "",
        targets_line(record["targets"], "Targets (wall time)"),
    ]


def best_of(fn, repeat: int):
    """(the least wall time of ``repeat`` calls of fn, in seconds; the last call's result)."""
    times, result = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - start)
    return min(times), result


def paper_problem(n: int, family: str = "square"):
    """The paper scene's assembled problem on the n x n mesh of ``family`` (square, or the structured
    triangles), and its record: n, family, DOFs and K's entries."""
    from vemkit.config.scene import load_scene
    from vemkit.contact.problem import scene_problem

    overrides = [f"discretization.mesh.n={n}", f"discretization.mesh.family={family}"]
    if family == "triangle":
        overrides.append("discretization.mesh.kind=structured")
    problem = scene_problem(load_scene(PAPER_SCENE, overrides))
    record = {"n": n, "family": family, "dofs": int(problem.n_dofs), "nnz": int(problem.stiffness.nnz)}
    return problem, record
