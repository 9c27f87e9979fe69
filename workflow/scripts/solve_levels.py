"""Rule solve_levels: every convergence level of a (family, stabilization) in one job."""

from _helpers import logged, write_solutions

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    write_solutions(smk)
