# Errors against the 2^-8 square reference of the same stabilization (docs/reference/mathematics.md), one job per
# family: the references and their quadrature are loaded once for all levels and stabilizations.


rule errors:
    input:
        references=[reference_file(stab) for stab in STABS],
        runs=lambda wc: [solution_file(wc.label, stab, n) for stab in STABS for n in LEVELS],
    output:
        "results/errors/{label}.json",
    params:
        references=lambda wc: {stab: reference_file(stab) for stab in STABS},
        runs=lambda wc: [[stab, n, solution_file(wc.label, stab, n)] for stab in STABS for n in LEVELS],
    log:
        "logs/errors/{label}.log",
    benchmark:
        "results/benchmarks/errors/{label}.tsv"
    script:
        "../scripts/errors.py"


def gauss_overrides():
    """The workflow's scene overrides and solver, with Gauss quadrature on Gamma_C (table1.gauss)."""
    gauss = config["table1"]["gauss"]
    return (config["overrides"] + [f"solver.{k}={v}" for k, v in config["solver"].items()]
            + ["discretization.contact_quadrature=gauss", f"discretization.contact_gauss_points={gauss['points']}"])


# Table 1 with Gauss quadrature on Gamma_C (config table1.gauss): one stabilization, its reference
# and levels solved in this job (~10 s), then measured like rule errors.
rule errors_gauss:
    input:
        meshes=lambda wc: [mesh_file(wc.label, n) for n in LEVELS],
        reference=mesh_file(REF["mesh"], REF["n"]),
    output:
        "results/errors-gauss/{label}.json",
    params:
        scene=config["scene"],
        overrides=lambda wc: gauss_overrides(),
        spec=lambda wc: MESHES[wc.label],
        stabilization=lambda wc: config["table1"]["gauss"]["stabilization"],
        levels=LEVELS,
        reference_n=REF["n"],
    log:
        "logs/errors-gauss/{label}.log",
    benchmark:
        "results/benchmarks/errors-gauss/{label}.tsv"
    script:
        "../scripts/errors_gauss.py"
