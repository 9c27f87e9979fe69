"""3D refinement benchmark (issue 36 item 6). Writes benchmarks/out/refine3d.{json,md}.

    .venv/bin/python benchmarks/refine3d.py [--quick]

``refine_cells`` on hexahedral grids (n = 20, 40 and the target 64), Kuhn tetrahedra and prisms
extruded from triangles, marking the 10 % or 30 % of the cells nearest the edge x = y = 0 of the box,
twice in a row (each step marks the same fraction of the mesh it refines; the 64^3 target once). The
time of every step (wall and CPU), the cells and vertices before and after it. ``--quick``: the small
meshes only. Target: the 64^3 hex grid (2.6e5 cells) with 10 % marked in a few seconds (<= 5 s).
"""

from __future__ import annotations

import os
import time

import numpy as np

from _common import MACHINE, quick_parser, shared_machine_lines, write_report

RECTANGLE = {"polygon": [[0, 0], [1, 0], [1, 1], [0, 1]], "sides": ["bottom", "right", "top", "left"]}


def _hex(n):
    from vemkit.mesh.families3d.grid import hex

    return hex(n=n)


def _tet(n):
    from vemkit.mesh.families3d.grid import tet

    return tet(n=n)


def _prisms(n):
    from vemkit.mesh.families import build_mesh
    from vemkit.mesh.families3d import extrude

    return extrude(build_mesh("triangle", n, domain=RECTANGLE), n, 1.0)


#: (label, builder, size, steps); --quick keeps the first of each family
CASES = [
    ("hex", _hex, 20, 2),
    ("hex", _hex, 40, 2),
    ("tet", _tet, 10, 2),
    ("tet", _tet, 20, 2),
    ("prism", _prisms, 16, 2),
    ("prism", _prisms, 32, 2),
    ("hex", _hex, 64, 1),
]
QUICK = {("hex", 20), ("tet", 10), ("prism", 16)}


def near_edge(mesh, fraction: float) -> np.ndarray:
    """The ``fraction`` of the cells whose centroids are nearest the edge x = y = 0."""
    centres = mesh.cell_centroids
    return np.argsort(np.hypot(centres[:, 0], centres[:, 1]), kind="stable")[: max(1, int(fraction * mesh.n_cells))]


def case(label, build, size, steps, fraction) -> list:
    from vemkit.mesh.refine_polyhedra import refine_cells

    mesh = build(size)
    out = []
    for step in range(steps):
        marked = near_edge(mesh, fraction)
        t, c = time.perf_counter(), time.process_time()
        new = refine_cells(mesh, marked).mesh
        seconds, cpu = time.perf_counter() - t, time.process_time() - c
        out.append(
            {
                "family": label,
                "size": size,
                "fraction": fraction,
                "step": step + 1,
                "marked": int(marked.size),
                "cells_before": mesh.n_cells,
                "vertices_before": mesh.n_vertices,
                "cells": new.n_cells,
                "vertices": new.n_vertices,
                "seconds": seconds,
                "cpu_seconds": cpu,
            }
        )
        print(out[-1], flush=True)
        mesh = new
    return out


def main():
    args = quick_parser(__doc__, "the small meshes").parse_args()
    case("hex", _hex, 4, 1, 0.3)  # warm-up (compiled kernels, imports)
    results = []
    for label, build, size, steps in CASES:
        if args.quick and (label, size) not in QUICK:
            continue
        for fraction in (0.1,) if size == 64 else (0.1, 0.3):
            results += case(label, build, size, steps, fraction)
    target = [r for r in results if r["family"] == "hex" and r["size"] == 64]
    record = {
        "command": "python benchmarks/refine3d.py" + (" --quick" if args.quick else ""),
        "machine": MACHINE,
        "results": results,
        "load_average": [round(x, 2) for x in os.getloadavg()],
        "targets": {"hex 64^3, 10 % marked <= 5 s": bool(target) and target[0]["seconds"] <= 5.0},
    }
    lines = [
        "# 3D refinement benchmark",
        "",
        f"`{record['command']}` on {record['machine']}",
        "",
        "| family | n | marked fraction | step | marked | cells before | vertices before | cells after | vertices after "
        "| seconds | CPU seconds | microseconds per cell |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        lines.append(
            f"| {r['family']} | {r['size']} | {r['fraction']:.0%} | {r['step']} | {r['marked']} | {r['cells_before']} | "
            f"{r['vertices_before']} | {r['cells']} | {r['vertices']} | {r['seconds']:.2f} | {r['cpu_seconds']:.2f} | "
            f"{1e6 * r['seconds'] / r['cells']:.1f} |"
        )
    lines += shared_machine_lines(record)
    write_report("refine3d", record, lines)


if __name__ == "__main__":
    main()
