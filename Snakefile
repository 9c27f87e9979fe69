# Reproduce the paper (Table 1, Figs. 3-6) and the convergence study on every mesh family.
#   snakemake -j2                        everything (rule all)
#   snakemake -j2 results/table1.nc      only what Table 1 needs
#   snakemake --report report.html       the HTML report
# Layout: workflow/rules/*.smk (rules), workflow/scripts/ (thin scripts calling vemkit),
# config/config.yaml, config/sweeps.yaml, config/adaptivity.yaml, config/adaptivity3d.yaml, config/three_d.yaml (Snakemake's
# config; add yours with --configfile), checked in common.smk before any job (also in `snakemake -n`):
# workflow/schemas/*.schema.yaml, then vemkit.studies.workflow_config; a refusal is one line naming the
# file and the key (docs/paper.md, "The configuration and its checks").
from snakemake.utils import min_version

min_version("8.0")


configfile: "config/config.yaml"
configfile: "config/sweeps.yaml"
configfile: "config/adaptivity.yaml"
configfile: "config/adaptivity3d.yaml"
configfile: "config/three_d.yaml"


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/meshes.smk"
include: "workflow/rules/solves.smk"
include: "workflow/rules/errors.smk"
include: "workflow/rules/tables.smk"
include: "workflow/rules/figures.smk"
# beyond the paper (not in `rule all`): `snakemake -j2 extras` -- sweeps, speed-accuracy, stability
include: "workflow/rules/sweeps.smk"
include: "workflow/rules/tradeoff.smk"
include: "workflow/rules/stability.smk"
# k = 1 against k = 2 (issue 14, not in the default target either): `snakemake -j2 order2`
include: "workflow/rules/order2.smk"
# adaptive against uniform refinement (not in `rule all`): `snakemake -j2 adaptivity`, in 3D `adaptivity3d`
include: "workflow/rules/adaptivity.smk"
# the shipped scenes against published references (not in `rule all`): `snakemake -j2 verification`
include: "workflow/rules/verification.smk"
# 3D verification: manufactured convergence, Lame, plane strain / plane stress (not in `rule all`):
# `snakemake -j2 three_d`
include: "workflow/rules/three_d_contact.smk"  # before three_d.smk: its targets join THREE_D_TARGETS
include: "workflow/rules/three_d.smk"


rule all:
    input:
        DEFAULT_TARGETS,
    default_target: True


rule extras:
    """Sweeps, speed-accuracy study and robustness matrix (not in the default target)."""
    input:
        EXTRAS_TARGETS,


localrules:
    extras,
