"""Speed against accuracy, the answers: which configuration is cheapest for a target error.

The runs of :mod:`vemkit.studies.tradeoff` (records with the keys below) become one Dataset
(:func:`tradeoff_dataset`, dim ``run``): :func:`pareto_front` marks the runs no other run beats in
both cost and error; :func:`cheapest_for_targets` answers "for X% error the cheapest configuration
is ..."; :func:`refinement_gain` compares refinement at Gamma_C with uniform refinement at equal
DOFs (piecewise linear interpolation of log error against log DOFs); :func:`tradeoff_markdown`
writes them as Markdown.
"""

from __future__ import annotations

import json

import numpy as np
import xarray as xr

from vemkit.solvers.verification import STATUS_MEANINGS

RECORD_FLOATS = (
    "tol",
    "error_h1",
    "error_h1_semi",
    "error_l2",
    "wall_time",
    "assembly_time",
    "mesh_time",
    "cost_time",
    "residual",
    "h_min",
)
RECORD_INTS = ("n", "n_dofs", "n_cells", "iterations", "status")
#: integer keys a record may omit (k = 1 producers such as the adaptive configuration): their defaults
RECORD_OPTIONAL_INTS = {"order": lambda r: 1, "n_unknowns": lambda r: r["n_dofs"]}
RECORD_STRINGS = ("family", "family_name", "solver", "stabilization", "message")


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
    """One run as "family[ (k = 2)], solver, tol, stabilization, n"."""
    order = int(ds["order"].values[i]) if "order" in ds else 1
    return (
        f"{ds['family'].values[i]}{f' (k = {order})' if order != 1 else ''}, {ds['solver'].values[i]} (tol {float(ds['tol'].values[i]):.0e}), "
        f"{ds['stabilization'].values[i]}, n = {int(ds['n'].values[i])}"
    )


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
                row[cost] = {
                    "run": i,
                    "configuration": describe(ds, i),
                    "cost_time": float(ds["cost_time"].values[i]),
                    "n_dofs": int(ds["n_dofs"].values[i]),
                    "error": float(ds[error].values[i]),
                }
        if not reach.any() and ok.any():
            i = int(np.argmin(np.where(ok, ds[error].values, np.inf)))
            row["closest"] = {"run": i, "configuration": describe(ds, i), "error": float(ds[error].values[i])}
        out.append(row)
    return out


def _loglog_interpolate(x_known, y_known, x):
    order = np.argsort(x_known)
    return np.exp(np.interp(np.log(x), np.log(np.asarray(x_known)[order]), np.log(np.asarray(y_known)[order])))


def refinement_gain(
    ds, uniform: str, refined: str, *, solver: str, tol: float, stabilization: str, error: str = "error_h1"
) -> dict:
    """Refinement at Gamma_C (family ``refined``) against uniform refinement (``uniform``).

    error_ratio: e_uniform(d) / e_refined(d) at the refined runs' DOFs d inside both DOF ranges
    (> 1: refining at Gamma_C is more accurate at equal DOFs), with its geometric mean;
    dofs_ratio: d_uniform(e) / d_refined(e) at the refined runs' errors inside both error ranges.
    """

    def runs(label):
        sel = (
            (ds["family"].values == label)
            & (ds["solver"].values == solver)
            & (ds["status"].values == 0)
            & (ds["stabilization"].values == stabilization)
            & np.isclose(ds["tol"].values, tol)
            & np.isfinite(ds[error].values)
        )
        d, e = ds["n_dofs"].values[sel].astype(float), ds[error].values[sel].astype(float)
        return d[np.argsort(d)], e[np.argsort(d)]

    du, eu = runs(uniform)
    dr, er = runs(refined)
    result = {
        "uniform": uniform,
        "refined": refined,
        "solver": solver,
        "tol": tol,
        "stabilization": stabilization,
        "error": error,
        "error_ratio": [],
        "dofs_ratio": [],
    }
    if du.size < 2 or dr.size < 1:
        result["note"] = "not enough converged runs to interpolate"
        return result
    inside = (dr >= du.min()) & (dr <= du.max())
    ratios = _loglog_interpolate(du, eu, dr[inside]) / er[inside]
    result["error_ratio"] = [{"n_dofs": int(d), "ratio": float(r)} for d, r in zip(dr[inside], ratios)]
    inside_e = (er >= eu.min()) & (er <= eu.max())
    d_needed = _loglog_interpolate(eu, du, er[inside_e])
    result["dofs_ratio"] = [
        {"error": float(e), "ratio": float(r)} for e, r in zip(er[inside_e], d_needed / dr[inside_e])
    ]
    for key in ("error_ratio", "dofs_ratio"):
        values = [r["ratio"] for r in result[key]]
        result[f"{key}_geometric_mean"] = float(np.exp(np.mean(np.log(values)))) if values else float("nan")
    return result


