# Verification of the shipped scenes (vemkit.studies.verification; not in the default target):
#   snakemake -j2 verification
# One job per (scene, family) solves the scene at every mesh size of its case (CASES) and keeps the
# solution at FIGURE_LEVEL; one job gathers the records into results/verification/verification.nc;
# one job writes the Markdown tables beside the published references and one figure per scene
# (mesh, deformed shape, a stress field) from the FIGURE_FAMILY solutions.
from vemkit.studies.verification import CASES as VERIFICATION_CASES
from vemkit.studies.verification import FAMILY_OPTIONS as VERIFICATION_FAMILIES

VERIFICATION_SCENES = list(VERIFICATION_CASES)
VERIFICATION_FIGURE_FAMILY = "voronoi"  # general polygons: the family VEM exists for
VERIFICATION_FIGURE_LEVEL = 1  # the second-coarsest size: cells still visible in the mesh panel
VERIFICATION_TARGETS = [
    "results/verification/verification.nc",
    "results/verification/verification.md",
] + [f"results/verification/figures/{scene}.png" for scene in VERIFICATION_SCENES]


def verification_run_file(scene, family):
    return f"results/verification/runs/{scene}/{family}.json"


def verification_solution_file(scene, family):
    return f"results/verification/solutions/{scene}/{family}.nc"


rule verification_run:
    input:
        scene="config/scenes/{scene}.yaml",
    output:
        records=verification_run_file("{scene}", "{family}"),
        solution=verification_solution_file("{scene}", "{family}"),
    params:
        figure_level=VERIFICATION_FIGURE_LEVEL,
    wildcard_constraints:
        scene="|".join(VERIFICATION_SCENES),
        family="|".join(VERIFICATION_FAMILIES),
    log:
        "logs/verification/{scene}/{family}.log",
    benchmark:
        "results/benchmarks/verification/{scene}/{family}.tsv"
    script:
        "../scripts/verification_run.py"


rule verification_gather:
    input:
        [verification_run_file(s, f) for s in VERIFICATION_SCENES for f in VERIFICATION_FAMILIES],
    output:
        "results/verification/verification.nc",
    params:
        scenes=VERIFICATION_SCENES,
        families=list(VERIFICATION_FAMILIES),
    log:
        "logs/verification/gather.log",
    script:
        "../scripts/verification_gather.py"


rule verification_report:
    input:
        dataset="results/verification/verification.nc",
        solutions=[verification_solution_file(s, VERIFICATION_FIGURE_FAMILY) for s in VERIFICATION_SCENES],
    output:
        md="results/verification/verification.md",
        figures=[f"results/verification/figures/{scene}.png" for scene in VERIFICATION_SCENES],
    params:
        scenes=VERIFICATION_SCENES,
        family=VERIFICATION_FIGURE_FAMILY,
        level=VERIFICATION_FIGURE_LEVEL,
    log:
        "logs/verification/report.log",
    script:
        "../scripts/verification_report.py"


rule verification:
    """The shipped scenes on every family against their references (not in the default target)."""
    input:
        VERIFICATION_TARGETS,


localrules:
    verification,
    verification_gather,
