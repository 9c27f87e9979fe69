"""Newton iterations of frictional contact against the mesh size, in 3D (issue 35 item 3). Writes
benchmarks/out/newton_iterations.{json,md}.

    .venv/bin/python benchmarks/newton_iterations.py [--quick]

Two cases, each from a cold start in one step, ssn with the scene's default linear solver (AMG above
a few thousand unknowns):
- the GetFEM friction box (benchmarks/peers3d.py: the unit cube on Kuhn tetrahedra, its top moved
  by (0.001, 0.0005, -0.01), Coulomb m_tau = 1, k_tau = 0.3 k_nu), n = 8 ... 69 (2 187 to
  1 030 301 unknowns), tol 1e-10;
- the Hertz half sphere (vemkit.studies.hertz, gmsh tetrahedra; k_nu = 1e3 E/R) pressed by 0.01 and
  sheared by 0.003 in one step, Coulomb m_tau = 1, k_tau = 0.3 k_nu, h = 0.03 ... 0.005, tol 1e-6;
- the box on very stiff foundations (k_nu = 1e5 E at n = 20, 24; 1e7 E at n = 12), where the coupled
  law's gamma must be rescaled at a stall.
Per row: unknowns, Newton iterations, how the damped Newton globalized (steps shorter than 1, the
shortest step, a fallback of the linear solver, rescalings of gamma), CG iterations, wall time, and
the independent check.
"""

from __future__ import annotations

import copy
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml
from peers3d import KN
from peers3d import scene as peer_scene

from vemkit.config.scene import scene_from_dict
from vemkit.contact.problem import scene_problem
from vemkit.solvers.dispatch import solve
from vemkit.solvers.verification import verify_solution

from _common import MACHINE, quick_parser, write_report

ROOT = Path(__file__).resolve().parents[1]

BOX_SIZES, BOX_QUICK = (8, 16, 32, 48, 69), (8, 16)
#: (n, k_nu / E) of the box on a very stiff foundation: ssn stalled at a merit of 2e-9 (1e5 E, n = 20
#: and 24) and 3e-9 (1e7 E, n = 12) before the coupled law's gamma was rescaled at a stall
#: (vemkit.solvers.ssn._rescaled_at_a_stall)
STIFF = ((20, 1e5), (24, 1e5), (12, 1e7))
SPHERE_SIZES, SPHERE_QUICK = (0.03, 0.015, 0.01, 0.0075, 0.005), (0.03,)
MU = 0.3


def _row(case: str, size: float, problem, solver: dict, check_tol: float) -> dict:
    start = time.perf_counter()
    solution = solve(problem, dict(solver))
    wall = time.perf_counter() - start
    steps = np.asarray(solution.history.get("step", []), dtype=float)
    check = verify_solution(problem, solution.u, solution.multiplier, check_tol)
    return {
        "case": case,
        "size": size,
        "dofs": int(problem.n_dofs),
        "iterations": int(solution.iterations),
        "damped_steps": int(np.sum(steps < 1.0)),
        "shortest_step": float(steps.min()) if steps.size else 1.0,
        "fallback": str(solution.info.get("fallback", "")),
        "gamma_rescaled": int(solution.info.get("gamma_rescaled", 0)),
        "linear_iterations": int(solution.linear_iterations),
        "wall_s": wall,
        "check": float(check["worst"]),
        "passed": bool(check["passed"]),
    }


def friction_box(n: int, k_normal: float = KN):
    """The friction box of benchmarks/peers3d.py on Kuhn tetrahedra (n per side), k_nu = ``k_normal``,
    k_tau = MU k_nu."""
    data = peer_scene({"family": "tet", "kind": "structured", "n": n}, "friction")
    data["contact"]["normal"]["k"] = k_normal
    data["contact"]["friction"] = {"k": MU * k_normal, "m": 1.0}
    return scene_problem(scene_from_dict(data))


def box_rows(sizes, k_normal: float = KN) -> list[dict]:
    solver = {"method": "ssn", "tol": 1e-10, "max_iterations": 60}
    case = "box" if k_normal == KN else f"box, k_nu = {k_normal / KN:g} E"
    return [_row(case, n, friction_box(n, k_normal), solver, 1e-8) for n in sizes]


def sphere_rows(sizes, folder: Path) -> list[dict]:
    from vemkit.studies.hertz import R, sphere_msh, sphere_problem

    data = copy.deepcopy(yaml.safe_load((ROOT / "benchmarks" / "hertz_sphere.yaml").read_text()))
    data["material"]["nu"] = 0.3
    data["contact"]["normal"]["m"] = 1.0
    data["contact"]["friction"] = {"k": MU * 1e3 * data["material"]["E"] / R, "m": 1.0}
    data["boundary"]["dirichlet"] = {"top": [None, -0.01, 0.003], "sym_x": [0.0, None, None]}
    solver = {"method": "ssn", "tol": 1e-6, "max_iterations": 60}
    rows = []
    for h in sizes:
        msh = folder / f"half_{h:g}.msh"
        sphere_msh(msh, h, 0.25, half=True)
        rows.append(_row("half sphere", h, sphere_problem(data, msh, 1e3), solver, 1e-5))
    return rows


def main() -> None:
    args = quick_parser(__doc__, "n = 8, 16 and h = 0.03 only").parse_args()
    with tempfile.TemporaryDirectory() as folder:
        rows = sphere_rows(SPHERE_QUICK if args.quick else SPHERE_SIZES, Path(folder))
    rows += box_rows(BOX_QUICK if args.quick else BOX_SIZES)
    for n, k in () if args.quick else STIFF:
        rows += box_rows((n,), k * KN)
    lines = [
        f"# Newton iterations of 3D Coulomb friction against the mesh ({MACHINE})",
        "",
        "| case | n or h | unknowns | Newton its | damped steps | shortest step | fallback | gamma rescaled | CG its | wall s | check |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['case']} | {r['size']:g} | {r['dofs']:,} | {r['iterations']} | {r['damped_steps']} | "
            f"{r['shortest_step']:.3g} | {r['fallback'] or '-'} | {r['gamma_rescaled']} | {r['linear_iterations']} | {r['wall_s']:.1f} | "
            f"{r['check']:.1e}{'' if r['passed'] else ' FAILED'} |"
        )
    write_report("newton_iterations", {"machine": MACHINE, "rows": rows}, lines)


if __name__ == "__main__":
    main()
