# Solves of the paper's scene on the meshes of rule mesh, one stabilization each; every solve
# rule has a benchmark. Each solution file also records its own assembly and solver wall times.


rule solve:
    input:
        meshes=["results/meshes/{label}/n{n}.nc"],
    output:
        "results/solutions/{label}/{stab}/n{n}.nc",
    params:
        **solve_params(),
        levels=lambda wc: [wc.n],
    log:
        "logs/solve/{label}/{stab}/n{n}.log",
    benchmark:
        "results/benchmarks/solve/{label}/{stab}/n{n}.tsv"
    script:
        "../scripts/solve.py"


if BATCH:

    # all convergence levels of a (family, stabilization) in one job; the reference and the
    # figure-only meshes by rule solve

    ruleorder: solve_levels > solve

    rule solve_levels:
        input:
            meshes=expand("results/meshes/{{label}}/n{n}.nc", n=LEVEL_TAGS),
        output:
            expand("results/solutions/{{label}}/{{stab}}/n{n}.nc", n=LEVEL_TAGS),
        params:
            **solve_params(),
            levels=LEVEL_TAGS,
        log:
            "logs/solve/{label}/{stab}/levels.log",
        benchmark:
            "results/benchmarks/solve/{label}/{stab}/levels.tsv"
        script:
            "../scripts/solve_levels.py"
