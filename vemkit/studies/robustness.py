"""The solver-robustness matrix: every contact solver on cases at the extremes of the parameters.

:data:`CASES` (``vemkit.studies.robustness_cases``: declared as data, scene overrides on the paper
scene or on a case's own scene), run with every solver by :func:`run_matrix` through the guarded
solve (``vemkit.solvers.verification``), gathered by :func:`stability_dataset` (dims ``case`` x
``solver``) and tabulated by :func:`stability_markdown`. Besides the outcome and the independent
check, every converged solve records one accuracy quantity, ``u_max`` (the largest displacement
component): locking shows as cell and nodal_average disagreeing on it.
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
from vemkit.studies.robustness_cases import (  # noqa: F401 - the cases are part of this module's API
    CASE_FAMILIES,
    CASE_SCENES,
    CASES,
    case_overrides,
    select_cases,
)


def status_attributes(long_name: str, dtype=np.int8) -> dict:
    """The attributes of a status variable: its long name, flag values and meanings (``STATUS_MEANINGS``)."""
    flags = np.arange(len(STATUS_MEANINGS), dtype=dtype)
    return {"long_name": long_name, "flag_values": flags, "flag_meanings": " ".join(STATUS_MEANINGS)}


def load_case_scenes(paths=None, overrides=(), root=".") -> dict:
    """{name: Scene} of the cases' own scenes (``paths``: {name: file}, :data:`CASE_SCENES` for None)."""
    from pathlib import Path

    from vemkit.config.scene import load_scene

    return {
        name: load_scene(Path(root) / path, overrides)
        for name, path in (CASE_SCENES if paths is None else paths).items()
    }


def case_base_scene(scene, case: dict, scenes=None):
    """The scene a case's overrides go on: its own (``scenes[case["scene"]]``) or ``scene``."""
    name = case.get("scene")
    if name is None:
        return scene
    if name not in (scenes or {}):
        raise ValueError(
            f"stability case {case['name']!r} needs the scene {name!r}: name it in stability.scenes "
            f"(config/sweeps.yaml), e.g. {name}: {CASE_SCENES.get(name, 'a scene file')}"
        )
    return scenes[name]


def largest_displacement(outcome) -> float:
    """The accuracy quantity of a solve: max |u_i| over the free unknowns (NaN unless converged)."""
    if not outcome.converged:
        return float("nan")
    return float(np.max(np.abs(outcome.solution.u))) if np.size(outcome.solution.u) else 0.0


def run_case(
    scene, case: dict, solvers: dict, n: int, *, time_budget=None, check_tol=DEFAULT_CHECK_TOL, scenes=None
) -> dict:
    """Every solver on one case: {"case", "n_dofs", "outcomes": {method: Outcome}, "u_max": {method: float}}.

    ``solvers``: {method: extra solver options}; ``scenes``: {name: Scene} of the cases that name
    their own base scene (:func:`load_case_scenes`). The problem (and one linear solver, when the
    solver takes it) is built once for all solvers.
    """
    from vemkit.contact.problem import scene_problem
    from vemkit.solvers.linear import linear_solver

    result = {"case": case, "n_dofs": -1, "parameters": {}, "outcomes": {}, "u_max": {}}
    try:
        scene = case_base_scene(scene, case, scenes)
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
        result["u_max"] = {m: float("nan") for m in solvers}
        return result
    result["n_dofs"] = int(problem.n_dofs)
    for method, extra in solvers.items():
        options = {**case_scene.solver_options, **(extra or {}), "method": method}
        result["outcomes"][method] = guarded_solve(
            problem, options, linear=linear, time_budget=time_budget, check_tol=check_tol
        )
        result["u_max"][method] = largest_displacement(result["outcomes"][method])
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


