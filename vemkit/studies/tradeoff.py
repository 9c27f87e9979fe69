"""Speed against accuracy: which (mesh family, solver, tolerance, stabilization, h) to pick.

Every run solves the scene on one mesh with one configuration and measures

- the error ||Pi_1(u_h - u_ref)|| / ||Pi_1 u_ref|| (full H1 norm, also the seminorm and L2) against
  ONE reference solution (the 2^-8 square mesh, SPEC §5), the same yardstick for every
  stabilization (``vemkit.vem.norms.projection_error``);
- the cost: ``cost_time`` = assembly + contact solve (with its linear solver set-up, nothing
  reused between runs; the fastest of ``repeats`` solves, after an untimed warm-up of the compiled
  kernels), and the number of free unknowns (DOFs). Mesh generation is recorded apart
  (``mesh_time``): a mesh is built once and reused.

Runs whose mesh is finer than the reference somewhere (hanging nodes: n 2^levels > n_ref) are
skipped: the error measure needs the reference at least as fine. The solver tolerance means the
Newton residual for ssn and eps_u = eps_lambda = tol (with the CG tolerance) for uzawa.

:func:`pareto_front` marks the runs no other run beats in both cost and error;
:func:`cheapest_for_targets` answers "for X% error the cheapest configuration is ...";
:func:`refinement_gain` compares refinement at Gamma_C with uniform refinement at equal DOFs
(piecewise linear interpolation of log error against log DOFs).
"""

from __future__ import annotations

import json
import time

import numpy as np
import xarray as xr

from vemkit.solvers.verification import STATUS_MEANINGS, guarded_solve

SCENE_SECTIONS = ("domain", "material", "body_force", "boundary", "contact")  # must match the reference's
RECORD_FLOATS = ("tol", "error_h1", "error_h1_semi", "error_l2", "wall_time", "assembly_time", "mesh_time",
                 "cost_time", "residual", "h_min")
RECORD_INTS = ("n", "n_dofs", "n_cells", "iterations", "status")
RECORD_STRINGS = ("family", "family_name", "solver", "stabilization", "message")


def check_reference_scene(scene, reference_scene_yaml: str) -> None:
    """The reference must solve the same physical problem (domain, material, loads, contact)."""
    import yaml

    reference = yaml.safe_load(reference_scene_yaml or "") or {}
    mine = scene.data
    for section in SCENE_SECTIONS:
        if section in reference and reference.get(section) != mine.get(section):
            raise ValueError(f"the reference solution solves another problem: scene section {section!r} differs "
                             f"({reference.get(section)!r} != {mine.get(section)!r})")


def _finest_ok(spec: dict, n: int, reference_n: int) -> bool:
    """Every cell at least as large as a reference cell (the error quadrature lives on the reference)."""
    options = spec.get("options") or {}
    refinement = 2 ** int(options.get("levels", 0)) if spec["family"] == "hanging" else 1
    return n * refinement <= reference_n


def run_family(scene, label: str, spec: dict, reference, *, levels, solvers, tolerances, stabilizations,
               repeats: int = 1, time_budget=None, reference_n: int = 256, max_iterations=None, progress=None) -> list[dict]:
    """Records of every run of one mesh family (``spec``: {family, options}); see the module docstring.

    ``reference``: a ``vemkit.studies.convergence.ReferenceSolution``. All-triangle families are solved with
    the first stabilization only (the VEM space is P1 there, the stabilization vanishes).
    ``max_iterations``: {solver: limit}.
    """
    from vemkit.vem.norms import projection_error
    from vemkit.mesh.families import build_mesh
    from vemkit.vem.projection import projected_solution
    from vemkit.contact.problem import scene_problem

    records = []
    stabs = list(stabilizations)[:1] if spec["family"] == "triangle" else list(stabilizations)
    _warm_up(scene, spec, stabs, solvers)
    for n in levels:
        if not _finest_ok(spec, n, reference_n):
            continue
        t0 = time.perf_counter()
        mesh = build_mesh(spec["family"], n, **(spec.get("options") or {}))
        mesh_time = time.perf_counter() - t0
        for stab in stabs:
            mesh_section = {"family": spec["family"], "n": int(n), **(spec.get("options") or {})}
            run_scene = scene.with_overrides([f"discretization.stabilization={stab}",
                                              f"discretization.mesh={json.dumps(mesh_section)}"])
            t0 = time.perf_counter()
            problem = scene_problem(run_scene, mesh)
            assembly_time = time.perf_counter() - t0
            for solver in solvers:
                for tol in tolerances:
                    options = {**run_scene.solver_options, "method": solver, "tol": float(tol)}
                    if (max_iterations or {}).get(solver):
                        options["max_iterations"] = int(max_iterations[solver])
                    if solver == "uzawa":
                        options.update(eps_u=float(tol), eps_lambda=float(tol))
                    best = guarded_solve(problem, options, time_budget=time_budget, check_tol=None)
                    for _ in range(int(repeats) - 1 if best.converged else 0):  # a failure is not repeated
                        again = guarded_solve(problem, options, time_budget=time_budget, check_tol=None)
                        best = again if again.converged and again.wall_time < best.wall_time else best
                    record = {"family": label, "family_name": spec["family"], "solver": solver, "tol": float(tol),
                              "stabilization": stab, "n": int(n), "n_dofs": int(problem.n_dofs),
                              "n_cells": int(mesh.n_cells), "h_min": float(_smallest_edge(mesh)),
                              "iterations": best.iterations, "status": best.code, "message": best.message,
                              "wall_time": best.wall_time, "assembly_time": assembly_time, "mesh_time": mesh_time,
                              "cost_time": assembly_time + best.wall_time,
                              "residual": float(best.checks.get("worst", np.nan)) if best.checks else float("nan")}
                    if best.converged:
                        u = problem.dofs.expand(best.solution.u)
                        err = projection_error(mesh, projected_solution(mesh, u), reference.mesh, reference.projected,
                                               reference.quadrature)
                        record.update(error_h1=err["h1"], error_h1_semi=err["h1_semi"], error_l2=err["l2"])
                    else:
                        record.update(error_h1=float("nan"), error_h1_semi=float("nan"), error_l2=float("nan"))
                    records.append(record)
                    if progress is not None:
                        progress(record)
    return records


