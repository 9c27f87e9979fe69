# The stability matrix (vemkit.studies.robustness): every case of vemkit.studies.robustness.CASES (or the list in
# config/sweeps.yaml: stability.cases) with every solver, cut into `parts` jobs, gathered into a
# netCDF file, a Markdown report and a plot. Needs sweeps.smk (the configuration) included first.

if "SWEEPS_CONFIG" not in globals():
    raise WorkflowError("workflow/rules/stability.smk needs workflow/rules/sweeps.smk included before it")

STABILITY = SWEEPS_CONFIG["stability"]
STABILITY_TARGETS = [f"results/stability/stability.{ext}" for ext in ("nc", "md", "png")]
EXTRAS_TARGETS += STABILITY_TARGETS


def stability_settings():
    return {"scene": SWEEPS_CONFIG["scene"], "overrides": SWEEPS_CONFIG["overrides"], **STABILITY}


rule stability_part:
    output:
        "results/stability/part{part}.nc",
    params:
        settings=stability_settings(),
    wildcard_constraints:
        part=r"\d+",
    log:
        "logs/stability/part{part}.log",
    benchmark:
        "results/benchmarks/stability/part{part}.tsv"
    script:
        "../scripts/stability.py"


rule stability:
    input:
        [f"results/stability/part{i}.nc" for i in range(STABILITY["parts"])],
    output:
        nc="results/stability/stability.nc",
        md="results/stability/stability.md",
        png="results/stability/stability.png",
    params:
        settings=stability_settings(),
    log:
        "logs/stability/gather.log",
    benchmark:
        "results/benchmarks/stability/gather.tsv"
    script:
        "../scripts/stability.py"


localrules:
    stability,
