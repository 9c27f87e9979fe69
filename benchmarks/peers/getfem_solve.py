"""GetFEM P1 peer of vemkit (runs under the system /usr/bin/python3 with python3-getfem), 2D or 3D.

    /usr/bin/python3 benchmarks/peers/getfem_solve.py CASE.npz OUT.npz

CASE.npz (written by benchmarks/peers.py or peers3d.py from the mesh file vemkit wrote): `vertices`
(n, d), `triangles` (m, 3) in 2D or `tetrahedra` (m, 4) in 3D, one (k, d) array of the vertices of
every boundary edge / face per side (`side_<name>`), optionally `gap` (n,) vertex values of the gap
(interpolated P1 on Gamma_C, as vemkit's gauss rule interpolates it), and `params` (JSON text):
problem "elasticity" | "compliance" | "friction", lam, mu, traction_affine (one row [a, b_1 ..
b_d] per component: t_i = a + b . x on the side `neumann`; no `neumann`: no traction), dirichlet
(sides with u = 0 unless `dirichlet_values` gives the side's vector), contact, gap (a number unless
the CASE has vertex gaps), kn, kt, friction_m (0 or 1), tangents (3D friction), r_friction, quadrature ("gauss" with gauss_points, or "nodal"),
max_res, lsolver ("mumps", "superlu" or "auto": MUMPS when this GetFEM has it, else SuperLU),
getfem_dirichlet ("multipliers", the default: a multiplier in u's own fem on each Dirichlet side;
"simplification": the dofs eliminated, ~18x slower assembly at 132 098 DOFs).
OUT.npz: `u` (n, d) at the CASE vertices, `info` (JSON text: times, Newton iterations, linear solver).

Only numpy, scipy and getfem: the system python has no netCDF4.
"""

import json
import sys
import time

import getfem as gf
import numpy as np
from scipy.spatial import cKDTree

# IM_TRIANGLE(k) restricted to an edge is a Gauss-Legendre rule: 2 points for k = 2, 3, 3 points
# for k = 4, 5, 4 points for k = 6, 7, 5 points for k = 9 (checked by its face_pts); IM_NC(2, 1)
# restricted to an edge is the trapezoid rule (vemkit's `nodal` contact quadrature).
GAUSS_EDGE_RULE = {
    1: "IM_TRIANGLE(1)",
    2: "IM_TRIANGLE(3)",
    3: "IM_TRIANGLE(5)",
    4: "IM_TRIANGLE(7)",
    5: "IM_TRIANGLE(9)",
}
# IM_TETRAHEDRON(k) restricted to a face: 1 point (the centroid) for k = 1, the symmetric 7-point
# degree-5 rule for k = 5 (checked by its face_pts and face_coeffs): vemkit's 3D gauss rule with
# contact_gauss_points 1 and 3 (vemkit.contact.gauss_rules); IM_NC(3, 1) on a face is the vertex rule
# |F|/3 per vertex (vemkit's nodal weights on a triangle).
GAUSS_FACE_RULE = {1: "IM_TETRAHEDRON(1)", 3: "IM_TETRAHEDRON(5)"}


def build_mesh(case):
    """The mesh with the CASE's vertices and triangles, and each side as a boundary region."""
    vertices = case["vertices"]
    cells = case["triangles"] if vertices.shape[1] == 2 else case["tetrahedra"]
    mesh = gf.Mesh("pt2D" if vertices.shape[1] == 2 else "ptND", vertices.T.copy(), cells.T.astype(np.int32).copy())
    to_gf = _vertex_map(vertices, mesh.pts().T)
    outer = {tuple(face) for face in mesh.outer_faces().T}
    regions = {}
    for number, name in enumerate(sorted(k[5:] for k in case.files if k.startswith("side_")), 1):
        pids = np.unique(to_gf[case[f"side_{name}"]])
        faces = [f for f in mesh.faces_from_pid(pids).T if tuple(f) in outer]
        mesh.set_region(number, np.array(faces, dtype=np.int32).T)
        regions[name] = number
    return mesh, to_gf, regions


def _vertex_map(vertices, gf_points):
    """GetFEM point id of every CASE vertex (by coordinates: 'pt2D' may renumber)."""
    distance, index = cKDTree(gf_points).query(vertices)
    assert distance.max() < 1e-12 * max(1.0, np.abs(vertices).max()), "vertex lost by GetFEM"
    return index