def tradeoff_dataset(
    records, *, targets=(0.1, 0.05, 0.02, 0.01), gains=(), error: str = "error_h1", scene_yaml: str = "", settings=None
) -> xr.Dataset:
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
    for key, default in RECORD_OPTIONAL_INTS.items():
        ds[key] = ("run", np.array([int(r[key]) if key in r else int(default(r)) for r in records], dtype=np.int64))
    units = {"wall_time": "s", "assembly_time": "s", "mesh_time": "s", "cost_time": "s", "h_min": "mm"}
    long_names = {
        "error_h1": "||Pi_k u_h - Pi_1 u_ref||_H1 / ||Pi_1 u_ref||_H1 (full H1 norm; Pi_k: the run's order)",
        "error_h1_semi": "same, H1 seminorm",
        "order": "polynomial order k of the virtual elements",
        "n_dofs": "free DOFs of the discrete space (k = 2: vertex values, edge and cell means)",
        "n_unknowns": "unknowns of the solved system (k = 2: cell means condensed out)",
        "error_l2": "same, L2 norm",
        "cost_time": "assembly + contact solve (linear solver set-up included)",
        "wall_time": "contact solve, best of the repeats",
        "mesh_time": "mesh generation (not in cost_time)",
        "residual": "worst independent check (vemkit.studies.robustness)",
        "tol": "solver tolerance",
        "h_min": "shortest edge",
        "family": "mesh family label",
        "family_name": "build_mesh family",
    }
    for key in ds.data_vars:
        ds[key].attrs.update({k: v for k, v in (("units", units.get(key)), ("long_name", long_names.get(key))) if v})
    ds["status"].attrs.update(
        {"flag_values": np.arange(len(STATUS_MEANINGS), dtype=np.int64), "flag_meanings": " ".join(STATUS_MEANINGS)}
    )
    ok = ds["status"].values == 0
    for cost, name in (("cost_time", "pareto_time"), ("n_dofs", "pareto_dofs")):
        front = pareto_front(
            np.where(ok, ds[cost].values.astype(float), np.nan), np.where(ok, ds[error].values, np.nan)
        )
        ds[name] = (
            "run",
            front.astype(np.int8),
            {
                "long_name": f"1 on the Pareto front of {error} against {cost}",
                "flag_values": np.array([0, 1], np.int8),
                "flag_meanings": "dominated front",
            },
        )
    cheapest = cheapest_for_targets(ds, targets, error)
    gain_results = [refinement_gain(ds, error=error, **g) for g in gains]
    ds.attrs.update(
        {
            "title": "vemkit speed-accuracy study",
            "Conventions": "CF-1.8",
            "error": error,
            "scene": scene_yaml,
            "settings": json.dumps(settings or {}, sort_keys=True, default=str),
            "cheapest": json.dumps(cheapest),
            "refinement_gain": json.dumps(gain_results),
            "vemkit_version": vemkit.__version__,
            "missing_values": "errors of runs that did not converge (status != 0): _FillValue -9999.0",
        }
    )
    return ds


def order_comparison(ds, targets, error: str = "error_h1") -> list[str]:
    """Markdown lines: per target error, the cheapest k = 1 and the cheapest k = 2 run (in wall time)
    and the time ratio; nothing unless both orders were run."""
    orders = ds["order"].values if "order" in ds else np.ones(ds.sizes["run"], dtype=np.int64)
    if not (np.any(orders == 1) and np.any(orders == 2)):
        return []
    best = {k: cheapest_for_targets(ds.isel(run=np.flatnonzero(orders == k)), targets, error) for k in (1, 2)}
    lines = [
        "",
        "## First against second order (k = 1 against k = 2)",
        "",
        "| target error | cheapest k = 1 | time [s] | DOFs | cheapest k = 2 | time [s] | DOFs | time k = 2 / k = 1 |",
        "|---|---|---:|---:|---|---:|---:|---:|",
    ]
    for one, two in zip(best[1], best[2], strict=True):
        cells = []
        for row in (one, two):
            t = row.get("cost_time")
            cells.append(f"{t['configuration']} | {t['cost_time']:.3f} | {t['n_dofs']}" if t else "not reached | | ")
        ratio = (
            f"{two['cost_time']['cost_time'] / one['cost_time']['cost_time']:.2f}"
            if one["reached"] and two["reached"]
            else ""
        )
        lines.append(f"| {_percent(one['target'])} | {cells[0]} | {cells[1]} | {ratio} |")
    return lines


