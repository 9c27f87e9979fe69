"""Which body-force load k = 2 should use by default (issue 18, item 9). Writes
benchmarks/out/body_force_projection.{json,md}.

    .venv/bin/python benchmarks/body_force_projection.py [--quick]

On the manufactured contact scenes config/order2/{sliding,sticking,separation}.yaml and on a smooth
field of tests/manufactured.py (clamped unit square, no contact), at n = 8, 16, 32 squares: k = 1
against k = 2 with ``discretization.body_force_projection`` p0 (the paper's P_0 f1) and p1 (P_1 f1
against Pi_2 v). Recorded: the relative H1 and L2 errors of the solution file (``error_h1``,
``error_l2``: Pi_k u_h against u) and the relative l2 error of the vertex values, and the observed
orders in h between sizes.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
OUT = ROOT / "benchmarks" / "out"
SCENES = ["sliding", "sticking", "separation"]
FIELD = ["0.01*sin(2*x)*cos(y) + 0.02*x*y", "0.015*exp(x - y) - 0.01*cos(3*y)"]
CASES = [("k1", 1, None), ("k2-p0", 2, "p0"), ("k2-p1", 2, "p1")]


def smooth_scene(n: int):
    from manufactured import elasticity_solution

    from vemkit.config.scene import scene_from_dict

    E, nu = 1000.0, 0.3
    return scene_from_dict(
        {
            "name": "smooth",
            "material": {"E": E, "nu": nu},
            "body_force": elasticity_solution(*FIELD, E, nu)["body_force"],
            "boundary": {"dirichlet": {side: FIELD for side in ("left", "bottom", "right", "top")}},
            "discretization": {"mesh": {"family": "square", "n": n}},
            "exact": {"displacement": FIELD},
        }
    )


def scene_of(name: str, n: int, order: int, projection):
    from vemkit.config.scene import load_scene

    sets = [f"discretization.mesh.n={n}", f"discretization.order={order}"]
    sets += [f"discretization.body_force_projection={projection}"] if projection else []
    if name == "smooth":
        return smooth_scene(n).with_overrides(sets)
    return load_scene(ROOT / "config" / "order2" / f"{name}.yaml", sets)


def vertex_error(scene, problem, ds) -> float:
    from vemkit.config.expressions import vector_field

    x, y = problem.mesh.vertices.T
    exact = np.stack(vector_field(scene.exact_displacement)(x, y), axis=1)
    u = np.stack([ds["u1"].values, ds["u2"].values], axis=1)
    return float(np.linalg.norm(u - exact) / np.linalg.norm(exact))


def measure(name: str, sizes) -> list[dict]:
    from vemkit.studies.scene_solve import solve_scene

    rows = []
    for label, order, projection in CASES:
        for n in sizes:
            scene = scene_of(name, n, order, projection)
            problem, _, ds = solve_scene(scene, verify=True)
            rows.append(
                {
                    "scene": name,
                    "case": label,
                    "n": n,
                    "n_dofs": int(ds.attrs["n_dofs"]),
                    "h1": float(ds.attrs["error_h1"]),
                    "l2": float(ds.attrs["error_l2"]),
                    "vertex": vertex_error(scene, problem, ds),
                }
            )
            print(json.dumps(rows[-1]), flush=True)
    return rows


def table(rows) -> str:
    lines = [
        "| scene | n | k = 1 H1 / L2 / vertex | k = 2 p0 H1 / L2 / vertex | k = 2 p1 H1 / L2 / vertex "
        "| vertex k1/p0 | vertex k1/p1 |",
        "|---|---|---|---|---|---|---|",
    ]
    by = {(r["scene"], r["case"], r["n"]): r for r in rows}
    for scene, _, n in sorted({(r["scene"], 0, r["n"]) for r in rows}, key=lambda t: (t[0], t[2])):
        cells = [by[(scene, case, n)] for case, _, _ in CASES]
        text = [" / ".join(f"{c[key]:.2e}" for key in ("h1", "l2", "vertex")) for c in cells]
        ratio = [f"{cells[0]['vertex'] / c['vertex']:.0f}" for c in cells[1:]]
        lines.append(f"| {scene} | {n} | " + " | ".join(text + ratio) + " |")
    lines += [
        "",
        "Observed orders in h (finest step), H1 / L2 / vertex:",
        "",
        "| scene | k = 1 | k = 2 p0 | k = 2 p1 |",
        "|---|---|---|---|",
    ]
    for scene in dict.fromkeys(r["scene"] for r in rows):
        orders = []
        for case, _, _ in CASES:
            pts = sorted((r for r in rows if r["scene"] == scene and r["case"] == case), key=lambda r: r["n"])
            a, b = pts[-2], pts[-1]
            step = np.log(b["n"] / a["n"])
            orders.append(" / ".join(f"{np.log(a[k] / b[k]) / step:.2f}" for k in ("h1", "l2", "vertex")))
        lines.append(f"| {scene} | " + " | ".join(orders) + " |")
    return "\n".join(lines) + "\n"


def main() -> None:
    sizes = [8, 16] if "--quick" in sys.argv else [8, 16, 32]
    rows = [row for name in SCENES + ["smooth"] for row in measure(name, sizes)]
    OUT.mkdir(exist_ok=True)
    (OUT / "body_force_projection.json").write_text(json.dumps(rows, indent=1))
    (OUT / "body_force_projection.md").write_text(table(rows))
    print(table(rows))


if __name__ == "__main__":
    main()
