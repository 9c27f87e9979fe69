# 3D verification (docs/reference/files.md, issue 20 items 7-8; vemkit.studies.three_d), configured by
# config/three_d.yaml. Not in the default target: `snakemake -j2 three_d`.
#
#   results/3d/manufactured/{case}.json       the errors of one manufactured case at every level
#   results/3d/solutions/{case}.nc            its solution at figure_level (mesh3d file, docs/reference/files.md)
#   results/3d/vtu/{case}.vtu                 the same as VTK polyhedra (ParaView)
#   results/3d/convergence.nc, convergence.md every case x level: errors, observed orders
#   results/3d/lame.nc, lame.md               Lame's cylinder against the closed form
#   results/3d/plane_strain.nc, .md           the extruded paper body against 2D plane strain
#   results/3d/plane_stress.nc, .md           the thin plate against 2D plane stress, per depth
#   results/3d/figures/{case}.png             the deformed boundary coloured by von Mises
import re

THREE_D = config["three_d"]
THREE_D_CASES = list(THREE_D["manufactured"])
THREE_D_FIGURES = THREE_D_CASES + ["lame"]
THREE_D_TARGETS = (
    ["results/3d/convergence.nc", "results/3d/convergence.md"]
    + [f"results/3d/{t}.{ext}" for t in ("lame", "plane_strain", "plane_stress") for ext in ("nc", "md")]
    + [f"results/3d/figures/{case}.png" for case in THREE_D_FIGURES]
    + [f"results/3d/vtu/{case}.vtu" for case in THREE_D_FIGURES]
    + THREE_D_CONTACT_TARGETS
)


rule three_d_manufactured:
    input:
        scene=lambda wc: THREE_D["manufactured"][wc.case]["scene"],
    output:
        records="results/3d/manufactured/{case}.json",
        solution="results/3d/solutions/{case}.nc",
        vtu="results/3d/vtu/{case}.vtu",
    params:
        case=lambda wc: THREE_D["manufactured"][wc.case],
        solver=THREE_D["solver"],
        figure_level=THREE_D["figure_level"],
    wildcard_constraints:
        case="|".join(map(re.escape, THREE_D_CASES)),
    log:
        "logs/3d/manufactured/{case}.log",
    benchmark:
        "results/benchmarks/3d/manufactured/{case}.tsv"
    script:
        "../scripts/three_d_manufactured.py"


rule three_d_convergence:
    input:
        [f"results/3d/manufactured/{case}.json" for case in THREE_D_CASES],
    output:
        nc="results/3d/convergence.nc",
        md="results/3d/convergence.md",
    params:
        cases=THREE_D_CASES,
        manufactured=THREE_D["manufactured"],
    log:
        "logs/3d/convergence.log",
    script:
        "../scripts/three_d_convergence.py"


rule three_d_lame:
    input:
        scene=THREE_D["lame"]["scene"],
    output:
        nc="results/3d/lame.nc",
        md="results/3d/lame.md",
        solution="results/3d/solutions/lame.nc",
        vtu="results/3d/vtu/lame.vtu",
    params:
        settings=THREE_D["lame"],
        solver=THREE_D["solver"],
    log:
        "logs/3d/lame.log",
    benchmark:
        "results/benchmarks/3d/lame.tsv"
    script:
        "../scripts/three_d_lame.py"


rule three_d_plane_strain:
    input:
        scene=THREE_D["plane_strain"]["scene"],
    output:
        nc="results/3d/plane_strain.nc",
        md="results/3d/plane_strain.md",
    params:
        settings=THREE_D["plane_strain"],
        solver=THREE_D["solver"],
    log:
        "logs/3d/plane_strain.log",
    benchmark:
        "results/benchmarks/3d/plane_strain.tsv"
    script:
        "../scripts/three_d_plane_strain.py"


rule three_d_plane_stress:
    input:
        scene=THREE_D["plane_stress"]["scene"],
    output:
        nc="results/3d/plane_stress.nc",
        md="results/3d/plane_stress.md",
    params:
        settings=THREE_D["plane_stress"],
        solver=THREE_D["solver"],
    log:
        "logs/3d/plane_stress.log",
    benchmark:
        "results/benchmarks/3d/plane_stress.tsv"
    script:
        "../scripts/three_d_plane_stress.py"


rule three_d_figure:
    input:
        "results/3d/solutions/{case}.nc",
    output:
        "results/3d/figures/{case}.png",
    params:
        magnification=THREE_D["magnification"],
    wildcard_constraints:
        case="|".join(map(re.escape, THREE_D_FIGURES)),
    log:
        "logs/3d/figures/{case}.log",
    script:
        "../scripts/three_d_figure.py"


rule three_d:
    """3D verification: manufactured convergence, Lame, plane strain / plane stress, figures, VTU
    (issue 20 items 7-8; not in the default target)."""
    input:
        THREE_D_TARGETS,


localrules:
    three_d,
    three_d_convergence,