def _warm_up(scene, spec, stabilizations, solvers):
    """One untimed assembly and solve per stabilization and solver on a 2 x 2 mesh: the first call of
    a kernel in a process loads its compiled code, which is no cost of the configuration timed next."""
    from vemkit.mesh.families import build_mesh
    from vemkit.contact.problem import scene_problem

    mesh = build_mesh(spec["family"], 2, **(spec.get("options") or {}))
    for stab in stabilizations:
        problem = scene_problem(scene.with_overrides([f"discretization.stabilization={stab}"]), mesh)
        for solver in solvers:
            guarded_solve(problem, {**scene.solver_options, "method": solver}, time_budget=10.0, check_tol=None)


def _smallest_edge(mesh) -> float:
    e = mesh.vertices[mesh.edges]
    return float(np.min(np.linalg.norm(e[:, 1] - e[:, 0], axis=1)))


def pareto_front(cost, error) -> np.ndarray:
    """Boolean mask of the points not dominated: no other point is at most as costly and more accurate.

    Points with a non-finite cost or error are never on the front; of equal points the first counts.
    """
    cost = np.asarray(cost, dtype=float)
    error = np.asarray(error, dtype=float)
    on = np.zeros(cost.shape, dtype=bool)
    best = np.inf
    for i in np.lexsort((error, cost)):
        if np.isfinite(cost[i]) and np.isfinite(error[i]) and error[i] < best:
            on[i] = True
            best = error[i]
    return on


def describe(ds, i) -> str:
    """One run as "family, solver, tol, stabilization, n"."""
    return (f"{ds['family'].values[i]}, {ds['solver'].values[i]} (tol {float(ds['tol'].values[i]):.0e}), "
            f"{ds['stabilization'].values[i]}, n = {int(ds['n'].values[i])}")


def cheapest_for_targets(ds, targets, error: str = "error_h1") -> list[dict]:
    """For each target error: the converged run reaching it at the least wall time, and at the fewest DOFs."""
    ok = (ds["status"].values == 0) & np.isfinite(ds[error].values)
    out = []
    for target in targets:
        reach = ok & (ds[error].values <= target)
        row = {"target": float(target), "reached": bool(reach.any())}
        for cost in ("cost_time", "n_dofs"):
            if reach.any():
                values = np.where(reach, ds[cost].values.astype(float), np.inf)
                i = int(np.argmin(values))
                row[cost] = {"run": i, "configuration": describe(ds, i), "cost_time": float(ds["cost_time"].values[i]),
                             "n_dofs": int(ds["n_dofs"].values[i]), "error": float(ds[error].values[i])}
        if not reach.any() and ok.any():
            i = int(np.argmin(np.where(ok, ds[error].values, np.inf)))
            row["closest"] = {"run": i, "configuration": describe(ds, i), "error": float(ds[error].values[i])}
        out.append(row)
    return out


def _loglog_interpolate(x_known, y_known, x):
    order = np.argsort(x_known)
    return np.exp(np.interp(np.log(x), np.log(np.asarray(x_known)[order]), np.log(np.asarray(y_known)[order])))


