"""The cases of the solver-robustness matrix (``vemkit.studies.robustness``), declared as data.

A case is a name, a group and scene overrides on a base scene: the studies scene (the paper's), or
the scene it names (``scene``: a key of :data:`CASE_SCENES`, the workflow's ``stability.scenes``).
Beyond the solver extremes of the paper's scene: nu -> 1/2 in plane strain on every 2D family and
on the 3D box of every 3D family, each with ``discretization.volumetric_strain`` cell (the paper's
form, which locks on triangles and tetrahedra) and nodal_average (``vemkit.vem.volumetric``); and
very stiff foundations and large friction (mu = k_tau / k_nu with m_tau = m_nu = 1) in 2D and 3D.
"""

from __future__ import annotations

import json

#: scene name -> its file (relative to the repository; the workflow's ``stability.scenes`` names the same)
CASE_SCENES = {"box3d": "config/scenes/3d/paper_box.yaml"}
#: Poisson ratios towards incompressibility, and the two treatments of the volumetric strain
INCOMPRESSIBLE_NU = (0.49, 0.499, 0.4999)
VOLUMETRIC_STRAINS = ("cell", "nodal_average")
#: family -> its mesh entry: 2D (plane strain on the paper's scene), 3D (the box3d scene at n = 8)
FAMILIES_2D = {
    "square": {"family": "square"},
    "triangle": {"family": "triangle"},
    "voronoi": {"family": "voronoi", "seed": 1},
    "hanging": {"family": "hanging", "levels": 3, "rule": "contact"},
}
BOX_N = 8
FAMILIES_3D = {
    "hex": {"family": "hex", "n": BOX_N},
    "tet": {"family": "tet", "n": BOX_N},
    "voronoi": {"family": "voronoi", "seed": 1, "n": BOX_N},
    "octree": {"family": "octree", "n": BOX_N},
}
#: the box3d scene's Young modulus: its foundations are k_nu = 1e2, 1e5, 1e7 E
_BOX_E = 2000.0


def _case(name, group, scene=None, **settings):
    """A case: its name, group and settings (scene overrides); ``scene``: the name of its own base
    scene (:data:`CASE_SCENES`), absent for the studies scene."""
    return {"name": name, "group": group, "set": settings, **({"scene": scene} if scene else {})}


_K_NU, _K_TAU, _M_NU, _M_TAU = "contact.normal.k", "contact.friction.k", "contact.normal.m", "contact.friction.m"
_GAP, _E, _NU, _MESH = "contact.gap", "material.E", "material.nu", "discretization.mesh"
_VOLUMETRIC = "discretization.volumetric_strain"


def _box(name: str, **settings) -> dict:
    """A 3D extreme: the box3d scene on its hexahedra at n = BOX_N (a case's own mesh wins)."""
    return _case(name, "3D extremes", scene="box3d", **{_MESH: FAMILIES_3D["hex"], **settings})


