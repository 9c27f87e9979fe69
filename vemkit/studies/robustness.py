"""The solver-robustness matrix: every contact solver on cases at the extremes of the parameters.

:data:`CASES` (>= 50 cases, declared as data: scene overrides on the paper scene), run with every
solver by :func:`run_matrix` through the guarded solve (``vemkit.solvers.verification``), gathered
by :func:`robustness_dataset` (dims ``case`` x ``solver``) and tabulated by
:func:`robustness_markdown`.
"""

from __future__ import annotations

import json

import numpy as np

from vemkit.solvers.verification import (
    CHECK_KEYS,
    DEFAULT_CHECK_TOL,
    STATUS_MEANINGS,
    failed,
    guarded_solve,
    prebuilt_linear_supported,
)


def status_attributes(long_name: str, dtype=np.int8) -> dict:
    """The attributes of a status variable: its long name, flag values and meanings (``STATUS_MEANINGS``)."""
    flags = np.arange(len(STATUS_MEANINGS), dtype=dtype)
    return {"long_name": long_name, "flag_values": flags, "flag_meanings": " ".join(STATUS_MEANINGS)}


# -- the stability matrix ---------------------------------------------------------------------------
def _case(name, group, **settings):
    return {"name": name, "group": group, "set": settings}


_K_NU, _K_TAU, _M_NU, _M_TAU = "contact.normal.k", "contact.friction.k", "contact.normal.m", "contact.friction.m"
_GAP, _E, _NU, _MESH = "contact.gap", "material.E", "material.nu", "discretization.mesh"
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
]


#: dimension -> the mesh family of a case that names none (None: the scene's own, hex by default)
CASE_FAMILIES = {2: "square", 3: None}


def case_overrides(case: dict, n: int, family: str = "square") -> list[str]:
    """Scene overrides of a case at n cells per unit length (a mesh entry replaces the whole mesh
    section; ``family`` where the case names none: squares in 2D, the scene's own family in 3D)."""
    settings = dict(case["set"])
    mesh = {"family": family, **settings.pop(_MESH, {}), "n": int(n)}
    return [f"{_MESH}={json.dumps(mesh)}"] + [f"{k}={json.dumps(v)}" for k, v in settings.items()]


def run_case(scene, case: dict, solvers: dict, n: int, *, time_budget=None, check_tol=DEFAULT_CHECK_TOL) -> dict:
    """Every solver on one case: {"case", "n_dofs", "outcomes": {method: Outcome}}.

    ``solvers``: {method: extra solver options}. The problem (and one linear solver, when the solver
    takes it) is built once for all solvers.
    """
    from vemkit.contact.problem import scene_problem
    from vemkit.solvers.linear import linear_solver

    result = {"case": case, "n_dofs": -1, "parameters": {}, "outcomes": {}}
    try:
        family = CASE_FAMILIES[scene.dimension] or scene.mesh_options.get("family", "hex")
        case_scene = scene.with_overrides(case_overrides(case, n, family))
        result["parameters"] = case_parameters(case_scene)
        problem = scene_problem(case_scene)
        linear = None
        if prebuilt_linear_supported():
            options = case_scene.solver_options
            linear = linear_solver(
                problem.stiffness,
                options.get("linear", "auto"),
                near_nullspace=problem.near_nullspace,
                tol=options["tol"],
            )
    except Exception as exc:  # noqa: BLE001 - an invalid case is a classified failure of every solver
        result["outcomes"] = {m: failed(m, exc, "setup") for m in solvers}
        return result
    result["n_dofs"] = int(problem.n_dofs)
    for method, extra in solvers.items():
        options = {**case_scene.solver_options, **(extra or {}), "method": method}
        result["outcomes"][method] = guarded_solve(
            problem, options, linear=linear, time_budget=time_budget, check_tol=check_tol
        )
    return result