def _percent(x) -> str:
    return f"{100 * x:.3g}%"


def tradeoff_markdown(ds) -> str:
    """The Markdown answer: cheapest configuration per target error, the Pareto fronts, the Gamma_C gain."""
    error = ds.attrs.get("error", "error_h1")
    settings = json.loads(ds.attrs.get("settings", "{}"))
    lines = [
        "# Speed against accuracy",
        "",
        f"Error: `{error}`, relative to the reference {settings.get('reference', '')} (one reference for every "
        "stabilization). Cost: wall time of assembly + contact solve (linear solver set-up included, mesh "
        "generation excluded), and free unknowns (DOFs). "
        f"{ds.sizes['run']} runs, {int(np.sum(ds['status'].values == 0))} converged.",
        "",
        "| target error | cheapest in wall time | time [s] | DOFs | error | fewest DOFs | DOFs | time [s] | error |",
        "|---|---|---:|---:|---:|---|---:|---:|---:|",
    ]
    answers = json.loads(ds.attrs["cheapest"])
    for row in answers:
        if not row["reached"]:
            closest = row.get("closest")
            lines.append(
                f"| {_percent(row['target'])} | not reached"
                + (f" (best: {closest['configuration']}, {_percent(closest['error'])})" if closest else "")
                + " | | | | | | | |"
            )
            continue
        t, d = row["cost_time"], row["n_dofs"]
        lines.append(
            f"| {_percent(row['target'])} | {t['configuration']} | {t['cost_time']:.3f} | {t['n_dofs']} | "
            f"{_percent(t['error'])} | {d['configuration']} | {d['n_dofs']} | {d['cost_time']:.3f} | {_percent(d['error'])} |"
        )
    lines.append("")
    for row in answers:
        if row["reached"]:
            t = row["cost_time"]
            lines.append(
                f"**For {_percent(row['target'])} error the cheapest configuration is** {t['configuration']}: "
                f"{t['cost_time']:.3f} s, {t['n_dofs']} DOFs, error {_percent(t['error'])}.  "
            )
    lines += order_comparison(ds, [row["target"] for row in answers], error)
    for cost, name, title in (("cost_time", "pareto_time", "wall time"), ("n_dofs", "pareto_dofs", "DOFs")):
        idx = np.flatnonzero(ds[name].values == 1)
        idx = idx[np.argsort(ds[cost].values[idx])]
        lines += [
            "",
            f"## Pareto front: {error} against {title}",
            "",
            "| configuration | time [s] | DOFs | error |",
            "|---|---:|---:|---:|",
        ]
        lines += [
            f"| {describe(ds, i)} | {float(ds['cost_time'].values[i]):.3f} | {int(ds['n_dofs'].values[i])} | "
            f"{_percent(float(ds[error].values[i]))} |"
            for i in idx
        ]
    gains = json.loads(ds.attrs.get("refinement_gain", "[]"))
    if gains:
        lines += [
            "",
            "## Refinement at Γ_C against uniform refinement, at equal DOFs",
            "",
            "error ratio = e_uniform / e_refined at the refined runs' DOFs (> 1: refining at Γ_C is more "
            "accurate); DOFs ratio = DOFs the uniform family needs for the refined run's error.",
            "",
            "| refined | uniform | settings | error ratio (geo. mean) | DOFs ratio (geo. mean) | per DOFs |",
            "|---|---|---|---:|---:|---|",
        ]
        for g in gains:
            per = ", ".join(f"{r['n_dofs']}: {r['ratio']:.3f}" for r in g["error_ratio"]) or g.get("note", "")
            lines.append(
                f"| {g['refined']} | {g['uniform']} | {g['solver']}, tol {g['tol']:.0e}, {g['stabilization']} | "
                f"{g.get('error_ratio_geometric_mean', float('nan')):.3f} | "
                f"{g.get('dofs_ratio_geometric_mean', float('nan')):.3f} | {per} |"
            )
    failed = np.flatnonzero(ds["status"].values != 0)
    if failed.size:
        lines += ["", "## Runs that did not converge", ""]
        lines += [
            f"- {describe(ds, i)}: {STATUS_MEANINGS[int(ds['status'].values[i])]}: {ds['message'].values[i]}"
            for i in failed
        ]
    return "\n".join(lines) + "\n"
