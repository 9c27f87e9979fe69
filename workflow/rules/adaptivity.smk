# Adaptive against uniform refinement (vemkit.studies.adaptivity, docs/reference/files.md) for the scenes of
# config/adaptivity.yaml: per scene a reference solution (unless the scene has an exact one), the
# adaptive and the uniform run (each a `vemkit adapt` file: final solution, error_indicator, adapt_*
# history; plus the meshes of the sequence figure), the figures; one summary of every scene.
# Not in the default target: `snakemake -j2 adaptivity`. Scene files that do not exist are skipped.
import re
from pathlib import Path

ADAPTIVITY = config["adaptivity_study"]
ADAPTIVITY_CASE_DEFAULTS = {"overrides": [], "theta": 0.5, "target": 1e-3, "max_dofs": 200000, "max_steps": 60,
                            "max_hanging": None, "uniform_steps": 5, "reference": None}
ADAPTIVITY_SCENES = [label for label, case in ADAPTIVITY["scenes"].items() if Path(case["scene"]).is_file()]
ADAPTIVITY_SNAPSHOTS = int(ADAPTIVITY.get("snapshots", 4))


def adaptivity_case(label):
    """The settings of one scene of config/adaptivity.yaml, defaults filled in."""
    return {**ADAPTIVITY_CASE_DEFAULTS, "error": ADAPTIVITY.get("error", "true_error"), **ADAPTIVITY["scenes"][label]}


def adaptivity_reference(label):
    """The reference solution a scene's errors are measured against ([] : the scene's exact solution)."""
    return [] if adaptivity_case(label)["reference"] is None else [f"results/adaptive/{label}/reference.nc"]


def adaptivity_snapshots(label, mode):
    return [f"results/adaptive/{label}/{mode}-mesh{k}.nc" for k in range(1, ADAPTIVITY_SNAPSHOTS + 1)]


ADAPTIVITY_TARGETS = ["results/adaptive/summary.md"] + [
    f"results/adaptive/{label}/{name}.png" for label in ADAPTIVITY_SCENES for name in ("convergence", "meshes")]


ADAPTIVITY_SCENE_PATTERN = "|".join(map(re.escape, ADAPTIVITY_SCENES)) if ADAPTIVITY_SCENES else "noscene"


def adaptivity_reference_case(label):
    """What a reference depends on (other settings may change without recomputing it)."""
    case = adaptivity_case(label)
    return {key: case[key] for key in ("scene", "overrides", "theta", "reference")}


rule adaptivity_reference:
    output:
        "results/adaptive/{adaptive_scene}/reference.nc",
    params:
        case=lambda wc: adaptivity_reference_case(wc.adaptive_scene),
    wildcard_constraints:
        adaptive_scene=ADAPTIVITY_SCENE_PATTERN,
    log:
        "logs/adaptive/{adaptive_scene}/reference.log",
    benchmark:
        "results/benchmarks/adaptive/{adaptive_scene}/reference.tsv"
    script:
        "../scripts/adaptivity_reference.py"


rule adaptivity_run:
    input:
        reference=lambda wc: adaptivity_reference(wc.adaptive_scene),
    output:
        nc="results/adaptive/{adaptive_scene}/{mode}.nc",
        snapshots=[f"results/adaptive/{{adaptive_scene}}/{{mode}}-mesh{k}.nc" for k in range(1, ADAPTIVITY_SNAPSHOTS + 1)],
    params:
        case=lambda wc: adaptivity_case(wc.adaptive_scene),
    wildcard_constraints:
        adaptive_scene=ADAPTIVITY_SCENE_PATTERN,
        mode="adaptive|uniform",
    log:
        "logs/adaptive/{adaptive_scene}/{mode}.log",
    benchmark:
        "results/benchmarks/adaptive/{adaptive_scene}/{mode}.tsv"
    script:
        "../scripts/adaptivity_run.py"


rule adaptivity_figures:
    input:
        adaptive="results/adaptive/{adaptive_scene}/adaptive.nc",
        uniform="results/adaptive/{adaptive_scene}/uniform.nc",
        snapshots=lambda wc: adaptivity_snapshots(wc.adaptive_scene, "adaptive"),
    output:
        convergence="results/adaptive/{adaptive_scene}/convergence.png",
        meshes="results/adaptive/{adaptive_scene}/meshes.png",
    params:
        error=lambda wc: adaptivity_case(wc.adaptive_scene)["error"],
    wildcard_constraints:
        adaptive_scene=ADAPTIVITY_SCENE_PATTERN,
    log:
        "logs/adaptive/{adaptive_scene}/figures.log",
    script:
        "../scripts/adaptivity_figures.py"


rule adaptivity_summary:
    input:
        adaptive=[f"results/adaptive/{label}/adaptive.nc" for label in ADAPTIVITY_SCENES],
        uniform=[f"results/adaptive/{label}/uniform.nc" for label in ADAPTIVITY_SCENES],
    output:
        md="results/adaptive/summary.md",
        json="results/adaptive/summary.json",
    params:
        scenes=ADAPTIVITY_SCENES,
        errors=[adaptivity_case(label)["error"] for label in ADAPTIVITY_SCENES],
        targets=ADAPTIVITY.get("targets", [0.01]),
    log:
        "logs/adaptive/summary.log",
    script:
        "../scripts/adaptivity_summary.py"


rule adaptivity:
    """Adaptive against uniform refinement for every scene of config/adaptivity.yaml (not in `all`)."""
    input:
        ADAPTIVITY_TARGETS,


localrules:
    adaptivity,
    adaptivity_summary,


# The speed-accuracy study (tradeoff.smk) gains the adaptive loop as a configuration when
# config/adaptivity.yaml has `tradeoff:` (common.smk: TRADEOFF_ADAPTIVE): same scene, reference and
# solvers/tolerances as the other families, one record per adaptive step.
rule tradeoff_adaptive:
    input:
        reference=reference_file(TRADEOFF["reference_stabilization"]),
    output:
        "results/tradeoff/runs/adaptive.json",
    params:
        settings=tradeoff_settings(),
        adaptive=ADAPTIVITY.get("tradeoff") or {},
    threads: 2  # as tradeoff_family: the second core keeps other jobs off the timings
    log:
        "logs/tradeoff/adaptive.log",
    benchmark:
        "results/benchmarks/tradeoff/adaptive.tsv"
    script:
        "../scripts/adaptivity_tradeoff.py"
