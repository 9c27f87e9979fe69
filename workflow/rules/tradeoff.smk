# The speed-accuracy study (vemkit.studies.tradeoff): one job per mesh family runs every level, solver,
# tolerance and stabilization of config/sweeps.yaml (tradeoff) and measures the errors against the
# reference solution of the main workflow (common.smk: reference_file); one job gathers them into
# results/tradeoff/tradeoff.nc, the Markdown answer pareto.md and the plot pareto.png.
# Needs common.smk (the reference) and sweeps.smk (the configuration) included first.

if "SWEEPS_CONFIG" not in globals() or "reference_file" not in globals():
    raise WorkflowError("workflow/rules/tradeoff.smk needs common.smk and sweeps.smk included before it")

TRADEOFF = SWEEPS_CONFIG["tradeoff"]
TRADEOFF_TARGETS = ["results/tradeoff/tradeoff.nc", "results/tradeoff/pareto.md", "results/tradeoff/pareto.png"]
EXTRAS_TARGETS += TRADEOFF_TARGETS


def _check_tradeoff():
    for i, gain in enumerate(TRADEOFF["refinement_gain"]):
        for key in ("uniform", "refined"):
            if gain[key] not in TRADEOFF["families"]:
                raise WorkflowError(f"{SWEEPS_CONFIG_FILE}: tradeoff.refinement_gain[{i}].{key} = {gain[key]!r} is not "
                                    f"a family of tradeoff.families ({', '.join(TRADEOFF['families'])})")
    too_fine = [n for n in TRADEOFF["levels"] if n > REF["n"]]
    if too_fine:
        raise WorkflowError(f"{SWEEPS_CONFIG_FILE}: tradeoff.levels lists {too_fine[0]} > reference n = {REF['n']} "
                            "(config/config.yaml): errors are measured against the finer reference")


_check_tradeoff()


def tradeoff_settings():
    return {
        "scene": config["scene"],
        "overrides": config["overrides"] + [f"solver.{k}={v}" for k, v in config["solver"].items()],
        "reference": {"mesh": REF["mesh"], "n": REF["n"], "stabilization": TRADEOFF["reference_stabilization"]},
        **{k: v for k, v in TRADEOFF.items() if k != "families"},
    }


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
        "../scripts/tradeoff.py"


rule tradeoff:
    input:
        [f"results/tradeoff/runs/{family}.json" for family in TRADEOFF["families"]],
    output:
        nc="results/tradeoff/tradeoff.nc",
        md="results/tradeoff/pareto.md",
        png="results/tradeoff/pareto.png",
    params:
        settings=tradeoff_settings(),
    log:
        "logs/tradeoff/gather.log",
    script:
        "../scripts/tradeoff.py"


localrules:
    tradeoff,
