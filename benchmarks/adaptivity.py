"""Adaptive refinement benchmark (issue 12, item 5). Writes benchmarks/out/adaptivity.{json,md}.

    .venv/bin/python benchmarks/adaptivity.py [--quick] [--scenes lbracket,paper,kirsch,cook]

Per scene of config/adaptivity.yaml, in this one process: the reference solution (or the scene's
exact solution; the workflow's results/adaptive/LABEL/reference.nc is reused when it was made
with the same settings), then the adaptive and the uniform run from the scene's mesh (the workflow's
``snakemake adaptivity`` runs the same: ``vemkit.studies.adaptivity_compare``), compared by
``adaptivity_compare.compare`` on the error config/adaptivity.yaml names: the relative H1-seminorm
error of Π_1 u_h, the full H1 norm for the paper scene (issue 12's measure). Targets:

- lbracket: the adaptive error decays like N^-1/2 (fitted rate <= -0.45) and reaches the finest
  uniform run's error with >= 5x fewer DOFs and less wall time (adaptive: every step of the loop;
  uniform: the one solve on that mesh);
- paper: 1 % relative H1 error against the 2^-10 reference with >= 2x fewer DOFs than uniform squares;
- kirsch: >= 2x fewer DOFs than uniform refinement at equal exact error (the finest uniform run's).

Also measured: the effectivity estimate / true error over each adaptive run, and the warm start
(each solve from the previous step's solution prolongated): total iterations and solve time of
adaptive loops with and without it (paper scene: ssn and uzawa; L-bracket: ssn). ``--quick`` shrinks every
run (a smoke test of the script, not the targets).
"""

from __future__ import annotations

import time
from pathlib import Path

import yaml

from _common import MACHINE, quick_parser, targets_line, write_report

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "config" / "adaptivity.yaml"
DEFAULTS = {
    "error": "true_error",
    "overrides": [],
    "theta": 0.5,
    "target": 1e-3,
    "max_dofs": 200000,
    "max_steps": 60,
    "max_hanging": None,
    "uniform_steps": 5,
    "reference": None,
}
QUICK = {"max_dofs": 20000, "uniform_steps": 4}


def case_of(label: str, quick: bool) -> dict:
    case = {**DEFAULTS, **yaml.safe_load(CONFIG.read_text())["adaptivity_study"]["scenes"][label]}
    if quick:
        case.update(QUICK)
        if case["reference"]:
            kind, size = next(iter(case["reference"].items()))
            case["reference"] = {kind: 5 if kind == "uniform" else 200000}
    return case


def _workflow_reference(label: str, case: dict, quick: bool):
    """The workflow's reference file of this scene (results/adaptive/LABEL/reference.nc) if it was
    computed for the same scene and reference settings: it is an input here, not what is measured."""
    import xarray as xr

    path = ROOT / "results" / "adaptive" / label / "reference.nc"
    if quick or not path.is_file():
        return None
    kind, size = next(iter(case["reference"].items()))
    with xr.open_dataset(path) as ds:
        same = ds.attrs.get("reference_kind") == f"{kind}: {size}"
    return path if same else None


def run_scene(label: str, quick: bool) -> dict:
    from vemkit.config.scene import load_scene
    from vemkit.io.solution_file import write_netcdf
    from vemkit.studies.adaptivity import adapt, adaptive_dataset
    from vemkit.studies.adaptivity_compare import compare, history, reference_dataset, run_settings
    from vemkit.studies.adaptivity_errors import scene_true_error

    case = case_of(label, quick)
    scene_path = ROOT / case["scene"]
    scene = load_scene(scene_path, case["overrides"])
    extra, t0, reused = [], time.perf_counter(), None
    if case["reference"] is not None:
        path = _workflow_reference(label, case, quick)
        reused = str(path) if path is not None else None
        if path is None:
            path = ROOT / "benchmarks" / "out" / f"adaptivity-{label}-reference.nc"
            write_netcdf(reference_dataset(scene, case["reference"], case["theta"]), path)
        extra = [f"adaptivity.reference={path}"]
    reference_time = time.perf_counter() - t0
    scene = load_scene(scene_path, case["overrides"] + extra)
    true_error = scene_true_error(scene)
    runs = {}
    for mode in ("adaptive", "uniform"):
        run = adapt(scene, run_settings(case, mode), true_error=true_error)
        runs[mode] = history(adaptive_dataset(scene, run))
        print(f"{label} {mode}: {len(run.history)} steps, {run.history[-1]['n_dofs']} dofs ({run.reason})", flush=True)
    result = compare(runs["adaptive"], runs["uniform"], case["error"], (0.01,))
    result.update(
        {
            "scene": case["scene"],
            "overrides": case["overrides"],
            "reference": case["reference"],
            "reference_time": reference_time,
            "reference_reused": reused,
            "steps": {
                mode: {
                    k: [float(v) for v in h[k]]
                    for k in ("n_dofs", "estimate", "true_error", "true_error_h1", "wall_time")
                }
                for mode, h in runs.items()
            },
        }
    )
    return result


