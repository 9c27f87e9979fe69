# Errors against the 2^-8 square reference of the same stabilization (SPEC 5), one job per
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
