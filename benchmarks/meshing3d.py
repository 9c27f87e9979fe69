"""3D meshing benchmark (docs/reference/files.md). Writes benchmarks/out/meshing3d.{json,md}.

    .venv/bin/python benchmarks/meshing3d.py [--quick] [--repeat R]

The unit cube meshed by every box family with about 10^5 cells (``cells=100000``; ``--quick``:
10^4), and an extruded plate with a hole (prisms over the 2D voronoi family), each timed after a
warm-up on a coarse mesh; best of ``--repeat`` runs, wall and CPU time (the machine may be shared:
the load average is reported). Also reported, outside the timing: the time of ``validate_mesh3d``,
the counts, and the prediction of ``estimate_mesh3d``. Target: Voronoi with 10^5 cells <= 30 s.
"""

from __future__ import annotations

import os
import time

from _common import MACHINE, quick_parser, shared_machine_lines, write_report

CUBE = {"box": [[0, 0, 0], [1, 1, 1]]}
PLATE = {
    "extrude": {"depth": 0.2},
    "polygon": [[0, 0], [2, 0], [2, 1], [0, 1]],
    "sides": ["bottom", "right", "top", "left"],
    "holes": [{"circle": [1.0, 0.5, 0.25], "side": "bore"}],
}
CASES = [
    ("voronoi", CUBE, {}),
    ("hex", CUBE, {}),
    ("tet", CUBE, {}),
    ("octree", CUBE, {"rule": "random", "seed": 1}),
    ("voronoi", PLATE, {}),
]


def case(family: str, domain: dict, options: dict, cells: int, repeat: int) -> dict:
    from vemkit.mesh.checks3d import validate_mesh3d
    from vemkit.mesh.families3d import build_mesh3d
    from vemkit.mesh.families3d.resources import estimate_mesh3d

    build_mesh3d(family, domain, cells=500, **options)  # warm-up
    times, cpu = [], []
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        mesh = build_mesh3d(family, domain, cells=cells, **options)
        times.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
    t = time.perf_counter()
    validate_mesh3d(mesh)
    check = time.perf_counter() - t
    record = {
        "family": family,
        "domain": "box" if "box" in domain else "extrude",
        "options": options,
        "cells_asked": cells,
        "cells": mesh.n_cells,
        "vertices": mesh.n_vertices,
        "faces": mesh.n_faces,
        "seconds": min(times),
        "cpu_seconds": min(cpu),
        "validate_seconds": check,
        "volume": float(mesh.cell_volumes.sum()),
    }
    if "box" in domain:
        record["estimate"] = estimate_mesh3d(family, domain, cells=cells, **options)._asdict()
    return record


def main():
    args = quick_parser(__doc__, "10 000 cells", repeat=1).parse_args()
    cells = 10_000 if args.quick else 100_000
    results = [case(family, domain, options, cells, args.repeat) for family, domain, options in CASES]
    voronoi = results[0]
    record = {
        "command": "python benchmarks/meshing3d.py" + (" --quick" if args.quick else ""),
        "machine": MACHINE,
        "results": results,
        "load_average": [round(x, 2) for x in os.getloadavg()],
        "targets": {"voronoi 1e5 cells <= 30 s": (not args.quick) and voronoi["seconds"] <= 30.0},
    }
    lines = [
        "# 3D meshing benchmark",
        "",
        f"`{record['command']}` on {record['machine']}",
        "",
        "| family | domain | cells | vertices | faces | seconds | CPU seconds | validate_mesh3d s | predicted cells / vertices / faces |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        est = r.get("estimate")
        guess = f"{est['cells']} / {est['vertices']} / {est['faces']}" if est else ""
        lines.append(
            f"| {r['family']} | {r['domain']} | {r['cells']} | {r['vertices']} | {r['faces']} | {r['seconds']:.2f} | "
            f"{r['cpu_seconds']:.2f} | {r['validate_seconds']:.2f} | {guess} |"
        )
    lines += shared_machine_lines(record)
    write_report("meshing3d", record, lines)


if __name__ == "__main__":
    main()
