"""Hertz's sphere on a stiff foundation in 3D (issue 21 item 4). Writes benchmarks/out/hertz3d.{json,md}.

    .venv/bin/python benchmarks/hertz3d.py [--quick] [--mindlin]

The lower half of a sphere of radius R = 1 centred at the origin, and of that the quarter x >= 0,
z >= 0 (benchmarks/hertz_sphere.yaml): symmetry rollers u1 = 0 on x = 0 (``sym_x``) and
u3 = 0 on z = 0 (``sym_z``); the flat cut y = 0 (``top``) is moved down by delta = 0.01 as a
frictionless platen (u2 = -delta, u1, u3 free); the curved surface (``sphere``) is Gamma_C, on the
foundation plane y = -R. E = 1, nu = 0.3, normal compliance p = k t (m = 1), frictionless.
The mesh: gmsh tetrahedra (written to a .msh file with physical surfaces, read through
``discretization.mesh.file``), refined near the contact point (0, -R, 0) by a gmsh size field (the
distance to the point as a MathEval field, through a Threshold): edge ``h`` within ``1.5 a_ref`` of the point, growing to ``H`` at distance 0.6.

From the solve: the total force P = 4 sum_i w_i p_i (a quarter); the contact radius a_zero from the
area where the piecewise linear interpolant of the nodal penetration on Gamma_C's triangles is positive
(projected on the foundation plane: a = sqrt(4 A / pi)) -- of the signed penetration u_nu - g, whose
zero level is the edge (the clipped pressure k (t)_+ would put it at the first vertex outside), a_fit and p0_fit from a least-squares fit
of p^2 = p0^2 (1 - r^2 / a^2) over the vertices in contact, p0_nodal the largest nodal pressure
(the vertex at the contact point, on both symmetry planes, stays a contact point). Hertz for a rigid
foundation (K. L. Johnson, Contact Mechanics, 1985, section 4.2): a = (3 P R / (4 E*))^(1/3),
p0 = 3 P / (2 pi a^2), E* = E / (1 - nu^2), both evaluated at the measured P.

``--mindlin`` also runs Cattaneo-Mindlin in steps (``mindlin``, ``vemkit.studies.mindlin``): the half
sphere x >= 0, Coulomb with m_tau = m_nu = 1, k_tau = mu k_nu, mu = 0.3; step 0 the normal load
(frictionless, Mindlin's setting: his theory assumes the normal loading leaves no shear traction,
or with Coulomb friction on), then the top moved sideways along z in SHIFTS, each step's slip
counted from the previous step's u_tau (``slip_reference``). The Gamma_C normals on the roller
plane x = 0 are put into the plane (``roller_normals``). Stick radius c from the vertices with
|lambda| < 1 against c = a (1 - Q/(mu P))^(1/3); the shear traction against Johnson's q(r).
"""

from __future__ import annotations

import copy
import math
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

from _common import MACHINE, quick_parser, write_report

ROOT = Path(__file__).resolve().parents[1]
SCENE = Path(__file__).resolve().parent / "hertz_sphere.yaml"  # its mesh file is made by sphere_msh()
R, E, NU = 1.0, 1.0, 0.3
E_STAR = E / (1 - NU**2)
A_REF = 0.1  # about the contact radius at delta = 0.01: the refined zone is 1.5 a_ref around the point

#: (h near the contact point, H far away, k_nu in units of E / R)
CASES = [
    (0.03, 0.25, 1e3),
    (0.015, 0.2, 1e3),
    (0.0075, 0.2, 1e3),
    (0.005, 0.2, 1e3),
    (0.005, 0.2, 1e2),
    (0.005, 0.2, 1e4),
    (0.005, 0.2, 1e5),
]
QUICK = [(0.03, 0.25, 1e3)]