WARM_CASES = (
    ("paper", ["discretization.mesh.n=8", "solver.method=ssn"], 60000),
    ("paper", ["discretization.mesh.n=8", "solver.method=uzawa"], 60000),
    ("lbracket", ["discretization.mesh.h=2.5", "solver.method=ssn"], 40000),
)


def warm_start(quick: bool) -> list:
    """Adaptive loops with and without the warm start: the paper scene (every contact vertex slips)
    with ssn and uzawa, the L-bracket (m_tau = 1: stick and slip, ssn's joint Newton)."""
    from vemkit.config.scene import load_scene
    from vemkit.studies.adaptivity import AdaptivitySettings, adapt

    rows = []
    for label, overrides, max_dofs in WARM_CASES:
        scene = load_scene(ROOT / "config" / "scenes" / f"{label}.yaml", overrides)
        settings = AdaptivitySettings(theta=0.5, target=1e-6, max_dofs=5000 if quick else max_dofs, max_steps=60)
        adapt(scene, AdaptivitySettings(max_steps=2))  # compiled kernels loaded before the timings
        for warm in (False, True):
            run = adapt(scene, settings, warm_start=warm)
            later = run.history[1:]  # the first step has nothing to start from
            rows.append(
                {
                    "scene": label,
                    "solver": scene.solver_options["method"],
                    "warm_start": warm,
                    "steps": len(run.history),
                    "final_dofs": run.history[-1]["n_dofs"],
                    "iterations": sum(r["iterations"] for r in later),
                    "linear_iterations": sum(r["linear_iterations"] for r in later),
                    "warm_chosen": sum(r["warm_start"] for r in later),
                    "solve_time": sum(r["solve_time"] for r in later),
                    "loop_time": sum(r["wall_time"] for r in run.history),
                }
            )
    return rows


def _lines(results: dict, warm: list, targets: dict, quick: bool) -> list:
    from vemkit.studies.adaptivity_compare import summary_markdown

    lines = [
        f"# Adaptive refinement benchmark ({MACHINE}){' (--quick: not the targets)' if quick else ''}",
        "",
        summary_markdown(results).split("\n", 2)[2],
    ]
    lines += ["## Effectivity estimate / true error over the adaptive runs", ""]
    lines += [
        f"- {k}: {v['effectivity_adaptive'][0]:.2f} – {v['effectivity_adaptive'][1]:.2f} "
        f"(uniform: {v['effectivity_uniform'][0]:.2f} – {v['effectivity_uniform'][1]:.2f})"
        for k, v in results.items()
        if "effectivity_adaptive" in v
    ]
    lines += [
        "",
        "## Warm start (adaptive loops; sums over the steps after the first)",
        "",
        "warm used: steps whose solve started from the prolongated solution (ssn keeps its cold start "
        "when that has the smaller residual).",
        "",
        "| scene | solver | warm start | steps | final DOFs | iterations | linear iterations | warm used | "
        "solve time [s] | loop time [s] |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    lines += [
        f"| {r['scene']} | {r['solver']} | {'yes' if r['warm_start'] else 'no'} | {r['steps']} | {r['final_dofs']} | "
        f"{r['iterations']} | {r['linear_iterations']} | {r['warm_chosen']} | {r['solve_time']:.2f} | "
        f"{r['loop_time']:.2f} |"
        for r in warm
    ]
    lines += ["", targets_line(targets)]
    return lines


def _targets(results: dict) -> dict:
    out = {}
    if "lbracket" in results:
        r = results["lbracket"]
        f = r["finest_uniform"]
        out["lbracket rate <= -0.45"] = r["rates"]["adaptive"]["rate"] <= -0.45
        out["lbracket >= 5x fewer DOFs at the finest uniform error"] = (f["dofs_ratio"] or 0) >= 5
        out["lbracket less wall time"] = f["adaptive_time"] is not None and f["adaptive_time"] < f["uniform_time"]
    if "paper" in results:
        out["paper 1 % with >= 2x fewer DOFs"] = (results["paper"]["targets"][0]["dofs_ratio"] or 0) >= 2
    if "kirsch" in results:
        out["kirsch >= 2x fewer DOFs at equal exact error"] = (
            results["kirsch"]["finest_uniform"]["dofs_ratio"] or 0
        ) >= 2
    return out


def main() -> None:
    parser = quick_parser(__doc__, "small runs and references")
    parser.add_argument(
        "--scenes", default="lbracket,paper,kirsch,cook", help="comma-separated labels of config/adaptivity.yaml"
    )
    args = parser.parse_args()
    results = {label: run_scene(label, args.quick) for label in args.scenes.split(",") if label}
    warm = warm_start(args.quick)
    targets = _targets(results)
    write_report(
        "adaptivity",
        {"machine": MACHINE, "quick": args.quick, "results": results, "warm_start": warm, "targets": targets},
        _lines(results, warm, targets, args.quick),
    )


if __name__ == "__main__":
    main()
