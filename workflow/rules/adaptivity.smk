# Adaptive against uniform refinement (vemkit.studies.adaptivity, docs/reference/files.md) for the scenes of
# config/adaptivity.yaml (plane bodies, results/adaptive/) and config/adaptivity3d.yaml (3D bodies,
# results/adaptive3d/): per scene a reference solution (2D, unless the scene has an exact one), the
# adaptive and the uniform run (each a `vemkit adapt` file: final solution, error_indicator, adapt_*
# history; plus the meshes of the sequence figure), the figures; one summary of every scene.
# Not in the default target: `snakemake -j2 adaptivity`, `snakemake -j2 adaptivity3d`. Scene files
# that do not exist are skipped.
import re
from pathlib import Path

#: the study's directory under results/ -> its part of the configuration
ADAPTIVE_STUDIES = {"adaptive": config["adaptivity_study"], "adaptive3d": config["adaptivity3d_study"]}
ADAPTIVITY = ADAPTIVE_STUDIES["adaptive"]
ADAPTIVITY_CASE_DEFAULTS = {"overrides": [], "theta": 0.5, "target": 1e-3, "max_dofs": 200000, "max_steps": 60,
                            "max_hanging": None, "uniform_steps": 5, "reference": None, "cut": None}


def adaptive_scenes(study):
    """The labels of a study's scenes whose scene file exists."""
    return [label for label, case in ADAPTIVE_STUDIES[study]["scenes"].items() if Path(case["scene"]).is_file()]


def adaptivity_case(study, label):
    """The settings of one scene of a study, defaults filled in."""
    part = ADAPTIVE_STUDIES[study]
    return {**ADAPTIVITY_CASE_DEFAULTS, "error": part.get("error", "true_error"), "cut": part.get("cut"),
            **part["scenes"][label]}


def adaptivity_reference(study, label):
    """The reference solution a scene's errors are measured against ([] : the scene's exact solution)."""
    return [] if adaptivity_case(study, label)["reference"] is None else [f"results/{study}/{label}/reference.nc"]


def snapshot_count(study):
    return int(ADAPTIVE_STUDIES[study].get("snapshots", 4))


def adaptivity_snapshots(study, label, mode):
    return [f"results/{study}/{label}/{mode}-mesh{k}.nc" for k in range(1, snapshot_count(study) + 1)]


def snapshot_outputs(study):
    """The output patterns of a run's snapshots (their number is the study's)."""
    return [f"results/{{study}}/{{adaptive_scene}}/{{mode}}-mesh{k}.nc" for k in range(1, snapshot_count(study) + 1)]


def adaptivity_targets(study):
    return [f"results/{study}/summary.md"] + [
        f"results/{study}/{label}/{name}.png" for label in adaptive_scenes(study) for name in ("convergence", "meshes")]


def _pattern(labels):
    return "|".join(map(re.escape, labels)) if labels else "noscene"


ADAPTIVITY_SCENES = adaptive_scenes("adaptive")
ADAPTIVITY_SCENE_PATTERN = _pattern(sorted({label for study in ADAPTIVE_STUDIES for label in adaptive_scenes(study)}))
ADAPTIVE_STUDY_PATTERN = _pattern(ADAPTIVE_STUDIES)


def adaptivity_reference_case(study, label):
    """What a reference depends on (other settings may change without recomputing it)."""
    case = adaptivity_case(study, label)
    return {key: case[key] for key in ("scene", "overrides", "theta", "reference")}


rule adaptivity_reference:
    output:
        "results/{study}/{adaptive_scene}/reference.nc",
    params:
        case=lambda wc: adaptivity_reference_case(wc.study, wc.adaptive_scene),
    wildcard_constraints:
        study=ADAPTIVE_STUDY_PATTERN,
        adaptive_scene=ADAPTIVITY_SCENE_PATTERN,
    log:
        "logs/{study}/{adaptive_scene}/reference.log",
    benchmark:
        "results/benchmarks/{study}/{adaptive_scene}/reference.tsv"
    script:
        "../scripts/adaptivity_reference.py"


rule adaptivity_run:
    input:
        reference=lambda wc: adaptivity_reference(wc.study, wc.adaptive_scene),
    output:
        nc="results/{study}/{adaptive_scene}/{mode}.nc",
        snapshots=snapshot_outputs("adaptive"),
    params:
        case=lambda wc: adaptivity_case(wc.study, wc.adaptive_scene),
    wildcard_constraints:
        study="adaptive",
        adaptive_scene=ADAPTIVITY_SCENE_PATTERN,
        mode="adaptive|uniform",
    log:
        "logs/{study}/{adaptive_scene}/{mode}.log",
    benchmark:
        "results/benchmarks/{study}/{adaptive_scene}/{mode}.tsv"
    script:
        "../scripts/adaptivity_run.py"


use rule adaptivity_run as adaptivity3d_run with:
    output:
        nc="results/{study}/{adaptive_scene}/{mode}.nc",
        snapshots=snapshot_outputs("adaptive3d"),
    wildcard_constraints:
        study="adaptive3d",
        adaptive_scene=ADAPTIVITY_SCENE_PATTERN,
        mode="adaptive|uniform",


rule adaptivity_figures:
    input:
        adaptive="results/{study}/{adaptive_scene}/adaptive.nc",
        uniform="results/{study}/{adaptive_scene}/uniform.nc",
        snapshots=lambda wc: adaptivity_snapshots(wc.study, wc.adaptive_scene, "adaptive"),
    output:
        convergence="results/{study}/{adaptive_scene}/convergence.png",
        meshes="results/{study}/{adaptive_scene}/meshes.png",
    params:
        error=lambda wc: adaptivity_case(wc.study, wc.adaptive_scene)["error"],
        cut=lambda wc: adaptivity_case(wc.study, wc.adaptive_scene)["cut"],
    wildcard_constraints:
        study=ADAPTIVE_STUDY_PATTERN,
        adaptive_scene=ADAPTIVITY_SCENE_PATTERN,
    log:
        "logs/{study}/{adaptive_scene}/figures.log",
    script:
        "../scripts/adaptivity_figures.py"


rule adaptivity_summary:
    input:
        adaptive=lambda wc: [f"results/{wc.study}/{label}/adaptive.nc" for label in adaptive_scenes(wc.study)],
        uniform=lambda wc: [f"results/{wc.study}/{label}/uniform.nc" for label in adaptive_scenes(wc.study)],
    output:
        md="results/{study}/summary.md",
        json="results/{study}/summary.json",
    params:
        scenes=lambda wc: adaptive_scenes(wc.study),
        errors=lambda wc: [adaptivity_case(wc.study, label)["error"] for label in adaptive_scenes(wc.study)],
        targets=lambda wc: ADAPTIVE_STUDIES[wc.study].get("targets", [0.01]),
    wildcard_constraints:
        study=ADAPTIVE_STUDY_PATTERN,
    log:
        "logs/{study}/summary.log",
    script:
        "../scripts/adaptivity_summary.py"


rule adaptivity:
    """Adaptive against uniform refinement for every scene of config/adaptivity.yaml (not in `all`)."""
    input:
        adaptivity_targets("adaptive"),


rule adaptivity3d:
    """The same for the 3D bodies of config/adaptivity3d.yaml (issue 36; not in `all`)."""
    input:
        adaptivity_targets("adaptive3d"),


localrules:
    adaptivity,
    adaptivity3d,
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
