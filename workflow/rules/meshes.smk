# Every mesh is built once (UGRID netCDF) and read by all the solves on it.


rule mesh:
    output:
        "results/meshes/{label}/n{n}.nc",
    params:
        spec=lambda wc: MESHES[wc.label],
        levels=lambda wc: [wc.n],
    log:
        "logs/mesh/{label}/n{n}.log",
    benchmark:
        "results/benchmarks/mesh/{label}/n{n}.tsv"
    script:
        "../scripts/mesh.py"


if BATCH:

    # the convergence levels of a family in one job (one Python start-up); other n (the
    # reference, figure meshes) by rule mesh

    ruleorder: mesh_levels > mesh

    rule mesh_levels:
        output:
            expand("results/meshes/{{label}}/n{n}.nc", n=LEVEL_TAGS),
        params:
            spec=lambda wc: MESHES[wc.label],
            levels=LEVEL_TAGS,
        log:
            "logs/mesh/{label}/levels.log",
        benchmark:
            "results/benchmarks/mesh/{label}/levels.tsv"
        script:
            "../scripts/mesh_levels.py"