PARAMETERS = {  # variable name: (scene path, long name)
    "k_nu": (("contact", "normal", "k"), "normal compliance coefficient k_nu (5.1)"),
    "m_nu": (("contact", "normal", "m"), "normal compliance exponent m_nu (5.1)"),
    "k_tau": (("contact", "friction", "k"), "friction bound coefficient k_tau (5.1)"),
    "m_tau": (("contact", "friction", "m"), "friction bound exponent m_tau (5.1)"),
    "g_a": (("contact", "gap"), "initial gap g_a"),
    "E": (("material", "E"), "Young modulus E"),
    "kappa": (("material", "nu"), "Poisson ratio kappa"),
}


def case_parameters(scene) -> dict:
    """The physical parameters of a case scene (NaN where not a number, e.g. a gap expression)."""
    data = scene.data
    out = {}
    for name, (path, _) in PARAMETERS.items():
        value = data
        for part in path:
            value = value.get(part, {}) if isinstance(value, dict) else {}
        out[name] = float(value) if isinstance(value, (int, float)) else float("nan")
    out["mesh"] = json.dumps(data["discretization"]["mesh"], sort_keys=True)
    return out


def select_cases(names=None) -> list[dict]:
    """The cases named (all of :data:`CASES` for None); an unknown name is an error."""
    if names is None:
        return list(CASES)
    index = {c["name"]: c for c in CASES}
    unknown = [name for name in names if name not in index]
    if unknown:
        raise ValueError(f"stability case {unknown[0]!r} is unknown; cases: {', '.join(index)}")
    return [index[name] for name in names]


def run_matrix(
    scene, cases, solvers: dict, n: int, *, time_budget=None, check_tol=DEFAULT_CHECK_TOL, progress=None
) -> list[dict]:
    """run_case for every case; progress(result) after each."""
    results = []
    for case in cases:
        results.append(run_case(scene, case, solvers, n, time_budget=time_budget, check_tol=check_tol))
        if progress is not None:
            progress(results[-1])
    return results


def stability_dataset(results, *, scene_yaml: str = "", settings=None):
    """The matrix as a Dataset: dims ``case`` x ``solver``; NaN / -1 where undefined (see sweeps.write_dataset)."""
    import xarray as xr

    import vemkit

    methods = list(dict.fromkeys(m for r in results for m in r["outcomes"]))
    names = [r["case"]["name"] for r in results]
    shape = (len(results), len(methods))
    status = np.zeros(shape, np.int8)
    iterations = np.full(shape, -1, np.int64)
    wall = np.zeros(shape)
    checks = {k: np.full(shape, np.nan) for k in (*CHECK_KEYS, "worst")}
    messages = np.full(shape, "", dtype=object)
    for i, r in enumerate(results):
        for j, m in enumerate(methods):
            o = r["outcomes"][m]
            status[i, j], iterations[i, j], wall[i, j], messages[i, j] = o.code, o.iterations, o.wall_time, o.message
            for k in checks:
                if o.checks and np.isfinite(o.checks.get(k, np.nan)):
                    checks[k][i, j] = o.checks[k]
    dims = ("case", "solver")
    ds = xr.Dataset(
        coords={
            "case": ("case", np.array(names, dtype=object), {"long_name": "stability case"}),
            "solver": ("solver", np.array(methods, dtype=object), {"long_name": "contact solver"}),
        }
    )
    ds["group"] = ("case", np.array([r["case"]["group"] for r in results], dtype=object))
    ds["overrides"] = (
        "case",
        np.array([json.dumps(r["case"]["set"], sort_keys=True) for r in results], dtype=object),
        {"long_name": "the case's settings on top of the base scene (JSON)"},
    )
    for name, (_, long_name) in PARAMETERS.items():
        ds[name] = (
            "case",
            np.array([r["parameters"].get(name, np.nan) for r in results], float),
            {"long_name": long_name},
        )
    ds["mesh"] = (
        "case",
        np.array([r["parameters"].get("mesh", "") for r in results], dtype=object),
        {"long_name": "discretization.mesh of the case (JSON)"},
    )
    ds["n_dofs"] = (
        "case",
        np.array([r["n_dofs"] for r in results], np.int64),
        {"long_name": "free unknowns (-1: not built)"},
    )
    ds["status"] = (dims, status, status_attributes("outcome of the solve"))
    ds["iterations"] = (dims, iterations, {"long_name": "nonlinear iterations (-1: unknown)"})
    ds["wall_time"] = (dims, wall, {"long_name": "wall time of the solve", "units": "s"})
    for k, values in checks.items():
        ds[f"check_{k}"] = (
            dims,
            values,
            {"long_name": f"independent check: {k} (dimensionless, see vemkit.studies.robustness)"},
        )
    ds["message"] = (dims, messages, {"long_name": "failure message (empty when converged)"})
    ds.attrs.update(
        {
            "title": "vemkit stability matrix",
            "scene": scene_yaml,
            "vemkit_version": vemkit.__version__,
            "settings": json.dumps(settings or {}, sort_keys=True, default=str),
            "check_tol": float((settings or {}).get("check_tol", DEFAULT_CHECK_TOL)),
        }
    )
    return summarize(ds)


