# Parameter sweeps (vemkit.studies.sweeps) of config/sweeps.yaml: one job per part of a grid, one
# gathering job, the figures. Settings and targets come from common.smk. Not in the default target.
import re


rule sweep_part:
    output:
        "results/sweeps/{sweep}/part{part}.nc",
    params:
        settings=lambda wc: sweep_settings(wc.sweep),
    wildcard_constraints:
        sweep="|".join(map(re.escape, SWEEPS)),
        part=r"\d+",
    log:
        "logs/sweeps/{sweep}/part{part}.log",
    benchmark:
        "results/benchmarks/sweeps/{sweep}/part{part}.tsv"
    script:
        "../scripts/sweep_part.py"


rule sweep:
    input:
        lambda wc: [f"results/sweeps/{wc.sweep}/part{i}.nc" for i in range(sweep_parts(wc.sweep))],
    output:
        "results/sweeps/{sweep}.nc",
    params:
        settings=lambda wc: sweep_settings(wc.sweep),
    wildcard_constraints:
        sweep="|".join(map(re.escape, SWEEPS)),
    log:
        "logs/sweeps/{sweep}/gather.log",
    benchmark:
        "results/benchmarks/sweeps/{sweep}/gather.tsv"
    script:
        "../scripts/sweep_gather.py"


rule sweep_figure:
    input:
        "results/sweeps/{sweep}.nc",
    output:
        "results/sweeps/{sweep}/{kind}.png",
    params:
        figure=lambda wc: SWEEPS[wc.sweep]["figures"][wc.kind],
    wildcard_constraints:
        sweep="|".join(map(re.escape, SWEEPS)),
        kind="map|lines|profiles",
    log:
        "logs/sweeps/{sweep}/{kind}.log",
    script:
        "../scripts/sweep_figure.py"


rule sweeps_all:
    """Every sweep of config/sweeps.yaml with its figures."""
    input:
        SWEEP_TARGETS,


localrules:
    sweep,
    sweep_figure,
    sweeps_all,