def sphere_msh(path: Path, h: float, H: float, half: bool = False) -> None:
    """A gmsh 4.1 file of the quarter lower hemisphere (x, z >= 0; ``half``: x >= 0 only), physical
    surfaces sphere, sym_x, sym_z (not on the half) and top."""
    import gmsh

    gmsh.initialize([], readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.Verbosity", 1)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.model.add("hertz_sphere")
        occ = gmsh.model.occ
        ball = occ.addSphere(0, 0, 0, R)
        box = occ.addBox(0, -R, -R, R, R, 2 * R) if half else occ.addBox(0, -R, 0, R, R, R)
        occ.intersect([(3, ball)], [(3, box)])
        occ.synchronize()
        groups = {}
        for dim, tag in gmsh.model.getEntities(2):
            box = np.asarray(gmsh.model.getBoundingBox(dim, tag)).reshape(2, 3)
            flat = np.flatnonzero(box[1] - box[0] < 1e-4 * R)  # the plane faces are flat in x, y or z
            name = ("sym_x", "top", "sym_z")[flat[0]] if flat.size else "sphere"
            groups.setdefault(name, []).append(tag)
        assert set(groups) == {"sphere", "sym_x", "top"} | (set() if half else {"sym_z"}), groups
        for name, tags in groups.items():
            gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, tags), name)
        gmsh.model.addPhysicalGroup(3, [t for _, t in gmsh.model.getEntities(3)])
        field = gmsh.model.mesh.field
        distance = field.add("MathEval")
        field.setString(distance, "F", f"Sqrt(x*x + (y + {R})*(y + {R}) + z*z)")
        threshold = field.add("Threshold")
        field.setNumber(threshold, "InField", distance)
        field.setNumber(threshold, "SizeMin", h)
        field.setNumber(threshold, "SizeMax", H)
        field.setNumber(threshold, "DistMin", 1.5 * A_REF)
        field.setNumber(threshold, "DistMax", 0.6)
        field.setAsBackgroundMesh(threshold)
        for key, value in {
            "Mesh.MeshSizeExtendFromBoundary": 0,
            "Mesh.MeshSizeFromPoints": 0,
            "Mesh.MeshSizeFromCurvature": 0,
            "Mesh.Algorithm": 6,
            "Mesh.Algorithm3D": 1,
            "Mesh.Optimize": 1,
            "Mesh.MshFileVersion": 4.1,
        }.items():
            gmsh.option.setNumber(key, value)
        gmsh.model.mesh.generate(3)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()


def positive_area(xz: np.ndarray, p: np.ndarray) -> float:
    """Area of {p_h > 0} of the piecewise linear p on triangles (n, 3, 2) with vertex values (n, 3)."""
    total = 0.0
    for tri, val in zip(xz, p):
        pos = val > 0
        if not pos.any():
            continue
        (ax, ay), (bx, by) = tri[1] - tri[0], tri[2] - tri[0]
        full = 0.5 * abs(ax * by - ay * bx)
        if pos.all():
            total += full
            continue
        # one vertex alone on its side: the small triangle cut off at the zero level
        lone = int(np.flatnonzero(pos)[0] if pos.sum() == 1 else np.flatnonzero(~pos)[0])
        others = [j for j in range(3) if j != lone]
        s = [val[lone] / (val[lone] - val[j]) for j in others]
        small = full * s[0] * s[1]
        total += small if pos.sum() == 1 else full - small
    return total


