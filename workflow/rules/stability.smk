# The solver-robustness matrix (vemkit.studies.robustness): every case of its CASES (or the list in
# config/sweeps.yaml: stability.cases) with every solver, cut into `parts` jobs, gathered into a
# netCDF file, a Markdown report and a plot. Settings come from common.smk.


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
        "../scripts/stability_part.py"


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
        "../scripts/stability_gather.py"


localrules:
    stability,