#: (name prefix, group, families, base) of the nu -> 1/2 cases: plane strain on the paper's scene
#: (its plane stress cannot lock: lambda* <= 2 mu), and the box3d scene
INCOMPRESSIBLE_BASES = (
    ("plane strain", "incompressible 2D", FAMILIES_2D, {"model": "plane_strain"}),
    ("3d", "incompressible 3D", FAMILIES_3D, {"scene": "box3d"}),
)
#: nu -> 1/2 on every family, the paper's cell form and the nodal average
INCOMPRESSIBLE_CASES = [
    _case(
        f"{prefix},{family},kappa={nu:g},{volumetric}", group, **base, **{_NU: nu, _VOLUMETRIC: volumetric, _MESH: mesh}
    )
    for prefix, group, families, base in INCOMPRESSIBLE_BASES
    for family, mesh in families.items()
    for nu in INCOMPRESSIBLE_NU
    for volumetric in VOLUMETRIC_STRAINS
]
#: foundations up to 1e7 E and friction coefficients mu = k_tau / k_nu up to 1e3 (coupled law m_tau = 1)
STIFF_CASES = [
    *(_case(f"k_nu={k:g}", "normal stiffness", **{_K_NU: k}) for k in (2e9, 2e10)),
    *(
        _case(f"m_tau=1,mu={mu:g},k_nu=2e+08", "friction exponent", **{_M_TAU: 1.0, _K_NU: 2e8, _K_TAU: mu * 2e8})
        for mu in (1e2, 1e3)
    ),
    *(_box(f"3d,k_nu={k / _BOX_E:g} E", **{_K_NU: k}) for k in (2e5, 2e8, 2e10)),
    *(_box(f"3d,k_tau={k:g}", **{_K_TAU: k}) for k in (0.0, 1e4, 1e6)),
    *(_box(f"3d,m_tau=1,mu={mu:g}", **{_M_TAU: 1.0, _K_TAU: mu * 10.0}) for mu in (0.3, 1e2, 1e3)),
    *(_box(f"3d,m_tau=1,mu={mu:g},k_nu=1e5 E", **{_M_TAU: 1.0, _K_NU: 2e8, _K_TAU: mu * 2e8}) for mu in (0.3, 1e2)),
    _box(
        "3d,tet,kappa=0.4999,nodal_average,k_nu=1e5 E,m_tau=1",
        **{_NU: 0.4999, _VOLUMETRIC: "nodal_average", _MESH: FAMILIES_3D["tet"], _K_NU: 2e8, _M_TAU: 1.0, _K_TAU: 6e7},
    ),
]


