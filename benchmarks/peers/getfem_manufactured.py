"""GetFEM P1 or P2 on the manufactured problem of benchmarks/peers/exact_elasticity.py, and its errors
against the exact solution (benchmarks/peers_order2.py; the system /usr/bin/python3, python3-getfem).

    /usr/bin/python3 benchmarks/peers/getfem_manufactured.py CASE.npz OUT.npz

CASE.npz as for getfem_solve.py; `params` as for skfem_manufactured.py (degree, the expressions,
error_order) and lsolver. As GetFEM's users write it: `FEM_PK(2, k)`, `IM_TRIANGLE(2k)` (exact
stiffness; load and traction to degree 2k), the isotropic linearized elasticity brick, the body force
and the tractions as source terms in the weak form language, u = u_exact on the Dirichlet sides
with multipliers in the same fem (`add_Dirichlet_condition_with_multipliers`, the data u_exact
interpolated on it; params getfem_dirichlet "simplification": `..._with_simplification`, whose
assembly is 16x slower here), `model.solve` with MUMPS. After the solve, timed apart: ||u_h - u||_L2 and |u_h - u|_H1 by
`asm_generic` under IM_TRIANGLE(error_order).
"""

import json
import sys
import time

import getfem as gf
import numpy as np
from exact_elasticity import evaluate, in_getfem
from getfem_solve import build_mesh, linear_solver, solve  # this folder


def vector(expressions):
    return "[" + ", ".join(in_getfem(e) for e in expressions) + "]"


def build_model(mesh, regions, p):
    mf = gf.MeshFem(mesh, 2)
    mf.set_fem(gf.Fem(f"FEM_PK(2,{p['degree']})"))
    mim = gf.MeshIm(mesh, gf.Integ(f"IM_TRIANGLE({2 * p['degree']})"))
    model = gf.Model("real")
    model.add_fem_variable("u", mf)
    model.add_initialized_data("lambda", [p["lam"]])
    model.add_initialized_data("mu", [p["mu"]])
    model.add_isotropic_linearized_elasticity_brick(mim, "u", "lambda", "mu")
    model.add_source_term_generic_assembly_brick(mim, f"{vector(p['body_force'])}.Test_u")
    for side, traction in p["traction"].items():
        model.add_source_term_generic_assembly_brick(mim, f"{vector(traction)}.Test_u", regions[side])
    nodes = mf.basic_dof_nodes()  # qdim 2: the dofs of a node are consecutive (component 0, 1)
    exact = np.empty(mf.nbdof())
    for component in (0, 1):
        exact[component::2] = evaluate([p["displacement"][component]], *nodes[:, component::2])[0]
    model.add_initialized_fem_data("u_exact", mf, exact)
    for side in p["dirichlet"]:
        if p.get("getfem_dirichlet", "multipliers") == "multipliers":
            model.add_Dirichlet_condition_with_multipliers(mim, "u", mf, regions[side], "u_exact")
        else:  # measured 8.7 s of assembly at 132 098 P2 DOFs (multipliers: 0.55 s), see the docs
            model.add_Dirichlet_condition_with_simplification("u", regions[side], "u_exact")
    return model, mf


def errors(model, mesh, p):
    """(||u_h - u||_L2, |u_h - u|_H1) under IM_TRIANGLE(error_order)."""
    mim = gf.MeshIm(mesh, gf.Integ(f"IM_TRIANGLE({p['error_order']})"))
    gradient = "[" + "; ".join(", ".join(in_getfem(e) for e in row) for row in p["gradient"]) + "]"
    l2 = gf.asm_generic(mim, 0, f"Norm_sqr(u - {vector(p['displacement'])})", -1, model)
    h1 = gf.asm_generic(mim, 0, f"Norm_sqr(Grad_u - {gradient})", -1, model)
    return float(np.sqrt(l2)), float(np.sqrt(h1))


def main(case_path, out_path):
    start = time.perf_counter()
    case = np.load(case_path)
    p = json.loads(str(case["params"]))
    mesh, _, regions = build_mesh(case)
    model, mf = build_model(mesh, regions, p)
    lsolver = linear_solver(p["lsolver"])
    setup_s = time.perf_counter() - start
    solve_s, _ = solve(model, p, lsolver)
    solved, cpu = time.perf_counter(), time.process_time()
    error_l2, error_h1 = errors(model, mesh, p)
    info = {
        "setup_s": setup_s,
        "solve_s": solve_s,
        "error_s": time.perf_counter() - solved,
        "error_cpu_s": time.process_time() - cpu,
        "lsolver": lsolver,
        "n_dofs": int(mf.nbdof()),
        "error_l2": error_l2,
        "error_h1_semi": error_h1,
    }
    np.savez(out_path, info=json.dumps(info))


if __name__ == "__main__":
    main(*sys.argv[1:3])
