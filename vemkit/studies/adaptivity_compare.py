"""Adaptive against uniform refinement, read from two ``vemkit adapt`` files (docs/reference/files.md).

Both runs start from the scene's mesh; the uniform one marks every cell (``adaptivity.marking.dorfler
= 1``), so both record the same history (``adapt_*``). Compared here:

- the fitted rate: the slope of log(error) against log(DOFs), least squares over the steps with at
  least ``ASYMPTOTIC_FROM`` times the first step's DOFs (the pre-asymptotic coarse steps left out);
  the optimal rate of k = 1 elements is −1/2 (error ~ N^−1/2);
- the DOFs at equal error: the DOFs each run needs to reach an error, by log-log interpolation
  between its steps (None beyond its range); ``dofs_ratio`` = uniform / adaptive at the finest
  uniform step's error, and at a target error (1 %);
- the wall time to reach that error: the adaptive loop's cumulative wall time up to the step that
  reaches it (every step, as the loop must run them; the true-error measurement excluded), against
  the uniform run's single step at that error (one solve on that mesh: no coarser level needed);
- the effectivity estimate / true error over the steps (its range).
"""

from __future__ import annotations

import json

import numpy as np

ASYMPTOTIC_FROM = 8.0  # fit the rate over the steps with >= this x the first step's DOFs (at least 3 steps)


def history(ds) -> dict:
    """The per-step arrays of an adaptive file: n_dofs, estimate, true_error(_h1), wall_time, ... (floats)."""
    return {
        name[len("adapt_") :]: np.asarray(ds[name].values, dtype=float)
        for name in ds.data_vars
        if name.startswith("adapt_")
    }


def fitted_rate(dofs, error, start_factor: float = ASYMPTOTIC_FROM) -> dict:
    """Least-squares slope of log(error) against log(DOFs) over the asymptotic steps (module docstring)."""
    dofs, error = np.asarray(dofs, float), np.asarray(error, float)
    use = dofs >= start_factor * dofs[0]
    if use.sum() < 3:
        use = np.arange(dofs.size) >= max(0, dofs.size - 3)
    slope, intercept = np.polyfit(np.log(dofs[use]), np.log(error[use]), 1)
    return {
        "rate": float(slope),
        "constant": float(np.exp(intercept)),
        "from_dofs": int(dofs[use].min()),
        "to_dofs": int(dofs[use].max()),
        "points": int(use.sum()),
    }


def dofs_at_error(dofs, error, target: float):
    """DOFs at which the run first reaches ``target`` (log-log interpolation between steps); None if never."""
    dofs, error = np.asarray(dofs, float), np.asarray(error, float)
    reached = np.flatnonzero(error <= target)
    if reached.size == 0:
        return None
    k = int(reached[0])
    if k == 0:
        return float(dofs[0])
    s = np.log(error[k - 1] / target) / np.log(error[k - 1] / error[k])
    return float(np.exp(np.log(dofs[k - 1]) + s * np.log(dofs[k] / dofs[k - 1])))


def _time_to(steps: dict, target: float, cumulative: bool):
    reached = np.flatnonzero(steps["error"] <= target)
    if reached.size == 0:
        return None
    k = int(reached[0])
    return float(np.sum(steps["wall_time"][: k + 1]) if cumulative else steps["solve_time"][k])


def compare(adaptive, uniform, error: str = "true_error_h1", targets=(0.01,)) -> dict:
    """The comparison of the module docstring; ``adaptive``/``uniform`` are :func:`history` dicts."""
    runs = {name: {**h, "error": h[error]} for name, h in (("adaptive", adaptive), ("uniform", uniform))}
    adaptive, uniform = runs["adaptive"], runs["uniform"]
    out = {"error": error, "rates": {}, "estimate_rates": {}}
    for name, h in runs.items():
        out["rates"][name] = fitted_rate(h["n_dofs"], h["error"])
        out["estimate_rates"][name] = fitted_rate(h["n_dofs"], h["estimate"])
        if "effectivity" in h:
            out[f"effectivity_{name}"] = [float(h["effectivity"].min()), float(h["effectivity"].max())]
    finest = float(uniform["error"][-1])
    adaptive_dofs = dofs_at_error(adaptive["n_dofs"], adaptive["error"], finest)
    out["finest_uniform"] = {
        "error": finest,
        "uniform_dofs": int(uniform["n_dofs"][-1]),
        "adaptive_dofs": adaptive_dofs,
        "dofs_ratio": None if adaptive_dofs is None else float(uniform["n_dofs"][-1] / adaptive_dofs),
        "uniform_time": float(uniform["solve_time"][-1]),
        "adaptive_time": _time_to(adaptive, finest, True),
    }
    out["targets"] = []
    for target in targets:
        a, u = (
            dofs_at_error(adaptive["n_dofs"], adaptive["error"], target),
            dofs_at_error(uniform["n_dofs"], uniform["error"], target),
        )
        out["targets"].append(
            {
                "target": float(target),
                "adaptive_dofs": a,
                "uniform_dofs": u,
                "dofs_ratio": None if a is None or u is None else float(u / a),
                "adaptive_time": _time_to(adaptive, target, True),
                "uniform_time": _time_to(uniform, target, False),
            }
        )
    return out