#: the cases: overrides of the base scene (the paper's, E = 2000, kappa = 0.4, g_a = 0.1, k_nu = 10,
#: m_nu = 1, k_tau = 450, m_tau = 0) at the matrix's mesh (``discretization.mesh.n`` of run_matrix)
CASES = [
    _case("paper", "baseline"),
    *(
        _case(f"k_nu={k:g}", "normal stiffness", **{_K_NU: k})
        for k in (1e-3, 1e-1, 1.0, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8)
    ),
    *(_case(f"k_tau={k:g}", "friction bound", **{_K_TAU: k}) for k in (0.0, 1.0, 10.0, 1e3, 1e4, 1e5, 1e6)),
    *(
        _case(f"m_nu={m:g},k_nu={k:g}", "normal exponent", **{_M_NU: m, _K_NU: k})
        for m in (2.0, 3.0)
        for k in (10.0, 1e4, 1e8)
    ),
    *(_case(f"m_tau=1,k_tau={k:g}", "friction exponent", **{_M_TAU: 1.0, _K_TAU: k}) for k in (450.0, 1e4, 1e6)),
    _case("m_tau=1,m_nu=3,k_nu=1e4", "friction exponent", **{_M_TAU: 1.0, _M_NU: 3.0, _K_NU: 1e4}),
    *(_case(f"kappa={nu:g}", "Poisson ratio", **{_NU: nu}) for nu in (0.0, 0.3, 0.45, 0.49, 0.499, 0.4999)),
    _case("kappa=0.4999,k_nu=1e6", "Poisson ratio", **{_NU: 0.4999, _K_NU: 1e6}),
    _case("kappa=0.4999,voronoi", "Poisson ratio", **{_NU: 0.4999, _MESH: {"family": "voronoi", "seed": 1}}),
    *(_case(f"E={E:g}", "Young modulus", **{_E: E}) for E in (2e-3, 2e9)),
    _case("E=2e-3,k_nu=1e-3", "Young modulus", **{_E: 2e-3, _K_NU: 1e-3}),
    _case("E=2e9,k_nu=1e8", "Young modulus", **{_E: 2e9, _K_NU: 1e8}),
    _case("E=2e9,k_tau=1e6", "Young modulus", **{_E: 2e9, _K_TAU: 1e6}),
    _case("E=2e-3,g_a=10", "Young modulus", **{_E: 2e-3, _GAP: 10.0}),
    *(_case(f"g_a={g:g}", "gap", **{_GAP: g}) for g in (0.0, 10.0)),
    _case("g_a=0,k_nu=1e8", "gap", **{_GAP: 0.0, _K_NU: 1e8}),
    _case("g_a=10,k_tau=0", "gap", **{_GAP: 10.0, _K_TAU: 0.0}),
    *(
        _case(f"voronoi,anisotropy={a:g}", "mesh", **{_MESH: {"family": "voronoi", "seed": 1, "anisotropy": a}})
        for a in (4.0, 10.0)
    ),
    _case(
        "voronoi,tiny edges",
        "mesh",
        **{_MESH: {"family": "voronoi", "seed": 2, "lloyd_iterations": 0, "merge_tol": 0.0}},
    ),
    _case(
        "voronoi,tiny edges,anisotropy=10",
        "mesh",
        **{_MESH: {"family": "voronoi", "seed": 3, "lloyd_iterations": 0, "merge_tol": 0.0, "anisotropy": 10.0}},
    ),
    *(
        _case(f"hanging,levels={L}", "mesh", **{_MESH: {"family": "hanging", "levels": L, "rule": "contact"}})
        for L in (3, 5)
    ),
    _case(
        "hanging,random,levels=4",
        "mesh",
        **{_MESH: {"family": "hanging", "levels": 4, "rule": "random", "seed": 1, "fraction": 0.3}},
    ),
    _case("triangle,delaunay", "mesh", **{_MESH: {"family": "triangle", "kind": "delaunay", "seed": 1}}),
    _case("k_nu=1e8,m_nu=3,k_tau=1e6", "combined", **{_K_NU: 1e8, _M_NU: 3.0, _K_TAU: 1e6}),
    _case(
        "hanging,levels=4,k_nu=1e8",
        "combined",
        **{_K_NU: 1e8, _MESH: {"family": "hanging", "levels": 4, "rule": "contact"}},
    ),
    _case(
        "tiny edges,kappa=0.4999,k_nu=1e6",
        "combined",
        **{_NU: 0.4999, _K_NU: 1e6, _MESH: {"family": "voronoi", "seed": 2, "lloyd_iterations": 0, "merge_tol": 0.0}},
    ),
    _case("m_nu=3,k_nu=1e-3,g_a=0", "combined", **{_M_NU: 3.0, _K_NU: 1e-3, _GAP: 0.0}),
    _case("E=2e9,kappa=0.4999,k_nu=1e-3", "combined", **{_E: 2e9, _NU: 0.4999, _K_NU: 1e-3}),
    *INCOMPRESSIBLE_CASES,
    *STIFF_CASES,
]


#: dimension -> the mesh family of a case that names none (None: the scene's own, hex by default)
CASE_FAMILIES = {2: "square", 3: None}


def case_overrides(case: dict, n: int, family: str = "square") -> list[str]:
    """Scene overrides of a case at n cells per unit length (a mesh entry replaces the whole mesh
    section; ``family`` where the case names none: squares in 2D, the scene's own family in 3D; a case's own ``n`` wins)."""
    settings = dict(case["set"])
    mesh = {"family": family, "n": int(n), **settings.pop(_MESH, {})}
    return [f"{_MESH}={json.dumps(mesh)}"] + [f"{k}={json.dumps(v)}" for k, v in settings.items()]


def select_cases(names=None) -> list[dict]:
    """The cases named (all of :data:`CASES` for None); an unknown name is an error."""
    if names is None:
        return list(CASES)
    index = {c["name"]: c for c in CASES}
    unknown = [name for name in names if name not in index]
    if unknown:
        raise ValueError(f"stability case {unknown[0]!r} is unknown; cases: {', '.join(index)}")
    return [index[name] for name in names]
