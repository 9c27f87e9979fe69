# The Section 4 study (issue 14): k = 1 against k = 2 virtual elements, uniform squares and squares
# refined at Gamma_C (hanging nodes), on the paper's scene (errors against a k = 2 reference on a fine
# square mesh) and on manufactured contact solutions (config/order2/*.yaml, errors against the exact
# u: sliding, sticking, and a separation point inside Gamma_C), observed orders, figures. Not in the
# default target: `snakemake -j2 order2`.
#
#   results/order2/solutions/{case}/n{n}.nc    one solve (the solution file of docs/reference/files.md; k = 2 adds edge/cell means)
#   results/order2/reference.nc                the k = 2 reference (square, ORDER2["reference"]["n"])
#   results/order2/errors/{case}.json          the errors of one case at every level
#   results/order2/order2.nc, orders.md        every run, the observed orders (per DOF), the table
#   results/order2/order2.png                  errors against DOFs, log-log
#   results/order2/manufactured/{scene}/{case}/n{n}.nc, manufactured/errors/{scene}/{case}.json
#   results/order2/manufactured.nc, manufactured.md, manufactured.png   the same for the exact solutions
#
# The paper's own measure (docs/reference/mathematics.md) needs vertex values on nested square meshes and a k = 1
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
    # the manufactured contact solutions: config/order2/{scene}.yaml (tests/manufactured_contact.py)
    "manufactured": ["sliding", "sticking", "separation"],
    # their extra case: k = 2 with the paper's P_0 f1 in the load (the k = 2 cases above load P_1 f1,
    # the default since issue 18 item 9; the paper scene has no body force: the same either way)
    "manufactured_cases": {
        "square-k2-p0": {"family": "square", "order": 2, "levels": [4, 8, 16, 32, 64],
                         "overrides": ["discretization.body_force_projection=p0"]},
    },
}
ORDER2_CASES = list(ORDER2["cases"])
MANUFACTURED = ORDER2["manufactured"]
MANUFACTURED_CASES = {**ORDER2["cases"], **ORDER2["manufactured_cases"]}


def order2_settings():
    return {
        "scene": config["scene"],
        "overrides": config["overrides"] + [f"solver.{k}={v}" for k, v in config["solver"].items()]
        + [f"discretization.stabilization={ORDER2['stabilization']}"],
        **ORDER2,
    }


def manufactured_settings(scene):
    """A manufactured scene with its own material, contact law and solver settings, the study's cases."""
    return {"scene": f"config/order2/{scene}.yaml", "overrides": [], "study": scene, **ORDER2,
            "cases": MANUFACTURED_CASES}


def order2_solutions(case):
    return [f"results/order2/solutions/{case}/n{n}.nc" for n in ORDER2["cases"][case]["levels"]]


def manufactured_solutions(scene, case):
    return [f"results/order2/manufactured/{scene}/{case}/n{n}.nc" for n in MANUFACTURED_CASES[case]["levels"]]


ORDER2_TARGETS = ["results/order2/order2.nc", "results/order2/orders.md", "results/order2/order2.png",
                  "results/order2/manufactured.nc", "results/order2/manufactured.md",
                  "results/order2/manufactured.png"]


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


rule order2_manufactured_solve:
    input:
        "config/order2/{scene}.yaml",
    output:
        "results/order2/manufactured/{scene}/{case}/n{n}.nc",
    params:
        settings=lambda wc: manufactured_settings(wc.scene),
    wildcard_constraints:
        case="|".join(map(re.escape, MANUFACTURED_CASES)),
        scene="|".join(map(re.escape, MANUFACTURED)),
    log:
        "logs/order2/manufactured/{scene}/{case}/n{n}.log",
    benchmark:
        "results/benchmarks/order2/manufactured/{scene}/{case}/n{n}.tsv"
    script:
        "../scripts/order2_solve.py"


rule order2_manufactured_errors:
    input:
        solutions=lambda wc: manufactured_solutions(wc.scene, wc.case),
    output:
        "results/order2/manufactured/errors/{scene}/{case}.json",
    params:
        settings=lambda wc: manufactured_settings(wc.scene),
    wildcard_constraints:
        case="|".join(map(re.escape, MANUFACTURED_CASES)),
        scene="|".join(map(re.escape, MANUFACTURED)),
    log:
        "logs/order2/manufactured/errors/{scene}/{case}.log",
    script:
        "../scripts/order2_manufactured_errors.py"


rule order2_gather:
    input:
        [f"results/order2/errors/{case}.json" for case in ORDER2_CASES],
    output:
        nc="results/order2/order2.nc",
        md="results/order2/orders.md",
    params:
        settings=order2_settings(),
        title="k = 1 against k = 2 on the paper's scene (Section 4 study)",
        measure="Errors relative to a k = 2 reference on fine squares",
    log:
        "logs/order2/gather.log",
    script:
        "../scripts/order2_gather.py"


rule order2_manufactured_gather:
    input:
        [f"results/order2/manufactured/errors/{scene}/{case}.json" for scene in MANUFACTURED for case in MANUFACTURED_CASES],
    output:
        nc="results/order2/manufactured.nc",
        md="results/order2/manufactured.md",
    params:
        settings={**ORDER2, "cases": MANUFACTURED_CASES},
        title="k = 1 against k = 2 on manufactured contact solutions (Section 4 study)",
        measure="Errors relative to the exact solution (config/order2/*.yaml, tests/manufactured_contact.py)",
    log:
        "logs/order2/manufactured_gather.log",
    script:
        "../scripts/order2_gather.py"


rule order2_figure:
    input:
        "results/order2/{table}.nc",
    output:
        "results/order2/{table}.png",
    wildcard_constraints:
        table="order2|manufactured",
    log:
        "logs/order2/figure_{table}.log",
    script:
        "../scripts/order2_figure.py"


rule order2:
    """k = 1 against k = 2 on the paper's scene (issue 14, Section 4; not in the default target)."""
    input:
        ORDER2_TARGETS,


localrules:
    order2,
    order2_gather,
    order2_manufactured_gather,
    order2_figure,