def measure(problem, solution) -> dict:
    from vemkit.mesh.polyhedral_build import csr_rows
    from vemkit.solvers.solution import contact_state

    cb, mesh = problem.contact, problem.mesh
    state = contact_state(problem, solution.u, solution.multiplier)
    p = state.normal_pressure
    P = 4.0 * float(np.sum(cb.weight * p))
    r = np.hypot(cb.coords[:, 0], cb.coords[:, 2])
    nodal = np.full(mesh.n_vertices, -np.inf)  # the signed penetration u_nu - g (> 0: in contact)
    nodal[cb.vertices] = state.penetration
    faces = mesh.boundary["sphere"]
    tri = np.asarray(csr_rows(mesh.face_offsets, mesh.face_vertices)[faces])
    near = (nodal[tri] > 0).any(axis=1)
    tri = tri[near]
    area = positive_area(mesh.vertices[tri][:, :, [0, 2]], nodal[tri])
    a_zero = math.sqrt(4.0 * area / math.pi)
    on = p > 0
    A = np.stack([np.ones(on.sum()), r[on] ** 2], axis=1)
    c0, c1 = np.linalg.lstsq(A, p[on] ** 2, rcond=None)[0]
    p0_fit = math.sqrt(max(c0, 0.0))
    a_fit = math.sqrt(c0 / -c1) if c1 < 0 < c0 else float("nan")
    a_h = (3.0 * P * R / (4.0 * E_STAR)) ** (1.0 / 3.0)
    p0_h = 3.0 * P / (2.0 * math.pi * a_h**2)
    return {
        "P": P,
        "a_zero": a_zero,
        "a_fit": a_fit,
        "a_max": float(r[on].max()),
        "a_hertz": a_h,
        "p0_nodal": float(p.max()),
        "p0_fit": p0_fit,
        "p0_hertz": p0_h,
        "err_a_zero": a_zero / a_h - 1,
        "err_a_fit": a_fit / a_h - 1,
        "err_p0_nodal": float(p.max()) / p0_h - 1,
        "err_p0_fit": p0_fit / p0_h - 1,
        "contact_vertices": int(on.sum()),
        "max_penetration_over_delta": float(state.penetration.max() / 0.01),
    }


def run(h: float, H: float, k: float, folder: Path) -> dict:
    from vemkit.config.scene import scene_from_dict
    from vemkit.contact.problem import scene_problem
    from vemkit.solvers.dispatch import solve

    start = time.perf_counter()
    msh = folder / f"sphere_{h:g}_{H:g}.msh"
    if not msh.exists():
        sphere_msh(msh, h, H)
    t_mesh = time.perf_counter() - start
    data = copy.deepcopy(yaml.safe_load(SCENE.read_text()))
    data["discretization"]["mesh"] = {"file": str(msh)}
    data["contact"]["normal"]["k"] = k * E / R
    problem = scene_problem(scene_from_dict(data, source=str(SCENE)))
    t_setup = time.perf_counter() - start - t_mesh
    solution = solve(problem, dict(data["solver"]))
    wall = time.perf_counter() - start
    row = {
        "h": h,
        "H": H,
        "k": k,
        "cells": int(problem.mesh.n_cells),
        "dofs": int(problem.n_dofs),
        "iterations": int(solution.iterations),
        "converged": bool(solution.converged),
        "seconds_mesh": t_mesh,
        "seconds_setup": t_setup,
        "seconds_solve": solution.wall_time,
        "wall": wall,
    }
    row.update(measure(problem, solution))
    return row


SOLVER_MINDLIN = {"method": "ssn", "tol": 1e-6, "linear": "direct", "max_iterations": 60}
MU = 0.3  # Coulomb coefficient of the Cattaneo-Mindlin runs
#: (h, H, k_nu R/E, Poisson's ratio, normal step frictionless): nu -> 0.5 removes the normal-tangential
#: coupling of an elastic sphere on a rigid plane (Dundurs' beta) that Mindlin ignores
MINDLIN = [
    (0.015, 0.2, 1e3, 0.3, True),
    (0.015, 0.2, 1e3, 0.3, False),
    (0.015, 0.2, 1e3, 0.49, True),
    (0.015, 0.2, 1e3, 0.49, False),
]
MINDLIN_QUICK = [(0.03, 0.25, 1e3, 0.3, True)]
#: the platen's sideways displacements (along z) of the tangential steps, each from the previous one
SHIFTS = (0.0005, 0.001, 0.0015, 0.002, 0.0025, 0.003)


