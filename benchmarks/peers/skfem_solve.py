"""scikit-fem P1 peer of vemkit for linear elasticity (no contact).

    .venv/bin/python benchmarks/peers/skfem_solve.py CASE.npz OUT.npz

CASE.npz as for getfem_solve.py (`params`: lam, mu, traction_affine: [[a, b, c], [a, b, c]], the
traction t_i = a + b x + c y on the side `neumann`, dirichlet, solver "direct" | "amg").
The solve is what scikit-fem's documentation shows: condense the Dirichlet dofs, then
scipy's spsolve ("direct") or CG preconditioned by pyamg smoothed aggregation ("amg", with the
three rigid-body modes as near-nullspace, relative residual `cg_rtol`).
"""

import json
import sys
import time

import numpy as np
import skfem
from skfem.helpers import dot
from skfem.models.elasticity import linear_elasticity


def facets_of(mesh, edges):
    """The facet numbers of the given vertex pairs (any order), vectorised as a careful user would
    (a Python dict over all facets cost 0.5 s at 5e5 DOFs): scikit-fem stores every facet with its
    smaller vertex first, so (low, high) keys looked up in the facets' sorted keys."""
    n = np.int64(mesh.p.shape[1])
    keys = mesh.facets[0].astype(np.int64) * n + mesh.facets[1]
    edges = np.sort(np.asarray(edges, dtype=np.int64), axis=1)
    wanted = edges[:, 0] * n + edges[:, 1]
    order = np.argsort(keys)
    found = order[np.minimum(np.searchsorted(keys, wanted, sorter=order), keys.size - 1)]
    assert np.array_equal(keys[found], wanted), "an edge of the case is not a facet of the mesh"
    return found


def assemble(case, p):
    mesh = skfem.MeshTri(case["vertices"].T.copy(), case["triangles"].T.copy())
    element = skfem.ElementVector(skfem.ElementTriP1())
    basis = skfem.Basis(mesh, element, intorder=2)
    stiffness = skfem.asm(linear_elasticity(p["lam"], p["mu"]), basis)
    coefficients = np.array(p["traction_affine"], dtype=float)
    neumann = skfem.FacetBasis(mesh, element, facets=facets_of(mesh, case[f"side_{p['neumann']}"]), intorder=4)

    @skfem.LinearForm
    def traction(v, w):
        x, y = w.x
        t = [a + b * x + c * y for a, b, c in coefficients]
        return dot(np.stack(t), v)

    load = skfem.asm(traction, neumann)
    fixed = np.unique(
        np.concatenate([basis.get_dofs(facets=facets_of(mesh, case[f"side_{s}"])).all() for s in p["dirichlet"]])
    )
    return mesh, basis, stiffness, load, fixed


def rigid_modes(basis):
    """The translations and the rotation (-y, x), in the basis' dof numbering."""
    x, y = basis.mesh.p
    first, second = basis.nodal_dofs
    modes = np.zeros((basis.N, 3))
    modes[first, 0] = 1.0
    modes[second, 1] = 1.0
    modes[first, 2], modes[second, 2] = -y, x
    return modes


def linear_solve(stiffness, load, fixed, modes, p, maxiter=1000):
    """spsolve, or pyamg SA-preconditioned CG on the condensed system (``modes``: the rigid-body
    modes in the basis' dof numbering, the near-nullspace; also the 3D peer's, skfem3d_solve.py)."""
    if p["solver"] == "direct":
        return skfem.solve(*skfem.condense(stiffness, load, D=fixed))
    import pyamg
    from scipy.sparse.linalg import cg

    A, b, x, interior = skfem.condense(stiffness, load, D=fixed)
    ml = pyamg.smoothed_aggregation_solver(A, B=modes[interior], symmetry="symmetric")
    solution, status = cg(A, b, M=ml.aspreconditioner(), rtol=p["cg_rtol"], atol=0.0, maxiter=maxiter)
    assert status == 0, f"CG did not converge ({status})"
    return skfem.solve(A, b, x=x, I=interior, solver=lambda *_: solution)


def main(case_path, out_path):
    start = time.perf_counter()
    case = np.load(case_path)
    p = json.loads(str(case["params"]))
    mesh, basis, stiffness, load, fixed = assemble(case, p)
    assembled = time.perf_counter()
    u = linear_solve(stiffness, load, fixed, rigid_modes(basis), p)
    solved = time.perf_counter()
    u = np.stack([u[basis.nodal_dofs[0]], u[basis.nodal_dofs[1]]], axis=1)
    info = {
        "setup_s": assembled - start,
        "solve_s": solved - assembled,
        "solver": p["solver"],
        "n_dofs": int(basis.N),
        "skfem": skfem.__version__,
    }
    np.savez(out_path, u=u, info=json.dumps(info))


if __name__ == "__main__":
    main(*sys.argv[1:3])
