"""scikit-fem P1 or P2 on the manufactured problem of benchmarks/peers/exact_elasticity.py, and its
errors against the exact solution (benchmarks/peers_order2.py).

    .venv/bin/python benchmarks/peers/skfem_manufactured.py CASE.npz OUT.npz

CASE.npz as for skfem_solve.py; `params`: degree (1 or 2), the problem's expressions
(exact_elasticity.manufactured_problem), solver ("direct" | "amg"), cg_rtol, error_order. As scikit-fem's
users write it: `ElementVector(ElementTriP1 | ElementTriP2)`, its default quadrature (intorder 2k:
exact stiffness, the load and the traction integrated to degree 2k), u = u_exact interpolated at the
Dirichlet dofs (a lift), then spsolve or pyamg SA + CG with the rigid modes on the condensed
system (skfem_solve.linear_solve). After the solve, timed apart: ||u_h - u||_L2 and |u_h - u|_H1
under a rule of degree `error_order` (u_h itself and its exact gradient: no projection).
OUT.npz: `info` (JSON text: the times, DOFs, errors).
"""

import json
import sys
import time

import numpy as np
import skfem
from exact_elasticity import evaluate  # this folder
from skfem.helpers import dot
from skfem.models.elasticity import linear_elasticity
from skfem_solve import facets_of, linear_solve, rigid_modes

ELEMENTS = {1: skfem.ElementTriP1, 2: skfem.ElementTriP2}


def expression_form(expressions):
    """The linear form v -> int expressions(x) . v."""

    @skfem.LinearForm
    def form(v, w):
        return dot(evaluate(expressions, *w.x), v)

    return form


def assemble(case, p):
    mesh = skfem.MeshTri(case["vertices"].T.copy(), case["triangles"].T.copy())
    element = skfem.ElementVector(ELEMENTS[p["degree"]]())
    basis = skfem.Basis(mesh, element)
    stiffness = skfem.asm(linear_elasticity(p["lam"], p["mu"]), basis)
    load = skfem.asm(expression_form(p["body_force"]), basis)
    for side, traction in p["traction"].items():
        facet_basis = skfem.FacetBasis(mesh, element, facets=facets_of(mesh, case[f"side_{side}"]))
        load += skfem.asm(expression_form(traction), facet_basis)
    dirichlet = [facets_of(mesh, case[f"side_{side}"]) for side in p["dirichlet"]]
    fixed = basis.get_dofs(facets=np.concatenate(dirichlet)).all()
    prescribed = np.zeros(basis.N)
    for component, dofs in enumerate(basis.split_indices()):
        on_side = np.intersect1d(dofs, fixed)
        prescribed[on_side] = evaluate([p["displacement"][component]], *basis.doflocs[:, on_side])[0]
    return basis, stiffness, load, fixed, prescribed


def solve(basis, stiffness, load, fixed, prescribed, p):
    """The Dirichlet lift, then the homogeneous condensed solve (spsolve or AMG-CG)."""
    lifted = load - stiffness @ prescribed
    return linear_solve(stiffness, lifted, fixed, rigid_modes(basis), p, maxiter=2000) + prescribed


def errors(basis, u, p):
    """(||u_h - u||_L2, |u_h - u|_H1) under a rule of degree p["error_order"]."""
    fine = skfem.Basis(basis.mesh, basis.elem, intorder=p["error_order"])
    field = fine.interpolate(u)
    x, y = fine.global_coordinates().value
    value = evaluate(p["displacement"], x, y)
    gradient = np.stack([evaluate(row, x, y) for row in p["gradient"]])
    l2 = np.sum(fine.dx * np.sum((field.value - value) ** 2, axis=0))
    h1 = np.sum(fine.dx * np.sum((field.grad - gradient) ** 2, axis=(0, 1)))
    return float(np.sqrt(l2)), float(np.sqrt(h1))


def main(case_path, out_path):
    start = time.perf_counter()
    case = np.load(case_path)
    p = json.loads(str(case["params"]))
    basis, stiffness, load, fixed, prescribed = assemble(case, p)
    assembled = time.perf_counter()
    u = solve(basis, stiffness, load, fixed, prescribed, p)
    solved, cpu = time.perf_counter(), time.process_time()
    error_l2, error_h1 = errors(basis, u, p)
    info = {
        "setup_s": assembled - start,
        "solve_s": solved - assembled,
        "error_s": time.perf_counter() - solved,
        "error_cpu_s": time.process_time() - cpu,
        "solver": p["solver"],
        "n_dofs": int(basis.N),
        "error_l2": error_l2,
        "error_h1_semi": error_h1,
        "skfem": skfem.__version__,
    }
    np.savez(out_path, info=json.dumps(info))


if __name__ == "__main__":
    main(*sys.argv[1:3])