def mindlin(h: float, H: float, k: float, nu: float, frictionless_normal: bool, folder: Path) -> list[dict]:
    """Cattaneo-Mindlin in steps on the half sphere x >= 0 (a tangential load along z is not symmetric
    about z = 0): step 0 the top pressed down by delta (Coulomb, or frictionless), then the top moved
    sideways along z by SHIFTS, each step's slip counted from the previous step's u_tau
    (``vemkit.studies.mindlin``); Coulomb m_tau = m_nu = 1, k_tau = MU k_nu. One row per tangential step."""
    from vemkit.config.scene import scene_from_dict
    from vemkit.contact.boundary import FoundationLine
    from vemkit.contact.problem import scene_problem
    from vemkit.studies.mindlin import loading_in_steps, mindlin_measures, roller_normals

    start = time.perf_counter()
    msh = folder / f"half_{h:g}_{H:g}.msh"
    if not msh.exists():
        sphere_msh(msh, h, H, half=True)
    data = copy.deepcopy(yaml.safe_load(SCENE.read_text()))
    data["discretization"]["mesh"] = {"file": str(msh)}
    data["material"]["nu"] = nu
    data["contact"]["normal"] = {"k": k * E / R, "m": 1.0}
    data["contact"]["friction"] = {"k": MU * k * E / R, "m": 1.0}

    def problem_at(shift):
        data["boundary"]["dirichlet"] = {"top": [None, -0.01, shift], "sym_x": [0.0, None, None]}
        problem = scene_problem(scene_from_dict(data, source=str(SCENE)))
        return roller_normals(problem, FoundationLine(*scene_from_dict(data, source=str(SCENE)).foundation))

    solver = dict(SOLVER_MINDLIN, linear="direct" if h >= 0.015 else "amg")
    steps = loading_in_steps(problem_at, SHIFTS, solver, frictionless_normal_step=frictionless_normal)
    rows = []
    for shift, problem, solution, reference, check in steps[1:]:
        m = mindlin_measures(problem, solution, reference, MU)
        profile = {key: m.pop(key) for key in ("r", "q", "on", "stick")}
        m.update(
            h=h,
            H=H,
            k=k,
            nu=nu,
            mu=MU,
            shift=shift,
            frictionless_normal=frictionless_normal,
            cells=int(problem.mesh.n_cells),
            dofs=int(problem.n_dofs),
            iterations=int(solution.iterations),
            check=float(check["worst"]),
            passed=bool(check["passed"]),
            wall=time.perf_counter() - start,
        )
        m["profile"] = {key: np.asarray(v).tolist() for key, v in profile.items()}
        m["normal_step_iterations"] = int(steps[0][2].iterations)
        rows.append(m)
    return rows