def build_model(mesh, regions, p):
    """Displacement P1, the linearized elasticity brick, u = 0 on the Dirichlet side, the traction."""
    d = mesh.dim()
    mf = gf.MeshFem(mesh, d)
    mf.set_fem(gf.Fem(f"FEM_PK({d},1)"))
    mim = gf.MeshIm(mesh, gf.Integ("IM_TRIANGLE(5)" if d == 2 else "IM_TETRAHEDRON(5)"))
    model = gf.Model("real")
    model.add_fem_variable("u", mf)
    model.add_initialized_data("lambda", [p["lam"]])
    model.add_initialized_data("mu", [p["mu"]])
    model.add_isotropic_linearized_elasticity_brick(mim, "u", "lambda", "mu")
    for side in p["dirichlet"]:
        add_dirichlet(model, mim, mf, regions[side], side, p)
    if p.get("neumann"):
        traction = ", ".join(
            " + ".join([repr(row[0])] + [f"{b!r}*X({i})" for i, b in enumerate(row[1:], 1)])
            for row in p["traction_affine"]
        )
        model.add_source_term_generic_assembly_brick(mim, f"[{traction}].Test_u", regions[p["neumann"]])
    return model, mf


def add_dirichlet(model, mim, mf, region, side, p):
    """u = 0 (or the side's `dirichlet_values`) on the region, by default with multipliers in the
    displacement's own fem restricted to the region (GetFEM adds the multiplier variable; MUMPS
    solves the saddle-point system); params getfem_dirichlet "simplification" eliminates the dofs
    instead (`..._with_simplification`: 4.8 s of assembly at 132 098 DOFs against 0.26 s).
    """
    value = p.get("dirichlet_values", {}).get(side)
    data = None
    if value is not None:
        data = f"u_{side}"
        model.add_initialized_data(data, value)
    if p.get("getfem_dirichlet", "multipliers") == "simplification":
        model.add_Dirichlet_condition_with_simplification("u", region, *([data] if data else []))
    else:
        model.add_Dirichlet_condition_with_multipliers(mim, "u", mf, region, *([data] if data else []))
        if value is not None:  # Newton starts from u = the value on the side, as with simplification:
            # from u = 0 GetFEM's default line search stalls (3D compliance, n = 8: 100 steps, no convergence)
            start = model.variable("u")
            dofs = mf.basic_dof_on_region(region)  # P1, qdim d: dof d*node + component
            start[dofs] = np.asarray(value, dtype=float)[dofs % mf.qdim()]
            model.set_variable("u", start)


def add_contact(model, mesh, regions, p, case, to_gf):
    """Normal compliance p_nu(t) = kn t_+ (m = 1) and, for "friction", the Tresca-type term."""
    d = mesh.dim()
    if p["quadrature"] == "gauss":
        rule = (GAUSS_EDGE_RULE if d == 2 else GAUSS_FACE_RULE)[p["gauss_points"]]
    else:
        rule = f"IM_NC({d},1)"
    mim_c = gf.MeshIm(mesh, gf.Integ(rule))
    region = regions[p["contact"]]
    model.add_initialized_data("kn", [p["kn"]])
    if "gap" in case.files:  # vertex values, interpolated P1 (vemkit's gauss rule interpolates t)
        mf_gap = gf.MeshFem(mesh, 1)
        mf_gap.set_fem(gf.Fem(f"FEM_PK({d},1)"))
        at_point = np.empty(mesh.nbpts())
        at_point[to_gf] = case["gap"]
        model.add_initialized_fem_data("gap", mf_gap, at_point[_vertex_map(mf_gap.basic_dof_nodes().T, mesh.pts().T)])
    else:
        model.add_initialized_data("gap", [p["gap"]])
    model.add_nonlinear_term(mim_c, "kn*pos_part(u.Normal - gap)*(Test_u.Normal)", region)
    if p["problem"] == "friction":
        add_friction(model, mesh, mim_c, region, p)


