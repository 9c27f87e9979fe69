"""Meshing benchmark (issue 11, item 8). Writes benchmarks/out/meshing.{json,md}.

    .venv/bin/python benchmarks/meshing.py [--quick]

A 4 x 2 plate with three circular holes (a domain as in docs/reference/files.md) meshed with about 100 000 cells
(``cells=100000``) in each family, timed after a warm-up on a coarse mesh (Numba compiled,
imports done); best of ``--repeat`` runs, wall and CPU time (the machine may be shared). Also reported, outside the timing: the time of
``validate_mesh``, the cell count, and for the cut-cell families the worst ratio of a cell's area to
its largest neighbour's. Target: <= 10 s per family.
"""

from __future__ import annotations

import os
import time

import numpy as np

from _common import MACHINE, quick_parser, targets_line, write_report

PLATE = {
    "polygon": [[0.0, 0.0], [4.0, 0.0], [4.0, 2.0], [0.0, 2.0]],
    "sides": ["bottom", "right", "top", "left"],
    "holes": [
        {"circle": [0.8, 1.0, 0.35], "side": "hole_a"},
        {"circle": [2.0, 0.9, 0.5], "side": "hole_b"},
        {"circle": [3.2, 1.1, 0.3], "side": "hole_c"},
    ],
}
FAMILIES = [("square", {}), ("triangle", {}), ("voronoi", {}), ("hanging", {"levels": 1})]


def worst_neighbour_ratio(mesh) -> float:
    """min over cells of area / (largest neighbour's area)."""
    area = mesh.cell_areas
    pairs = mesh.edge_cells[mesh.edge_cells[:, 1] >= 0]
    largest = np.zeros(mesh.n_cells)
    np.maximum.at(largest, pairs[:, 0], area[pairs[:, 1]])
    np.maximum.at(largest, pairs[:, 1], area[pairs[:, 0]])
    return float((area / largest).min())


def case(family: str, options: dict, cells: int, repeat: int) -> dict:
    from vemkit.mesh.checks import validate_mesh
    from vemkit.mesh.families import build_mesh

    build_mesh(family, cells=2000, domain=PLATE, **options)  # warm-up
    times, cpu = [], []
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        mesh = build_mesh(family, cells=cells, domain=PLATE, **options)
        times.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
    t = time.perf_counter()
    validate_mesh(mesh)
    check = time.perf_counter() - t
    record = {
        "family": family,
        "options": options,
        "cells_asked": cells,
        "cells": mesh.n_cells,
        "vertices": mesh.n_vertices,
        "seconds": min(times),
        "cpu_seconds": min(cpu),
        "validate_seconds": check,
        "sides": sorted(mesh.boundary),
    }
    if family in ("square", "hanging"):
        record["worst_area_ratio_to_largest_neighbour"] = worst_neighbour_ratio(mesh)
    return record


def main():
    args = quick_parser(__doc__, "10 000 cells", repeat=2).parse_args()
    cells = 10_000 if args.quick else 100_000
    results = [case(family, options, cells, args.repeat) for family, options in FAMILIES]
    record = {
        "command": "python benchmarks/meshing.py" + (" --quick" if args.quick else ""),
        "machine": MACHINE,
        "domain": PLATE,
        "results": results,
        "load_average": [round(x, 2) for x in os.getloadavg()],
        "targets": {f"{r['family']} <= 10 s": (not args.quick) and r["seconds"] <= 10.0 for r in results},
    }
    lines = [
        "# Meshing benchmark: a plate with three circular holes",
        "",
        f"`{record['command']}` on {record['machine']}",
        "",
        "| family | options | cells | vertices | seconds | CPU seconds | validate_mesh s | worst area ratio |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        ratio = r.get("worst_area_ratio_to_largest_neighbour")
        lines.append(
            f"| {r['family']} | {r['options'] or ''} | {r['cells']} | {r['vertices']} | {r['seconds']:.2f} | "
            f"{r['cpu_seconds']:.2f} | {r['validate_seconds']:.2f} | {'' if ratio is None else f'{ratio:.3f}'} |"
        )
    lines += [
        "",
        f"Load average while running (1, 5, 15 min): {record['load_average']}. On a shared machine "
        "the wall time includes waiting for a core; the CPU time is the process's own.",
        "",
        targets_line(record["targets"], "Targets (wall time)"),
    ]
    write_report("meshing", record, lines)


if __name__ == "__main__":
    main()