def main() -> None:
    parser = quick_parser(__doc__, "one coarse mesh, k = 1e3 E/R")
    parser.add_argument("--mindlin", action="store_true", help="also Cattaneo-Mindlin in steps")
    args = parser.parse_args()
    cases = QUICK if args.quick else CASES
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for h, H, k in cases:
            rows.append(run(h, H, k, Path(tmp)))
            print(f"h = {h}, k = {k:g}: {rows[-1]['wall']:.1f} s", flush=True)

    def pc(x):
        return f"{100 * x:+.1f} %"

    lines = [
        "# Hertz: a sphere on a stiff foundation (3D, frictionless)",
        "",
        f"Quarter of the lower hemisphere, R = {R:g}, E = {E:g}, nu = {NU:g} (E* = {E_STAR:.4f}), delta = 0.01; "
        "gmsh tetrahedra refined near the contact point (h there, H far); p = k t; ssn. "
        "Hertz a = (3PR/(4E*))^(1/3), p0 = 3P/(2 pi a^2) at the measured P. "
        "a_zero: sqrt(4A/pi), A the area where the linear interpolant of the nodal penetration u_nu - g is > 0; "
        "a_fit, p0_fit: least squares of p^2 = p0^2 (1 - r^2/a^2); p0 nodal: the largest nodal pressure.",
        "",
        f"Machine: {MACHINE}. Command: `.venv/bin/python benchmarks/hertz3d.py{' --quick' if args.quick else ''}`",
        "",
        "| h | H | cells | DOFs | k R/E | P | a Hertz | a_zero (err) | a_fit (err) | p0 Hertz | p0 nodal (err) "
        "| p0_fit (err) | ssn it. | wall s |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['h']:g} | {r['H']:g} | {r['cells']} | {r['dofs']} | {r['k']:.0e} | {r['P']:.5f} | {r['a_hertz']:.4f} "
            f"| {r['a_zero']:.4f} ({pc(r['err_a_zero'])}) | {r['a_fit']:.4f} ({pc(r['err_a_fit'])}) "
            f"| {r['p0_hertz']:.4f} | {r['p0_nodal']:.4f} ({pc(r['err_p0_nodal'])}) "
            f"| {r['p0_fit']:.4f} ({pc(r['err_p0_fit'])}) | {r['iterations']} | {r['wall']:.1f} |"
        )
    extra = []
    failures = []
    if args.mindlin:
        from vemkit.exceptions import ConvergenceError

        with tempfile.TemporaryDirectory() as tmp:
            for h, H, k, nu, frictionless in MINDLIN_QUICK if args.quick else MINDLIN:
                try:
                    extra += mindlin(h, H, k, nu, frictionless, Path(tmp))
                    print(
                        f"Mindlin h = {h}, nu = {nu}, frictionless normal step {frictionless}: {extra[-1]['wall']:.1f} s",
                        flush=True,
                    )
                except ConvergenceError as error:
                    failures.append(
                        {"h": h, "H": H, "k": k, "nu": nu, "frictionless": frictionless, "error": str(error)}
                    )
                    print(f"Mindlin h = {h}, nu = {nu}: {error}", flush=True)
    if failures:
        lines += ["", "## Cattaneo-Mindlin: not converged", ""]
        lines += [
            f"- h = {f['h']}, k = {f['k']:g}, nu = {f['nu']}, frictionless normal step {f['frictionless']}: {f['error']}"
            for f in failures
        ]
    if extra:
        lines += [
            "",
            "## Cattaneo-Mindlin in steps (half sphere x >= 0, Coulomb mu = 0.3, m_tau = m_nu = 1, k_tau = mu k_nu)",
            "",
            "Step 0: the top pressed down by 0.01 (with Coulomb friction, or frictionless: the column 'normal "
            "step'); then the top moved sideways along z by the shift, each step's slip counted from the previous "
            "step's u_tau (ssn with slip_reference). c = sqrt(2 A_stick/pi) from the nodal weights of the vertices "
            "with |lambda| < 1; Mindlin c = a (1 - Q/(mu P))^(1/3) at the measured Q, P and a = sqrt(2 A_contact/pi); "
            "q misfit: RMS of |sigma_tau . e_z| - q_Mindlin(r) over the contact vertices / (mu p0).",
            "",
            "| h | DOFs | nu | normal step | shift | P | Q/(mu P) | a | c | c_max | c Mindlin (err) | q misfit "
            "| stick/slip | ssn it. | check |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
        ]
        for r in extra:
            lines.append(
                f"| {r['h']:g} | {r['dofs']} | {r['nu']:g} | {'frictionless' if r['frictionless_normal'] else 'Coulomb'} "
                f"| {r['shift']:g} | {r['P']:.5f} | {r['Q_over_muP']:.3f} | {r['a']:.4f} | {r['c']:.4f} | {r['c_max']:.4f} "
                f"| {r['c_mindlin']:.4f} ({pc(r['err_c'])}) | {r['q_rms_misfit']:.3f} "
                f"| {r['stick_vertices']}/{r['slip_vertices']} | {r['iterations']} | {r['check']:.0e} |"
            )
    record = {"machine": MACHINE, "quick": args.quick, "rows": rows, "mindlin": extra, "mindlin_failures": failures}
    write_report("hertz3d", record, lines)


if __name__ == "__main__":
    main()
