# 3D contact benchmarks (issue 21 items 4-5; vemkit.studies.hertz, vemkit.studies.mindlin),
# configured by the keys hertz: and mindlin: of config/three_d.yaml; part of the `three_d` target.
#
#   results/3d/hertz.nc, hertz.md          P, a, p0 measured against Hertz, per mesh size h
#   results/3d/mindlin.nc, mindlin.md      per mesh and load step: Q/(mu P), c against Mindlin, ssn its, check
#   results/3d/figures/hertz_pressure.png  p(r) against Hertz
#   results/3d/figures/mindlin_shear.png   the shear traction against Johnson's q(r) (the finest mesh)
#   results/3d/figures/mindlin_zones.png   stick / slip / separated on Gamma_C seen from below
THREE_D_CONTACT_TARGETS = [
    f"results/3d/{name}" for name in ("hertz.nc", "hertz.md", "mindlin.nc", "mindlin.md")
] + [f"results/3d/figures/{name}.png" for name in ("hertz_pressure", "mindlin_shear", "mindlin_zones")]


rule three_d_hertz:
    input:
        scene=config["hertz"]["scene"],
    output:
        nc="results/3d/hertz.nc",
        md="results/3d/hertz.md",
        figure="results/3d/figures/hertz_pressure.png",
    params:
        settings=config["hertz"],
        solver=config["three_d"].get("solver", {}),
    log:
        "logs/3d/hertz.log",
    benchmark:
        "results/benchmarks/3d/hertz.tsv"
    script:
        "../scripts/three_d_hertz.py"


rule three_d_mindlin:
    input:
        scene=config["mindlin"]["scene"],
    output:
        nc="results/3d/mindlin.nc",
        md="results/3d/mindlin.md",
        shear="results/3d/figures/mindlin_shear.png",
        zones="results/3d/figures/mindlin_zones.png",
    params:
        settings=config["mindlin"],
    log:
        "logs/3d/mindlin.log",
    benchmark:
        "results/benchmarks/3d/mindlin.tsv"
    script:
        "../scripts/three_d_mindlin.py"
