"""Rule convergence_dataset: every family's error records -> results/convergence.nc."""

from _helpers import logged, write_convergence_file

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    write_convergence_file(smk)
