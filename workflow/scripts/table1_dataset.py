"""Rule table1_dataset: the square family's error records -> results/table1.nc."""

from _helpers import logged, write_convergence_file

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    write_convergence_file(smk)