def refinement_gain(ds, uniform: str, refined: str, *, solver: str, tol: float, stabilization: str,
                    error: str = "error_h1") -> dict:
    """Refinement at Gamma_C (family ``refined``) against uniform refinement (``uniform``).

    error_ratio: e_uniform(d) / e_refined(d) at the refined runs' DOFs d inside both DOF ranges
    (> 1: refining at Gamma_C is more accurate at equal DOFs), with its geometric mean;
    dofs_ratio: d_uniform(e) / d_refined(e) at the refined runs' errors inside both error ranges.
    """
    def runs(label):
        sel = ((ds["family"].values == label) & (ds["solver"].values == solver) & (ds["status"].values == 0)
               & (ds["stabilization"].values == stabilization) & np.isclose(ds["tol"].values, tol)
               & np.isfinite(ds[error].values))
        d, e = ds["n_dofs"].values[sel].astype(float), ds[error].values[sel].astype(float)
        return d[np.argsort(d)], e[np.argsort(d)]

    du, eu = runs(uniform)
    dr, er = runs(refined)
    result = {"uniform": uniform, "refined": refined, "solver": solver, "tol": tol, "stabilization": stabilization,
              "error": error, "error_ratio": [], "dofs_ratio": []}
    if du.size < 2 or dr.size < 1:
        result["note"] = "not enough converged runs to interpolate"
        return result
    inside = (dr >= du.min()) & (dr <= du.max())
    ratios = _loglog_interpolate(du, eu, dr[inside]) / er[inside]
    result["error_ratio"] = [{"n_dofs": int(d), "ratio": float(r)} for d, r in zip(dr[inside], ratios)]
    inside_e = (er >= eu.min()) & (er <= eu.max())
    d_needed = _loglog_interpolate(eu, du, er[inside_e])
    result["dofs_ratio"] = [{"error": float(e), "ratio": float(r)} for e, r in zip(er[inside_e], d_needed / dr[inside_e])]
    for key in ("error_ratio", "dofs_ratio"):
        values = [r["ratio"] for r in result[key]]
        result[f"{key}_geometric_mean"] = float(np.exp(np.mean(np.log(values)))) if values else float("nan")
    return result


def tradeoff_dataset(records, *, targets=(0.1, 0.05, 0.02, 0.01), gains=(), error: str = "error_h1",
                     scene_yaml: str = "", settings=None) -> xr.Dataset:
    """Records -> Dataset (dim ``run``) with the Pareto masks, the cheapest-configuration answers
    (attribute ``cheapest``, JSON) and the refinement gains (``gains``: dicts of refinement_gain
    keyword arguments; attribute ``refinement_gain``, JSON). NaN where a run did not converge."""
    import vemkit

    records = list(records)
    if not records:
        raise ValueError("no trade-off runs to gather")
    ds = xr.Dataset(coords={"run": ("run", np.arange(len(records)))})
    for key in RECORD_STRINGS:
        ds[key] = ("run", np.array([str(r[key]) for r in records], dtype=object))
    for key in RECORD_FLOATS:
        ds[key] = ("run", np.array([float(r[key]) for r in records]))
    for key in RECORD_INTS:
        ds[key] = ("run", np.array([int(r[key]) for r in records], dtype=np.int64))
    units = {"wall_time": "s", "assembly_time": "s", "mesh_time": "s", "cost_time": "s", "h_min": "mm"}
    long_names = {
        "error_h1": "||Pi_1(u_h - u_ref)||_H1 / ||Pi_1 u_ref||_H1 (full H1 norm)", "error_h1_semi": "same, H1 seminorm",
        "error_l2": "same, L2 norm", "cost_time": "assembly + contact solve (linear solver set-up included)",
        "wall_time": "contact solve, best of the repeats", "mesh_time": "mesh generation (not in cost_time)",
        "residual": "worst independent check (vemkit.studies.robustness)", "tol": "solver tolerance", "h_min": "shortest edge",
        "family": "mesh family label", "family_name": "build_mesh family",
    }
    for key in ds.data_vars:
        ds[key].attrs.update({k: v for k, v in (("units", units.get(key)), ("long_name", long_names.get(key))) if v})
    ds["status"].attrs.update({"flag_values": np.arange(len(STATUS_MEANINGS), dtype=np.int64),
                               "flag_meanings": " ".join(STATUS_MEANINGS)})
    ok = ds["status"].values == 0
    for cost, name in (("cost_time", "pareto_time"), ("n_dofs", "pareto_dofs")):
        front = pareto_front(np.where(ok, ds[cost].values.astype(float), np.nan), np.where(ok, ds[error].values, np.nan))
        ds[name] = ("run", front.astype(np.int8), {"long_name": f"1 on the Pareto front of {error} against {cost}",
                                                   "flag_values": np.array([0, 1], np.int8), "flag_meanings": "dominated front"})
    cheapest = cheapest_for_targets(ds, targets, error)
    gain_results = [refinement_gain(ds, error=error, **g) for g in gains]
    ds.attrs.update({"title": "vemkit speed-accuracy study", "Conventions": "CF-1.8", "error": error, "scene": scene_yaml,
                     "settings": json.dumps(settings or {}, sort_keys=True, default=str),
                     "cheapest": json.dumps(cheapest), "refinement_gain": json.dumps(gain_results),
                     "vemkit_version": vemkit.__version__,
                     "missing_values": "errors of runs that did not converge (status != 0): _FillValue -9999.0"})
    return ds


