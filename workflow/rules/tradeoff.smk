# The speed-accuracy study (vemkit.studies.tradeoff): one job per mesh family runs every level, solver,
# tolerance and stabilization of config/sweeps.yaml (tradeoff) and measures the errors against the
# reference solution of the main workflow (common.smk: reference_file); one job gathers them into
# results/tradeoff/tradeoff.nc, the Markdown answer pareto.md and the plot pareto.png.
import re


rule tradeoff_family:
    input:
        reference=reference_file(TRADEOFF["reference_stabilization"]),
    output:
        "results/tradeoff/runs/{family}.json",
    params:
        spec=lambda wc: TRADEOFF["families"][wc.family],
        settings=tradeoff_settings(),
    wildcard_constraints:
        family="|".join(map(re.escape, TRADEOFF["families"])),
    threads: 2  # the solves are single-threaded: the 2nd core keeps other jobs off the timings (-j2 runs it alone)
    log:
        "logs/tradeoff/{family}.log",
    benchmark:
        "results/benchmarks/tradeoff/{family}.tsv"
    script:
        "../scripts/tradeoff_family.py"


rule tradeoff:
    input:
        [f"results/tradeoff/runs/{family}.json" for family in TRADEOFF["families"]] + TRADEOFF_ADAPTIVE,
    output:
        nc="results/tradeoff/tradeoff.nc",
        md="results/tradeoff/pareto.md",
        png="results/tradeoff/pareto.png",
    params:
        settings=tradeoff_settings(),
    log:
        "logs/tradeoff/gather.log",
    script:
        "../scripts/tradeoff_gather.py"


localrules:
    tradeoff,