def summarize(ds):
    """Attributes counting the cases and the outcomes per solver (after gathering parts too)."""
    status = ds["status"].values
    counts = {
        str(m): {STATUS_MEANINGS[c]: int(np.sum(status[:, j] == c)) for c in np.unique(status[:, j])}
        for j, m in enumerate(ds["solver"].values)
    }
    ds.attrs.update(
        {
            "cases": int(ds.sizes["case"]),
            "outcomes_per_solver": json.dumps(counts, sort_keys=True),
            "converged_per_solver": json.dumps({m: c.get("converged", 0) for m, c in counts.items()}),
        }
    )
    return ds


def _cell(ds, i, j) -> str:
    status = STATUS_MEANINGS[int(ds["status"].values[i, j])]
    its = int(ds["iterations"].values[i, j])
    worst = ds["check_worst"].values[i, j]
    if status == "converged":
        return f"ok, {its} it, {worst:.0e}, {ds['wall_time'].values[i, j]:.2f} s"
    return f"**{status.split('_', 2)[-1] if status.startswith('not_') else status}**" + (
        f" ({its} it)" if its >= 0 else ""
    )


def stability_markdown(ds) -> str:
    """A Markdown report: summary per solver, one row per case, then every failure message."""
    methods = [str(m) for m in ds["solver"].values]
    lines = [
        "# Stability matrix",
        "",
        f"{ds.attrs.get('cases', ds.sizes['case'])} cases; each cell: outcome, iterations, worst "
        "independent check (dimensionless), wall time.",
        "",
    ]
    for j, m in enumerate(methods):
        codes = ds["status"].values[:, j]
        counts = {STATUS_MEANINGS[c]: int(np.sum(codes == c)) for c in np.unique(codes)}
        lines.append(f"- **{m}**: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items(), key=lambda kv: -kv[1])))
    lines += ["", "| case | group | dofs | " + " | ".join(methods) + " |", "|---|---|---:|" + "---|" * len(methods)]
    for i, name in enumerate(ds["case"].values):
        cells = " | ".join(_cell(ds, i, j) for j in range(len(methods)))
        lines.append(f"| {name} | {ds['group'].values[i]} | {int(ds['n_dofs'].values[i])} | {cells} |")
    failures = [
        (str(ds["case"].values[i]), methods[j], str(ds["message"].values[i, j]))
        for i in range(ds.sizes["case"])
        for j in range(len(methods))
        if ds["status"].values[i, j] != 0
    ]
    if failures:
        lines += ["", "## Failures", ""] + [f"- {case} / {m}: {msg}" for case, m, msg in failures]
    return "\n".join(lines) + "\n"