def _percent(x) -> str:
    return f"{100 * x:.3g}%"


def tradeoff_markdown(ds) -> str:
    """The Markdown answer: cheapest configuration per target error, the Pareto fronts, the Gamma_C gain."""
    error = ds.attrs.get("error", "error_h1")
    settings = json.loads(ds.attrs.get("settings", "{}"))
    lines = ["# Speed against accuracy", "",
             f"Error: `{error}`, relative to the reference {settings.get('reference', '')} (one reference for every "
             "stabilization). Cost: wall time of assembly + contact solve (linear solver set-up included, mesh "
             "generation excluded), and free unknowns (DOFs). "
             f"{ds.sizes['run']} runs, {int(np.sum(ds['status'].values == 0))} converged.", "",
             "| target error | cheapest in wall time | time [s] | DOFs | error | fewest DOFs | DOFs | time [s] | error |",
             "|---|---|---:|---:|---:|---|---:|---:|---:|"]
    answers = json.loads(ds.attrs["cheapest"])
    for row in answers:
        if not row["reached"]:
            closest = row.get("closest")
            lines.append(f"| {_percent(row['target'])} | not reached" + (
                f" (best: {closest['configuration']}, {_percent(closest['error'])})" if closest else "") + " | | | | | | | |")
            continue
        t, d = row["cost_time"], row["n_dofs"]
        lines.append(f"| {_percent(row['target'])} | {t['configuration']} | {t['cost_time']:.3f} | {t['n_dofs']} | "
                     f"{_percent(t['error'])} | {d['configuration']} | {d['n_dofs']} | {d['cost_time']:.3f} | {_percent(d['error'])} |")
    lines.append("")
    for row in answers:
        if row["reached"]:
            t = row["cost_time"]
            lines.append(f"**For {_percent(row['target'])} error the cheapest configuration is** {t['configuration']}: "
                         f"{t['cost_time']:.3f} s, {t['n_dofs']} DOFs, error {_percent(t['error'])}.  ")
    for cost, name, title in (("cost_time", "pareto_time", "wall time"), ("n_dofs", "pareto_dofs", "DOFs")):
        idx = np.flatnonzero(ds[name].values == 1)
        idx = idx[np.argsort(ds[cost].values[idx])]
        lines += ["", f"## Pareto front: {error} against {title}", "", "| configuration | time [s] | DOFs | error |",
                  "|---|---:|---:|---:|"]
        lines += [f"| {describe(ds, i)} | {float(ds['cost_time'].values[i]):.3f} | {int(ds['n_dofs'].values[i])} | "
                  f"{_percent(float(ds[error].values[i]))} |" for i in idx]
    gains = json.loads(ds.attrs.get("refinement_gain", "[]"))
    if gains:
        lines += ["", "## Refinement at Γ_C against uniform refinement, at equal DOFs", "",
                  "error ratio = e_uniform / e_refined at the refined runs' DOFs (> 1: refining at Γ_C is more "
                  "accurate); DOFs ratio = DOFs the uniform family needs for the refined run's error.", "",
                  "| refined | uniform | settings | error ratio (geo. mean) | DOFs ratio (geo. mean) | per DOFs |",
                  "|---|---|---|---:|---:|---|"]
        for g in gains:
            per = ", ".join(f"{r['n_dofs']}: {r['ratio']:.3f}" for r in g["error_ratio"]) or g.get("note", "")
            lines.append(f"| {g['refined']} | {g['uniform']} | {g['solver']}, tol {g['tol']:.0e}, {g['stabilization']} | "
                         f"{g.get('error_ratio_geometric_mean', float('nan')):.3f} | "
                         f"{g.get('dofs_ratio_geometric_mean', float('nan')):.3f} | {per} |")
    failed = np.flatnonzero(ds["status"].values != 0)
    if failed.size:
        lines += ["", "## Runs that did not converge", ""]
        lines += [f"- {describe(ds, i)}: {STATUS_MEANINGS[int(ds['status'].values[i])]}: {ds['message'].values[i]}"
                  for i in failed]
    return "\n".join(lines) + "\n"
