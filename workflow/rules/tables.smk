# The error records gathered in results/table1.nc (square family, the paper's Table 1, and with
# table1.gauss the paper's measure with Gauss quadrature on Gamma_C) and results/convergence.nc
# (every family); the tables as Markdown, CSV and LaTeX; the archive.


rule table1_dataset:
    input:
        errors=[errors_file(config["table1"]["mesh"])],
        gauss=[f"results/errors-gauss/{config['table1']['mesh']}.json"] if config["table1"]["gauss"] else [],
    output:
        "results/table1.nc",
    params:
        families=[config["table1"]["mesh"]],
        gauss=config["table1"]["gauss"],
        stabilizations=STABS,
        scene=config["scene"],
        parameters=workflow_parameters(),
        title="vemkit: Table 1 of the paper (square meshes)",
    log:
        "logs/table1_dataset.log",
    script:
        "../scripts/table1_dataset.py"


rule convergence_dataset:
    input:
        errors=[errors_file(label) for label in config["convergence"]],
        gauss=[],
    output:
        "results/convergence.nc",
    params:
        families=config["convergence"],
        stabilizations=STABS,
        scene=config["scene"],
        parameters=workflow_parameters(),
        title="vemkit: convergence on every mesh family",
        gauss=None,
    log:
        "logs/convergence_dataset.log",
    script:
        "../scripts/convergence_dataset.py"


rule archive:
    """The canonical tables, committed under results/archive/; run it on purpose only."""
    input:
        table1="results/table1.nc",
        convergence="results/convergence.nc",
    output:
        table1="results/archive/table1.nc",
        convergence="results/archive/convergence.nc",
    log:
        "logs/archive.log",
    shell:
        "(cp {input.table1} {output.table1} && cp {input.convergence} {output.convergence}) > {log} 2>&1"


# cheap rules: on a cluster they run where snakemake runs
localrules:
    archive,
    table,
    table1_dataset,
    convergence_dataset,


rule table:
    input:
        "results/{table}.nc",
    output:
        md="results/tables/{table}.md",
        csv=report("results/tables/{table}.csv", caption="../report/tables.rst", category="Tables"),
        tex="results/tables/{table}.tex",
    wildcard_constraints:
        table="table1|convergence",
    log:
        "logs/tables/{table}.log",
    script:
        "../scripts/tables.py"