CASE_STRINGS = {  # variable name: long name (strings per case)
    "model": "the case scene's model (empty: plane stress)",
    "volumetric_strain": "discretization.volumetric_strain of the case (auto: vemkit.config.volumetric)",
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
    out["model"] = str(data.get("model", ""))
    out["volumetric_strain"] = str(data["discretization"].get("volumetric_strain", "auto"))
    return out


def run_matrix(
    scene, cases, solvers: dict, n: int, *, time_budget=None, check_tol=DEFAULT_CHECK_TOL, progress=None, scenes=None
) -> list[dict]:
    """run_case for every case (``scenes``: the cases' own base scenes); progress(result) after each."""
    results = []
    for case in cases:
        results.append(run_case(scene, case, solvers, n, time_budget=time_budget, check_tol=check_tol, scenes=scenes))
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
    for name, long_name in CASE_STRINGS.items():
        ds[name] = (
            "case",
            np.array([r["parameters"].get(name, "") for r in results], dtype=object),
            {"long_name": long_name},
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
    ds["u_max"] = (
        dims,
        np.array([[r.get("u_max", {}).get(m, np.nan) for m in methods] for r in results], float).reshape(shape),
        {
            "long_name": "largest displacement component max |u_i| over the free unknowns (NaN: not converged)",
            "units": "length unit of the scene",
            "comment": "the accuracy quantity: locking shows as volumetric_strain cell and nodal_average disagreeing",
        },
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


def case_u_max(ds) -> np.ndarray:
    """(case,) the accuracy quantity of every case: its first converged solver's u_max (NaN: none)."""
    values = ds["u_max"].values if "u_max" in ds else np.full((ds.sizes["case"], 1), np.nan)
    return np.array([next((v for v in row if np.isfinite(v)), np.nan) for row in values], float)


def nodal_average_ratio(ds) -> np.ndarray:
    """(case,) u_max over u_max of the case's nodal_average twin (the same name ending in
    nodal_average instead of cell; 1 for the twin itself); NaN for a case without one."""
    u_max = case_u_max(ds)
    index = {str(name): i for i, name in enumerate(ds["case"].values)}
    ratio = np.full(len(u_max), np.nan)
    for name, i in index.items():
        twin = name[: -len(",cell")] + ",nodal_average" if name.endswith(",cell") else name
        if twin.endswith(",nodal_average") and twin in index:
            ratio[i] = u_max[i] / u_max[index[twin]]
    return ratio


def _u_max(u_max: float, ratio: float) -> str:
    """A case's accuracy quantity, with its ratio to the nodal_average twin's for a cell case."""
    if not np.isfinite(u_max):
        return "-"
    return f"{u_max:.5g}" + (f" (×{ratio:.4f})" if np.isfinite(ratio) and ratio != 1.0 else "")


def stability_markdown(ds) -> str:
    """A Markdown report: summary per solver, one row per case, then every failure message."""
    methods = [str(m) for m in ds["solver"].values]
    lines = [
        "# Stability matrix",
        "",
        f"{ds.attrs.get('cases', ds.sizes['case'])} cases; each cell: outcome, iterations, worst "
        "independent check (dimensionless), wall time; max |u|: the largest displacement component of the "
        "first converged solver, (×r): r = its ratio to the same case with nodal_average (locking: r != 1).",
        "",
    ]
    for j, m in enumerate(methods):
        codes = ds["status"].values[:, j]
        counts = {STATUS_MEANINGS[c]: int(np.sum(codes == c)) for c in np.unique(codes)}
        lines.append(f"- **{m}**: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items(), key=lambda kv: -kv[1])))
    lines += [
        "",
        "| case | group | dofs | max \\|u\\| | " + " | ".join(methods) + " |",
        "|---|---|---:|---:|" + "---|" * len(methods),
    ]
    u_max, ratio = case_u_max(ds), nodal_average_ratio(ds)
    for i, name in enumerate(ds["case"].values):
        cells = " | ".join(_cell(ds, i, j) for j in range(len(methods)))
        accuracy = _u_max(u_max[i], ratio[i])
        lines.append(f"| {name} | {ds['group'].values[i]} | {int(ds['n_dofs'].values[i])} | {accuracy} | {cells} |")
    failures = [
        (str(ds["case"].values[i]), methods[j], str(ds["message"].values[i, j]))
        for i in range(ds.sizes["case"])
        for j in range(len(methods))
        if ds["status"].values[i, j] != 0
    ]
    if failures:
        lines += ["", "## Failures", ""] + [f"- {case} / {m}: {msg}" for case, m, msg in failures]
    return "\n".join(lines) + "\n"