def add_friction(model, mesh, mim_c, region, p):
    """The friction term with a nodal multiplier, under IM_NC(d, 1) (the vertex rule on edges / faces)
    vertex by vertex: vemkit's nodal problem.

    2D, vemkit's m_tau = 0 (p_tau = kt): lam_t in [-1, 1] on the contact side (P1 trace), friction
    stress kt*lam_t; the inclusion lam_t in Sign(u.T) as the fixed point lam_t = P_[-1,1](lam_t + r u.T),
    tested with P1. 3D: the friction stress itself, sig_t = p_tau lam_t (two components in the
    tangents t1, t2 of params "tangents", vemkit's basis of a flat Gamma_C), with p_tau = kt (m_tau = 0)
    or kt (u.Normal - gap)_+ (friction_m = 1: Coulomb's law on the normal-compliance pressure), and
    sig_t = Ball_projection(sig_t + r u_T, p_tau): also determined where p_tau = 0 (out of contact).
    """
    model.add_initialized_data("kt", [p["kt"]])
    model.add_initialized_data("r_t", [p["r_friction"]])
    if mesh.dim() == 2:
        model.add_fem_variable("lam_t", multiplier_fem(mesh, region, p))
        tangent = "[-Normal(2), Normal(1)]"  # (1, 0) on the bottom, nu = (0, -1): vemkit's tau
        model.add_nonlinear_term(mim_c, f"kt*lam_t*(Test_u.{tangent})", region)
        z = f"(lam_t + r_t*(u.{tangent}))"
        projected = f"({z} - pos_part({z} - 1) + pos_part(-{z} - 1))"
        model.add_nonlinear_term(mim_c, f"(lam_t - {projected})*Test_lam_t/r_t", region)
        return
    model.add_fem_variable("sig_t", multiplier_fem(mesh, region, p))
    bound = "kt*pos_part(u.Normal - gap)" if p.get("friction_m", 0) == 1 else "kt"
    t1, t2 = (f"[{a!r}, {b!r}, {c!r}]" for a, b, c in p["tangents"])
    model.add_nonlinear_term(mim_c, f"sig_t(1)*(Test_u.{t1}) + sig_t(2)*(Test_u.{t2})", region)
    z = f"(sig_t + r_t*[u.{t1}, u.{t2}])"
    model.add_nonlinear_term(mim_c, f"(sig_t - Ball_projection({z}, {bound})).Test_sig_t/r_t", region)


def linear_solver(requested):
    """MUMPS if requested or ("auto") if this GetFEM was built with it, else SuperLU."""
    if requested != "auto":
        return requested
    try:
        gf.linsolve_mumps(gf.Spmat("identity", 2), np.ones(2))
        return "mumps"
    except Exception:  # GetFEM raises its own error type when MUMPS is not compiled in
        return "superlu"


_KEEP_ALIVE = []


def multiplier_fem(mesh, region, p):
    """P1 on the contact side's vertices, less those on a Dirichlet side.

    u is fixed there, so their friction rows would be empty (a singular tangent matrix); vemkit
    eliminates the same vertices, their friction terms never reach the solved equations.
    """
    full = gf.MeshFem(mesh, mesh.dim() - 1)
    full.set_fem(gf.Fem(f"FEM_PK({mesh.dim()},1)"))
    dofs = set(full.basic_dof_on_region(region))
    for side_region in p["dirichlet_regions"]:
        dofs -= set(full.basic_dof_on_region(side_region))
    partial = gf.MeshFem("partial", full, np.array(sorted(dofs), dtype=np.int32))
    _KEEP_ALIVE.append(full)  # the partial MeshFem refers to it: freeing it would crash GetFEM
    return partial


def solve(model, p, lsolver):
    """GetFEM's Newton (with its default line search) and the given linear solver."""
    options = ["max_res", p["max_res"], "max_iter", 100, "lsolver", lsolver]
    start = time.perf_counter()
    iterations, converged = model.solve(*options)
    if not converged:
        sys.exit(f"getfem_solve: Newton did not converge in {iterations} iterations")
    return time.perf_counter() - start, iterations


def main(case_path, out_path):
    start = time.perf_counter()
    case = np.load(case_path)
    p = json.loads(str(case["params"]))
    mesh, to_gf, regions = build_mesh(case)
    model, mf = build_model(mesh, regions, p)
    p["dirichlet_regions"] = [regions[side] for side in p["dirichlet"]]
    if p["problem"] != "elasticity":
        add_contact(model, mesh, regions, p, case, to_gf)
    lsolver = linear_solver(p["lsolver"])
    setup_s = time.perf_counter() - start
    solve_s, iterations = solve(model, p, lsolver)
    u = nodal_displacement(model, mf, mesh, to_gf)
    info = {
        "setup_s": setup_s,
        "solve_s": solve_s,
        "lsolver": lsolver,
        "dirichlet": p.get("getfem_dirichlet", "multipliers"),
        "iterations": _as_int(iterations),
        "n_dofs": int(mf.nbdof()),
        "getfem": getattr(gf, "__version__", str(getattr(gf, "__revision__", "?"))),
    }
    np.savez(out_path, u=u, info=json.dumps(info))


def nodal_displacement(model, mf, mesh, to_gf):
    """u at every CASE vertex (P1: one dof per component at each mesh point)."""
    d = mesh.dim()
    values = model.variable("u").reshape(-1, d)
    nodes = mf.basic_dof_nodes()[:, ::d].T
    at_point = np.empty_like(values)
    at_point[_vertex_map(nodes, mesh.pts().T)] = values
    return at_point[to_gf]


def _as_int(value):
    return int(np.ravel(value)[0]) if np.size(value) else -1


if __name__ == "__main__":
    main(*sys.argv[1:3])
