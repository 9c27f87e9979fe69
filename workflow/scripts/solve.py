"""Rule solve: the configured scene, one stabilization, on one mesh file."""

from _helpers import logged, write_solutions

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    write_solutions(smk)
