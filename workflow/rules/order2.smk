# The Section 4 study (issue 14): k = 1 against k = 2 virtual elements on the paper's scene, uniform
# squares and squares refined at Gamma_C (hanging nodes), errors against a k = 2 reference on a fine
# square mesh, observed orders, a figure. Not in the default target: `snakemake -j2 order2`.
#
#   results/order2/solutions/{case}/n{n}.nc    one solve (SPEC §6 file; k = 2 adds edge/cell means)
#   results/order2/reference.nc                the k = 2 reference (square, ORDER2["reference"]["n"])
#   results/order2/errors/{case}.json          the errors of one case at every level
#   results/order2/order2.nc, orders.md        every run, the observed orders (per DOF), the table
#   results/order2/order2.png                  errors against DOFs, log-log
#
# The paper's own measure (SPEC §5) needs vertex values on nested square meshes and a k = 1
# reference: it is reported for the k = 1 cases against the main workflow's 2^-8 reference.
import re

#: the study's settings (cases: a label -> mesh family, its options, the order k and the levels n)
ORDER2 = {
    "stabilization": "dofi-2mu",
    "reference": {"family": "square", "n": 256},
    "cases": {
        "square-k1": {"family": "square", "order": 1, "levels": [4, 8, 16, 32, 64, 128]},
        "square-k2": {"family": "square", "order": 2, "levels": [4, 8, 16, 32, 64]},
        "contact-refined-k1": {"family": "hanging", "options": {"levels": 2, "rule": "contact"}, "order": 1,
                               "levels": [4, 8, 16, 32]},
        "contact-refined-k2": {"family": "hanging", "options": {"levels": 2, "rule": "contact"}, "order": 2,
                               "levels": [4, 8, 16, 32]},
    },
    "region_radius": 0.1,  # the error shares near the corners and near the contact-zone boundary
}
ORDER2_CASES = list(ORDER2["cases"])


def order2_settings():
    return {
        "scene": config["scene"],
        "overrides": config["overrides"] + [f"solver.{k}={v}" for k, v in config["solver"].items()]
        + [f"discretization.stabilization={ORDER2['stabilization']}"],
        **ORDER2,
    }


def order2_solutions(case):
    return [f"results/order2/solutions/{case}/n{n}.nc" for n in ORDER2["cases"][case]["levels"]]


ORDER2_TARGETS = ["results/order2/order2.nc", "results/order2/orders.md", "results/order2/order2.png"]


rule order2_solve:
    output:
        "results/order2/solutions/{case}/n{n}.nc",
    params:
        settings=order2_settings(),
    wildcard_constraints:
        case="|".join(map(re.escape, ORDER2_CASES)),
    log:
        "logs/order2/{case}/n{n}.log",
    benchmark:
        "results/benchmarks/order2/{case}/n{n}.tsv"
    script:
        "../scripts/order2_solve.py"


rule order2_reference:
    output:
        "results/order2/reference.nc",
    params:
        settings=order2_settings(),
    threads: 2
    log:
        "logs/order2/reference.log",
    benchmark:
        "results/benchmarks/order2/reference.tsv"
    script:
        "../scripts/order2_reference.py"


rule order2_errors:
    input:
        solutions=lambda wc: order2_solutions(wc.case),
        reference="results/order2/reference.nc",
        paper_reference=reference_file(ORDER2["stabilization"]),
    output:
        "results/order2/errors/{case}.json",
    params:
        settings=order2_settings(),
    wildcard_constraints:
        case="|".join(map(re.escape, ORDER2_CASES)),
    log:
        "logs/order2/errors/{case}.log",
    script:
        "../scripts/order2_errors.py"


rule order2_gather:
    input:
        [f"results/order2/errors/{case}.json" for case in ORDER2_CASES],
    output:
        nc="results/order2/order2.nc",
        md="results/order2/orders.md",
    params:
        settings=order2_settings(),
    log:
        "logs/order2/gather.log",
    script:
        "../scripts/order2_gather.py"


rule order2_figure:
    input:
        "results/order2/order2.nc",
    output:
        "results/order2/order2.png",
    log:
        "logs/order2/figure.log",
    script:
        "../scripts/order2_figure.py"


rule order2:
    """k = 1 against k = 2 on the paper's scene (issue 14, Section 4; not in the default target)."""
    input:
        ORDER2_TARGETS,


localrules:
    order2,
    order2_gather,
    order2_figure,
