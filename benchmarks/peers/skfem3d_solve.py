"""scikit-fem P1 tetrahedra, the peer of vemkit's 3D k = 1 element (issue 22 (d)): linear elasticity.

    .venv/bin/python benchmarks/peers/skfem3d_solve.py CASE.npz OUT.npz

CASE.npz: ``vertices`` (N, 3), ``tetrahedra`` (M, 4) and ``params`` (JSON: lam, mu, traction [t1, t2, t3]
on the face z = z_max, clamped face z = z_min, solver "direct" | "amg", cg_rtol). As scikit-fem's
documentation does it: ElementVector(ElementTetP1()), ``linear_elasticity``, the traction by a
FacetBasis on the facets where z = z_max, the clamped dofs condensed, then spsolve ("direct") or CG
preconditioned by pyamg smoothed aggregation with the six rigid-body modes ("amg").
"""

import json
import sys
import time

import numpy as np
import skfem
from skfem.helpers import dot
from skfem.models.elasticity import linear_elasticity
from skfem_solve import linear_solve  # this folder: the 2D peer's condensed spsolve / AMG-CG


def assemble(case, p):
    mesh = skfem.MeshTet(case["vertices"].T.copy(), case["tetrahedra"].T.copy())
    element = skfem.ElementVector(skfem.ElementTetP1())
    basis = skfem.Basis(mesh, element, intorder=2)
    stiffness = skfem.asm(linear_elasticity(p["lam"], p["mu"]), basis)
    z0, z1 = mesh.p[2].min(), mesh.p[2].max()
    top = skfem.FacetBasis(
        mesh, element, facets=mesh.facets_satisfying(lambda x: x[2] > z1 - 1e-9 * (z1 - z0)), intorder=2
    )
    traction = np.array(p["traction"], dtype=float)

    @skfem.LinearForm
    def load_form(v, w):
        return dot(np.broadcast_to(traction[:, None, None], v.value.shape), v)

    load = skfem.asm(load_form, top)
    fixed = basis.get_dofs(lambda x: x[2] < z0 + 1e-9 * (z1 - z0)).all()
    return basis, stiffness, load, fixed


def rigid_modes(basis):
    """Three translations and three rotations omega x (x - xbar), in the basis' dof numbering."""
    x = basis.mesh.p - basis.mesh.p.mean(axis=1, keepdims=True)
    dofs = basis.nodal_dofs
    modes = np.zeros((basis.N, 6))
    for i in range(3):
        modes[dofs[i], i] = 1.0
    for k, (a, b) in enumerate(((1, 2), (2, 0), (0, 1))):  # e_k x x: (x_a, x_b) -> (-x_b, x_a)
        modes[dofs[a], 3 + k] = -x[b]
        modes[dofs[b], 3 + k] = x[a]
    return modes


def main(case_path, out_path):
    start = time.perf_counter()
    case = np.load(case_path)
    p = json.loads(str(case["params"]))
    basis, stiffness, load, fixed = assemble(case, p)
    assembled = time.perf_counter()
    u = linear_solve(stiffness, load, fixed, rigid_modes(basis), p, maxiter=2000)
    solved = time.perf_counter()
    info = {
        "setup_s": assembled - start,
        "solve_s": solved - assembled,
        "solver": p["solver"],
        "n_dofs": int(basis.N),
        "skfem": skfem.__version__,
    }
    np.savez(out_path, u=np.stack([u[d] for d in basis.nodal_dofs], axis=1), info=json.dumps(info))


if __name__ == "__main__":
    main(*sys.argv[1:3])