def _number(value, fmt: str) -> str:
    return "—" if value is None else format(value, fmt)


def summary_markdown(comparisons: dict) -> str:
    """{scene: compare(...)} as the Markdown table of results/adaptive/summary.md."""
    lines = [
        "# Adaptive against uniform refinement",
        "",
        "Rates: slope of log(error) against log(DOFs) over the asymptotic steps (optimal for k = 1: −1/2 in 2D, −1/3 in 3D). "
        "DOFs ratio: uniform / adaptive DOFs at the finest uniform step's error. Times: the adaptive loop's "
        "cumulative wall time to that error against the uniform run's single solve there.",
        "",
        "| scene | error | rate adaptive | rate uniform | finest uniform error | DOFs uniform | DOFs adaptive "
        "| DOFs ratio | time adaptive [s] | time uniform [s] | effectivity (adaptive) |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    for scene, c in comparisons.items():
        f = c["finest_uniform"]
        eff = c.get("effectivity_adaptive")
        lines.append(
            f"| {scene} | {c['error']} | {c['rates']['adaptive']['rate']:.3f} | {c['rates']['uniform']['rate']:.3f} | "
            f"{f['error']:.3e} | {f['uniform_dofs']} | {_number(f['adaptive_dofs'], '.0f')} | "
            f"{_number(f['dofs_ratio'], '.2f')} | {_number(f['adaptive_time'], '.2f')} | {f['uniform_time']:.2f} | "
            f"{'—' if eff is None else f'{eff[0]:.2f} – {eff[1]:.2f}'} |"
        )
    lines += [
        "",
        "| scene | target error | DOFs adaptive | DOFs uniform | DOFs ratio | time adaptive [s] | time uniform [s] |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for scene, c in comparisons.items():
        for t in c["targets"]:
            lines.append(
                f"| {scene} | {100 * t['target']:.3g} % | {_number(t['adaptive_dofs'], '.0f')} | "
                f"{_number(t['uniform_dofs'], '.0f')} | {_number(t['dofs_ratio'], '.2f')} | "
                f"{_number(t['adaptive_time'], '.2f')} | {_number(t['uniform_time'], '.2f')} |"
            )
    return "\n".join(lines) + "\n"


def summary_json(comparisons: dict) -> str:
    return json.dumps(comparisons, indent=1, default=float) + "\n"


# -- the runs of a comparison (the workflow's rules and benchmarks/adaptivity.py) -----------------------
def run_settings(case: dict, mode: str):
    """AdaptivitySettings of the ``adaptive`` or ``uniform`` run of a case of config/adaptivity.yaml:
    {theta, target, max_dofs, max_steps, max_hanging, uniform_steps}; uniform marks every cell."""
    from vemkit.studies.adaptivity import AdaptivitySettings

    if mode == "uniform":
        return AdaptivitySettings(theta=1.0, target=1e-9, max_dofs=10**8, max_steps=int(case["uniform_steps"]))
    return AdaptivitySettings(
        theta=case["theta"],
        target=case["target"],
        max_dofs=case["max_dofs"],
        max_steps=case["max_steps"],
        max_hanging=case.get("max_hanging"),
    )


def reference_dataset(scene, reference: dict, theta: float = 0.5, progress=None):
    """A reference solution Dataset (a ``vemkit solve`` file) of ``scene``: ``{"uniform": L}`` the scene's
    mesh refined uniformly L times (new vertices on curved sides), solved and checked once;
    ``{"adaptive": N}`` the adaptive loop with ``theta`` up to N DOFs (nested with every run from the
    same mesh: the common-refinement error of ``adaptivity_errors`` is exact on straight sides)."""
    import numpy as np

    from vemkit.mesh.meshing import scene_mesh
    from vemkit.mesh.refine import refine_cells
    from vemkit.studies.adaptivity import AdaptivitySettings, adapt, adaptive_dataset, curved_sides
    from vemkit.studies.scene_solve import solve_scene

    ((kind, size),) = reference.items()
    if kind == "uniform":
        mesh, circles = scene_mesh(scene), curved_sides(scene.domain)
        for _ in range(int(size)):
            mesh = refine_cells(mesh, np.arange(mesh.n_cells), circles=circles).mesh
        ds = solve_scene(scene, mesh=mesh, verify=True)[2]
    else:
        settings = AdaptivitySettings(theta=theta, target=1e-9, max_dofs=int(size), max_steps=1000)
        ds = adaptive_dataset(scene, adapt(scene, settings, progress=progress))
    ds.attrs["reference_kind"] = f"{kind}: {size}"
    return ds


def tradeoff_records(
    scene,
    reference,
    *,
    theta: float,
    max_dofs: int,
    solvers,
    tolerances,
    stabilization: str,
    max_iterations=None,
    label: str = "adaptive",
    progress=None,
) -> list[dict]:
    """The adaptive loop as configurations of the speed-accuracy study (``vemkit.studies.tradeoff``): one
    record per step and (solver, tolerance), errors against the study's ``reference`` (a ReferenceSolution;
    the common-refinement measure of ``adaptivity_errors``, exact where the adapted mesh is finer), cost =
    the loop's cumulative wall time up to that step (every earlier step is part of the price). A solve
    that fails ends its run with a failed record (status of ``vemkit.solvers.verification``)."""
    import numpy as np

    from vemkit.solvers.verification import failed
    from vemkit.studies.adaptivity import AdaptivitySettings, adapt
    from vemkit.studies.adaptivity_errors import reference_errors

    records = []
    run_scene = scene.with_overrides([f"discretization.stabilization={stabilization}"])
    for solver in solvers:
        for tol in tolerances:
            options = [f"solver.method={solver}", f"solver.tol={float(tol)}"]
            if solver == "uzawa":
                options += [f"solver.eps_u={float(tol)}", f"solver.eps_lambda={float(tol)}"]
            if (max_iterations or {}).get(solver):
                options.append(f"solver.max_iterations={int(max_iterations[solver])}")
            base = {
                "family": label,
                "family_name": f"adaptive (theta {theta:g})",
                "solver": solver,
                "tol": float(tol),
                "stabilization": stabilization,
                "n": int(scene.mesh_options.get("n", 0)),
                "mesh_time": 0.0,
            }
            spent = [0.0]

            def record(step, run, base=base, spent=spent):
                r, mesh = run.history[-1], run.problem.mesh
                spent[0] += r["wall_time"]
                edges = mesh.vertices[mesh.edges]
                found = reference_errors(mesh, run.problem.projected(run.solution.u), reference)
                records.append(
                    {
                        **base,
                        "n_dofs": int(r["n_dofs"]),
                        "n_cells": int(r["n_cells"]),
                        "h_min": float(np.min(np.linalg.norm(edges[:, 1] - edges[:, 0], axis=1))),
                        "iterations": int(r["iterations"]),
                        "status": 0,
                        "message": f"step {step + 1}",
                        "wall_time": float(r["solve_time"]),
                        "assembly_time": 0.0,
                        "cost_time": spent[0],
                        "residual": float(run.checks.get("check_worst", np.nan)),
                        **found,
                    }
                )
                if progress is not None:
                    progress(records[-1])

            try:
                adapt(
                    run_scene.with_overrides(options),
                    AdaptivitySettings(theta=theta, target=1e-9, max_dofs=max_dofs, max_steps=1000),
                    observe=record,
                )
            except Exception as exc:  # noqa: BLE001 - a failed configuration is a record, as in tradeoff.run_family
                outcome = failed(solver, exc, "solve")
                nan = float("nan")
                records.append(
                    {
                        **base,
                        "n_dofs": 0,
                        "n_cells": 0,
                        "h_min": nan,
                        "iterations": outcome.iterations,
                        "status": outcome.code,
                        "message": outcome.message,
                        "wall_time": nan,
                        "assembly_time": 0.0,
                        "cost_time": nan,
                        "residual": nan,
                        "error_h1": nan,
                        "error_h1_semi": nan,
                        "error_l2": nan,
                    }
                )
    return records
