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
    """The facet numbers of the given vertex pairs (any order), by sorted keys (no Python loop)."""
    n = mesh.p.shape[1]
    facets = np.sort(mesh.facets, axis=0).astype(np.int64)  # int64: the keys exceed int32 from n ~ 46 000
    pairs = np.sort(np.asarray(edges, dtype=np.int64).reshape(-1, 2), axis=1)
    keys, wanted = facets[0] * n + facets[1], pairs[:, 0] * n + pairs[:, 1]
    order = np.argsort(keys)
    found = order[np.minimum(np.searchsorted(keys, wanted, sorter=order), keys.size - 1)]
    assert np.array_equal(keys[found], wanted), "a side edge is not a facet of the mesh"
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
    """The translations and the rotation (-y, x), in the basis' dof numbering (any Lagrange
    element: the dofs are point values at ``basis.doflocs``)."""
    x, y = basis.doflocs
    first, second = basis.split_indices()
    modes = np.zeros((basis.N, 3))
    modes[first, 0] = 1.0
    modes[second, 1] = 1.0
    modes[first, 2], modes[second, 2] = -y[first], x[second]
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
